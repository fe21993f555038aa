"""Shared helpers: where the repository's data is, and the command-line
binary the package's output is compared with."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
"""The repository checkout: tests/data, scenarios/, netlists/, fuzz seeds."""


def _cli_binary():
    explicit = os.environ.get("CHATTERSPICE_BIN")
    if explicit:
        return Path(explicit)
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for profile in ("debug", "release"):
        candidate = target / profile / "chatterspice"
        if candidate.is_file():
            return candidate
    found = shutil.which("chatterspice")
    return Path(found) if found else None


@pytest.fixture(scope="session")
def cli():
    """Run the `chatterspice` binary and return its stdout; the package's
    reports must equal what it prints. scripts/test sets CHATTERSPICE_BIN."""
    binary = _cli_binary()
    if binary is None or not binary.is_file():
        pytest.fail(
            "the chatterspice binary is needed to compare outputs: build it "
            "(cargo build) or set CHATTERSPICE_BIN"
        )

    def call(*args, cwd=None, check=True):
        done = subprocess.run(
            [str(binary), *map(str, args)],
            cwd=cwd,
            capture_output=True,
            text=True,
        )
        if check and done.returncode not in (0, 1):
            pytest.fail(f"chatterspice {' '.join(map(str, args))}: {done.stderr}")
        return done

    return call


@pytest.fixture(scope="session")
def cli_json(cli):
    def call(*args, cwd=None):
        return json.loads(cli(*args, "--format", "json", cwd=cwd).stdout)

    return call


@pytest.fixture(scope="session", autouse=True)
def ngspice_present():
    """Tests run ngspice for real: without it they fail, never skip."""
    program = os.environ.get("CHATTERSPICE_NGSPICE") or shutil.which("ngspice")
    if not program:
        pytest.fail("ngspice is not installed (scripts/setup installs it)")
