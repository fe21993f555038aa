"""Relay contact bounce from physics, run through ngspice.

Every function that simulates takes its scenario one of three ways:
``path``, a scenario file read exactly as the command line reads it;
``toml_text``, TOML laid over the built-in default scenario (keys it
leaves out keep the default's values) or over its own ``base``; or
neither, the built-in default itself. Reports are the command line's JSON
(``--format json``) as dicts; waveforms are numpy arrays. Numbers are in
SI units (s, V, A, m, N, kg). Ctrl-C stops any call.
"""

import os
from typing import (
    Any,
    Callable,
    Dict,
    Iterator,
    List,
    Mapping,
    Optional,
    Sequence,
    Tuple,
    Union,
    final,
    overload,
)

import numpy as np
import numpy.typing as npt

_Path = Union[str, bytes, "os.PathLike[str]", "os.PathLike[bytes]"]
_Array = npt.NDArray[Any]

__all__ = [
    "bounce",
    "run",
    "check",
    "envelope",
    "life",
    "sweep",
    "fit",
    "capture",
    "read_raw",
    "parts",
    "part",
    "pwl",
    "Run",
    "Sweep",
    "SweepRows",
    "Fit",
    "RawFile",
    "Plot",
    "InputError",
    "NgspiceError",
    "SimulationError",
    "ChatterspiceWarning",
    "DEFAULT_SCENARIO",
    "__version__",
]

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

class ChatterspiceWarning(UserWarning):
    """Something worth a look that did not stop the call: a run that is not
    physical as set up, a coupling that fell back from lock-step to passes,
    a life that could not be estimated, a remark on a limit's figure."""

@final
class Run:
    """What :func:`run` returns: the report, the waveforms and what ngspice
    ran and said."""

    def __new__(
        cls,
        report: Dict[str, Any],
        waveforms: Dict[str, _Array],
        ideal_waveforms: Optional[Dict[str, _Array]],
        deck: str,
        include: str,
        log: str,
        ideal_log: Optional[str],
        workdir: Optional[str],
        raw_path: Optional[str],
        ideal_workdir: Optional[str],
    ) -> "Run":
        """A run from its fields, as pickle rebuilds it."""
    @property
    def report(self) -> Dict[str, Any]:
        """The JSON of ``chatterspice run --format json``."""
    @property
    def waveforms(self) -> Dict[str, _Array]:
        """The bounced run's vectors by their raw-file names (``time`` in s,
        ``v(in)`` in V, ``i(vdd)`` in A): float64 arrays of equal length."""
    @property
    def ideal_waveforms(self) -> Optional[Dict[str, _Array]]:
        """The ideal-contact run's vectors, or None when it was not run."""
    @property
    def deck(self) -> str:
        """The deck ngspice ran: the netlist with the contact included."""
    @property
    def include(self) -> str:
        """The contact include (``contact.inc``) that was run."""
    @property
    def log(self) -> str:
        """ngspice's output (stdout and stderr) of the bounced run."""
    @property
    def ideal_log(self) -> Optional[str]:
        """ngspice's output of the ideal-contact run, or None."""
    @property
    def workdir(self) -> Optional[str]:
        """With ``keep_workdir=True``, the bounced run's work directory."""
    @property
    def raw_path(self) -> Optional[str]:
        """With ``keep_workdir=True``, the raw file in ``workdir``."""
    @property
    def ideal_workdir(self) -> Optional[str]:
        """With ``keep_workdir=True``, the ideal-contact run's work directory."""

_Row = Dict[str, Union[int, float, str, None]]

@final
class SweepRows:
    """The rows of the ``sweep.csv`` a sweep wrote (``sweep(out=DIR)``),
    read from the file when asked: ``len(rows)``, ``rows[k]``, ``rows[a:b]``
    and iteration in index order."""

    def __new__(cls, path: str, len: int) -> "SweepRows":
        """The rows of the file at ``path``, as pickle rebuilds them."""
    @property
    def path(self) -> str:
        """The CSV the rows are read from."""
    def __len__(self) -> int: ...
    @overload
    def __getitem__(self, key: int, /) -> _Row: ...
    @overload
    def __getitem__(self, key: slice, /) -> List[_Row]: ...
    def __iter__(self) -> Iterator[_Row]: ...

@final
class Sweep:
    """What :func:`sweep` returns: the summary and one row per sample."""

    def __new__(
        cls,
        summary: Dict[str, Any],
        rows: Union[List[_Row], SweepRows],
        csv: Optional[str],
        out: Optional[str] = None,
    ) -> "Sweep":
        """A sweep from its fields, as pickle rebuilds it."""
    @property
    def summary(self) -> Dict[str, Any]:
        """``summary.json`` of ``chatterspice sweep``."""
    @property
    def rows(self) -> Union[List[_Row], SweepRows]:
        """``sweep.csv``, one dict per sample in index order: a list, or
        with ``out=`` a :class:`SweepRows` reading them from the file."""
    @property
    def csv(self) -> Optional[str]:
        """``sweep.csv`` as text; None with ``out=``."""
    @property
    def out(self) -> Optional[str]:
        """With ``out=``, the directory the sweep's files are in."""

