"""What the package says besides its results: run warnings as Python
warnings, messages in Python's words, and a Ctrl-C in the first call of
a fresh interpreter."""

import os
import signal
import subprocess
import sys
import time

import pytest

import chatterspice
from conftest import ROOT

LAMP = ROOT / "examples" / "scenarios" / "lamp.toml"


def test_a_run_that_is_not_physical_warns_in_python():
    with pytest.warns(chatterspice.ChatterspiceWarning, match="not physical") as said:
        result = chatterspice.run(LAMP, ideal=False)
    # The same words as the report's, which the command line prints.
    assert [str(w.message) for w in said] == result.report["warnings"]
    assert issubclass(chatterspice.ChatterspiceWarning, UserWarning)


def test_messages_name_python_arguments_not_options():
    import re

    flag = re.compile(r"(^|[\s(`'])--[a-z]")
    with pytest.raises(chatterspice.NgspiceError) as raised:
        chatterspice.run(timeout=0.001)
    message = str(raised.value)
    assert not flag.search(message), message
    assert "timeout" in message
    if "work directory" in message:
        assert "keep_workdir=True" in message
    with pytest.raises(chatterspice.InputError) as raised:
        chatterspice.fit(free=[])
    assert "free=[...]" in str(raised.value)
    assert not flag.search(str(raised.value))


def test_an_unknown_free_key_names_its_file_once_and_fills_the_key():
    with pytest.raises(chatterspice.InputError) as raised:
        chatterspice.fit(free=["nope.key"])
    message = str(raised.value)
    head = message.split("`nope.key`")[0]
    assert "free key" in head
    assert message.count(head.split(":")[0] + ":") == 1
    assert raised.value.key == "nope.key"


def test_an_error_that_names_its_file_fills_path(tmp_path):
    netlist = tmp_path / "missing.cir"
    text = f'[circuit]\nnetlist = "{netlist}"\n[[probe]]\nsignal = "v(out)"\n'
    with pytest.raises((chatterspice.InputError, FileNotFoundError)) as raised:
        chatterspice.run(toml_text=text)
    assert raised.value.path is not None
    assert raised.value.path in str(raised.value)


FIRST_CALL = """
import signal, sys
# Ctrl-C as in an interactive Python, even when pytest was started in the
# background with SIGINT ignored.
signal.signal(signal.SIGINT, signal.default_int_handler)
sys.stdout.write("ready\\n"); sys.stdout.flush()
import chatterspice
try:
    chatterspice.run(ideal=False)
except KeyboardInterrupt:
    print("interrupted")
else:
    print("finished")
"""


def test_twenty_first_call_interrupts_raise_no_panic():
    """SIGINT at twenty points from the import through the first call of
    fresh interpreters: a KeyboardInterrupt (or a finished call), never a
    Rust panic, and numpy works after it."""
    outcomes = []
    for k in range(20):
        child = subprocess.Popen(
            [sys.executable, "-c", FIRST_CALL],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=os.getcwd(),
        )
        assert child.stdout.readline().strip() == "ready"
        time.sleep(0.015 * k)
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=60)
        assert "panicked" not in err and "PanicException" not in err, err
        assert "Failed to access NumPy" not in err, err
        outcomes.append(out.strip() or err.strip().splitlines()[-1])
    assert all(
        o in ("interrupted", "finished") or o.endswith("KeyboardInterrupt") for o in outcomes
    ), outcomes
    # The signals arrived: not every call ran to its end.
    assert any(o != "finished" for o in outcomes), outcomes


OTHER_USER_FIRST = """
import ctypes, json, sys, warnings
library = ctypes.CDLL("libngspice.so.0")
# What PySpice does first: ngspice's shared library initialised by
# another user of this process.
library.ngSpice_Init(None, None, None, None, None, None, None)
import chatterspice
with warnings.catch_warnings(record=True) as said:
    warnings.simplefilter("always")
    result = chatterspice.run(sys.argv[1], ideal=False, timeout=600)
print(json.dumps({
    "warned": [str(w.message) for w in said
               if issubclass(w.category, chatterspice.ChatterspiceWarning)],
    "report": result.report["warnings"],
    "schemes": [i["scheme"] for i in result.report["coupling"]],
}))
"""


def test_lock_step_falling_back_to_passes_is_a_python_warning():
    """After another user (PySpice, ctypes) has initialised libngspice in
    the process, the lock-step run is found inconsistent and the coupling
    runs as passes: the caller is told so by a ChatterspiceWarning."""
    import ctypes
    import json

    try:
        ctypes.CDLL("libngspice.so.0")
    except OSError:
        pytest.skip("ngspice's shared library (libngspice.so.0) is not installed")
    scenario = ROOT / "examples" / "scenarios" / "relay-driver.toml"
    done = subprocess.run(
        [sys.executable, "-c", OTHER_USER_FIRST, str(scenario)],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert done.returncode == 0, done.stderr
    said = json.loads(done.stdout.strip().splitlines()[-1])
    assert said["schemes"] and set(said["schemes"]) == {"passes"}
    fallbacks = [w for w in said["warned"] if "run again as passes" in w]
    assert fallbacks, said
    assert fallbacks == [w for w in said["report"] if "run again as passes" in w]
