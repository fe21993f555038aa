"""Ctrl-C and SIGTERM stop a long call within 0.5 s, with no ngspice
process or work directory left behind. Each case runs in a fresh
interpreter with a temporary directory of its own (TMPDIR), which the
work directories are made in and ngspice runs in."""

import os
import select
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

LIMIT = 0.5  # s from the signal to the exception

# A sweep of 600 circuit samples, one at a time: about a minute of work.
SWEEP = textwrap.dedent(
    """
    import chatterspice, sys, time
    text = '[sweep]\\nsamples = 600\\nseed = 1\\n[sweep.vary]\\n"surface.damping" = 0.3\\n'
    started = []
    def progress(done, total):
        if done >= 2 and not started:
            started.append(True)
            print("running", flush=True)
    try:
        chatterspice.sweep(toml_text=text, jobs=1, progress=progress)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
    """
)

# A sweep of the relay alone, a million samples: minutes of the
# mechanics, no ngspice.
MECHANICS = SWEEP.replace("samples = 600", "samples = 1000000").replace(
    "jobs=1, progress=progress", "jobs=1, mechanics_only=True, progress=progress"
)

# One run whose ngspice takes many seconds: a 1 ns step over 0.5 s.
RUN = textwrap.dedent(
    """
    import chatterspice, pathlib
    net = pathlib.Path("slow.cir")
    net.write_text(
        "slow\\nV1 vdd 0 DC 3.3\\nR1 vdd in 10k\\nX1 in 0 CONTACT\\nC1 in 0 1n\\n"
        ".tran 1n 0.5 0 1n\\n.end\\n"
    )
    text = (
        f'[circuit]\\nnetlist = "{net.resolve()}"\\n'
        '[[probe]]\\nsignal = "v(in)"\\nlow = 1.0\\nhigh = 2.3\\n'
    )
    print("running", flush=True)
    try:
        chatterspice.run(toml_text=text, ideal=False, timeout=600.0)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
    """
)


def processes_in(directory):
    """Processes whose working directory is under `directory`: ngspice runs
    in its work directory."""
    found = []
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            cwd = os.readlink(proc / "cwd")
        except OSError:
            continue
        if cwd.startswith(str(directory)):
            found.append((proc.name, (proc / "comm").read_text().strip()))
    return found


def ngspice_running_in(directory):
    return any("ngspice" in name for _, name in processes_in(directory))


# Ctrl-C as in an interactive Python. A shell that runs pytest in the
# background (as CI scripts may) starts it with SIGINT ignored, and Python
# then installs no KeyboardInterrupt handler in the script's process.
INTERACTIVE = "import signal\nsignal.signal(signal.SIGINT, signal.default_int_handler)\n"


def interrupt(tmp_path, script, sig, wait_for_ngspice):
    """Start `script`, wait until it prints `running` (and, if asked, until
    ngspice runs under tmp_path), send `sig`; returns the seconds from the
    signal to the script's last line, that line, and the exit status."""
    work = tmp_path / "tmp"
    work.mkdir()
    env = dict(os.environ, TMPDIR=str(work))
    child = subprocess.Popen(
        [sys.executable, "-c", INTERACTIVE + script],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdout.readline().strip() == "running", child.stderr.read()
        deadline = time.monotonic() + 30
        while wait_for_ngspice and not ngspice_running_in(work):
            assert time.monotonic() < deadline, "ngspice never started"
            time.sleep(0.01)
        sent = time.monotonic()
        child.send_signal(sig)
        # A call the signal did not stop must fail the test, not hang it.
        ready, _, _ = select.select([child.stdout], [], [], 30)
        assert ready, f"the script said nothing in the 30 s after {sig.name}"
        last = child.stdout.readline().strip()
        elapsed = time.monotonic() - sent
        child.wait(timeout=30)
        print(f"{sig.name}: {elapsed * 1e3:.0f} ms from the signal to the end of the call")
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    return elapsed, last, child.returncode, work


def assert_clean(work):
    # ngspice is killed by then; give the kernel a moment to reap.
    deadline = time.monotonic() + 2
    while processes_in(work) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert processes_in(work) == []
    assert list(work.iterdir()) == []


def test_ctrl_c_stops_a_circuit_sweep_within_half_a_second(tmp_path):
    elapsed, last, status, work = interrupt(tmp_path, SWEEP, signal.SIGINT, True)
    assert last == "interrupted"
    assert elapsed < LIMIT, f"KeyboardInterrupt {elapsed:.3f} s after SIGINT"
    assert status == 0
    assert_clean(work)


def test_ctrl_c_stops_a_long_ngspice_run_within_half_a_second(tmp_path):
    elapsed, last, status, work = interrupt(tmp_path, RUN, signal.SIGINT, True)
    assert last == "interrupted"
    assert elapsed < LIMIT, f"KeyboardInterrupt {elapsed:.3f} s after SIGINT"
    assert status == 0
    assert_clean(work)


def test_ctrl_c_stops_a_sweep_of_the_mechanics_within_half_a_second(tmp_path):
    elapsed, last, status, work = interrupt(tmp_path, MECHANICS, signal.SIGINT, False)
    assert last == "interrupted"
    assert elapsed < LIMIT, f"KeyboardInterrupt {elapsed:.3f} s after SIGINT"
    assert status == 0


def test_sigterm_stops_a_sweep_cleans_up_and_ends_the_process(tmp_path):
    elapsed, last, status, work = interrupt(tmp_path, SWEEP, signal.SIGTERM, True)
    # The process ends (SystemExit, not the script's except clause).
    assert last == ""
    assert status == 128 + signal.SIGTERM
    assert elapsed < LIMIT, f"exit {elapsed:.3f} s after SIGTERM"
    assert_clean(work)


def test_the_sigterm_handler_is_put_back_after_a_call():
    import chatterspice

    before = signal.getsignal(signal.SIGTERM)
    chatterspice.bounce()
    assert signal.getsignal(signal.SIGTERM) is before


def test_a_callback_that_raises_stops_the_sweep_with_its_exception(tmp_path):
    import chatterspice

    class Stop(Exception):
        pass

    seen = []

    def progress(done, total):
        seen.append(done)
        if done >= 1:
            raise Stop(done)

    text = '[sweep]\nsamples = 200\nseed = 1\n[sweep.vary]\n"surface.damping" = 0.3\n'
    started = time.monotonic()
    with pytest.raises(Stop):
        chatterspice.sweep(toml_text=text, jobs=1, progress=progress)
    # 200 circuit samples take many seconds; the stop came after a few.
    assert time.monotonic() - started < 10
    assert seen[-1] >= 1