@final
class Fit:
    """What :func:`fit` returns: the report and the fitted scenario."""

    def __new__(cls, report: Dict[str, Any], scenario: str) -> "Fit":
        """A fit from its fields, as pickle rebuilds it."""
    @property
    def report(self) -> Dict[str, Any]:
        """The JSON of ``chatterspice fit --format json``."""
    @property
    def scenario(self) -> str:
        """The fitted scenario as TOML, with its ``[provenance]``."""

@final
class Plot(Mapping[str, _Array]):
    """One plot of a raw file: vector name -> read-only 1-D array (float64,
    or complex128 for the vectors of a complex plot)."""

    def __new__(
        cls,
        name: str,
        index: int,
        complex: bool,
        points: int,
        metadata: Dict[str, Any],
        vectors: Dict[str, _Array],
    ) -> "Plot":
        """A plot from its fields, as pickle rebuilds it."""
    @property
    def name(self) -> str:
        """The plot's name, e.g. ``Transient Analysis``."""
    @property
    def index(self) -> int:
        """Its place in the file, from 0."""
    @property
    def complex(self) -> bool:
        """Whether its vectors are complex."""
    @property
    def points(self) -> int:
        """The number of points."""
    @property
    def metadata(self) -> Dict[str, Any]:
        """The plot's entry of ``chatterspice raw FILE --format json``."""
    @property
    def vectors(self) -> Dict[str, _Array]:
        """The vectors as a plain dict (the same arrays)."""
    def __getitem__(self, key: str, /) -> _Array: ...
    def __len__(self) -> int: ...
    def __iter__(self) -> Iterator[str]: ...
    def __contains__(self, key: object, /) -> bool: ...
    def keys(self) -> List[str]:  # type: ignore[override]
        """The vector names, in the file's order."""
    def values(self) -> List[_Array]:  # type: ignore[override]
        """The arrays, in the file's order."""
    def items(self) -> List[Tuple[str, _Array]]:  # type: ignore[override]
        """``(name, array)`` pairs, in the file's order."""
    def get(self, name: str, default: Any = None) -> Any:  # type: ignore[override]
        """The vector ``name``, or ``default``."""

@final
class RawFile(Mapping[str, _Array]):
    """A raw file: its plots in file order. As a mapping it is its last plot."""

    def __new__(
        cls, path: str, plots: List[Plot], warnings: List[str], summary: Dict[str, Any]
    ) -> "RawFile":
        """A file from its fields, as pickle rebuilds it."""
    @property
    def path(self) -> str:
        """The file as given."""
    @property
    def plots(self) -> List[Plot]:
        """Every plot, in file order."""
    @property
    def warnings(self) -> List[str]:
        """What the reader recovered from (a run cut short, extra points)."""
    @property
    def summary(self) -> Dict[str, Any]:
        """``chatterspice raw FILE --format json``."""
    def plot(self, which: Union[int, str]) -> Plot:
        """The plot at index ``which`` (negative from the end), or the first
        plot named ``which``."""
    def __getitem__(self, key: str, /) -> _Array: ...
    def __len__(self) -> int: ...
    def __iter__(self) -> Iterator[str]: ...
    def __contains__(self, key: object, /) -> bool: ...
    def keys(self) -> List[str]:  # type: ignore[override]
        """The last plot's vector names."""
    def values(self) -> List[_Array]:  # type: ignore[override]
        """The last plot's arrays."""
    def items(self) -> List[Tuple[str, _Array]]:  # type: ignore[override]
        """The last plot's ``(name, array)`` pairs."""
    def get(self, name: str, default: Any = None) -> Any:  # type: ignore[override]
        """The last plot's vector ``name``, or ``default``."""

def bounce(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    origin: Optional[_Path] = None,
    measured: Optional[_Path] = None,
) -> Dict[str, Any]:
    """The chatter of one closing: the JSON of ``chatterspice bounce
    --format json``. ``toml_text`` is laid over the default (or read from its
    own ``base``); ``origin`` is the file it stands for (errors name it,
    relative paths resolve against its directory). With ``measured`` (a
    ``time,state`` CSV), that record is reported instead."""

