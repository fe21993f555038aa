"""run(), check() and sweep() through real ngspice."""

import numpy as np
import pytest

import chatterspice
from conftest import ROOT


def schmitt_edges(values, low, high):
    """Edges a Schmitt input with thresholds low/high sees in samples,
    counted independently of the library's analysis."""
    state = values[0] > (low + high) / 2
    edges = 0
    for v in values[1:]:
        if state and v < low:
            state, edges = False, edges + 1
        elif not state and v > high:
            state, edges = True, edges + 1
    return edges


def without_timings(doc):
    """The run JSON less what differs between two runs of one scenario:
    ngspice's wall-clock time."""
    if isinstance(doc, dict):
        return {k: without_timings(v) for k, v in doc.items() if "elapsed" not in k}
    if isinstance(doc, list):
        return [without_timings(v) for v in doc]
    return doc


@pytest.fixture(scope="module")
def default_run():
    return chatterspice.run()


def test_the_default_run_sees_seven_edges_on_v_in(default_run):
    v_in = default_run.waveforms["v(in)"]
    time = default_run.waveforms["time"]
    assert isinstance(v_in, np.ndarray) and v_in.dtype == np.float64
    assert v_in.shape == time.shape and v_in.ndim == 1
    assert np.all(np.diff(time) > 0)
    assert v_in.max() == pytest.approx(3.3, abs=1e-3)
    probe = default_run.report["probes"][0]
    assert probe["signal"] == "v(in)"
    assert probe["edges"] == 7
    assert schmitt_edges(v_in, probe["low"], probe["high"]) == 7


def test_the_run_report_is_the_cli_report(default_run, cli_json):
    assert without_timings(default_run.report) == without_timings(cli_json("run"))


def test_the_ideal_contact_run_makes_one_edge(default_run):
    ideal = default_run.ideal_waveforms
    assert ideal is not None
    probe = default_run.report["probes"][0]
    assert schmitt_edges(ideal["v(in)"], probe["low"], probe["high"]) == 1
    assert "CONTACT" in default_run.include
    assert ".include" in default_run.deck


def test_run_without_the_ideal_contact():
    result = chatterspice.run(toml_text="[surface]\ndamping = 6.0\n", ideal=False)
    assert result.ideal_waveforms is None
    probe = result.report["probes"][0]
    assert probe["edges"] == schmitt_edges(result.waveforms["v(in)"], probe["low"], probe["high"])


def test_ngspice_failing_is_a_runtime_error_with_its_words(tmp_path):
    netlist = tmp_path / "bad.cir"
    netlist.write_text(
        "bad model\nV1 a 0 DC 1\nR1 a b 1k\nX1 b 0 CONTACT\nD1 b 0 NOSUCHMODEL\n.tran 1u 5m\n.end\n"
    )
    text = f'[circuit]\nnetlist = "{netlist}"\n\n[[probe]]\nsignal = "v(b)"\nlow = 0.3\nhigh = 0.7\n'
    with pytest.raises(RuntimeError) as caught:
        chatterspice.run(toml_text=text)
    assert isinstance(caught.value, chatterspice.NgspiceError)
    assert "ngspice failed" in str(caught.value)
    assert "nosuchmodel" in str(caught.value).lower()


def test_a_bad_timeout_is_named():
    with pytest.raises(ValueError, match="timeout = -1"):
        chatterspice.run(timeout=-1.0)


def test_check_holds_relay_limits_without_ngspice(cli_json, tmp_path):
    for limit, passed in ((4, False), (5, True)):
        text = f"[limits]\nmax_bounces = {limit}\n"
        doc = chatterspice.check(toml_text=text)
        assert doc["passed"] is passed
        path = tmp_path / f"limit{limit}.toml"
        path.write_text((ROOT / "scenarios" / "default.toml").read_text() + "\n" + text)
        assert doc == chatterspice.check(path)
        assert doc == cli_json("check", path)


def test_check_holds_probe_limits_through_ngspice():
    text = (
        '[[probe]]\nsignal = "v(in)"\nlow = 0.99\nhigh = 2.31\nmax_edges = 1\nmax_value = 3.6\n'
    )
    doc = chatterspice.check(toml_text=text)
    assert doc["passed"] is False
    failed = [c for c in doc["checks"] if not c["passed"]]
    assert [c["key"] for c in failed] == ["probe[0].max_edges"]
    assert failed[0]["actual"] == 7


def test_a_mechanics_only_sweep_is_the_cli_sweep(cli, tmp_path):
    text = "[sweep]\nsamples = 12\nseed = 3\n[sweep.vary]\n\"surface.damping\" = 0.3\n"
    result = chatterspice.sweep(toml_text=text, mechanics_only=True)
    assert len(result.rows) == 12
    assert [r["index"] for r in result.rows] == list(range(12))
    assert result.summary["samples"] == 12
    path = tmp_path / "sweep.toml"
    path.write_text((ROOT / "scenarios" / "default.toml").read_text() + "\n" + text)
    cli("sweep", path, "--mechanics-only", "--out", tmp_path / "out")
    assert result.csv == (tmp_path / "out" / "sweep.csv").read_text()
    bounces = [r["bounce_count"] for r in result.rows]
    assert min(bounces) < max(bounces)  # the damping moved the count
