"""The `chaoscam simulate` command."""

import pandas as pd

from chaoscam.cli import main


def test_simulate_prints_summary_and_writes_files(tmp_path, capsys):
    """simulate writes series, section and impacts and prints the summary."""
    out, sec, imp = tmp_path / "s.csv", tmp_path / "sec.csv", tmp_path / "imp.csv"
    code = main(
        [
            "simulate",
            "--duration",
            "1",
            "--set",
            "omega=28.7",
            "--out",
            str(out),
            "--section",
            str(sec),
            "--impacts",
            str(imp),
        ]
    )
    assert code == 0
    text = capsys.readouterr().out
    assert "status: OK" in text and "contact fraction" in text
    assert len(pd.read_csv(out)) > 900 and len(pd.read_csv(sec)) == 5
    assert "omega_after" in pd.read_csv(imp).columns


def test_unknown_parameter_exits_2(capsys):
    """An unknown --set name is an error naming it, exit code 2."""
    assert main(["simulate", "--duration", "0.1", "--set", "omgea=3"]) == 2
    assert "omgea" in capsys.readouterr().err


def test_bad_value_exits_2(capsys):
    """A value outside its range is an error naming the field, exit 2."""
    assert main(["simulate", "--duration", "0.1", "--set", "m=-1"]) == 2
    assert "m = -1.0" in capsys.readouterr().err
    assert main(["simulate", "--duration", "-1"]) == 2
    assert main(["simulate", "--duration", "0.1", "--set", "omega"]) == 2


def test_ctrl_c_while_writing_says_what_is_on_disk(tmp_path, monkeypatch, capsys):
    """Ctrl-C after the summary, while the outputs are written: one line saying which are
    written and that none is half-written (it said only "interrupted")."""
    out, section = tmp_path / "s.parquet", tmp_path / "sec.csv"

    def stopped(self, *args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(pd.DataFrame, "to_csv", stopped)
    argv = ["simulate", "--duration", "0.2", "--out", str(out), "--section", str(section)]
    assert main(argv) == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"chaoscam: interrupted; written: {out}; no output is half-written "
                   "(each is written whole or not at all)"]  # fmt: skip
    assert out.exists() and not section.exists()
