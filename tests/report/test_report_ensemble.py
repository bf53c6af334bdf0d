"""Ensembles in the report: ``chaoscam ensemble --out`` records its run in the members file,
and ``chaoscam report`` shows the members' section, the share of each label with its Wilson
interval, why members stayed undetermined, and that record."""

from __future__ import annotations

import re

import pandas as pd
import pytest

from chaoscam.cli import main
from chaoscam.report._ensemble import label_shares
from chaoscam.sweep import read_ensemble, wilson_interval


def _ensemble(d, name, *extra):
    out = d / f"{name}.parquet"
    args = ["ensemble", "--members", "6", "--duration", "2", "--seed", "4", "--quiet"]
    assert main([*args, *extra, "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("ens")
    return {
        "random": _ensemble(d, "random", "--set", "l_lambda_sigma=0.002", "--classify"),
        "fixed": _ensemble(d, "fixed", "--classify"),
        "plain": _ensemble(d, "plain", "--set", "l_lambda_sigma=0.002"),
    }


def _report(inputs, tmp_path, capsys):
    out = tmp_path / "r.html"
    code = main(["report", *map(str, inputs), "--out", str(out)])
    return code, out.read_text() if out.exists() else "", capsys.readouterr().err


def _rows(text: str, caption: str) -> list[list[str]]:
    table = text[text.index(caption) :]
    table = table[: table.index("</table>")]
    return [re.findall(r"<td>(.*?)</td>", r) for r in table.split("<tr>")[2:]]


def test_members_file_records_the_run(runs):
    """The members file says what made it: parameters, seed, indices, duration, device and
    classifier (none without --classify)."""
    record = read_ensemble(runs["random"]).config
    assert record["kind"] == "ensemble" and record["device"] == "cpu"
    assert record["params"]["l_lambda_sigma"] == 0.002 and record["seed"] == 4
    assert (record["first"], record["members"], record["duration"]) == (0, 6, 2.0)
    assert record["classifier"].startswith("chaoscam.classify(")
    assert read_ensemble(runs["plain"]).config["classifier"] == "none"


def test_report_shows_the_share_of_each_label_with_its_interval(runs, tmp_path, capsys):
    """The table counts each label as the members file does, with the Wilson interval over
    the members; the ensemble is in the contents and the summary; its record is shown."""
    code, text, err = _report([runs["random"]], tmp_path, capsys)
    assert code == 0, err
    members = pd.read_parquet(runs["random"])
    rows = _rows(text, "Members of Ensemble of 6 members")
    counts = members["label"].value_counts()
    assert sum(int(r[1]) for r in rows) == 6 and len(rows) == len(counts)
    for label, count, share, interval in rows:
        assert int(count) == (members["label"] == label.split(" (")[0]).sum()
        lo, hi = wilson_interval(int(count), 6)
        assert interval == f"[{lo:.3f}, {hi:.3f}]" and share == f"{int(count) / 6:.3f}"
    assert '<a href="#ensembles">Ensembles</a>' in text and "random.parquet: ensemble of 6" in text
    assert "ensemble: " in text and "realization indices" in text and "0 .. 5" in text


def test_sections_file_names_its_ensemble(runs, tmp_path, capsys):
    """Naming the ensemble by its .sections.parquet reads the whole ensemble."""
    sections = runs["random"].with_suffix(".sections.parquet")
    code, text, err = _report([sections], tmp_path, capsys)
    assert code == 0, err
    assert "Ensemble of 6 members (random.parquet)" in text


def test_sigma_zero_is_one_deterministic_run(runs, tmp_path, capsys):
    """With sigma = 0 every member is the same run: no interval over identical runs."""
    code, text, err = _report([runs["fixed"]], tmp_path, capsys)
    assert code == 0, err
    rows = _rows(text, "Members of Ensemble of 6 members")
    assert rows and all(r[3] == "none: one deterministic run" for r in rows)
    assert "one deterministic run" in text and "Wilson interval." not in text


def test_unclassified_members_are_counted_by_status(runs, tmp_path, capsys):
    """Without --classify the table counts the run statuses and says so."""
    code, text, err = _report([runs["plain"]], tmp_path, capsys)
    assert code == 0, err
    assert "run statuses (not classified)" in text
    assert [r[0] for r in _rows(text, "Members of Ensemble of 6 members")] == ["OK"]


def test_shares_order_periods_and_undetermined_reasons():
    """Periodic members are counted per period, in the label order; undetermined members'
    reasons are counted per reason."""
    from chaoscam.report._ensemble import _reasons

    members = pd.DataFrame(
        {
            "member": range(6),
            "status": ["OK"] * 5 + ["LEFT_REACH"],
            "label": ["chaotic", "periodic", "periodic"]
            + ["undetermined", "undetermined", "left_reach"],
            "period": pd.array([None, 2, 1, None, None, None], dtype="Int64"),
            "reasons": ["", "", "", "too few points; no rule", "too few points", ""],
        }
    )
    rows = label_shares(members)
    assert [r["label"] for r in rows] == [
        "periodic (period 1)",
        "periodic (period 2)",
        "chaotic",
        "undetermined",
        "left_reach",
    ]
    assert [r["count"] for r in rows] == [1, 1, 1, 2, 1]
    assert _reasons(members) == [("too few points", 2), ("no rule", 1)]
