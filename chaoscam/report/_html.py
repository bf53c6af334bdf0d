"""The self-contained HTML report: inputs read, figures drawn, a Jinja2 template rendered.

Figures are inline PNG data URIs and the template holds its own CSS: nothing in the file
refers to the network, so it opens from disk anywhere. A report built from a partial set of
inputs says what is missing instead of failing. It leads with its answer (:mod:`._headline`);
the paper's sections (figures reproduced, the comparison, why it differs) appear only in the
report of :mod:`chaoscam.paper` (``ReportParts(paper=True)``).
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import math
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..io import code_rows
from ..sweep import fate_clause
from ._figures import png_bytes, png_uri, response_figure
from ._headline import fold, frame_tags, headline, verdict_tag
from ._inputs import as_inputs

__all__ = ["Comparison", "FigureItem", "ReportParts", "add_bifurcation", "add_ensemble"]
__all__ += ["add_regime_map", "add_trajectory", "build_report", "git_commit", "render"]
__all__ += ["uncommitted_sources", "write_report"]

CLASSIFIER = "chaoscam.classify() (tangent exponent, orbit certificate)"
"""The classifier the report's runs are labelled with, in words."""

SOURCE_PAPER = (
    "Effect of Surface Morphology on Dynamic Characteristics of Cam-Follower Oblique Impact System"
)
"""The title of the paper whose model chaoscam implements (authors, venue, year and DOI are
not recorded)."""

SECTIONS = (
    ("answer", "The answer"),
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

PAPER_SECTIONS = ("paper-figures", "comparison", "why")
"""The sections only :mod:`chaoscam.paper`'s report has."""

ENSEMBLES = ("ensembles", "Ensembles")
"""A section shown after the bifurcation diagrams only when the report has an ensemble."""

SOURCES = ("chaoscam", "analyses", "pyproject.toml")
"""What a report's numbers come from: uncommitted changes there are named in its provenance."""

_SWEEP_ROWS = {
    "kind": "kind", "version": "package version", "seed": "seed", "duration": "duration [s]",
    "transient": "transient [s]", "realizations": "realizations per cell",
    "classifier": "classifier", "device": "device", "confidence": "confidence of the intervals",
    "adaptive": "adaptive sampling", "continuation": "continuation",
}  # fmt: skip
"""The sweep record's keys shown in its provenance, and their names there."""


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
    """Everything the template shows, gathered before rendering.

    ``paper``: the report of :mod:`chaoscam.paper` (with its sections). ``headline``: the
    answer's sentences and ``lead`` its figure (else computed from ``found``: per input its
    name, what it sweeps and its verdicts' tags). ``listing``: one line per input (folded).
    ``responses``: one figure per distinct verdict, with the runs it stands for.
    """

    paper: bool = False
    headline: list[str] = field(default_factory=list)
    lead: FigureItem | None = None
    found: list[dict[str, Any]] = field(default_factory=list)
    listing: list[str] = field(default_factory=list)
    summary: list[str] = field(default_factory=list)
    provenance: list[dict[str, Any]] = field(default_factory=list)
    paper_figures: list[FigureItem] = field(default_factory=list)
    regime_maps: list[dict[str, Any]] = field(default_factory=list)
    bifurcations: list[dict[str, Any]] = field(default_factory=list)
    ensembles: list[dict[str, Any]] = field(default_factory=list)
    responses: list[dict[str, Any]] = field(default_factory=list)
    evidence: list[dict[str, Any]] = field(default_factory=list)
    comparison: list[Comparison] = field(default_factory=list)
    why: list[str] = field(default_factory=list)
    why_figures: list[FigureItem] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)


def _checkout(start: Path | None) -> Path | None:
    """The folder holding the ``.git`` around ``start`` (default: this file), or None."""
    here = Path(start or Path(__file__)).resolve()
    return next((d for d in [here, *here.parents] if (d / ".git").exists()), None)


