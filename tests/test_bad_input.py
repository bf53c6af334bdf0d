"""Bad input, on the command line and through the API: a message naming what is wrong and
exit code 2 (the API: ParameterError / SweepError / TypeError), never a traceback; numpy
scalars accepted; a run that could not simulate what was asked exits 1 with the cause."""

import dataclasses
import json
import math

import numpy as np
import pandas as pd
import pytest

import chaoscam
from chaoscam import Numerics, ParameterError, Params
from chaoscam.cli import main
from chaoscam.sweep import (
    Axis,
    SweepError,
    bifurcation,
    initial_offsets,
    realization_index,
    regime_map,
    wilson_interval,
)

SIM = ["simulate", "--duration", "0.05"]
BIF = [
    "bifurcation",
    "--param",
    "l_lambda",
    "--values",
    "0.006:0.008:2",
    "--duration",
    "0.5",
    "--workers",
    "1",
    "--quiet",
]
MAP = [
    "regime-map",
    "--mu",
    "0.006:0.008:2",
    "--sigma",
    "0:0.001:2",
    "--duration",
    "0.5",
    "--workers",
    "1",
    "--quiet",
]
ENS = ["ensemble", "--members", "2", "--duration", "0.5", "--quiet"]

CLI_CASES = {
    "seed -1": ([*SIM, "--seed", "-1"], "seed"),
    "index -1": ([*SIM, "--index", "-1"], "index"),
    "output-dt 0": ([*SIM, "--output-dt", "0"], "output_dt"),
    "output-dt -1": ([*SIM, "--output-dt", "-1"], "output_dt"),
    "output-dt nan": ([*SIM, "--output-dt", "nan"], "output_dt"),
    "omega 1e300": ([*SIM, "--set", "omega=1e300"], "omega"),
    "omega 1_0 (Python would read 10)": ([*SIM, "--set", "omega=1_0"], "omega = '1_0'"),
    "l 1e308": ([*SIM, "--set", "l=1e308"], "l ="),
    "flight_merge 1e9": ([*SIM, "--set", "flight_merge=1000000000"], "flight_merge"),
    "max_events 1e12": (
        [*SIM, "--set", "max_events_per_step=1000000000000"],
        "max_events_per_step",
    ),
    "theta_f0 1e308": ([*SIM, "--set", "theta_f0=1e308"], "theta_f0"),
    "set twice": ([*SIM, "--set", "omega=30", "--set", "omega=40"], "omega is given twice"),
    "set in capitals": ([*SIM, "--set", "OMEGA=30"], "Did you mean omega"),
    "x_O 1e308": ([*SIM, "--set", "x_O=1e308"], "x_O"),
    "duration 1e9": (["simulate", "--duration", "1e9", "--out", "OUT.parquet"], "memory"),
    "dt above duration": (["simulate", "--duration", "0.4", "--set", "dt=1"], "dt"),
    "values 1e8": ([*BIF[:4], "0.001:0.018:100000000", *BIF[5:], "--out", "OUT.parquet"], "NUM"),
    "checkpoint nan": (
        [*BIF, "--checkpoint-interval", "nan", "--out", "OUT.parquet"],
        "--checkpoint-interval",
    ),
    "checkpoint inf": (
        [*MAP, "--checkpoint-interval", "inf", "--out", "OUT.parquet"],
        "--checkpoint-interval",
    ),
    "realizations 1e9": ([*MAP, "--realizations", "1000000000", "--out", "OUT.parquet"], "memory"),
    "ensemble duration 1e9": (
        ["ensemble", "--members", "2", "--duration", "1e9", "--out", "OUT.parquet"],
        "memory",
    ),
    "ensemble seed -1": ([*ENS, "--seed", "-1", "--out", "OUT.parquet"], "seed"),
    "paper workers 0": (["paper", "--workers", "0", "--out", "OUT.html"], "--workers"),
    "map duration 1e9": ([*MAP, "--duration", "1e9", "--out", "OUT.parquet"], "memory"),
    "bifurcation duration 1e9": ([*BIF, "--duration", "1e9", "--out", "OUT.parquet"], "memory"),
    "map seed -1": ([*MAP, "--seed", "-1", "--out", "OUT.parquet"], "seed"),
    "bifurcation seed -1": ([*BIF, "--seed", "-1", "--out", "OUT.parquet"], "seed"),
    # Beyond the tables' 64-bit integers: the sweep ran, then failed writing (and on resume).
    "map seed 2**64": (
        [*MAP, "--seed", str(2**64), "--out", "OUT.parquet"],
        "<= 9223372036854775807",
    ),
    "bifurcation seed 2**63": ([*BIF, "--seed", str(2**63), "--out", "OUT.parquet"], "seed"),
    "ensemble first 2**63-1": (
        [*ENS, "--first", str(2**63 - 1), "--out", "OUT.parquet"],
        "first = 9223372036854775807",
    ),
    "simulate index 2**63": ([*SIM, "--index", str(2**63)], "index"),
    "bifurcation workers 99999": (
        [*BIF[:-3], "--workers", "99999", "--out", "OUT.parquet"],
        "workers",
    ),
    "map workers 99999": (
        [*MAP[:-3], "--workers", "99999", "--out", "OUT.parquet"],
        "workers",
    ),
    "ensemble workers 99999": ([*ENS, "--workers", "99999", "--out", "OUT.parquet"], "workers"),
    "initial conditions 1e10": (
        [*BIF, "--initial-conditions", "10000000000", "--out", "OUT.parquet"],
        "memory",
    ),
    "fate 1e300": ([*BIF, "--fate", "1e300", "--out", "OUT.parquet"], "fate horizon"),
    "scheduler without port": ([*BIF, "--scheduler", "bogus", "--out", "OUT.parquet"], "scheduler"),
}


