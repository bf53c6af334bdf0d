"""The self-contained HTML report: inputs read, figures drawn, a Jinja2 template rendered.

Figures are inline PNG data URIs; the template holds its own CSS; nothing in the file refers
to the network, so it opens from disk anywhere. A report built from a partial set of inputs
says what is missing instead of failing.
"""

from __future__ import annotations

import datetime as _dt
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..io import code_rows
from ..sweep import fate_clause
from ._figures import png_bytes, png_uri, response_figure
from ._inputs import require_inputs

__all__ = ["Comparison", "FigureItem", "ReportParts", "add_bifurcation", "add_ensemble"]
__all__ += ["add_regime_map", "add_trajectory", "build_report", "git_commit", "render"]
__all__ += ["uncommitted_sources", "write_report"]

CLASSIFIER = "chaoscam.classify() (tangent exponent, orbit certificate)"
"""The classifier the report's runs are labelled with, in words."""

SECTIONS = (
    ("summary", "Summary of findings"),
    ("provenance", "Parameters and provenance"),
    ("paper-figures", "Paper figures reproduced"),
    ("regime-maps", "Regime maps"),
    ("bifurcations", "Bifurcation diagrams"),
    ("responses", "Representative responses"),
    ("evidence", "Classifier evidence"),
    ("comparison", "The paper against this run"),
    ("why", "Why the paper differs"),
    ("missing", "What is missing"),
)

ENSEMBLES = ("ensembles", "Ensembles")
"""A section shown after the bifurcation diagrams only when the report has an ensemble."""


@dataclass
class FigureItem:
    """One embedded figure: anchor id, title, data URI, alt text, caption."""

    id: str
    title: str
    uri: str
    alt: str
    caption: str


@dataclass
class Comparison:
    """One row of the paper-vs-run table; ``verdict`` is agrees / differs / not comparable."""

    figure: str
    paper: str
    found: str
    verdict: str
    reason: str
    anchor: str = ""

    def __post_init__(self):
        if self.verdict not in ("agrees", "differs", "not comparable"):
            raise ValueError(f"verdict {self.verdict!r}: agrees, differs or not comparable")


@dataclass
class ReportParts:
    """Everything the template shows, gathered before rendering."""

    summary: list[str] = field(default_factory=list)
    provenance: list[dict[str, Any]] = field(default_factory=list)
    paper_figures: list[FigureItem] = field(default_factory=list)
    regime_maps: list[dict[str, Any]] = field(default_factory=list)
    bifurcations: list[dict[str, Any]] = field(default_factory=list)
    ensembles: list[dict[str, Any]] = field(default_factory=list)
    responses: list[FigureItem] = field(default_factory=list)
    evidence: list[dict[str, Any]] = field(default_factory=list)
    comparison: list[Comparison] = field(default_factory=list)
    why: list[str] = field(default_factory=list)
    why_figures: list[FigureItem] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)


def git_commit(start: Path | None = None) -> str | None:
    """The commit checked out around ``start`` (read from ``.git``, no git process), or None."""
    here = Path(start or Path(__file__)).resolve()
    for d in [here, *here.parents]:
        g = d / ".git"
        if g.is_file():  # a worktree: "gitdir: PATH"
            text = g.read_text().strip()
            if text.startswith("gitdir:"):
                g = (d / text.split(":", 1)[1].strip()).resolve()
        if not g.is_dir():
            continue
        try:
            head = (g / "HEAD").read_text().strip()
            if not head.startswith("ref:"):
                return head
            ref = head.split(":", 1)[1].strip()
            common = g
            if (g / "commondir").exists():
                common = (g / (g / "commondir").read_text().strip()).resolve()
            for base in (g, common):
                if (base / ref).exists():
                    return (base / ref).read_text().strip()
            packed = common / "packed-refs"
            if packed.exists():
                for line in packed.read_text().splitlines():
                    if line.endswith(" " + ref):
                        return line.split()[0]
        except OSError:
            return None
        return None
    return None


