"""The package from another working directory: the built-in scenario's
circuit is found wherever Python runs, and relative paths are relative to
where the user is."""

import os
import subprocess
import sys

import chatterspice
from conftest import ROOT


def test_run_from_another_directory_in_a_fresh_interpreter(tmp_path):
    script = (
        "import chatterspice\n"
        "r = chatterspice.run()\n"
        "print(r.report['probes'][0]['edges'], round(float(r.waveforms['v(in)'].max()), 3))\n"
        "print(chatterspice.bounce(toml_text='[surface]\\ndamping = 6.0\\n')['bounce_count'])\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    first, second = done.stdout.split("\n")[:2]
    assert first == "7 3.3"
    assert int(second) < 5


def test_a_relative_scenario_path_is_relative_to_the_working_directory(tmp_path, monkeypatch):
    text = (ROOT / "scenarios" / "default.toml").read_text()
    # Its netlist is relative to the scenario file, as the CLI reads it.
    text = text.replace('"../netlists/mcu_input.cir"', '"netlists/mcu_input.cir"')
    (tmp_path / "netlists").mkdir()
    (tmp_path / "netlists" / "mcu_input.cir").write_text(
        (ROOT / "netlists" / "mcu_input.cir").read_text()
    )
    (tmp_path / "relay.toml").write_text(text)
    monkeypatch.chdir(tmp_path)
    assert os.getcwd() == str(tmp_path)
    result = chatterspice.run("relay.toml", ideal=False)
    assert result.report["probes"][0]["edges"] == 7
    assert result.report["netlist"] == os.path.join("netlists", "mcu_input.cir")


def test_the_example_notebook_runs(tmp_path):
    example = ROOT / "examples" / "python" / "bounce_and_run.py"
    done = subprocess.run(
        [sys.executable, str(example)], cwd=tmp_path, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert "5 bounces, stuck" in done.stdout
    assert "v(in): 7 edges" in done.stdout