@pytest.mark.parametrize("case", list(CLI_CASES))
def test_cli_bad_input_exits_2_naming_the_field(tmp_path, case, capsys):
    """Each bad input: exit 2, one message naming the field, nothing written."""
    args, named = CLI_CASES[case]
    args = [a.replace("OUT", str(tmp_path / "o")) for a in args]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("chaoscam: error:") and named in err, err
    assert list(tmp_path.iterdir()) == []


def test_run_that_left_the_model_exits_1_with_the_cause(capsys):
    """dt too coarse: the run ends LEFT_REACH; exit 1, the step-size warning given as the
    likely cause (not a raw Python warning). (dt = 5e-3 s: which way a run this coarse leaves
    the model is rounding's choice; at 5e-3 it is LEFT_REACH with both the naive and the
    exact clock, at 1e-2 it turned PENETRATION with the exact clock.)"""
    assert main(["simulate", "--duration", "0.1", "--set", "dt=0.005"]) == 1
    err = capsys.readouterr().err
    assert "LEFT_REACH" in err and "likely cause: dt" in err and "Warning:" not in err


def _empty_trajectory(path, rows):
    run = chaoscam.simulate(duration=0.2)
    run = dataclasses.replace(run, series=run.series.iloc[:rows], sections=run.sections.iloc[:rows])
    run.to_parquet(path)
    return path


@pytest.mark.parametrize("rows", [0, 1])
def test_too_little_data_is_an_error(tmp_path, rows, capsys):
    """A 0- or 1-row trajectory: classify and report both say "too little data" (exit 2)."""
    path = _empty_trajectory(tmp_path / "t.parquet", rows)
    assert main(["classify", str(path)]) == 2
    assert "too little data" in capsys.readouterr().err
    assert main(["report", str(path), "--out", str(tmp_path / "r.html")]) == 2
    assert "too little data" in capsys.readouterr().err


@pytest.mark.parametrize("text", ["x\n", "x\n1.0\n"])
def test_header_only_or_one_row_csv(tmp_path, text, capsys):
    """classify-series on a header-only or one-row CSV: "too little data", exit 2."""
    path = tmp_path / "s.csv"
    path.write_text(text)
    assert main(["classify-series", str(path), "--column", "x", "--dt", "0.01"]) == 2
    err = capsys.readouterr().err
    assert "too little data" in err and "record a longer signal" in err  # not "simulate"