def run(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    origin: Optional[_Path] = None,
    measured: Optional[_Path] = None,
    ideal: bool = True,
    timeout: float = 60.0,
    keep_workdir: bool = False,
    element: Optional[str] = None,
    coupling: Optional[str] = None,
    max_iterations: int = 20,
    coupling_tolerance: float = 1e-07,
    ngspice: Optional[_Path] = None,
    no_spiceinit: bool = False,
    envelope: bool = False,
    samples: int = 32,
    seed: int = 1,
    jobs: Optional[int] = None,
    life_phases: int = 16,
    no_life: bool = False,
) -> Run:
    """The relay's chatter switching the scenario's circuit in ngspice, and
    the analysis of every probe, as ``chatterspice run``: the same options
    with the same defaults. ``ideal=False`` skips the ideal-contact run;
    ``timeout`` bounds each ngspice run, in s; ``keep_workdir`` leaves the
    work directories (named in the result); ``coupling`` is ``"lock-step"``
    or ``"passes"`` for a coil-driven relay. Warnings are issued as
    :class:`ChatterspiceWarning`."""

def check(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    origin: Optional[_Path] = None,
    measured: Optional[_Path] = None,
    timeout: float = 60.0,
    element: Optional[str] = None,
    coupling: Optional[str] = None,
    max_iterations: int = 20,
    coupling_tolerance: float = 1e-07,
    ngspice: Optional[_Path] = None,
    no_spiceinit: bool = False,
    envelope: bool = False,
    samples: int = 32,
    seed: int = 1,
    jobs: Optional[int] = None,
    life_phases: int = 16,
    no_life: bool = False,
) -> Dict[str, Any]:
    """The scenario's limits held against its run: the JSON of ``chatterspice
    check --format json``; ``passed`` is False when a limit failed (the
    electrical life's ``min_electrical_life`` among them)."""

def envelope(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    origin: Optional[_Path] = None,
    samples: int = 32,
    seed: int = 1,
    jobs: Optional[int] = None,
    timeout: float = 60.0,
    element: Optional[str] = None,
    coupling: Optional[str] = None,
    max_iterations: int = 20,
    coupling_tolerance: float = 1e-07,
    ngspice: Optional[_Path] = None,
    no_spiceinit: bool = False,
) -> Dict[str, Any]:
    """Every relay the datasheet allows, each limit held against the worst:
    the JSON of ``chatterspice check --envelope --format json``."""

def life(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    origin: Optional[_Path] = None,
    phases: int = 16,
    jobs: Optional[int] = None,
    timeout: float = 60.0,
    element: Optional[str] = None,
    coupling: Optional[str] = None,
    max_iterations: int = 20,
    coupling_tolerance: float = 1e-07,
    ngspice: Optional[_Path] = None,
    no_spiceinit: bool = False,
) -> Dict[str, Any]:
    """The contacts' electrical life from the scenario's endurance figures:
    the JSON of ``chatterspice life --format json``."""

def sweep(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    origin: Optional[_Path] = None,
    samples: Optional[int] = None,
    seed: Optional[int] = None,
    jobs: Optional[int] = None,
    out: Optional[_Path] = None,
    force: bool = False,
    resume: Optional[_Path] = None,
    mechanics_only: bool = False,
    ideal: bool = False,
    timeout: float = 60.0,
    element: Optional[str] = None,
    coupling: Optional[str] = None,
    max_iterations: int = 20,
    coupling_tolerance: float = 1e-07,
    ngspice: Optional[_Path] = None,
    no_spiceinit: bool = False,
    progress: Optional[Callable[[int, int], object]] = None,
) -> Sweep:
    """The scenario run many times with the numbers of its ``[sweep]``
    varied, as ``chatterspice sweep``: in memory, or with ``out=DIR``
    written into DIR as ``chatterspice sweep --out DIR`` writes it, the
    rows read back from there when asked. ``progress(done, total)`` is
    called on the calling thread as samples finish."""

def fit(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    origin: Optional[_Path] = None,
    capture: Optional[_Path] = None,
    channel: Optional[str] = None,
    measured: Optional[_Path] = None,
    free: Union[str, Sequence[str], None] = None,
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
    --format json``. ``low``/``high`` in V; ``closed`` is ``"high"`` or
    ``"low"``."""

def read_raw(path: _Path) -> RawFile:
    """Read an ngspice or LTspice raw file whole; its arrays are read-only
    views of the data read."""

def parts() -> List[str]:
    """The names of the bundled parts, sorted (``base = "part:NAME"``)."""

def part(name: str) -> str:
    """The scenario TOML of the bundled part ``name``."""

def pwl(
    path: Optional[_Path] = None,
    *,
    toml_text: Optional[str] = None,
    origin: Optional[_Path] = None,
    measured: Optional[_Path] = None,
) -> str:
    """The contact as a PWL netlist include, as ``chatterspice pwl --element
    pwl`` prints it."""