def git_commit(start: Path | None = None) -> str | None:
    """The commit checked out around ``start`` (read from ``.git``, no git process), or None."""
    root = _checkout(start)
    if root is None:
        return None
    g = root / ".git"
    try:
        if g.is_file() and (text := g.read_text().strip()).startswith("gitdir:"):  # a worktree
            g = (root / text.split(":", 1)[1].strip()).resolve()
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
        lines = packed.read_text().splitlines() if packed.exists() else []
        return next((line.split()[0] for line in lines if line.endswith(" " + ref)), None)
    except OSError:
        return None


def uncommitted_sources(start: Path | None = None) -> list[str] | None:
    """Tracked files under :data:`SOURCES` that differ from the commit checked out (``git
    status``), so that a report does not pass for that commit; None without git or checkout."""
    root = _checkout(start)
    if root is None:
        return None
    cmd = ["git", "status", "--porcelain", "--untracked-files=no", "--", *SOURCES]
    try:
        out = subprocess.run(cmd, cwd=root, capture_output=True, text=True, timeout=20, check=True)
    except (OSError, subprocess.SubprocessError):
        return None
    return sorted(line[3:] for line in out.stdout.splitlines() if len(line) > 3)


def _counts(counts: dict) -> str:
    return ", ".join(f"{k} {v}" for k, v in counts.items()) or "none"


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.6g}"
    return "" if v is None else str(v)


def _uri(png: bytes | None, draw) -> str:
    """The data URI of ``png``, or of ``draw()``'s figure rendered when there is none."""
    return png_uri(png_bytes(draw()) if png is None else png)


def _record(parts: ReportParts, path: str, kind: str, settings: dict, summary: str) -> None:
    """An input's settings in the provenance section and its line in the listing."""
    rows = [(k, _fmt(v)) for k, v in settings.items()]
    parts.provenance.append({"source": path, "kind": kind, "rows": rows})
    parts.listing.append(summary)


def _evidence_rows(evidence) -> list[tuple[str, str, str, str]]:
    """(method, value, vote, detail) of a verdict's evidence; methods that abstain with the
    same detail share one row."""
    rows: list[list[str]] = []
    for e in evidence:
        row = [e.name, _fmt(e.value), e.vote or "abstains", e.detail]
        if rows and row[1:] == rows[-1][1:] and not row[1]:
            rows[-1][0] += f", {e.name}"
        else:
            rows.append(row)
    return [tuple(r) for r in rows]


