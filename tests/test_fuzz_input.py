"""Fuzz (Hypothesis): every generated bad input — a Params or Numerics field (both set with
``--set``) out of its range or not a number, a malformed START:STOP:NUM, a file that is not
what it claims — gives a message and exit code 2 naming the field or file; never a traceback
(an uncaught exception fails)."""

import contextlib
import dataclasses
import io
import math

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from chaoscam.cli import main  # noqa: E402
from chaoscam.model import FIELD_DOCS as MODEL_DOCS  # noqa: E402
from chaoscam.model import ParameterError, Params  # noqa: E402
from chaoscam.numerics import Numerics  # noqa: E402
from chaoscam.sweep import Axis, SweepError  # noqa: E402

QUICK = settings(
    max_examples=50, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
BIG = settings(
    max_examples=2000, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)

FIELD_DOCS = {**MODEL_DOCS, **Numerics.field_docs()}  # what --set takes
NUMERIC = [n for n, d in FIELD_DOCS.items() if d["choices"] is None]
CHOICE = [n for n, d in FIELD_DOCS.items() if d["choices"] is not None]
FIELDS = {f.name: f for cls in (Params, Numerics) for f in dataclasses.fields(cls)}
INT_FIELDS = {name for name, f in FIELDS.items() if f.type == "int"}


def _outside(name):
    """Values outside the field's range (or not finite)."""
    lo, hi, lo_inc, hi_inc = FIELD_DOCS[name]["range"] or (None, None, None, None)
    below = (
        []
        if lo is None
        else [st.floats(max_value=lo, exclude_max=lo_inc, allow_nan=False, allow_infinity=False)]
    )
    above = (
        []
        if hi is None
        else [st.floats(min_value=hi, exclude_min=hi_inc, allow_nan=False, allow_infinity=False)]
    )
    if name in INT_FIELDS:
        below = [] if lo is None else [st.integers(max_value=int(lo) - (1 if lo_inc else 0))]
        above = [] if hi is None else [st.integers(min_value=int(hi) + (1 if hi_inc else 0))]
    return st.one_of(*below, *above, st.sampled_from([math.nan, math.inf, -math.inf]))


def _text_value(value):
    return repr(value) if isinstance(value, float) else str(value)


@st.composite
def bad_assignment(draw):
    """(field, text) of a --set that must be refused."""
    kind = draw(st.sampled_from(["range", "text", "choice"]))
    if kind == "choice":
        name = draw(st.sampled_from(CHOICE))
        text = draw(
            st.text(min_size=1, max_size=12).filter(
                lambda t: t.strip() not in FIELD_DOCS[name]["choices"] and "\x00" not in t
            )
        )
        return name, text
    name = draw(st.sampled_from(NUMERIC))
    if kind == "text":
        text = draw(st.text(alphabet="abcxyz,;#%$ ", min_size=1, max_size=8))
        if text.strip().lower() in ("none", "nan", "inf", "infinity"):
            text = "abc"
        return name, text
    if FIELD_DOCS[name]["range"] is None:  # only non-finite values are out of range
        return name, draw(st.sampled_from(["nan", "inf", "-inf"]))
    return name, _text_value(draw(_outside(name)))


def _run(args):
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(args)
    return code, err.getvalue()


def _check_assignment(name, text, tmp_path):
    if text.strip().lower() == "none" and FIELDS[name].default is None:
        return  # None is the documented default rule
    code, err = _run(["simulate", "--duration", "0.01", "--set", f"{name}={text}"])
    assert code == 2, (name, text, err)
    assert err.startswith("chaoscam: error:") and name in err, (name, text, err)


@QUICK
@given(bad_assignment())
def test_fuzz_params_on_the_command_line(tmp_path, case):
    _check_assignment(*case, tmp_path)


@pytest.mark.slow
@BIG
@given(bad_assignment())
def test_fuzz_params_many(tmp_path, case):
    _check_assignment(*case, tmp_path)


RANGE_TEXT = st.one_of(
    st.text(alphabet="0123456789.:-+eEnaif x", max_size=20),
    st.tuples(st.floats(), st.floats(), st.integers(-5, 10**12)).map(
        lambda t: f"{t[0]!r}:{t[1]!r}:{t[2]}"
    ),
)


@QUICK
@given(RANGE_TEXT)
def test_fuzz_range_syntax(text):
    """Any START:STOP:NUM text for a swept field: an Axis, or SweepError/ParameterError."""
    try:
        axis = Axis.parse(text, name="l_lambda")
    except (SweepError, ParameterError) as err:
        assert "l_lambda" in str(err) or "range" in str(err)
        return
    assert 1 <= len(axis) <= 100_000


FILE_BYTES = st.one_of(
    st.binary(max_size=200),
    st.sampled_from([b"", b"x\n", b"x\n1\n", b"x,y\n1,2\n", b"PAR1", b"PAR1\x00\x00PAR1"]),
)


@QUICK
@given(FILE_BYTES, st.sampled_from([".parquet", ".csv"]))
def test_fuzz_file_inputs(tmp_path, data, suffix):
    """A file of arbitrary bytes given to classify, report and classify-series: exit 2 and
    a message naming the file."""
    path = tmp_path / f"in{suffix}"
    path.write_bytes(data)
    out = tmp_path / "r.html"
    for args in (
        ["classify", str(path)],
        ["report", str(path), "--out", str(out)],
        ["classify-series", str(path), "--column", "x", "--dt", "0.01"],
    ):
        code, err = _run(args)
        assert code == 2, (args, data, err)
        assert "error" in err and (path.name in err or "--column" in err), (args, err)
        assert not out.exists()
