"""The `chaoscam classify` and `chaoscam classify-series` commands."""

import json
import math

import numpy as np
import pandas as pd
import pytest

import chaoscam
from chaoscam.cli import main


@pytest.fixture(scope="module")
def traj_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("cli") / "t.parquet"
    chaoscam.simulate(duration=3.0).to_parquet(path)
    return path


def _json(capsys, extended=False):
    out = json.loads(capsys.readouterr().out)
    keys = {"label", "period", "evidence", "reasons"}
    assert set(out) == (keys | {"extended"} if extended else keys)
    return out


def test_classify_says_when_the_verdict_needed_a_longer_run(tmp_path, capsys):
    """l_lambda = 1 mm, 10 s recorded: undetermined as given, settled by running the
    realization longer; the JSON says how long, and why."""
    path = tmp_path / "short.parquet"
    chaoscam.simulate(duration=20.0, transient=10.0, l_lambda=0.001).to_parquet(path)
    assert main(["classify", str(path), "--json"]) == 0
    out = _json(capsys, extended=True)
    assert out["label"] == "chaotic"
    assert out["extended"] == {
        "recorded_s": 40.0,
        "why": "the verdict on the run as given was undetermined",
    }
    assert main(["classify", str(path), "--no-extend", "--json"]) == 0
    assert _json(capsys)["label"] == "undetermined"


def test_classify_prints_the_verdict_as_json(traj_file, capsys):
    """classify TRAJ.parquet --json: JSON verdict on stdout, exit 0 (--no-extend: the 3 s run's
    own evidence, from its section and the tangent exponent; 8 periods are too few to
    decide, so by default the run is extended)."""
    assert main(["classify", str(traj_file), "--no-extend", "--json"]) == 0
    out = _json(capsys)
    assert out["label"] in ("periodic", "quasiperiodic", "chaotic", "undetermined")
    assert {e["name"] for e in out["evidence"]} >= {"section_period", "exponent"}


def test_classify_bad_files_exit_2(tmp_path, capsys):
    """A missing file or a file of the wrong kind: exit 2 with a message naming it."""
    assert main(["classify", str(tmp_path / "none.parquet")]) == 2
    assert "none.parquet" in capsys.readouterr().err
    csv = tmp_path / "x.csv"
    csv.write_text("a\n1\n")
    assert main(["classify", str(csv)]) == 2
    assert "x.csv" in capsys.readouterr().err


def test_series_with_dt_and_forcing_period(tmp_path, capsys):
    """--dt: a forced period-2 signal is periodic with period 2 forcing periods."""
    t = np.arange(20_000) * 0.01
    x = np.cos(2 * math.pi * t) + 0.3 * np.cos(math.pi * t + 0.4)
    pd.DataFrame({"t": t, "x": x}).to_csv(tmp_path / "s.csv", index=False)
    argv = [
        "classify-series",
        str(tmp_path / "s.csv"),
        "--column",
        "x",
        "--dt",
        "0.01",
        "--forcing-period",
        "1.0",
    ]
    assert main(argv) == 0
    out = _json(capsys)
    assert (out["label"], out["period"]) == ("periodic", 2)


def test_series_with_section_points(tmp_path, capsys):
    """--section: period-3 points in two columns are periodic with period 3."""
    k = np.arange(60)
    pts = pd.DataFrame({"a": np.cos(2 * math.pi * k / 3), "b": np.sin(2 * math.pi * k / 3)})
    pts.to_csv(tmp_path / "p.csv", index=False)
    argv = [
        "classify-series",
        str(tmp_path / "p.csv"),
        "--column",
        "a",
        "--column",
        "b",
        "--section",
    ]
    assert main(argv) == 0
    out = _json(capsys)
    assert (out["label"], out["period"]) == ("periodic", 3)
    assert out["reasons"] == []  # exact points: nothing to add


