"""The result of :func:`chaoscam.solve`, one type for one run and an ensemble: the members'
sections, impacts, series and statuses (tidy, with a ``member`` column) and their settings."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._util import FrozenDict, freeze_fields
from ..kernel import Status, contact_fraction, section_jacobians
from ..kernel import layout as k
from ..model import Params, contact_angle, contact_period, gap, normal_force, truncated_mass
from ..numerics import Numerics
from ._batch import Batch, Resume

if TYPE_CHECKING:
    import pandas as pd

SECTION_COLUMNS = k.SECTION_NAMES
IMPACT_COLUMNS = k.IMPACT_NAMES
IMPACT_KINDS = k.IMPACT_KINDS
SERIES_COLUMNS = ("t", "theta_f", "omega_f", "theta_fc", "gap", "contact", "F_n", "l_lambda")
MEMBER_COLUMNS = (
    "member", "index", "status", "n_impacts", "contact_fraction", "slow_closings",
    "chatter_handovers", "t_end", "theta_f_end", "omega_f_end",
)  # fmt: skip


@dataclass(frozen=True)
class Solution:
    """Members simulated with their settings: what :func:`chaoscam.solve` returns.

    Attributes
    ----------
    models, numerics : tuple of Params, Numerics
        Each member's model (one object shared by members of one model); the integrator.
    settings : dict
        Read-only: duration, transient [s], seed, tangent, output_dt (None without a series),
        impacts (kept or only counted), backend, device, batch, models (digest), version,
        threads, wall_time_s; after :func:`chaoscam.extend` also ``continued_from`` (the grid
        step its members went on from, None when run again) and ``backends`` (each leg's).
    members : pandas.DataFrame
        One row per member (:data:`MEMBER_COLUMNS`): realization ``index``, ``status`` (a
        :class:`Status` name), impacts applied after the transient, the recorded time's
        fraction in contact, closings slower than ``v_min``, chattering-guard hand-overs, and
        where it stopped (``t_end`` [s], ``theta_f_end`` [rad], ``omega_f_end`` [rad/s]).
    sections : pandas.DataFrame
        member, k, t, theta_f, omega_f, l_lambda: the stroboscopic Poincaré section at
        t = k 2 pi / omega after the transient.
    jacobians, divergence : ndarray or None
        With ``tangent=True`` (read-only): the stroboscopic map's Jacobian d(theta_f,
        theta_f')(t_k) / d(theta_f, theta_f')(t_k - T), shape (len(sections), 2, 2), and the
        flow's divergence integrated over the period that ends at each section row (Liouville:
        ln|det J_k| = divergence_k + 2 ln(xi) per restitution jump).
    impacts : pandas.DataFrame or None
        With ``impacts=True``: member and the restitution jumps after the transient
        (:data:`IMPACT_COLUMNS`; kind "macro", "micro" (slower than ``v_micro``) or
        "chatter_end", the plastic closure ending a complete chattering).
    series : pandas.DataFrame or None
        With ``series=True``: member and the series every ``output_dt`` (:data:`SERIES_COLUMNS`).
    resume : Resume or None
        With ``resumable=True`` (RK4): each member's state near its end, for :func:`extend`.
    """

    models: tuple[Params, ...]
    numerics: Numerics
    settings: dict[str, Any]
    members: pd.DataFrame
    sections: pd.DataFrame
    jacobians: np.ndarray | None = field(default=None, repr=False)
    divergence: np.ndarray | None = field(default=None, repr=False)
    impacts: pd.DataFrame | None = field(default=None, repr=False)
    series: pd.DataFrame | None = field(default=None, repr=False)
    resume: Resume | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        freeze_fields(self, "settings", "jacobians", "divergence")

    def __len__(self) -> int:
        return len(self.members)

    def __getitem__(self, member: int) -> Solution:
        return self.select([member])

    @property
    def params(self) -> Params:
        """The model of every member (a ValueError when members have different models)."""
        first = self.models[0]
        if any(p is not first and p != first for p in self.models):
            raise ValueError("the members have different models: see Solution.models")
        return first

    def _only(self, what: str) -> int:
        if len(self) != 1:
            raise ValueError(
                f"{what} is one member's; this solution has {len(self)}: use solution[i]"
            )
        return 0

    @property
    def status(self) -> Status:
        """How the only member's run ended (:attr:`Status.message` says what to do)."""
        self._only("status")
        return Status[self.members["status"].iat[0]]

    @property
    def message(self) -> str:
        return self.status.message

    @property
    def ok(self) -> bool:
        return self.status is Status.OK

    @property
    def index(self) -> int:
        """The only member's realization index."""
        self._only("index")
        return int(self.members["index"].iat[0])

    @property
    def section(self) -> pd.DataFrame:
        """The only member's section (k, t, theta_f, omega_f, l_lambda)."""
        self._only("section")
        return self.sections.drop(columns="member")

    @property
    def final_state(self) -> tuple[float, float, float]:
        """(t, theta_f, omega_f) where the only member's run stopped."""
        self._only("final_state")
        row = self.members.iloc[0]
        return (float(row["t_end"]), float(row["theta_f_end"]), float(row["omega_f_end"]))

    @property
    def stats(self) -> dict[str, Any]:
        """The only member's statistics (read-only): contact_fraction, n_impacts (with impacts
        kept also n_macro_impacts, n_micro_impacts, n_chatter_ends), slow_closings,
        chatter_handovers, truncated_mass, steps_per_contact_period."""
        self._only("stats")
        row, p = self.members.iloc[0], self.models[0]
        out: dict[str, Any] = {"contact_fraction": float(row["contact_fraction"]),
                               "n_impacts": int(row["n_impacts"])}  # fmt: skip
        if self.impacts is not None:
            kinds = self.impacts["kind"].astype(str)
            for key, kind in zip(("n_macro_impacts", "n_micro_impacts", "n_chatter_ends"),
                                 IMPACT_KINDS, strict=True):  # fmt: skip
                out[key] = int((kinds == kind).sum())
        out["slow_closings"] = int(row["slow_closings"])
        out["chatter_handovers"] = int(row["chatter_handovers"])
        out["truncated_mass"] = truncated_mass(p.l_lambda, p.l_lambda_sigma, p.l_min)
        out["steps_per_contact_period"] = contact_period(p) / self.numerics.dt
        return FrozenDict(out)

    def summary(self) -> str:
        """A few lines for a terminal: status, time simulated, impacts, contact fraction."""
        if len(self) != 1:
            counts = self.members["status"].value_counts().to_dict()
            return f"{len(self)} members: " + ", ".join(f"{v} {k_}" for k_, v in counts.items())
        s = self.stats
        fraction = s["contact_fraction"]
        contact = "n/a (no step recorded)" if math.isnan(fraction) else f"{fraction:.4f}"
        end = self.final_state[0]  # NaN for a run read from a file that kept no section row
        reached = "an end time not recorded in the file" if math.isnan(end) else f"{end:.4g} s"
        kinds = (
            f" ({s['n_macro_impacts']} macro, {s['n_micro_impacts']} micro, "
            f"{s['n_chatter_ends']} chattering ends)"
            if "n_macro_impacts" in s
            else ""
        )
        return (
            f"status: {self.status.name} - {self.message}\n"
            f"simulated: {reached} of {self.settings['duration']:.4g} s "
            f"(transient {self.settings['transient']:.4g} s discarded), "
            f"{self.numerics.describe_step()}\n"
            f"impacts: {s['n_impacts']} applied{kinds}, "
            f"{s['slow_closings']} slow closings left to the compliant contact, "
            f"{s['chatter_handovers']} chattering-guard hand-overs\n"
            f"contact fraction: {contact}\n"
            f"section points: {len(self.sections)}"
        )

    def plot(self, ax=None, *, kind: str = "section", last: float | None = None):
        """The only member on ``ax`` (None: a new pyplot figure's); returns the Axes.

        ``kind`` = "section": the stroboscopic section (θ_f [rad], θ̇_f [rad/s]) at
        t = k 2π/ω after the transient; "series": θ_f and the persistent-contact angle θ_fc
        [rad] over t [s] (a run with ``series=True``), its last ``last`` seconds if given.
        """
        from ..plot import axes, plot_section, plot_series

        self._only("plot")
        if kind == "section":
            return plot_section(self.section, axes(ax))
        if kind != "series":
            raise ValueError(f"kind = {kind!r}: 'section' or 'series'")
        if self.series is None or not len(self.series):
            raise ValueError("no series kept: simulate with series=True")
        return plot_series(self.series, axes(ax), last=last)

    def select(self, picks) -> Solution:
        """Members ``picks`` (their ``member`` numbers), renumbered 0, 1, ... in that order."""
        import pandas as pd

        picks = [int(m) for m in picks]
        renum = {m: i for i, m in enumerate(picks)}

        def rows(frame):
            if frame is None:
                return None, None
            pos = np.concatenate(
                [np.flatnonzero(frame["member"].to_numpy() == m) for m in picks] or [[]]
            ).astype(np.int64)
            sub = frame.iloc[pos].reset_index(drop=True)
            sub["member"] = sub["member"].map(renum).astype(np.int64)
            return sub, pos

        members = self.members.iloc[picks].reset_index(drop=True)
        members["member"] = np.arange(len(picks), dtype=np.int64)
        sections, pos = rows(self.sections)
        impacts, _ = rows(self.impacts)
        series, _ = rows(self.series)
        return Solution(
            models=tuple(self.models[m] for m in picks), numerics=self.numerics,
            settings=dict(self.settings), members=pd.DataFrame(members), sections=sections,
            jacobians=None if self.jacobians is None else self.jacobians[pos],
            divergence=None if self.divergence is None else self.divergence[pos],
            impacts=impacts, series=series,
            resume=None if self.resume is None else self.resume.select(picks),
        )  # fmt: skip

    def provenance(self) -> dict[str, Any]:
        """The only member's model, numerics, settings and statistics, JSON-serialisable."""
        return {
            "params": self.params.to_dict(),
            "numerics": self.numerics.to_dict(),
            "settings": {**self.settings, "index": self.index},
            "status": self.status.name,
            "stats": self.stats,
        }

    def to_parquet(self, path, *, replace: bool = False) -> None:
        """The only member as a trajectory file (:meth:`parquet_table`), written atomically;
        an existing file is refused unless ``replace=True``."""
        from ..io import write_new_parquet

        write_new_parquet(self.parquet_table(), path, replace=replace)

    def parquet_table(self):
        """The only member's series (or section) as a pyarrow table, with its section, impacts
        and provenance in the metadata (:func:`chaoscam.load_trajectory` reads it)."""
        import pyarrow as pa

        from ..io import exact_json

        frame = self.section if self.series is None else self.series.drop(columns="member")
        table = pa.Table.from_pandas(frame, preserve_index=False)
        meta = dict(table.schema.metadata or {})
        meta[b"chaoscam.trajectory"] = json.dumps(self.provenance()).encode()
        meta[b"chaoscam.section"] = exact_json(self.section).encode()
        if self.impacts is None:
            import pandas as pd

            impacts = pd.DataFrame(columns=list(IMPACT_COLUMNS))
        else:
            impacts = self.impacts.drop(columns="member")
        meta[b"chaoscam.impacts"] = exact_json(impacts).encode()
        return table.replace_schema_metadata(meta)


