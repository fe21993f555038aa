"""read_raw() on the repository's ngspice and LTspice raw files, checked
against the circuits that made them."""

import numpy as np
import pytest

import chatterspice
from conftest import ROOT

RAW = ROOT / "tests" / "data" / "raw"


def test_a_transient_is_the_rc_step_response():
    raw = chatterspice.read_raw(RAW / "rc_tran.raw")
    assert len(raw.plots) == 1
    assert list(raw.keys())[0] == "time"
    t, out = raw["time"], raw["v(out)"]
    assert out.dtype == np.float64 and t.shape == out.shape == (raw.plots[0].points,)
    # R = 1k, C = 1 µF: 1 - exp(-t/RC) after the 1 ns ramp.
    late = t > 1e-6
    assert out[late] == pytest.approx(1 - np.exp(-t[late] / 1e-3), abs=2e-3)


def test_an_ascii_file_is_read_as_its_circuit_says():
    raw = chatterspice.read_raw(RAW / "rc_tran_ascii.raw")
    t, out = raw["time"], raw["v(out)"]
    assert t[-1] == pytest.approx(2e-3)
    late = t > 1e-6
    assert out[late] == pytest.approx(1 - np.exp(-t[late] / 1e-3), abs=2e-3)


def test_a_complex_file_gives_complex_arrays_of_the_rc_response():
    raw = chatterspice.read_raw(RAW / "rc_ac.raw")
    plot = raw.plots[0]
    assert plot.complex and plot.name == "AC Analysis"
    f, out = raw["frequency"], raw["v(out)"]
    assert f.dtype == np.float64  # the scale is real
    assert out.dtype == np.complex128
    expected = 1 / (1 + 1j * 2 * np.pi * f * 1e-3)
    assert out == pytest.approx(expected, rel=1e-6)
    assert plot.metadata["variables"][0]["attributes"] == ["grid=3"]


def test_every_plot_of_a_file_is_kept_in_order():
    raw = chatterspice.read_raw(RAW / "divider_op_tran.raw")
    assert [p.name for p in raw.plots] == ["Operating Point", "Transient Analysis"]
    op = raw.plot("Operating Point")
    assert op is raw.plots[0] or op.index == 0
    assert op["v(mid)"] == pytest.approx([1.0])  # 4 V over 3k + 1k
    assert raw.plot(-1).index == 1
    # As a mapping the file is its last plot.
    assert list(raw) == list(raw.plots[1])
    assert raw["v(mid)"].max() == pytest.approx(1.0, rel=1e-6)
    assert dict(raw.plots[1]).keys() == raw.plots[1].vectors.keys()


def test_the_summary_is_the_cli_summary(cli_json):
    path = RAW / "divider_op_tran.raw"
    assert chatterspice.read_raw(path).summary == cli_json("raw", path)


def test_an_ltspice_stepped_run_is_one_plot_per_step():
    raw = chatterspice.read_raw(ROOT / "tests" / "data" / "ltspice" / "tran_stepped.raw")
    steps = [p.metadata["step"] for p in raw.plots]
    assert len(raw.plots) > 1
    assert [s["index"] for s in steps] == list(range(len(raw.plots)))


def test_a_killed_run_keeps_its_points_with_a_warning():
    raw = chatterspice.read_raw(RAW / "killed_binary.raw")
    assert raw.warnings
    assert len(raw["time"]) == raw.plots[-1].points > 0


def test_a_missing_vector_and_plot_name_what_there_is():
    raw = chatterspice.read_raw(RAW / "rc_tran.raw")
    with pytest.raises(KeyError, match="v\\(out\\)"):
        raw["v(nowhere)"]
    with pytest.raises(IndexError, match="1 plot"):
        raw.plot(3)
    assert raw.get("v(nowhere)") is None


def test_a_broken_file_is_an_input_error_naming_it(tmp_path):
    broken = tmp_path / "broken.raw"
    broken.write_text("Title: t\nDate: d\nPlotname: p\nFlags: real\nNo. Variables: two\n")
    with pytest.raises(ValueError, match="broken.raw"):
        chatterspice.read_raw(broken)
    with pytest.raises(FileNotFoundError, match="absent.raw"):
        chatterspice.read_raw(tmp_path / "absent.raw")


def test_the_arrays_are_read_only_views_of_one_read():
    raw = chatterspice.read_raw(RAW / "rc_tran.raw")
    out = raw["v(out)"]
    assert not out.flags.writeable and not out.flags.owndata
    with pytest.raises(ValueError):
        out[0] = 1.0
    with pytest.raises(ValueError):
        out.setflags(write=True)
    # Every access views the same memory: nothing is copied per access.
    assert np.shares_memory(out, raw.plots[0]["v(out)"])
    assert np.shares_memory(out, raw.plots[0].vectors["v(out)"])
    # The data outlive the file object and its plots.
    plot = raw.plots[0]
    del raw
    assert plot["v(out)"][-1] == pytest.approx(1 - np.exp(-5), abs=2e-3)  # t = 5 ms, RC = 1 ms
    copy = out.copy()
    copy[0] = 5.0
    assert copy.flags.writeable and out[0] != 5.0


def test_a_plot_asked_for_by_neither_index_nor_name_is_an_input_error():
    raw = chatterspice.read_raw(RAW / "divider_op_tran.raw")
    with pytest.raises(chatterspice.InputError, match=r"^which = 1\.5 \(float\)"):
        raw.plot(1.5)
    assert raw.plot(1).index == raw.plot(-1).index == 1
