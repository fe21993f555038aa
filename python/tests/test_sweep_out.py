"""sweep(out=DIR): the command line's files, written row by row by the
library's own writer, and rows read back from them when asked."""

import csv
import json
import os
import pickle
import time
from collections.abc import Sequence

import pytest

import chatterspice

SCENARIO = """base = "default"
[sweep]
samples = 300
seed = 5
[sweep.vary]
"surface.damping" = 0.3
"mechanics.mass" = 0.1
"""


def files_of(directory):
    """The files a sweep left, without the lock file of a running one."""
    return sorted(n for n in os.listdir(directory) if not n.startswith("."))


def cell(text):
    """A CSV cell as the package gives it."""
    if text == "":
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def csv_rows(path):
    with open(path, newline="") as f:
        return [{k: cell(v) for k, v in row.items()} for row in csv.DictReader(f)]


@pytest.fixture
def scenario(tmp_path):
    path = tmp_path / "relay.toml"
    path.write_text(SCENARIO)
    return path


def test_out_writes_the_files_of_the_cli_byte_for_byte(cli, scenario, tmp_path):
    result = chatterspice.sweep(scenario, mechanics_only=True, out=tmp_path / "py")
    cli("sweep", scenario, "--mechanics-only", "--out", tmp_path / "cli")
    names = files_of(tmp_path / "cli")
    assert names == [
        "summary.json",
        "sweep.csv",
        "sweep.meta.json",
        "sweep.png",
        "sweep.svg",
    ]
    assert files_of(tmp_path / "py") == names
    for name in names:
        ours = (tmp_path / "py" / name).read_bytes()
        assert ours == (tmp_path / "cli" / name).read_bytes(), name
    assert result.summary == json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert result.csv is None
    assert result.out == str(tmp_path / "py")
    assert "written to" in repr(result)


def test_rows_are_read_back_from_the_file_one_by_one(scenario, tmp_path):
    result = chatterspice.sweep(scenario, mechanics_only=True, out=os.fsencode(tmp_path / "o"))
    rows = result.rows
    assert isinstance(rows, chatterspice.SweepRows)
    assert isinstance(rows, Sequence)
    expected = csv_rows(tmp_path / "o" / "sweep.csv")
    assert len(expected) == 300
    assert len(rows) == 300
    for k in (0, 1, 255, 256, 299, -1, -300):
        assert rows[k] == expected[k]
    assert rows[3]["index"] == 3 and rows[-1]["index"] == 299
    assert rows[250:260] == expected[250:260]
    assert rows[::97] == expected[::97]
    assert rows[290:400] == expected[290:]
    assert list(rows) == expected
    with pytest.raises(IndexError):
        rows[300]
    # The same rows as a sweep held in memory.
    in_memory = chatterspice.sweep(scenario, mechanics_only=True)
    assert list(rows) == in_memory.rows
    again = pickle.loads(pickle.dumps(result))
    assert again == result and list(again.rows) == expected


def test_rows_beyond_the_first_stride_seek_to_the_right_row(scenario, tmp_path):
    result = chatterspice.sweep(scenario, mechanics_only=True, samples=2500, out=tmp_path / "o")
    expected = csv_rows(tmp_path / "o" / "sweep.csv")
    for k in (1023, 1024, 1025, 2047, 2048, 2499):
        assert result.rows[k] == expected[k]
        assert result.rows[k]["index"] == k


def test_a_sweep_never_replaces_files_unless_forced(scenario, tmp_path):
    out = tmp_path / "o"
    chatterspice.sweep(scenario, mechanics_only=True, samples=20, out=out)
    before = {n: (out / n).read_bytes() for n in files_of(out)}
    with pytest.raises(FileExistsError) as raised:
        chatterspice.sweep(scenario, mechanics_only=True, samples=30, out=out)
    message = str(raised.value)
    assert "force=True" in message and "--force" not in message
    assert {n: (out / n).read_bytes() for n in files_of(out)} == before
    replaced = chatterspice.sweep(scenario, mechanics_only=True, samples=30, out=out, force=True)
    assert len(replaced.rows) == 30
    assert len(csv_rows(out / "sweep.csv")) == 30
    with pytest.raises(chatterspice.InputError, match="out="):
        chatterspice.sweep(scenario, mechanics_only=True, force=True)


def test_a_stopped_sweep_keeps_its_rows_and_resumes_to_the_same_files(scenario, tmp_path):
    whole, stopped = tmp_path / "whole", tmp_path / "stopped"
    samples = 60_000
    chatterspice.sweep(scenario, mechanics_only=True, samples=samples, out=whole, jobs=1)

    class Stop(Exception):
        pass

    def progress(done, total):
        if 0 < done < total:
            raise Stop

    with pytest.raises(Stop):
        chatterspice.sweep(
            scenario, mechanics_only=True, samples=samples, out=stopped, jobs=1,
            progress=progress,
        )
    # The rows are kept as the work unwinds.
    meta = stopped / "sweep.meta.json"
    for _ in range(100):
        if meta.exists():
            break
        time.sleep(0.05)
    record = json.loads(meta.read_text())
    assert record["complete"] is False
    kept = csv_rows(stopped / "sweep.csv")
    assert 0 < record["rows"] == len(kept) < samples
    assert [r["index"] for r in kept] == list(range(len(kept)))
    resumed = chatterspice.sweep(
        scenario, mechanics_only=True, samples=samples, resume=stopped, jobs=1
    )
    assert len(resumed.rows) == samples
    for name in files_of(whole):
        assert (stopped / name).read_bytes() == (whole / name).read_bytes(), name