def series_frame(p: Params, a: np.ndarray) -> pd.DataFrame:
    """One member's tidy series: kernel samples (t, theta_f, omega_f, l_lambda) and observables."""
    import pandas as pd

    t, th, om, lam = a[:, 0], a[:, 1], a[:, 2], a[:, 3]
    d = gap(p, t, th)
    force = normal_force(p, t, th, om, lam)
    columns = (t, th, om, contact_angle(p, t), d, d <= 0.0, force, lam)
    return pd.DataFrame(dict(zip(SERIES_COLUMNS, columns, strict=True)))


def _tagged(batches: list[Batch], name: str, ncol: int) -> np.ndarray:
    """The kept rows ``name`` of every member, in order, with its member number in front."""
    out = [np.column_stack([np.full(len(rows), b.first + j), rows])
           for b in batches for j, rows in enumerate(b.kept[name])]  # fmt: skip
    return np.concatenate(out) if out else np.empty((0, 1 + ncol))


def assemble(batches: list[Batch], plist, num, settings: dict) -> Solution:
    """The Solution of finished batches, in order."""
    import pandas as pd

    sec = _tagged(batches, "section", k.SECTION_COLS)
    n_sec = len(SECTION_COLUMNS)
    sections = pd.DataFrame(sec[:, : 1 + n_sec], columns=["member", *SECTION_COLUMNS])
    sections[["member", "k"]] = sections[["member", "k"]].astype(np.int64)
    tangent = bool(settings["tangent"])
    members = pd.DataFrame([row for b in batches for row in _member_rows(b)],
                           columns=list(MEMBER_COLUMNS))  # fmt: skip
    impacts = None
    if all(b.kept["impacts"] is not None for b in batches) and settings["impacts"]:
        a = _tagged(batches, "impacts", k.IMPACT_COLS)
        impacts = pd.DataFrame(a, columns=["member", *IMPACT_COLUMNS])
        impacts["member"] = impacts["member"].astype(np.int64)
        impacts["kind"] = pd.Categorical.from_codes(
            impacts["kind"].to_numpy(dtype=np.int64), categories=list(IMPACT_KINDS)
        )
    series = None
    if settings["output_dt"] is not None:
        frames = [series_frame(plist[b.first + j], rows).assign(member=b.first + j)
                  for b in batches for j, rows in enumerate(b.kept["series"])]  # fmt: skip
        series = pd.concat(frames, ignore_index=True) if frames else None
        if series is not None:
            series = series[["member", *SERIES_COLUMNS]]
    resumes = [b.resume for b in batches]
    resume = Resume.join(resumes) if resumes and all(r is not None for r in resumes) else None
    return Solution(
        models=tuple(plist), numerics=num, settings=settings, members=members, sections=sections,
        jacobians=section_jacobians(sec[:, 1:]) if tangent else None,
        divergence=sec[:, 1 + n_sec + 4].copy() if tangent else None,
        impacts=impacts, series=series, resume=resume,
    )  # fmt: skip


def _member_rows(b: Batch):
    for j in range(len(b.indices)):
        y, cnt, c = b.y[j], b.cnt[j], b.c[j]
        yield (
            b.first + j, b.indices[j], Status(int(b.status[j])).name, int(b.n_impacts[j]),
            contact_fraction(y, cnt, c), int(cnt[k.I_SLOW_CLOSINGS]), int(cnt[k.I_CHATTER]),
            float(y[k.Y_TIME]), float(y[k.Y_THETA]), float(y[k.Y_OMEGA]),
        )  # fmt: skip