@pytest.mark.parametrize(
    ("column", "label", "period"),
    [
        ("cos", "quasiperiodic", None),
        ("angle", "quasiperiodic", None),
        ("period3", "periodic", 3),
        ("logistic", "chaotic", None),
        ("henon_x", "chaotic", None),
    ],
)
def test_series_section_of_one_scalar(tmp_path, capsys, column, label, period):
    """--section on one column: a golden rotation seen through cos of its angle and through
    the angle (turns) is quasiperiodic, cos(2πk/3) periodic 3, the logistic map (r = 4) and
    the Hénon map's x chaotic."""
    from chaoscam.testsystems import GOLDEN, henon_orbit, logistic_orbit

    k = np.arange(2000)
    angle = np.mod(GOLDEN * k, 1.0)
    data = {"cos": np.cos(2 * math.pi * angle), "angle": angle,
            "period3": np.cos(2 * math.pi * k / 3), "logistic": logistic_orbit(4.0, k.size),
            "henon_x": henon_orbit(k.size)[:, 0]}  # fmt: skip
    pd.DataFrame({column: data[column]}).to_csv(tmp_path / "x.csv", index=False)
    assert main(["classify-series", str(tmp_path / "x.csv"), "--column", column, "--section"]) == 0
    out = _json(capsys)
    assert (out["label"], out["period"]) == (label, period), out["reasons"]


def test_series_section_of_a_scalar_repeating_a_value_says_it_is_not_certified(tmp_path, capsys):
    """cos(πk/2) (1, 0, -1, 0) with 1e-5 noise is periodic 4 from its delays, and its bands
    (~3e-5 of the extent) are reported not certified, as for points of several columns."""
    k = np.arange(1000)
    x = np.cos(math.pi * k / 2) + 1e-5 * np.random.default_rng(0).standard_normal(k.size)
    pd.DataFrame({"x": x}).to_csv(tmp_path / "x.csv", index=False)
    assert main(["classify-series", str(tmp_path / "x.csv"), "--column", "x", "--section"]) == 0
    out = _json(capsys)
    assert (out["label"], out["period"]) == ("periodic", 4)
    assert out["reasons"][-1].startswith("periodic to the tolerance, not certified: its 4 band")


def test_series_section_with_wide_bands_says_it_is_not_certified(tmp_path, capsys):
    """The default model's section (8 bands up to 8e-4 of the extent, chaotic by its
    tangent exponent) is periodic 8 to the tolerance on points alone: the verdict says it
    is not certified and how to decide it."""
    import chaoscam

    tr = chaoscam.simulate(chaoscam.Params(), duration=20)
    tr.section[["theta_f", "omega_f"]].to_csv(tmp_path / "s.csv", index=False)
    argv = ["classify-series", str(tmp_path / "s.csv"), "--section"]
    assert main([*argv, "--column", "theta_f", "--column", "omega_f"]) == 0
    out = _json(capsys)
    assert (out["label"], out["period"]) == ("periodic", 8)
    assert out["reasons"][-1].startswith("periodic to the tolerance, not certified: its 8 band")
    assert "`chaoscam classify RUN`" in out["reasons"][-1]


@pytest.mark.parametrize(
    "extra, content, message",
    [
        (["--column", "x", "--dt", "0.01"], None, "no such file"),
        (["--column", "y", "--dt", "0.01"], "x\n1\n2\n", "no column 'y'"),
        (["--column", "x", "--section"], "x\n1\n\n2\nnan\n", "NaN"),
        (["--column", "x"], "x\n1\n2\n", "--dt SECONDS"),
        (["--column", "x", "--dt", "0"], "x\n1\n2\n", "--dt"),
        (["--column", "x", "--section", "--forcing-period", "1"], "x\n1\n2\n", "forcing"),
        (["--column", "x", "--dt", "0.1"], "x\n1\nfoo\n", "not numbers"),
        (["--column", "x", "--column", "x", "--section"], "x\n1\n2\n", "'x' given more than once"),
        # pandas read the first of two same-named columns and renamed the other "x.1"
        (["--column", "x", "--dt", "0.1"], "x,x\n1,2\n3,4\n", "names column 'x' more than once"),
    ],
    ids=[
        "missing-file",
        "missing-column",
        "nan",
        "no-mode",
        "bad-dt",
        "section-forcing",
        "text",
        "column-twice",
        "header-twice",
    ],
)
def test_series_bad_input_exits_2(tmp_path, capsys, extra, content, message):
    """Bad input to classify-series: a clear message on stderr and exit code 2."""
    path = tmp_path / "d.csv"
    if content is not None:
        path.write_text(content)
    assert main(["classify-series", str(path), *extra]) == 2
    assert message in capsys.readouterr().err