SOURCES = ("chaoscam", "analyses", "pyproject.toml")
"""What a report's numbers come from: changes there that are not committed are named in its
provenance (a report and its data are not)."""


def uncommitted_sources(start: Path | None = None) -> list[str] | None:
    """Tracked files under :data:`SOURCES` that differ from the commit checked out (``git
    status``), so that a report built from an uncommitted tree does not pass for the commit
    it names; None when git or the checkout is not there."""
    import subprocess

    here = Path(start or Path(__file__)).resolve()
    root = next((d for d in [here, *here.parents] if (d / ".git").exists()), None)
    if root is None:
        return None
    try:
        out = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no", "--", *SOURCES],
            cwd=root,
            capture_output=True,
            text=True,
            timeout=20,
            check=True,
        ).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    return sorted(line[3:] for line in out.splitlines() if len(line) > 3)


def _counts(counts: dict) -> str:
    return ", ".join(f"{k} {v}" for k, v in counts.items()) or "none"


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.6g}"
    return "" if v is None else str(v)


def _provenance_rows(source: str, kind: str, rows: dict[str, Any]) -> dict[str, Any]:
    return {"source": source, "kind": kind, "rows": [(k, _fmt(v)) for k, v in rows.items()]}


def classifier_fingerprint() -> str:
    """:data:`CLASSIFIER` and the sha256 (12 hex digits) of the verdict package's source, for
    provenance."""
    import hashlib

    from .. import verdict

    digest = hashlib.sha256()
    try:
        for f in sorted(Path(verdict.__file__).parent.glob("*.py")):
            digest.update(f.read_bytes())
        text = digest.hexdigest()[:12]
    except (OSError, TypeError):
        text = "unknown"
    return f"{CLASSIFIER} (source sha256 {text})"


def add_trajectory(
    parts: ReportParts, path: str, run, *, caption: str = "", png: bytes | None = None,
    verdict=None,
) -> None:  # fmt: skip
    """A run's response figure, its verdict and its provenance (``run``: a one-member
    :class:`chaoscam.Solution`).

    ``png``: the response figure already rendered (:func:`._figures.png_bytes`); without it
    the figure is drawn here, titled with the file name and the label. ``verdict``: the run's
    verdict by :func:`chaoscam.classify`, already computed; without it the run is classified
    here.
    """
    from ..verdict import classify

    name = Path(path).name
    p, s = run.params, run.settings
    if verdict is None:
        (verdict,) = classify(run)
    parts.provenance.append(
        _provenance_rows(path, "trajectory", {
            "status": run.status.name,
            "seed": s.get("seed"),
            "realization index": run.index,
            "integrator": run.numerics.integrator,
            "integration": run.numerics.describe_step(),
            "duration [s]": s.get("duration"),
            "transient [s]": s.get("transient"),
            "package version": s.get("version"),
            "stiffness": p.stiffness,
            "l_lambda (mean) [m]": p.l_lambda,
            "l_lambda_sigma [m]": p.l_lambda_sigma,
            "resample": p.resample,
            "impacts applied": run.stats.get("n_impacts"),
            "contact fraction": run.stats.get("contact_fraction"),
        })
    )  # fmt: skip
    label = verdict.label + (f" (period {verdict.period})" if verdict.period else "")
    if png is None:
        png = png_bytes(response_figure(run, title=f"{name}: {label}"))
    parts.responses.append(
        FigureItem(
            f"resp-{len(parts.responses) + 1}",
            f"Response of {name}",
            png_uri(png),
            f"Four panels for {name}: follower angle and persistent-contact angle over the "
            f"last 2 s, phase portrait, stroboscopic Poincaré section and spectrum of theta_f; "
            f"classified {label}.",
            caption
            or f"μ = l_lambda = {p.l_lambda:g} m, σ = {p.l_lambda_sigma:g} m, "
            f"stiffness {p.stiffness}; classified {label}.",
        )
    )
    parts.evidence.append(
        {
            "run": name,
            "label": verdict.label,
            "period": verdict.period,
            "reasons": list(verdict.reasons),
            "classifier": CLASSIFIER,
            "rows": [
                (e.name, _fmt(e.value), e.vote or "abstains", e.detail) for e in verdict.evidence
            ],
        }
    )
    parts.summary.append(f"{name}: {label} ({run.status.name}).")


