"""The same verdict from every door: every bundled example and every
bundled part through the command line's JSON and the package's report,
compared whole but for ngspice's wall-clock times.

The routes are the cheap ones a scenario allows: ``bounce`` for every
scenario, ``check`` for every scenario (ngspice only where a limit or a
coil's driver circuit needs it), ``run`` for every example with a
circuit. The command-line runs go in parallel with the package's calls,
which release the GIL."""

import json
import os
import subprocess
import warnings
from concurrent.futures import ThreadPoolExecutor

import pytest

import chatterspice
from conftest import ROOT, _cli_binary
from test_run import without_timings

EXAMPLES = sorted((ROOT / "examples" / "scenarios").glob("*.toml")) + [
    ROOT / "scenarios" / "default.toml"
]
# Two switching phases per AC endurance figure: the life's figures are
# compared, not converged (the default, 16, is the same code 8× longer).
LIFE = ("--life-phases", "2")
# A loaded machine runs a coil's lock-step run in tens of seconds (debug
# build, two at once): the timeout is not what is compared.
SLOW = ("--timeout", "600")
CHECKED = {}
"""The CLI's check of each example, by path: a check that ran the
circuit (`run` not null) already compared the whole run."""


def has_circuit(path):
    return any(line.strip() == "[circuit]" for line in path.read_text().splitlines())


def cli_doc(*args):
    """The command line's JSON (exit 0 or 1: a failed limit is a verdict)."""
    done = subprocess.run(
        [str(_cli_binary()), *map(str, args), "--format", "json"],
        capture_output=True,
        text=True,
        cwd=os.getcwd(),
    )
    assert done.returncode in (0, 1), f"chatterspice {' '.join(map(str, args))}: {done.stderr}"
    return json.loads(done.stdout)


def quietly(call, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", chatterspice.ChatterspiceWarning)
        return call(*args, **kwargs)


def both(pool, cli_args, call, *args, **kwargs):
    """(CLI JSON, package report) of one scenario, the CLI in `pool`."""
    theirs = pool.submit(cli_doc, *cli_args)
    ours = quietly(call, *args, **kwargs)
    return theirs.result(), ours


def part_files(tmp_path):
    files = []
    for name in chatterspice.parts():
        path = tmp_path / f"{name}.toml"
        path.write_text(f'base = "part:{name}"\n')
        files.append(path)
    return files


@pytest.fixture(scope="module")
def pool():
    with ThreadPoolExecutor(max_workers=2) as executor:
        yield executor


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_check_of_every_example_is_the_cli_check(pool, path):
    theirs, ours = both(
        pool, ("check", path, *LIFE, *SLOW), chatterspice.check, path, life_phases=2, timeout=600
    )
    CHECKED[path] = theirs
    assert without_timings(ours) == without_timings(theirs)
    assert isinstance(ours["passed"], bool)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_bounce_of_every_example_is_the_cli_bounce(path):
    done = subprocess.run(
        [str(_cli_binary()), "bounce", str(path), "--format", "json"],
        capture_output=True,
        text=True,
    )
    if done.returncode == 2:
        # Refused alike (a coil with no voltage of its own to close on),
        # in the same words.
        with pytest.raises(chatterspice.InputError) as raised:
            chatterspice.bounce(path)
        said = done.stderr.splitlines()[0].removeprefix("error: ")
        assert str(raised.value).splitlines()[0] == said
        return
    assert done.returncode == 0, done.stderr
    assert chatterspice.bounce(path) == json.loads(done.stdout)


@pytest.mark.parametrize(
    "path", [p for p in EXAMPLES if has_circuit(p)], ids=lambda p: p.stem
)
def test_run_of_every_example_with_a_circuit_is_the_cli_run(pool, path):
    checked = CHECKED.get(path) or cli_doc("check", path, *LIFE, *SLOW)
    if checked["run"] is not None:
        pytest.skip("its check ran the whole circuit, compared above")
    theirs, ours = both(
        pool, ("run", path, *LIFE, *SLOW), chatterspice.run, path, life_phases=2, timeout=600
    )
    assert without_timings(ours.report) == without_timings(theirs)


def test_check_and_bounce_of_every_part_are_the_cli_ones(pool, tmp_path):
    files = part_files(tmp_path)
    assert len(files) >= 3
    for path in files:
        text = path.read_text()
        for command, call in (("check", chatterspice.check), ("bounce", chatterspice.bounce)):
            theirs, ours = both(pool, (command, path), call, toml_text=text, origin=path)
            assert without_timings(ours) == without_timings(theirs), (command, path.stem)
            assert ours == quietly(call, path)


def test_check_holds_min_electrical_life_as_the_cli_does(pool, tmp_path):
    life = ROOT / "examples" / "scenarios" / "life.toml"
    # A limit far above any contact's life fails; the CLI exits 1 on it.
    path = tmp_path / "life-limit.toml"
    path.write_text(f'base = "{life}"\n[limits]\nmin_electrical_life = 1e15\n')
    ours = quietly(chatterspice.check, path, life_phases=2, timeout=600)
    row = [c for c in ours["checks"] if c["key"] == "limits.min_electrical_life"]
    assert len(row) == 1 and row[0]["passed"] is False
    assert ours["passed"] is False and ours["life"] is not None
    done = subprocess.run(
        [str(_cli_binary()), "check", str(path), *LIFE, *SLOW, "--format", "json"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 1
    theirs = json.loads(done.stdout)
    assert without_timings(ours) == without_timings(theirs)


def test_run_couples_a_coil_as_the_cli_does_and_can_choose(pool):
    solenoid = ROOT / "examples" / "scenarios" / "relay-driver.toml"
    default = quietly(chatterspice.run, solenoid, timeout=600)
    schemes = [i["scheme"] for i in default.report["coupling"]]
    passes = quietly(chatterspice.run, solenoid, coupling="passes", timeout=600)
    assert [i["scheme"] for i in passes.report["coupling"]] == ["passes"] * len(
        passes.report["coupling"]
    )
    theirs = cli_doc("run", solenoid, *SLOW)
    assert [i["scheme"] for i in theirs["coupling"]] == schemes
    assert without_timings(default.report) == without_timings(theirs)
    with pytest.raises(chatterspice.InputError, match="coupling"):
        chatterspice.run(solenoid, coupling="sideways")
