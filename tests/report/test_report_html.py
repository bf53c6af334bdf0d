"""The HTML report: every section, decodable inline PNGs, no network reference, clear errors."""

from __future__ import annotations

import base64
import io
import re
from html.parser import HTMLParser

import pytest

import chaoscam
from chaoscam.cli import main
from chaoscam.report._html import PAPER_SECTIONS, SECTIONS

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


class _Collect(HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids, self.imgs, self.tables, self.open = set(), [], 0, []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "img":
            self.imgs.append(a)
        if tag == "table":
            self.tables += 1


def _parse(text: str) -> _Collect:
    p = _Collect()
    p.feed(text)
    p.close()
    return p


@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    """A tiny trajectory, bifurcation diagram and regime map, written as chaoscam writes them
    (the sweeps judged by the package's verdict, as the report's runs are)."""
    from chaoscam.sweep import Axis, bifurcation, regime_map

    d = tmp_path_factory.mktemp("inputs")
    traj = chaoscam.simulate(duration=3.0, transient=1.0)
    traj.to_parquet(d / "traj.parquet")
    bif = bifurcation(
        "l_lambda",
        "0.006:0.010:2",
        duration=3.0,
        transient=1.5,
        workers=1,
    )
    bif.to_parquet(d / "bif.parquet")
    rm = regime_map(
        Axis("l_lambda", (0.008,)),
        Axis("l_lambda_sigma", (0.0, 0.001)),
        realizations=2,
        duration=2.5,
        transient=1.0,
        workers=1,
    )
    rm.to_parquet(d / "map.parquet")
    return d


def _report(args, tmp_path, capsys) -> tuple[int, str, str]:
    out = tmp_path / "r.html"
    code = main(["report", *map(str, args), "--out", str(out)])
    err = capsys.readouterr().err
    return code, (out.read_text() if out.exists() else ""), err


def test_full_report_has_every_section_and_valid_images(outputs, tmp_path, capsys):
    """A report of all three kinds parses, has each section, and every image is a real PNG."""
    import matplotlib.image as mpimg

    code, text, err = _report(
        [outputs / "traj.parquet", outputs / "bif.parquet", outputs / "map.parquet"],
        tmp_path,
        capsys,
    )
    assert code == 0, err
    doc = _parse(text)
    assert {sid for sid, _ in SECTIONS if sid not in PAPER_SECTIONS} <= doc.ids
    assert len(doc.imgs) >= 3 and doc.tables >= 4
    for img in doc.imgs:
        assert img.get("alt"), "every figure has alt text"
        head, _, data = img["src"].partition(",")
        assert head == "data:image/png;base64"
        raw = base64.b64decode(data, validate=True)
        assert raw.startswith(PNG_SIGNATURE)
        assert mpimg.imread(io.BytesIO(raw), format="png").shape[0] > 50
    assert not re.search(r"https?:", text, re.IGNORECASE), "no network reference"
    # The evidence section defines the labels and the tables' columns it points readers to.
    for term in ("periodic n", "chaotic", "undetermined", "left_reach", "exponent"):
        assert f"<dt>{term}" in text
    assert "Nothing: every part of the report has its inputs." in text
    assert "chaoscam report " in text and "package version" in text and "git commit" in text
    # The parameter set every run starts from, with units; a sweep's settings list the base
    # fields it changes (here none but the integrator and step, always shown).
    assert "<td>omega</td><td>28.7</td><td>rad/s</td>" in text
    assert "<td>xi</td><td>0.42</td>" in text
    assert "<td>base dt [s]</td>" in text and "<td>base xi" not in text


def test_a_report_of_ones_own_runs_has_no_paper_sections(outputs, tmp_path, capsys):
    """`chaoscam report` of non-paper inputs: no paper figures, no comparison with the paper,
    no "why the paper differs", neither in the page nor in its contents (they stood there,
    empty); the source paper is cited by title."""
    code, text, err = _report([outputs / "traj.parquet", outputs / "map.parquet"], tmp_path, capsys)
    assert code == 0, err
    doc = _parse(text)
    assert not doc.ids & set(PAPER_SECTIONS)
    for absent in ("Paper figures reproduced", "The paper against this run", "Why the paper"):
        assert absent not in text
    assert "<cite>Effect of Surface Morphology on Dynamic Characteristics of Cam-Follower" in text
    assert "docs/" not in text and ".md" not in text  # the docs are not shipped: named only


def test_the_headline_is_computed_from_the_verdicts(outputs):
    """The answer names the commonest regime of the inputs' verdicts and where it lies;
    other verdicts give another answer, and the lead figure is the first sweep's."""
    from chaoscam.report import build_report
    from chaoscam.report._html import lead_figure
    from chaoscam.sweep import read_bifurcation

    bif = read_bifurcation(outputs / "bif.parquet")
    parts = build_report([bif])
    from chaoscam.report._headline import headline

    before = headline(parts.found)
    assert len(before) == 2 and before[0].startswith(f"Of the {len(bif.verdicts)} runs given, ")
    assert lead_figure(parts).id == "bif-1"
    bif.verdicts["label"], bif.verdicts["period"] = "periodic", 3
    after = headline(build_report([bif]).found)
    assert after != before
    n = len(bif.verdicts)
    assert after[0] == f"Of the {n} runs given, {n} are period 3."
    assert "period 3 in 2 of 2 runs" in after[1]


def test_long_texts_fold_and_abstaining_methods_share_a_row():
    """fold keeps short texts whole and cuts long ones after a sentence within the limit;
    methods abstaining with one detail share one evidence row."""
    from types import SimpleNamespace as E

    from chaoscam.report._headline import fold
    from chaoscam.report._html import _evidence_rows

    assert fold("short.") == ("short.", "")
    head, rest = fold("A first sentence. " + "word " * 80)
    assert head == "A first sentence." and rest.startswith("word")
    same = "periodic to the tolerance"
    ev = [E(name=n, value=None, vote=None, detail=same) for n in ("a", "b", "c")]
    ev.append(E(name="exponent", value=0.5, vote="chaotic", detail="positive"))
    rows = _evidence_rows(ev)
    assert rows == [("a, b, c", "", "abstains", same), ("exponent", "0.5", "chaotic", "positive")]


def test_a_sweep_lists_every_base_field_it_changes():
    """Settings rows: every base field that differs from Params(), with its unit (a fixed
    list of nine fields hid a changed ω, ξ or e)."""
    from chaoscam.model import Params
    from chaoscam.numerics import Numerics
    from chaoscam.report._html import _sweep_settings

    base, numerics = Params(xi=0.3, omega=40.0).to_dict(), Numerics(dt=1e-6).to_dict()
    rows = _sweep_settings({"kind": "bifurcation", "base": base, "numerics": numerics})
    assert rows["base xi [-]"] == 0.3 and rows["base omega [rad/s]"] == 40.0
    assert rows["base dt [s]"] == 1e-6 and rows["base integrator"] == "rk4"
    assert not any("base e " in k or k == "base e [m]" for k in rows)


def test_partial_inputs_say_what_is_missing(outputs, tmp_path, capsys):
    """A trajectory alone still gives a report, which names the missing sweeps."""
    code, text, _ = _report([outputs / "traj.parquet"], tmp_path, capsys)
    assert code == 0
    assert "No regime map among the inputs" in text
    assert "No bifurcation diagram among the inputs" in text


def test_companion_file_reads_its_sweep(outputs, tmp_path, capsys):
    """Naming a sweep by its companion (.verdicts / .cells) reads the whole sweep."""
    code, text, _ = _report(
        [outputs / "bif.verdicts.parquet", outputs / "map.cells.parquet"], tmp_path, capsys
    )
    assert code == 0
    assert "Bifurcation diagram over l_lambda" in text and "Regime map l_lambda" in text


@pytest.mark.parametrize("kind", ["missing", "not_parquet", "foreign_parquet", "suffix"])
def test_bad_input_is_a_usage_error_naming_the_file(kind, tmp_path, capsys):
    """Missing, unreadable or foreign input exits 2 with the file's name in the message."""
    import pandas as pd

    path = tmp_path / f"{kind}.parquet"
    if kind == "not_parquet":
        path.write_text("t,theta\n0,1\n")
    elif kind == "foreign_parquet":
        pd.DataFrame({"a": [1, 2]}).to_parquet(path)
    elif kind == "suffix":
        path = tmp_path / "run.csv"
        path.write_text("x\n")
    code, _, err = _report([path], tmp_path, capsys)
    assert code == 2
    assert str(path) in err


def test_out_must_be_html(outputs, tmp_path, capsys):
    """The report's name must end in .html."""
    code = main(["report", str(outputs / "traj.parquet"), "--out", str(tmp_path / "r.txt")])
    assert code == 2 and "html" in capsys.readouterr().err


def test_a_map_at_another_confidence_is_reported_at_that_level(tmp_path, capsys):
    """A map made with confidence = 0.8 says 80% where it said 95% (its intervals are at
    80 %), and names its confidence and device in the provenance; confidence = 95 is refused
    before any run (it failed at the end, leaving a checkpoint that could not finish)."""
    from chaoscam.sweep import Axis, SweepError, regime_map

    x, y = Axis("l_lambda", (0.008,)), Axis("l_lambda_sigma", (0.002,))
    kw = dict(realizations=2, duration=2.0, transient=1.0, workers=1)
    with pytest.raises(SweepError, match=r"confidence = 95: .*\(0, 1\)"):
        regime_map(x, y, confidence=95, out=tmp_path / "bad.parquet", **kw)
    assert not list(tmp_path.iterdir())
    rm = regime_map(x, y, confidence=0.8, **kw)
    rm.to_parquet(tmp_path / "m80.parquet")
    code, text, err = _report([tmp_path / "m80.parquet"], tmp_path, capsys)
    assert code == 0, err
    assert "P(chaotic) [80% CI]" in text and "its 80% Wilson interval" in text
    assert "95%" not in text
    assert "confidence of the intervals</td><td>0.8" in text and "<td>device</td><td>cpu" in text