def add_bifurcation(
    parts: ReportParts, path: str, bif, *, caption: str = "", png: bytes | None = None
) -> None:
    """A bifurcation diagram, its verdicts per value and its provenance (``png``: its figure
    already rendered, else drawn here)."""
    import pandas as pd

    from ._sweep_figures import sweep_diagram

    name = Path(path).name
    cfg = bif.config or {}
    param = cfg.get("axis", {}).get("name", "value")
    v = bif.verdicts
    counts = v["label"].value_counts().to_dict() if len(v) else {}
    if png is None:
        png = png_bytes(sweep_diagram(bif))
    ev_cols = [c for c in v.columns if c.startswith("ev_")]
    named = dict(fate="at the fate horizon", fate_label="label there", fate_period="period there")
    later = [c for c in named if c in v] if cfg.get("fate") else []  # the sweep had a horizon
    parts.bifurcations.append(
        {
            "figure": FigureItem(
                f"bif-{len(parts.bifurcations) + 1}",
                f"Bifurcation diagram over {param} ({name})",
                png_uri(png),
                f"Stroboscopic section theta_f in rad against {param}, coloured by the "
                f"classifier's label; label counts {_counts(counts)}.",
                caption
                or f"{len(v)} runs, {len(bif.points)} section points; labels {_counts(counts)}.",
            ),
            "header": [param, "initial condition", "label", "period", "status"]
            + [c[3:] for c in ev_cols]
            + [named[c] for c in later],
            "rows": [
                (
                    _fmt(r["value"]),
                    int(r["ic"]),
                    r["label"],
                    _fmt(r["period"]),
                    r["status"],
                    *(_fmt(float(r[c])) for c in ev_cols),
                    *(_fmt(r[c]) if pd.notna(r[c]) else "" for c in later),
                )
                for r in v.sort_values(["value", "ic"]).to_dict("records")
            ][:300],
        }
    )
    parts.provenance.append(_provenance_rows(path, "bifurcation", _sweep_settings(cfg)))
    parts.summary.append(
        f"{name}: bifurcation over {param}, labels {_counts(counts)}"
        + fate_clause(v, cfg.get("fate"), "runs")
        + "."
    )


def add_regime_map(
    parts: ReportParts, path: str, rm, *, caption: str = "", png: bytes | None = None
) -> None:
    """A regime map's figure, its cell table and its provenance (``png``: its figure already
    rendered, else drawn here)."""
    from ._sweep_figures import all_deterministic, percent, regime_map_figure

    name = Path(path).name
    cfg = rm.config or {}
    x, y = cfg.get("x", {}).get("name", "x"), cfg.get("y", {}).get("name", "y")
    confidence = float(cfg.get("confidence", 0.95))
    c = rm.cells
    if png is None:
        png = png_bytes(regime_map_figure(c, x=x, y=y, confidence=confidence))
    rows = []
    for r in c.sort_values([x, y]).to_dict("records"):
        rows.append(
            (
                _fmt(r[x]),
                _fmt(r[y]),
                int(r.get("n", 0)),
                r.get("dominant", ""),
                _p_chaotic_text(r),
                f"{r.get('p_quasiperiodic', float('nan')):.2f}",
                f"{r.get('p_periodic', float('nan')):.2f}",
            )
        )
    parts.regime_maps.append(
        {
            "figure": FigureItem(
                f"map-{len(parts.regime_maps) + 1}",
                f"Regime map {x} × {y} ({name})",
                png_uri(png),
                f"Heatmap over {x} and {y}: the label and period of each deterministic cell."
                if all_deterministic(c)
                else f"Heatmaps over {x} and {y}: dominant label per cell, probability of chaos "
                f"with its {percent(confidence)} Wilson interval, and the interval width.",
                caption or f"{len(rm.realizations)} realizations in {len(c)} cells.",
            ),
            "x": x,
            "y": y,
            "level": percent(confidence),
            "rows": rows,
        }
    )
    parts.provenance.append(_provenance_rows(path, "regime map", _sweep_settings(cfg)))
    dom = c["dominant"].value_counts().to_dict() if len(c) else {}
    parts.summary.append(
        f"{name}: regime map {x} × {y}, dominant labels {_counts(dom)}"
        + fate_clause(rm.realizations, cfg.get("fate"), "realizations")
        + "."
    )