def classifier_fingerprint() -> str:
    """:data:`CLASSIFIER` and the sha256 (12 hex digits) of the verdict package's source."""
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

    ``png``: the response figure already rendered (:func:`png_bytes`), else drawn here and
    titled with the file name and the label. ``verdict``: the run's verdict by
    :func:`chaoscam.classify`, else classified here.
    """
    from ..verdict import classify

    name, p, s = Path(path).name, run.params, run.settings
    if verdict is None:
        (verdict,) = classify(run)
    label = verdict.label + (f" (period {verdict.period})" if verdict.period else "")
    bands = next((e.value for e in verdict.evidence if e.name == "banded_chaos"), None)
    tag = verdict_tag(verdict.label, verdict.period, bands)
    parts.found.append({"name": name, "what": "a run", "tags": [tag], "unit": "run"})
    where = f"μ = l_lambda = {p.l_lambda:g} m, σ = {p.l_lambda_sigma:g} m, stiffness {p.stiffness}"
    key = (tag, run.status.name)
    same = next((r for r in parts.responses if r["key"] == key), None)
    if same is not None:  # drawn once per distinct verdict: this run joins its panel
        same["runs"].append(f"{name} ({where})")
    else:
        figure = FigureItem(
            f"resp-{len(parts.responses) + 1}",
            f"Response of {name}",
            _uri(png, lambda: response_figure(run, title=f"{name}: {label}")),
            f"Four panels for {name}: follower angle and persistent-contact angle over the "
            f"last 2 s, phase portrait, stroboscopic Poincaré section and spectrum of "
            f"theta_f; classified {label}.",
            caption or f"{where}; classified {label}.",
        )
        parts.responses.append({"figure": figure, "key": key, "tag": tag,
                                "runs": [f"{name} ({where})"]})  # fmt: skip
    rows = _evidence_rows(verdict.evidence)
    parts.evidence.append({
        "run": name, "label": verdict.label, "period": verdict.period,
        "reasons": list(verdict.reasons), "classifier": CLASSIFIER, "rows": rows,
    })  # fmt: skip
    settings = {
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
    }
    _record(parts, path, "trajectory", settings, f"{name}: {label} ({run.status.name}).")


def add_bifurcation(
    parts: ReportParts, path: str, bif, *, caption: str = "", png: bytes | None = None
) -> None:
    """A bifurcation diagram, its verdicts per value and its provenance (``png``: its figure
    already rendered, else drawn here)."""
    import pandas as pd

    from ..plot import sweep_diagram

    name, cfg, v = Path(path).name, bif.config or {}, bif.verdicts
    param = cfg.get("axis", {}).get("name", "value")
    counts = _counts(v["label"].value_counts().to_dict() if len(v) else {})
    ev_cols = [c for c in v.columns if c.startswith("ev_")]
    named = dict(fate="at the fate horizon", fate_label="label there", fate_period="period there")
    later = [c for c in named if c in v] if cfg.get("fate") else []  # the sweep had a horizon
    rows = [
        (_fmt(r["value"]), int(r["ic"]), r["label"], _fmt(r["period"]), r["status"],
         *(_fmt(float(r[c])) for c in ev_cols),
         *(_fmt(r[c]) if pd.notna(r[c]) else "" for c in later))
        for r in v.sort_values(["value", "ic"]).to_dict("records")
    ]  # fmt: skip
    figure = FigureItem(
        f"bif-{len(parts.bifurcations) + 1}",
        f"Bifurcation diagram over {param} ({name})",
        _uri(png, lambda: sweep_diagram(bif)),
        f"Stroboscopic section theta_f in rad against {param}, coloured by the classifier's "
        f"label; label counts {counts}.",
        caption or f"{len(v)} runs, {len(bif.points)} section points; labels {counts}.",
    )
    vals = v["value"] if len(v) else pd.Series([0.0])
    what = f"{param} from {vals.min():g} to {vals.max():g}"
    parts.found.append({"name": name, "what": what, "tags": frame_tags(v), "unit": "runs"})
    header = [param, "initial condition", "label", "period", "status"]
    header += [c[3:] for c in ev_cols] + [named[c] for c in later]
    parts.bifurcations.append({"figure": figure, "header": header, "rows": rows[:300]})
    fate = fate_clause(v, cfg.get("fate"), "runs")
    summary = f"{name}: bifurcation over {param}, labels {counts}{fate}."
    _record(parts, path, "bifurcation", _sweep_settings(cfg), summary)


def add_regime_map(
    parts: ReportParts, path: str, rm, *, caption: str = "", png: bytes | None = None
) -> None:
    """A regime map's figure, its cell table and its provenance (``png``: its figure already
    rendered, else drawn here)."""
    from ..plot import all_deterministic, percent, regime_map_figure

    name, cfg, c = Path(path).name, rm.config or {}, rm.cells
    x, y = cfg.get("x", {}).get("name", "x"), cfg.get("y", {}).get("name", "y")
    confidence = float(cfg.get("confidence", 0.95))
    nan = float("nan")
    rows = [
        (_fmt(r[x]), _fmt(r[y]), int(r.get("n", 0)), r.get("dominant", ""), _p_chaotic_text(r),
         f"{r.get('p_quasiperiodic', nan):.2f}", f"{r.get('p_periodic', nan):.2f}")
        for r in c.sort_values([x, y]).to_dict("records")
    ]  # fmt: skip
    figure = FigureItem(
        f"map-{len(parts.regime_maps) + 1}",
        f"Regime map {x} × {y} ({name})",
        _uri(png, lambda: regime_map_figure(c, x=x, y=y, confidence=confidence)),
        f"Heatmap over {x} and {y}: the label and period of each deterministic cell."
        if all_deterministic(c)
        else f"Heatmaps over {x} and {y}: dominant label per cell, probability of chaos "
        f"with its {percent(confidence)} Wilson interval, and the interval width.",
        caption or f"{len(rm.realizations)} realizations in {len(c)} cells.",
    )
    level = percent(confidence)
    tags = [verdict_tag(d, per) for d, per in zip(c["dominant"], c["period"], strict=True)]
    what = f"{x} × {y}"
    runs = frame_tags(rm.realizations)
    parts.found.append({"name": name, "what": what, "tags": tags, "unit": "cells", "runs": runs})
    parts.regime_maps.append({"figure": figure, "x": x, "y": y, "level": level, "rows": rows})
    dom = _counts(c["dominant"].value_counts().to_dict() if len(c) else {})
    fate = fate_clause(rm.realizations, cfg.get("fate"), "realizations")
    summary = f"{name}: regime map {x} × {y}, dominant labels {dom}{fate}."
    _record(parts, path, "regime map", _sweep_settings(cfg), summary)


def add_ensemble(parts: ReportParts, path: str, ens, *, png: bytes | None = None) -> None:
    """An ensemble's figure, label table, undetermined reasons, provenance and summary line
    (``png``: its figure already rendered, else drawn here)."""
    from . import _ensemble as e

    name, n, members = Path(path).name, len(ens.members), ens.members
    shares, fixed = e.label_shares(members), ens.identical
    what = "verdicts" if e.classified(members) else "run statuses (not classified)"
    alone = "; every member is the same deterministic run (l_lambda_sigma = 0 or the fractal "
    alone += "stiffness)."
    figure = FigureItem(
        f"ens-{len(parts.ensembles) + 1}",
        f"Ensemble of {n} members ({name})",
        _uri(png, lambda: e.ensemble_figure(ens, title=name)),
        f"Left: the stroboscopic section theta_f, omega_f of every member, coloured by its "
        f"label. Right: the share of each label among {n} members"
        + ("." if fixed else " with its 95% Wilson interval."),
        f"{n} members, {what}" + (alone if fixed else "."),
    )
    rows = [
        (r["label"], r["count"], f"{r['share']:.3f}",
         "none: one deterministic run" if fixed else f"[{r['lo']:.3f}, {r['hi']:.3f}]")
        for r in shares
    ]  # fmt: skip
    parts.ensembles.append({"figure": figure, "rows": rows, "reasons": e.top_reasons(members)})
    tags = [r["label"] for r in shares for _ in range(int(r["count"]))]
    parts.found.append({"name": name, "what": "an ensemble", "tags": tags, "unit": "members"})
    counts = "; ".join(f"{r['label']}: {r['count']}" for r in shares)
    summary = f"{name}: ensemble of {n} members, {what}: {counts}"
    summary += " (σ = 0: one deterministic run)." if fixed else "."
    _record(parts, path, "ensemble", e.ensemble_settings(ens.config, ens), summary)


def _p_chaotic_text(r: dict[str, Any]) -> str:
    """P(chaotic) with its Wilson interval; a deterministic cell (one run standing for
    identical realizations, sigma = 0) has no sampling interval and says so instead."""
    p = f"{r.get('p_chaotic', float('nan')):.2f}"
    if bool(r.get("deterministic", False)):
        return f"{p} (deterministic: one run)"
    lo, hi = r.get("p_chaotic_lo", float("nan")), r.get("p_chaotic_hi", float("nan"))
    return f"{p} [{lo:.2f}, {hi:.2f}]"


def _sweep_settings(cfg: dict[str, Any]) -> dict[str, Any]:
    """The provenance rows of a bifurcation's or regime map's record."""
    rows = {label: cfg.get(k) for k, label in _SWEEP_ROWS.items() if k in cfg}
    rows.update(code_rows(cfg.get("code")))
    for axis, label in (("axis", "swept parameter"), ("x", "x axis"), ("y", "y axis")):
        if axis in cfg:
            name, vals = cfg[axis].get("name"), cfg[axis].get("values", [])
            rows[label] = name
            if vals:
                rows[label] = f"{name}: {len(vals)} values in [{min(vals):g}, {max(vals):g}]"
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
    every run starts; a meaning over 160 characters is cut near 150."""
    from ..model import FIELD_DOCS, Params
    from ..numerics import Numerics

    def short(doc: str) -> str:
        return doc if len(doc) < 160 else doc[:150].rsplit(" ", 1)[0] + " …"

    docs = {**FIELD_DOCS, **Numerics.field_docs()}
    docs = {k: (d.get("unit") or "", short(d.get("doc") or "")) for k, d in docs.items()}
    values = {**Params().to_dict(), **Numerics().to_dict()}
    return [(k, v, *docs.get(k, ("", ""))) for k, v in values.items()]


