"""Every Parquet file chaoscam writes has a checksum per data page, verified on reading
(chaoscam.io): bytes changed inside a file are an error naming the file, not wrong
numbers read without a word (400 flipped bytes in a trajectory changed 50 values of
omega_f and were read silently)."""

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import chaoscam
from chaoscam.cli import main
from chaoscam.io import DamagedFileError, read_frame
from chaoscam.sweep import read_regime_map, regime_map


def _flip(path, start=200, n=400):
    """Flip n bytes inside the first data page (after the 4-byte magic and its header)."""
    data = bytearray(path.read_bytes())
    assert len(data) > start + n + 1000
    for i in range(start, start + n):
        data[i] ^= 0x5A
    path.write_bytes(bytes(data))


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("traj") / "run.parquet"
    chaoscam.simulate(chaoscam.Params(), duration=2.0).to_parquet(path)
    return path


def test_every_page_of_a_trajectory_file_has_a_checksum(run_file):
    """The writer asked for page checksums: the file reads back whole and verified."""
    meta = pq.ParquetFile(run_file).metadata
    assert meta.num_rows > 1000
    assert len(read_frame(run_file)) == meta.num_rows


def test_a_damaged_trajectory_is_refused_by_name(run_file, tmp_path, capsys):
    """Flipped bytes in a trajectory file: load_trajectory and `chaoscam classify` refuse
    it naming the file, without a traceback."""
    bad = tmp_path / "bad.parquet"
    bad.write_bytes(run_file.read_bytes())
    _flip(bad)
    with pytest.raises(ValueError, match=r"bad.parquet: damaged \(a data page does not match"):
        chaoscam.load_trajectory(bad)
    assert main(["classify", str(bad), "--no-extend"]) == 2
    err = capsys.readouterr().err
    assert "damaged" in err and "Traceback" not in err


def test_a_damaged_sweep_table_is_refused_by_name(tmp_path):
    """Flipped bytes inside a regime map's cells table: reading it names that file."""
    from tests.sweep._helpers import SpreadClassifier  # cheap: the file is what is tested

    rm = regime_map(
        "omega=25:30:2", "xi=0.2:0.3:2", duration=1.0, workers=1, classify=SpreadClassifier()
    )
    out = tmp_path / "map.parquet"
    rm.to_parquet(out)
    assert read_regime_map(out).realizations["label"].tolist() == rm.realizations["label"].tolist()
    cells = out.with_name("map.cells.parquet")
    # the last bytes of its largest column chunk: inside a data page's values, not a header
    group = pq.ParquetFile(cells).metadata.row_group(0)
    chunk = max(
        (group.column(i) for i in range(group.num_columns)), key=lambda c: c.total_compressed_size
    )
    end = chunk.data_page_offset + chunk.total_compressed_size
    data = bytearray(cells.read_bytes())
    for i in range(end - 9, end - 1):
        data[i] ^= 0x5A
    cells.write_bytes(bytes(data))
    with pytest.raises(DamagedFileError, match=r"map.cells.parquet: damaged"):
        read_regime_map(out)


def test_files_without_checksums_are_still_read(tmp_path):
    """A file written before the checksums (or by another program) reads as before."""
    path = tmp_path / "old.parquet"
    frame = pd.DataFrame({"a": np.arange(5000.0)})
    frame.to_parquet(path)  # no page checksums
    assert read_frame(path).equals(frame)
    assert issubclass(DamagedFileError, OSError)


def test_metadata_edited_after_writing_is_refused(run_file, tmp_path):
    """The metadata (a trajectory's section and impacts, a sweep's configuration) has no page
    checksum: its digest finds a change. Here one section value, edited with pyarrow."""
    table = pq.read_table(run_file)
    meta = dict(table.schema.metadata)
    section = meta[b"chaoscam.section"]
    meta[b"chaoscam.section"] = section.replace(b"[1,", b"[2,", 1)
    assert meta[b"chaoscam.section"] != section
    bad = tmp_path / "edited.parquet"
    pq.write_table(table.replace_schema_metadata(meta), bad)
    with pytest.raises(ValueError, match=r"edited.parquet: damaged \(its metadata does not match"):
        chaoscam.load_trajectory(bad)