def add_ensemble(parts: ReportParts, path: str, ens, *, png: bytes | None = None) -> None:
    """An ensemble's figure, label table, undetermined reasons, record and summary line
    (:func:`._ensemble.ensemble_entry`; ``png``: its figure already rendered)."""
    from ._ensemble import ensemble_entry

    entry = ensemble_entry(path, ens, png=png)
    entry["figure"] = FigureItem(f"ens-{len(parts.ensembles) + 1}", **entry["figure"])
    parts.ensembles.append(entry)
    parts.provenance.append(_provenance_rows(path, "ensemble", entry.pop("settings")))
    parts.summary.append(entry.pop("summary"))


def _p_chaotic_text(r: dict[str, Any]) -> str:
    """P(chaotic) with its Wilson interval; a deterministic cell (one run standing for
    identical realizations, sigma = 0) has no sampling interval and says so instead."""
    p = f"{r.get('p_chaotic', float('nan')):.2f}"
    if bool(r.get("deterministic", False)):
        return f"{p} (deterministic: one run)"
    lo, hi = r.get("p_chaotic_lo", float("nan")), r.get("p_chaotic_hi", float("nan"))
    return f"{p} [{lo:.2f}, {hi:.2f}]"


def _sweep_settings(cfg: dict[str, Any]) -> dict[str, Any]:
    names = {
        "kind": "kind",
        "version": "package version",
        "seed": "seed",
        "duration": "duration [s]",
        "transient": "transient [s]",
        "realizations": "realizations per cell",
        "classifier": "classifier",
        "device": "device",
        "confidence": "confidence of the intervals",
        "adaptive": "adaptive sampling",
        "continuation": "continuation",
    }
    rows = {label: cfg.get(k) for k, label in names.items() if k in cfg}
    rows.update(code_rows(cfg.get("code")))
    for axis, label in (("axis", "swept parameter"), ("x", "x axis"), ("y", "y axis")):
        if axis in cfg:
            a = cfg[axis]
            vals = a.get("values", [])
            rows[label] = (
                f"{a.get('name')}: {len(vals)} values in [{min(vals):g}, {max(vals):g}]"
                if vals
                else a.get("name")
            )
    return rows | _base_rows(cfg.get("base", {}), cfg.get("numerics", {}))


def _base_rows(base: dict[str, Any], numerics: dict[str, Any]) -> dict[str, Any]:
    """The sweep's base model where it differs from ``Params()``, and its integrator and step
    always (other numerics where they differ from ``Numerics()``)."""
    from ..model import FIELD_DOCS, Params
    from ..numerics import Numerics

    rows = {}
    for values, default, docs, always in (
        (numerics, Numerics().to_dict(), Numerics.field_docs(), ("integrator", "dt")),
        (base, Params().to_dict(), FIELD_DOCS, ()),
    ):
        for k, v in values.items():
            if k in always or v != default.get(k, v):
                unit = "" if isinstance(v, str) else docs.get(k, {}).get("unit", "")
                rows[f"base {k}" + (f" [{unit}]" if unit else "")] = v
    return rows