def test_report_and_classify_refuse_the_same_files(tmp_path, capsys):
    """A trajectory without its metadata, or a column missing: both commands, exit 2."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    good = _empty_trajectory(tmp_path / "g.parquet", 50)
    table = pq.read_table(good)
    pq.write_table(table.drop(["gap"]), tmp_path / "col.parquet")
    meta = dict(table.schema.metadata)
    meta[b"chaoscam.trajectory"] = b"{not json"
    del meta[b"chaoscam.digest"]  # as another program (or an older chaoscam) writes it
    pq.write_table(table.replace_schema_metadata(meta), tmp_path / "meta.parquet")
    pq.write_table(pa.table({"x": [1.0]}), tmp_path / "plain.parquet")
    # Data edited in place (the digest covers the metadata), and a section cut to one
    # column: both ended in a ValueError traceback from the classifier.
    theta = table.column("theta_f").to_numpy().copy()
    theta[5] = np.nan
    edited = table.set_column(table.schema.get_field_index("theta_f"), "theta_f", pa.array(theta))
    pq.write_table(edited, tmp_path / "nan.parquet")
    meta = dict(table.schema.metadata)
    section = json.loads(meta[b"chaoscam.section"])
    section["columns"], section["data"] = ["k"], [row[:1] for row in section["data"]]
    meta[b"chaoscam.section"] = json.dumps(section).encode()
    del meta[b"chaoscam.digest"]
    pq.write_table(table.replace_schema_metadata(meta), tmp_path / "sect.parquet")
    for name in ("col", "meta", "plain", "nan", "sect"):
        path = str(tmp_path / f"{name}.parquet")
        assert main(["classify", path]) == 2
        assert main(["report", path, "--out", str(tmp_path / f"{name}.html")]) == 2
        assert "Traceback" not in capsys.readouterr().err


API_TYPE_CASES = [
    (lambda: chaoscam.simulate("abc"), TypeError, "Params"),
    (lambda: chaoscam.simulate({"omega": 30}), TypeError, "Params"),
    (lambda: chaoscam.simulate(seed="a"), ParameterError, "seed"),
    (lambda: chaoscam.simulate(seed=1.5), ParameterError, "seed"),
    (lambda: chaoscam.simulate(index=-1), ParameterError, "index"),
    (lambda: bifurcation("l_lambda", 0.01), SweepError, "sequence"),
    (lambda: regime_map(("omega", [1e300]), ("xi", [0.4])), ParameterError, "omega"),
    (
        lambda: Axis.parse("0:1.7976931348623157e308:4", name="l_lambda"),
        SweepError,
        "l_lambda range .*overflow a float",
    ),
    (
        lambda: regime_map(("omega", [30.0]), ("xi", [0.4]), scheduler=3),
        SweepError,
        "scheduler = 3 is not a Dask scheduler",
    ),
    (
        lambda: regime_map(
            ("omega", [30.0]), ("xi", [0.4]), flush_interval=math.nan, out="x.parquet"
        ),
        ParameterError,
        "flush_interval",
    ),
    (lambda: chaoscam.periodic_orbit(Params(), [0.0, 0.0], 1.5), ParameterError, "period"),
    (lambda: chaoscam.periodic_orbit(Params(), [0.0], 1), ParameterError, "x0"),
    (lambda: chaoscam.periodic_orbit(Params(), [0.0, math.nan], 1), ParameterError, "x0"),
    (lambda: chaoscam.periodic_orbit(Params(), [0.0, 0.0], 1, tol=-1), ParameterError, "tol"),
    (lambda: chaoscam.contact_period(Params(), -1.0), ParameterError, "l_lambda"),
    (lambda: chaoscam.contact_period(Params(), math.nan), ParameterError, "l_lambda"),
    (
        lambda: chaoscam.classify(chaoscam.simulate(duration=0.5), extend_to=-1),
        ValueError,
        "extend_to",
    ),
    (
        lambda: chaoscam.classify(chaoscam.simulate(duration=0.5), bogus=1),
        TypeError,
        "classify got an unknown option 'bogus'.*rtol",
    ),
    (lambda: Params(omega=np.array([28.0, 29.0])), ParameterError, "omega"),
    (lambda: chaoscam.simulate_reference(Params(), -1.0), ParameterError, "duration"),
    (lambda: chaoscam.simulate_reference(Params(), math.nan), ParameterError, "duration"),
    (
        lambda: chaoscam.simulate_reference(Params(), 0.01, max_pieces=0),
        ParameterError,
        "max_pieces",
    ),
    (lambda: chaoscam.simulate_reference(Params(), 0.01, rtol=0.0), ParameterError, "rtol"),
    # A misspelt setting is named as such, with what was meant (it listed only the model's
    # parameters); a parameter in the wrong case is found too.
    (
        lambda: chaoscam.simulate(duraton=1.0),
        ParameterError,
        "simulate.. got an unknown keyword 'duraton'.*Did you mean duration",
    ),
    (lambda: chaoscam.simulate(OMEGA=30.0), ParameterError, "Did you mean omega"),
    (lambda: chaoscam.simulate(DT=1e-6), ParameterError, "Did you mean dt"),  # a numerics field
]


@pytest.mark.parametrize("i", range(len(API_TYPE_CASES)))
def test_api_errors_say_what_was_expected(i):
    call, error, named = API_TYPE_CASES[i]
    with pytest.raises(error, match=named):
        call()


def test_numpy_scalars_are_accepted():
    """numpy scalars where numbers are expected: accepted and stored as Python numbers."""
    p, num = Params(omega=np.float32(30)), Numerics(max_events_per_step=np.int64(4))
    assert p.omega == 30.0 and type(p.omega) is float and type(num.max_events_per_step) is int
    res = regime_map(
        ("l_lambda", [0.008]),
        ("l_lambda_sigma", [0.001]),
        duration=0.2,
        realizations=np.int64(2),
        seed=np.int64(1),
        workers=1,
        classify=_Label(),
    )
    assert len(res.realizations) == 2
    assert chaoscam.simulate(duration=0.05, seed=np.int64(2)).settings["seed"] == 2


class _Label:
    needs_series = False

    def __call__(self, run):
        from tests.sweep._helpers import SpreadClassifier

        return SpreadClassifier()(run)


def test_simulate_csv_written_whole(tmp_path):
    """A CSV written by simulate --out (through a temporary name) is read back whole."""
    out = tmp_path / "s.csv"
    assert main(["simulate", "--duration", "0.05", "--out", str(out)]) == 0
    assert len(pd.read_csv(out)) == 51


@pytest.mark.parametrize("x", [[], [1.0]])
def test_classify_signal_on_too_little_data(x):
    """classify_signal on an empty or one-sample signal: "too little data", not a verdict."""
    from chaoscam.analysis import classify_signal

    with pytest.raises(ValueError, match="too little data"):
        classify_signal(np.array(x), 0.01)


def test_series_too_fine_for_its_length_is_announced_before_the_run(monkeypatch):
    """300 s sampled every 2e-6 s (1.5e8 rows, ~10 GB) on a machine with the memory for it:
    a warning with the estimate and the fields to change, given while checking the settings
    (before any step is taken)."""
    from chaoscam.simulation import _budget, _solve

    class NoStepTaken(Exception):
        pass

    def first_step(*args, **kwargs):
        raise NoStepTaken

    monkeypatch.setattr(_budget, "available_memory", lambda: math.inf)
    monkeypatch.setattr(_solve, "fresh", first_step)  # where the run's first batch starts
    with pytest.warns(RuntimeWarning, match=r"will take about .*1.5e\+08 series rows.*output_dt"):
        with pytest.raises(NoStepTaken):
            chaoscam.simulate(duration=300.0, output_dt=2e-6)


def test_left_the_model_labelled_alike_in_ensembles_and_sweeps():
    """dt = 5e-3 s leaves the model (LEFT_REACH): ensemble members and regime-map runs (dt
    swept as an axis) both say "left_reach"; the verdict of such a run is undetermined,
    naming the status."""
    num = Numerics(dt=0.005)
    with pytest.warns(RuntimeWarning, match="resolves the contact oscillation"):  # as simulate
        ens = chaoscam.ensemble(Params(), num, members=2, duration=0.5, workers=1)
    assert list(ens.members["label"]) == ["left_reach", "left_reach"]
    with pytest.warns(RuntimeWarning):
        rm = regime_map(("l_lambda", [0.008]), ("dt", [0.005]), duration=0.5, workers=1)
    assert list(rm.realizations["label"]) == ["left_reach"]
    with pytest.warns(RuntimeWarning, match="resolves the contact oscillation"):
        sol = chaoscam.solve(Params(), num, indices=[0, 1], duration=0.5, tangent=True)
    verdicts = chaoscam.classify(sol)
    assert [v.label for v in verdicts] == ["undetermined", "undetermined"]
    assert [v.settings["status"] for v in verdicts] == ["LEFT_REACH", "LEFT_REACH"]


def test_failing_classifier_is_one_line_exit_1(tmp_path, capsys):
    """A classifier that raises: exit 1 and one line saying how to reproduce, no traceback."""
    args = [
        *MAP,
        "--classifier",
        "tests.sweep._helpers:FailingClassifier",
        "--out",
        str(tmp_path / "m.parquet"),
    ]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert err.startswith("chaoscam: error: task") and "this classifier has a bug" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    # The call that reproduces it names the run's parameters and window (it said
    # "chaoscam.simulate(params, ...)" without them): the first run of the failed batch
    # (this classifier fails on every run).
    hint = err.split("reproduce it with ")[1]
    call = "chaoscam.simulate(" + hint.split("chaoscam.simulate(")[1].split(")")[0] + ")"
    run = eval(call, {"chaoscam": chaoscam})
    assert run.params.l_lambda in (0.006, 0.008) and run.settings["duration"] == 0.5


@pytest.mark.parametrize(
    "name, value",
    [
        ("NUMBA_THREADING_LAYER", ""),
        ("NUMBA_THREADING_LAYER", "bogus"),
        ("NUMBA_NUM_THREADS", "0"),
        ("NUMBA_NUM_THREADS", "two"),
    ],
)
def test_numba_settings_numba_would_reject_exit_2(monkeypatch, capsys, name, value):
    """A numba variable numba itself rejects mid-run with a traceback: exit 2 naming it."""
    monkeypatch.setenv(name, value)
    assert main(SIM) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"chaoscam: error: {name}=") and "Traceback" not in err


def test_negative_values_may_follow_their_option(tmp_path):
    """``--values -0.5,-0.4`` (and START:STOP:NUM with negative ends) is read as the value,
    not as an unknown option."""
    out = tmp_path / "b.parquet"
    args = ["bifurcation", "--param", "x_O", "--values", "-0.47,-0.46", "--duration", "0.3"]
    assert main([*args, "--workers", "1", "--quiet", "--out", str(out)]) == 0
    assert sorted(pd.read_parquet(out)["value"].unique()) == [-0.47, -0.46]


def test_classify_a_run_shorter_than_a_cam_period(tmp_path, capsys):
    """A saved run that records no cam period after its transient: classified undetermined
    with the reason (too few section points to judge), not a traceback; a discard beyond
    the recorded time is refused naming discard and its range."""
    out = tmp_path / "s.parquet"
    assert main(["simulate", "--duration", "0.2", "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["classify", "--no-extend", "--json", str(out)]) == 0
    captured = capsys.readouterr()
    verdict = json.loads(captured.out)
    assert "Traceback" not in captured.err and verdict["label"] == "undetermined"
    assert "too few to judge" in verdict["reasons"][0]
    run = chaoscam.simulate(duration=0.5, transient=0.25)
    with pytest.raises(ValueError, match=r"discard = 5.0 s must be in \[0, 0.25\)"):
        chaoscam.classify(run, discard=5.0)


@pytest.mark.parametrize("damage", ["output", "manifest"])
def test_resume_over_a_damaged_output_or_manifest_exits_2(tmp_path, capsys, damage):
    """--resume where the output is not a parquet file, or the checkpoint's manifest is
    JSON but not an object: exit 2 with what is wrong, not a pyarrow or attribute error."""
    out = tmp_path / "b.parquet"
    if damage == "output":
        out.write_text("junk")
    else:
        ckpt = out.with_suffix(".parquet.ckpt")
        ckpt.mkdir()
        (ckpt / "manifest.json").write_text("[]")
    assert main([*BIF, "--resume", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    said = "not a readable chaoscam sweep" if damage == "output" else "no readable manifest.json"
    assert err.startswith("chaoscam: error:") and said in err, err
    assert "--force without --resume" in err  # the way forward, which it did not say
    assert main([*BIF, "--force", "--out", str(out)]) == 0


def test_trajectory_file_with_text_in_a_number_column(tmp_path):
    """A trajectory file whose theta_f column was edited to text: the error names the file
    and the column, not numpy's "could not convert string to float"."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path, bad = tmp_path / "t.parquet", tmp_path / "bad.parquet"
    chaoscam.simulate(duration=0.3).to_parquet(path)
    table = pq.read_table(path)
    frame = table.to_pandas().assign(theta_f="a")
    edited = pa.Table.from_pandas(frame, preserve_index=False)
    pq.write_table(edited.replace_schema_metadata(table.schema.metadata), bad)
    with pytest.raises(ValueError, match=r"bad.parquet: column 'theta_f' of the table"):
        chaoscam.load_trajectory(bad)
    assert chaoscam.load_trajectory(path).series is not None