def test_classify_uses_the_tangent_exponent(traj_file, capsys):
    """The verdict, extended by default, carries the tangent exponent through the impacts
    (a trajectory file keeps no Jacobians: the realization is solved again with them)."""
    assert main(["classify", str(traj_file), "--json"]) == 0
    out = _json(capsys, extended=True)
    exponent = [e for e in out["evidence"] if e["name"] == "exponent"]
    assert len(exponent) == 1 and math.isfinite(exponent[0]["value"])


def test_classify_series_on_a_directory_says_so(tmp_path, capsys):
    """A directory given as the CSV file is named as a directory (it said "no such file")."""
    assert main(["classify-series", str(tmp_path), "--column", "x", "--dt", "0.001"]) == 2
    assert "is a directory; give a CSV file" in capsys.readouterr().err


def test_a_closed_pipe_ends_quietly(traj_file):
    """`chaoscam classify RUN | head -c 10`: the reader leaves before the verdict is written;
    no "Broken pipe" error and no traceback, exit 141 as a shell reports SIGPIPE."""
    import subprocess
    import sys

    code = "import sys; from chaoscam.cli import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.Popen(
        [sys.executable, "-c", code, "classify", str(traj_file), "--no-extend"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.close()  # the reader is gone before anything is written
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141, err
    assert "Broken pipe" not in err and "Traceback" not in err


def test_classify_prints_one_line_by_default(traj_file, capsys):
    """classify TRAJ.parquet without --json: one line, the API verdict's (it printed ~50
    lines of JSON)."""
    from chaoscam.cli._classify import verdict_line

    assert main(["classify", str(traj_file), "--no-extend"]) == 0
    out = capsys.readouterr().out
    (api,) = chaoscam.classify(chaoscam.load_trajectory(traj_file), extend_to=None)
    assert out == verdict_line(api) + "\n" and out.startswith(api.label)


def test_the_verdict_line_says_label_period_certificate_and_exponent():
    """The line names the label, the period, a certified orbit and lambda_1 +- its standard
    error [1/s]; an undetermined verdict its first reason."""
    from chaoscam.analysis import Evidence, Verdict
    from chaoscam.cli._classify import verdict_line

    def tangent(lam, err):
        return {"tangent": {"exponents": [lam, -5.0], "stderr": [err, 0.1]}}

    cert = Evidence("periodic_orbit", 4, "periodic", "certified: ...")
    periodic = Verdict("periodic", 4, (cert,), (), tangent(-0.8, 0.02))
    assert (
        verdict_line(periodic) == "periodic, period 4 (certified orbit, lambda_1 = -0.8 +- 0.02 /s)"
    )
    chaotic = Verdict("chaotic", None, (), (), tangent(1.4, 0.1))
    assert verdict_line(chaotic) == "chaotic (lambda_1 = +1.4 +- 0.1 /s)"
    undetermined = Verdict("undetermined", None, (), ("too few points", "another"), {})
    assert verdict_line(undetermined) == "undetermined: too few points"


def test_the_one_line_verdict_names_the_twins_and_the_noise_width():
    """A noisy period of the random model says what decided it and how wide its clusters are."""
    from chaoscam.analysis import Evidence, Verdict
    from chaoscam.cli._classify import verdict_line

    v = Verdict("periodic", 8, (Evidence("twins", -0.3, "not_chaotic", "synchronised"),), (),
                {"twins": {"outcome": "synchronised"}, "noisy": {"band_width": 1.2e-4},
                 "tangent": {"exponents": [1.17, -3.0], "stderr": [0.11, 0.1]}})  # fmt: skip
    assert verdict_line(v) == (
        "periodic, period 8 (twins sharing the draws synchronised, noise width 0.00012 rad, "
        "lambda_1 = +1.2 +- 0.1 /s)"
    )
