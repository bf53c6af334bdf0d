"""Equal Params have equal records: a whole number given to a float field is stored as a
float (omega=30 as 30.0), so a sweep made with one resumes with the other (it was refused as
"a different configuration"), and the CLI's "30" (read as 30.0) matches the Python API's 30."""

import numpy as np

from chaoscam import Numerics, Params
from chaoscam.sweep import bifurcation


def test_whole_numbers_in_float_fields_are_stored_as_floats():
    """30, np.int64(30) and np.float32(30) are stored as the float 30.0; an int field of
    the numerics keeps an int."""
    for value in (30, np.int64(30), np.float32(30.0), 30.0):
        p = Params(omega=value)
        assert type(p.omega) is float and p.to_dict() == Params(omega=30.0).to_dict()
    assert type(Params(J=1).J) is float  # an optional float field too
    assert type(Numerics(flight_merge=4.0).flight_merge) is int  # an int field: as before


def test_a_sweep_made_with_an_int_resumes_with_the_float(tmp_path):
    """A bifurcation made with omega=30 resumes with omega=30.0 (the same configuration)."""
    out = tmp_path / "b.parquet"
    kw = dict(duration=1.0, transient=0.5, workers=1, out=out)
    first = bifurcation("xi", [0.2], base=Params(omega=30), **kw)
    again = bifurcation("xi", [0.2], base=Params(omega=30.0), resume=True, **kw)
    assert again.verdicts.equals(first.verdicts)