def _sections(parts: ReportParts) -> tuple[tuple[str, str], ...]:
    """The table of contents: :data:`SECTIONS` (without :data:`PAPER_SECTIONS` outside the
    paper's report), with :data:`ENSEMBLES` after the bifurcation diagrams when there is an
    ensemble."""
    shown = tuple(s for s in SECTIONS if parts.paper or s[0] not in PAPER_SECTIONS)
    if not parts.ensembles:
        return shown
    at = [sid for sid, _ in shown].index("bifurcations") + 1
    return (*shown[:at], ENSEMBLES, *shown[at:])


def lead_figure(parts: ReportParts) -> FigureItem | None:
    """The figure the headline leads with: :attr:`ReportParts.lead`, else the first regime
    map, bifurcation diagram, ensemble, response or paper figure."""
    for item in (
        parts.lead,
        *(m["figure"] for m in parts.regime_maps + parts.bifurcations + parts.ensembles),
        *(r["figure"] for r in parts.responses),
        *parts.paper_figures,
    ):
        if item is not None:
            return item
    return None


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
    changed = uncommitted_sources() if commit else None
    if changed:
        more = f" and {len(changed) - 5} more" if len(changed) > 5 else ""
        commit += " plus uncommitted changes to " + ", ".join(changed[:5]) + more
    return env.get_template("report.html").render(
        title=title,
        sections=_sections(parts),
        parts=parts,
        answer=parts.headline or headline(parts.found),
        lead=lead_figure(parts),
        fold=fold,
        source=SOURCE_PAPER,
        version=__version__,
        commit=commit or "not available (not run from a git checkout)",
        date=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
        command=command or " ".join(["chaoscam", *sys.argv[1:]]),
        python=sys.version.split()[0],
        classifier=classifier_fingerprint(),
        model=model_rows(),
    )


def build_report(inputs, parts: ReportParts | None = None) -> ReportParts:
    """Add every input to the report parts: what :func:`load_inputs` returns, or paths and
    results in memory (:func:`~chaoscam.report.as_inputs`); a kind of input that is not there
    is named in the "What is missing" section."""
    inputs = as_inputs(inputs)
    parts = parts or ReportParts()
    for add, items, kind, what in (
        (add_regime_map, inputs.regime_maps, "regime map", "regime-map"),
        (add_bifurcation, inputs.bifurcations, "bifurcation diagram", "bifurcation"),
        (add_ensemble, inputs.ensembles, None, None),
        (add_trajectory, inputs.trajectories, "trajectory", "simulate --out"),
    ):
        for path, result in items:
            add(parts, path, result)
        if kind and not items:
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
