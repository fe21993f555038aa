"""Relay contact bounce from physics, run through ngspice.

Every function takes its scenario one of three ways: ``path``, a scenario
file read exactly as the command line reads it; ``toml_text``, TOML whose
keys are laid over the built-in default scenario (keys it leaves out keep
the default's values); or neither, the built-in default itself. Reports are
the command line's JSON (``--format json``) parsed into dicts.
"""

import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Array = npt.NDArray[Any]

__version__: str
DEFAULT_SCENARIO: str
"""The text of the built-in default scenario (scenarios/default.toml)."""

class InputError(ValueError):
    """Bad input: a scenario key or value, a netlist, a raw file, a capture or
    a measured record. ``key``, ``path`` and ``line`` say where, when known."""

    key: Optional[str]
    path: Optional[str]
    line: Optional[int]

class NgspiceError(RuntimeError):
    """ngspice could not be run, or failed on the deck; the message carries
    ngspice's own words."""

    key: Optional[str]
    path: Optional[str]
    line: Optional[int]

class SimulationError(RuntimeError):
    """The mechanics, the coil coupling or the analysis of a run failed."""

    key: Optional[str]
    path: Optional[str]
    line: Optional[int]

class Run:
    """What :func:`run` returns."""

    report: Dict[str, Any]
    """The JSON of ``chatterspice run --format json``."""
    waveforms: Dict[str, _Array]
    """The bounced run's vectors by their raw-file names (``time``, ``v(in)``):
    float64 arrays of equal length."""
    ideal_waveforms: Optional[Dict[str, _Array]]
    """The ideal-contact run's vectors, or None when it was not run."""
    deck: str
    """The deck ngspice ran: the netlist with the contact included."""
    include: str
    """The contact include (``contact.inc``) that was run."""

class Sweep:
    """What :func:`sweep` returns."""

    summary: Dict[str, Any]
    """``summary.json`` of ``chatterspice sweep``."""
    rows: List[Dict[str, Union[int, float, str, None]]]
    """``sweep.csv``, one dict per sample in index order."""
    csv: str
    """``sweep.csv`` as text."""

class Fit:
    """What :func:`fit` returns."""

    report: Dict[str, Any]
    """The JSON of ``chatterspice fit --format json``."""
    scenario: str
    """The fitted scenario as TOML, with its ``[provenance]``."""

class Plot(Mapping[str, _Array]):
    """One plot of a raw file: vector name -> 1-D array (float64, or
    complex128 for the vectors of a complex plot)."""

    name: str
    index: int
    complex: bool
    points: int
    metadata: Dict[str, Any]
    """The plot's entry of ``chatterspice raw FILE --format json``."""
    @property
    def vectors(self) -> Dict[str, _Array]: ...
    def __getitem__(self, name: str) -> _Array: ...
    def __len__(self) -> int: ...
    def __iter__(self) -> Iterator[str]: ...

class RawFile(Mapping[str, _Array]):
    """A raw file: its plots in file order. As a mapping it is its last plot."""

    path: str
    plots: List[Plot]
    warnings: List[str]
    summary: Dict[str, Any]
    """``chatterspice raw FILE --format json``."""
    def plot(self, which: Union[int, str]) -> Plot:
        """The plot at index ``which`` (negative from the end), or the first
        plot named ``which``."""
    def __getitem__(self, name: str) -> _Array: ...
    def __len__(self) -> int: ...
    def __iter__(self) -> Iterator[str]: ...

def bounce(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    measured: Optional[_Path] = None,
) -> Dict[str, Any]:
    """The chatter sequence of one closing: the JSON of ``chatterspice bounce
    --format json``. With ``measured`` (a ``time,state`` CSV), that record is
    reported instead and no scenario is read."""

def run(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    measured: Optional[_Path] = None,
    ideal: bool = True,
    timeout: float = 60.0,
) -> Run:
    """The relay's chatter switching the scenario's circuit in ngspice, and
    the analysis of every probe. ``ideal=False`` skips the ideal-contact run;
    ``timeout`` bounds each ngspice run, in seconds."""

def check(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    measured: Optional[_Path] = None,
    timeout: float = 60.0,
) -> Dict[str, Any]:
    """The scenario's limits held against its run: the JSON of ``chatterspice
    check --format json``; ``passed`` is False when a limit failed (the
    command's exit status 1)."""

def sweep(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    samples: Optional[int] = None,
    seed: Optional[int] = None,
    jobs: Optional[int] = None,
    mechanics_only: bool = False,
    ideal: bool = False,
    timeout: float = 60.0,
) -> Sweep:
    """The scenario run many times with the numbers of its ``[sweep]``
    varied; no files are written."""

def fit(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    capture: Optional[_Path] = None,
    channel: Optional[str] = None,
    measured: Optional[_Path] = None,
    free: Optional[Sequence[str]] = None,
) -> Fit:
    """Fit the scenario's free keys (``[fit] free``, or ``free``) to a scope
    capture or a measured record and/or its ``[datasheet]``."""

def capture(
    path: _Path,
    *,
    channel: Optional[str] = None,
    low: Optional[float] = None,
    high: Optional[float] = None,
    closed: Optional[str] = None,
) -> Dict[str, Any]:
    """A scope capture of the contact: the JSON of ``chatterspice capture
    --format json``. ``closed`` is ``"high"`` or ``"low"``."""

def read_raw(path: _Path) -> RawFile:
    """Read an ngspice or LTspice raw file whole."""