def test_an_unknown_option_shows_its_commands_usage(capsys):
    """`chaoscam simulate --bogus`: the simulate usage and its name (it showed the top-level
    `usage: chaoscam [-h] [--version] COMMAND ...`); exit 2."""
    with pytest.raises(SystemExit) as stop:
        main(["simulate", "--bogus"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("usage: chaoscam simulate ")
    assert "chaoscam simulate: error: unrecognized arguments: --bogus" in err


def test_classify_discard_on_the_command_line(tmp_path, capsys):
    """classify --discard S: the verdict leaves out S s (its evidence differs from the whole
    run's, as the API's does); beyond the record, exit 2 naming discard and the range (no
    traceback)."""
    import json

    run = chaoscam.simulate(duration=2.0)
    path = tmp_path / "r.parquet"
    run.to_parquet(path)
    for discard in (0.0, 1.0):
        assert (
            main(["classify", str(path), "--discard", str(discard), "--no-extend", "--json"]) == 0
        )
        out = json.loads(capsys.readouterr().out)
        (api,) = chaoscam.classify(run, discard=discard, extend_to=None)
        assert out == json.loads(json.dumps(api.to_dict()))
    (whole,) = chaoscam.classify(run, extend_to=None)
    assert out != json.loads(json.dumps(whole.to_dict()))
    assert main(["classify", str(path), "--discard", "3"]) == 2
    err = capsys.readouterr().err
    assert "discard = 3.0 s must be in [0, 2) s" in err and "Traceback" not in err


def _tiny_ensemble():
    return chaoscam.solve(Params(), indices=range(2), duration=0.3, tangent=True, resumable=True)


# A review's API mistakes, each refused naming the argument (they were accepted, or failed
# deep inside with numpy's, Python's or a TaskFailed's words).
API_REVIEW_CASES = [
    (lambda: chaoscam.simulate(duration=0.05, series="no"), "series = 'no' must be True or False"),
    (lambda: chaoscam.simulate(duration=0.05, tangent=1), "tangent = 1 must be True or False"),
    (lambda: chaoscam.classify(chaoscam.simulate(duration=0.5), check_step="no"), "check_step"),
    (lambda: regime_map(("xi", [0.4]), ("omega", [30.0]), lyapunov="no"), "lyapunov"),
    (lambda: bifurcation("xi", [0.4], duration=0.3, workers=1.5), "workers = 1.5"),
    (lambda: bifurcation("xi", [0.4], duration=0.3, workers=True), "workers = True"),
    (lambda: chaoscam.lyapunov_spectrum(duration=0.5, transient=0.0, seed=True), "seed = True"),
    (lambda: chaoscam.extend(_tiny_ensemble(), 0.6, members=[-1]), "members = -1"),
    (lambda: chaoscam.extend(_tiny_ensemble(), 0.6, members=[True]), "members = True"),
    (
        lambda: chaoscam.extend(_tiny_ensemble(), 0.6, backend="tpu"),
        "backend must be one of 'cpu', 'gpu', 'auto', got 'tpu'",
    ),
    (lambda: chaoscam.solve(Params(), indices=range(1), duration=0.2, batch=1.5), "batch = 1.5"),
    (lambda: chaoscam.solve(Params(), indices=range(1), duration=0.2, impacts="no"), "impacts"),
    (lambda: chaoscam.periodic_orbit(Params(), [0.0, 0.0], 10**6), "the shooting .up to"),
    # a second review (2026-11-27): flags that took "no" as True, a string half-width
    (lambda: bifurcation("xi", [0.4], duration=0.3, continuation="no"), "continuation = 'no'"),
    (lambda: regime_map(("xi", [0.4]), ("omega", [30.0]), resume="yes"), "resume = 'yes'"),
    (lambda: regime_map(("xi", [0.4]), ("omega", [30.0]), force="no"), "force = 'no'"),
    (
        lambda: regime_map(("xi", [0.4]), ("omega", [30.0]), target_halfwidth="0.1"),
        "target half-width = '0.1'",
    ),
    (
        lambda: chaoscam.solve(Params(), indices=[0], duration=0.2, resumable="no"),
        "resumable = 'no'",
    ),
    (
        lambda: chaoscam.extend(chaoscam.simulate(duration=0.2, resumable=True), 0.4, series="no"),
        "series = 'no'",
    ),
]


def test_event_tol_and_h_max_are_bounded_and_the_longest_step_fits_its_buffers():
    """event_tol near dt silently collapsed event location onto the grid (822 -> 164 impacts
    in 0.5 s at 1e-5 s), and h_max = 5 s stopped with an internal error (a step's series rows
    did not fit a buffer): both are bounded, and the longest allowed step fits."""
    with pytest.raises(ParameterError, match=r"event_tol = 1e-05 \[s\] is outside"):
        Numerics(event_tol=1e-5)
    with pytest.raises(ParameterError, match=r"h_max = 5.0 \[s\] is outside"):
        Numerics(h_max=5.0)
    tr = chaoscam.simulate(duration=0.5, integrator="adaptive", h_max=1.0, output_dt=1e-5)
    assert tr.ok and len(tr.series) > 40_000


@pytest.mark.parametrize(
    "atol", ["x", "1e-3", float("nan"), float("inf"), -1.0, [1e-5], True, [True, True]]
)
def test_a_bad_atol_is_refused_by_every_classifier(atol, run1):
    """atol="x" made the period evidence fail and the other votes said "quasiperiodic";
    inf made uniform noise "periodic 1"; NaN found no period in a clean period 2."""
    from chaoscam.analysis import classify_section, classify_signal, section_period

    pts = np.array([[0.1, 0.2], [0.3, 0.4]] * 50)
    x = np.sin(np.linspace(0.0, 60.0, 2000))
    calls = (
        lambda: section_period(pts, atol=atol),
        lambda: classify_section(pts, atol=atol),
        lambda: classify_signal(x, 0.01, 1.0, section=pts, atol=atol),
        lambda: chaoscam.classify(run1, atol=atol),
    )
    for call in calls:
        with pytest.raises(ValueError, match="atol = .* must be a finite number >= 0, or 2 of"):
            call()


@pytest.fixture(scope="module")
def run1():
    return chaoscam.simulate(duration=1.0)


def test_lyapunov_tol_is_refused_by_the_tangent_verdict(run1):
    """lyapunov_tol=-5 was accepted, and on the tangent path any value was dropped in
    silence (the tangent exponent is judged by its confidence interval): now the verdict,
    which has only the tangent exponent, refuses it by name as an option it does not take."""
    for value in (-5.0, 0.5):
        with pytest.raises(TypeError, match="unknown option 'lyapunov_tol'"):
            chaoscam.classify(run1, lyapunov_tol=value, extend_to=None)


def test_review_tracebacks_are_named():
    """lyapunov_spectrum("run.parquet") was an AttributeError, run_paper(figures=3) a
    TypeError from list(3); a contact too stiff for any allowed dt is said so (it advised
    "use dt <= 0 s")."""
    from chaoscam.paper import run_paper
    from chaoscam.simulation import resolution_warning

    with pytest.raises(TypeError, match="must be a chaoscam.Params"):
        chaoscam.lyapunov_spectrum("run.parquet")
    for figures in (99, np.array([99]), (f for f in [99])):  # one figure, or any iterable
        with pytest.raises(ValueError, match=r"figures = \[.*99\)?\]: choose from"):
            run_paper(quick=True, out="unused.html", figures=figures)
    stiffest = Params(l_lambda=10.0, Y_f=1e13, Y_c=1e13, J=1e-15)  # the ranges' extremes
    assert "no allowed dt (>= 1e-12 s)" in resolution_warning(stiffest, Numerics())


@pytest.mark.parametrize(
    "call, named",
    [
        (lambda: Axis(3, [1.0]), "axis name 3"),
        (lambda: Axis("l_lambda", [True]), "not True/False"),
        (lambda: realization_index("a", 0), "cell = 'a'"),
        (lambda: realization_index(1.7, 0), "cell = 1.7"),
        (lambda: realization_index(0, True), "index = True"),
        (lambda: initial_offsets(2.5), "n = 2.5"),
        (lambda: bifurcation(Axis("xi", (0.2,)), "0.3:0.4:2"), "has its values"),
        (
            lambda: bifurcation("xi", [0.2], initial_conditions=[(0.1, 0.0), (0.1, 0.0)]),
            r"initial_conditions\[1\] = \(0.1, 0.0\) is given twice",
        ),
        (lambda: wilson_interval(float("nan"), 5), "whole numbers"),
        (lambda: wilson_interval(2.5, 5), "whole numbers"),
    ],
)
def test_sweep_helpers_name_a_bad_argument(call, named):
    """Public sweep helpers refused these with an AttributeError, TypeError or scipy's words,
    or silently cut 1.7 to 1, True to 1, 2.5 successes to a fraction (API review)."""
    with pytest.raises(ValueError, match=named):
        call()


def test_reading_a_folder_as_a_sweep_says_so(tmp_path):
    """read_regime_map(folder) said "no such file"."""
    from chaoscam.sweep import read_bifurcation, read_regime_map

    for read in (read_regime_map, read_bifurcation):
        with pytest.raises(SweepError, match="is a directory"):
            read(tmp_path)


def test_numpy_scalars_are_numbers():
    """A window or horizon given as numpy scalars (np.int64(1), np.float32(0.5)) was
    refused as not 'a finite number', which it is."""
    tr = chaoscam.simulate(duration=np.int64(1), transient=np.float32(0.5), series=False)
    assert tr.settings["duration"] == 1.0 and tr.settings["transient"] == 0.5


@pytest.mark.parametrize("i", range(len(API_REVIEW_CASES)))
def test_api_review_mistakes_are_named(i):
    call, named = API_REVIEW_CASES[i]
    with pytest.raises((ParameterError, ValueError), match=named):
        call()


def test_whole_number_floats_in_integer_fields_are_stored_as_integers():
    """flight_merge = 2.0 (what START:STOP:NUM gives) is 2: an ensemble and a sweep over it
    run (they failed in numpy: 'expected a sequence of integers')."""
    num = Numerics(flight_merge=2.0, max_events_per_step=4.0)
    assert (num.flight_merge, num.max_events_per_step) == (2, 4)
    assert type(num.flight_merge) is int
    sol = chaoscam.solve(Params(), num, indices=range(1), duration=0.2)
    assert sol.members["status"].tolist() == ["OK"]
    res = bifurcation("flight_merge", "2:4:2", duration=0.3, workers=1)
    assert len(res.verdicts) == 2


def test_axis_linspace_takes_numpy_scalars():
    from chaoscam.sweep import Axis

    assert Axis.linspace("xi", np.float64(0.1), np.float32(0.5), np.int64(2)).values == (0.1, 0.5)


# The wrong kind of object where a run, an ensemble or a model goes: a TypeError naming the
# argument and what makes one (they failed with an AttributeError from deep inside).
WRONG_KIND_CASES = [
    (lambda: chaoscam.classify("run.parquet"), "solution must be a chaoscam Solution"),
    (lambda: chaoscam.classify(None), "solution must be a chaoscam Solution"),
    (lambda: chaoscam.extend(None, 10.0), "solution must be a chaoscam Solution"),
    (lambda: chaoscam.lyapunov_spectrum("x"), "params must be a chaoscam.Params"),
    (lambda: chaoscam.contact_period({"omega": 30.0}), "p must be a chaoscam Params"),
]


@pytest.mark.parametrize("i", range(len(WRONG_KIND_CASES)))
def test_the_wrong_kind_of_object_is_named(i):
    call, named = WRONG_KIND_CASES[i]
    with pytest.raises(TypeError, match=named):
        call()


def test_a_step_longer_than_the_contact_period_is_said_so():
    """dt = 1 s against a contact period of 9.14e-5 s: a step 1.09e4 times the period, not
    "0.0 steps"."""
    from chaoscam.simulation import resolution_warning

    assert "with a step 1.09e+04x the period;" in resolution_warning(Params(), Numerics(dt=1.0))
    assert "with only 1.8 steps" in resolution_warning(Params(), Numerics(dt=5e-5))


@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "--out", ""],
        ["simulate", "--section", " "],
        ["ensemble", "--members", "2", "--out", ""],
        ["regime-map", "--x", "omega=20:30:2", "--y", "xi=0.2:0.3:2", "--out", ""],
        ["classify", ""],
        ["report", "--out", ""],
    ],
    ids=["simulate", "section", "ensemble", "regime-map", "classify", "report"],
)
def test_an_empty_path_is_refused_as_such(argv, capsys):
    """`--out ''` read as the current folder ("--out .: the file must end in .parquet"): now
    every file argument refuses an empty path by name, exit 2."""
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    assert "an empty path: give a file name" in capsys.readouterr().err
