"""``chaoscam paper``: figure scripts write data and PNGs; the comparison table is filled."""

from __future__ import annotations

import re

from chaoscam.cli import main


def test_paper_figs_3_and_5_agree_on_their_checkable_claims(tmp_path, capsys):
    """Figs. 3 and 5 (no dynamics) run in seconds, write their data and agree with the paper."""
    out = tmp_path / "paper.html"
    assert main(["paper", "--quick", "--figures", "3,5", "--out", str(out)]) == 0
    data = tmp_path / "paper-data"
    for name in ("fig3.csv", "fig3.png", "fig5.csv", "fig5.png"):
        assert (data / name).stat().st_size > 0
    text = out.read_text()
    rows = re.findall(r'<td class="([a-z-]+)">', text)
    assert rows == ["agrees", "agrees"]
    assert 'href="#fig3"' in text and 'href="#fig5"' in text  # each row links to its figure
    assert not re.search(r"https?:", text, re.IGNORECASE)


def test_paper_rejects_unknown_figure(tmp_path, capsys):
    """An unknown figure number is a usage error."""
    assert main(["paper", "--figures", "2", "--out", str(tmp_path / "p.html")]) == 2
    assert "no figure" in capsys.readouterr().err


def test_sequence_rule_finds_the_papers_order_and_nothing_else():
    """The Fig. 4 rule: the paper's regimes must appear in order among the label runs."""
    from chaoscam.report._paper import _is_subsequence, _runs

    wanted = ["chaotic", "periodic-2", "quasiperiodic", "chaotic"]
    labels = ["chaotic", "chaotic", "periodic-2", "quasiperiodic", "periodic", "chaotic"]
    assert _runs(labels)[0] == ("chaotic", 2)
    assert _is_subsequence(wanted, [lab for lab, _ in _runs(labels)])
    assert not _is_subsequence(wanted, ["quasiperiodic", "chaotic", "periodic-2", "chaotic"])


def test_a_failing_figure_is_reported_as_missing(tmp_path, monkeypatch):
    """A figure script that raises leaves a report that names the failure."""
    from chaoscam.report import _paper

    def boom(quick, outdir, workers=None):
        raise RuntimeError("no luck")

    monkeypatch.setitem(_paper.FIGURES, 3, boom)
    out = _paper.run_paper(quick=True, out=tmp_path / "p.html", figures=[3, 5])
    text = out.read_text()
    assert "boom: failed with RuntimeError: no luck" in text
    assert "Fig. 5 — fractal stiffness against D" in text