def model_rows() -> list[tuple[str, Any, str, str]]:
    """(name, value, unit, meaning) of each field of ``Params()`` and ``Numerics()``, where
    every run starts."""
    from ..model import FIELD_DOCS, Params
    from ..numerics import Numerics

    def short(doc: str) -> str:  # the first ~150 characters of a long field doc
        return doc if len(doc) < 160 else doc[:150].rsplit(" ", 1)[0] + " …"

    docs = {**FIELD_DOCS, **Numerics.field_docs()}
    docs = {k: (d.get("unit") or "", short(d.get("doc") or "")) for k, d in docs.items()}
    values = {**Params().to_dict(), **Numerics().to_dict()}
    return [(k, v, *docs.get(k, ("", ""))) for k, v in values.items()]


def _sections(parts: ReportParts) -> tuple[tuple[str, str], ...]:
    """The table of contents: :data:`SECTIONS`, with :data:`ENSEMBLES` after the
    bifurcation diagrams when there is an ensemble."""
    if not parts.ensembles:
        return SECTIONS
    at = [sid for sid, _ in SECTIONS].index("bifurcations") + 1
    return (*SECTIONS[:at], ENSEMBLES, *SECTIONS[at:])


def render(parts: ReportParts, *, title: str, command: str | None = None) -> str:
    """The report's HTML text."""
    import jinja2

    from .._version import __version__

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("chaoscam.report", "templates"),
        autoescape=jinja2.select_autoescape(["html"]),
        undefined=jinja2.StrictUndefined,
    )
    commit = git_commit()
    if commit:
        changed = uncommitted_sources()
        if changed:
            more = f" and {len(changed) - 5} more" if len(changed) > 5 else ""
            shown = ", ".join(changed[:5]) + more
            commit += f" plus uncommitted changes to {shown}"
    return env.get_template("report.html").render(
        title=title,
        sections=_sections(parts),
        parts=parts,
        version=__version__,
        commit=commit or "not available (not run from a git checkout)",
        date=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
        command=command or " ".join(["chaoscam", *sys.argv[1:]]),
        python=sys.version.split()[0],
        classifier=classifier_fingerprint(),
        model=model_rows(),
    )


def build_report(inputs, parts: ReportParts | None = None) -> ReportParts:
    """Add every input (:func:`load_inputs`' :class:`~._inputs.Inputs`) to the report parts."""
    inputs, parts = require_inputs(inputs), parts or ReportParts()
    for path, rm in inputs.regime_maps:
        add_regime_map(parts, path, rm)
    for path, bif in inputs.bifurcations:
        add_bifurcation(parts, path, bif)
    for path, ens in inputs.ensembles:
        add_ensemble(parts, path, ens)
    for path, traj in inputs.trajectories:
        add_trajectory(parts, path, traj)
    for kind, items, what in (
        ("regime map", inputs.regime_maps, "regime-map"),
        ("bifurcation diagram", inputs.bifurcations, "bifurcation"),
        ("trajectory", inputs.trajectories, "simulate --out"),
    ):
        if not items:
            parts.missing.append(
                f"No {kind} among the inputs: its section is empty (make one with "
                f"`chaoscam {what}`)."
            )
    return parts


def write_report(
    parts: ReportParts, out: str | Path, *, title: str, command=None, replace: bool = False
) -> Path:
    """Render and write the report atomically into an existing folder; returns the path.

    Never over an existing file unless ``replace=True``: the report then goes beside it
    (``NAME.PID.html``) with an :class:`chaoscam.io.OutputError` naming both.
    """
    from ..io import atomic_write_bytes, check_output

    out = check_output(out, flag="out", force=True, suffixes=(".html", ".htm"))
    data = render(parts, title=title, command=command).encode("utf-8")
    atomic_write_bytes(out, data, replace=replace)
    return out
