"""The one error base of rocksweep: everything a user can fix, reported as one line.

Every module raises a subclass of ``RocksweepError`` for a problem the user can fix (a bad
scene, a body that is not physical, a result file that cannot be made or read, an output
path that cannot be written). ``str(err)`` is one line naming the key or path, the value
and what is allowed. The command line prints it as ``Error: ...`` with a non-zero exit and
no traceback; from Python it is an ordinary exception (``except rocksweep.RocksweepError``).
"""

from __future__ import annotations

import dataclasses
import numbers
from collections.abc import Callable
from typing import Any


class Said:
    """A message that may name arguments of the caller: a template whose fields are
    ``Arg``s (``rtol = 0.3``, "pass ``resume=True``"). ``str()`` says them as the Python
    API's keywords, ``said(words)`` in another caller's words (the command line's options:
    ``rocksweep.cli.main``); a field that is itself a ``Said`` (a message wrapping another)
    is said in the same words. The library never writes a command-line option. The base of
    ``RocksweepError`` and of ``AnalysisWarning``: an error and a warning are said alike."""

    def __init__(self, message: str = "", /, *args: Any, **fields: Any) -> None:
        self.template = message
        self.fields = fields
        super().__init__(_filled(message, fields), *args)

    def said(self, words: Callable[[Arg], str]) -> str:
        """The message with each ``Arg`` said by ``words``."""
        if not self.fields:
            return str(self)
        return _filled(self.template, {
            k: words(v) if isinstance(v, Arg) else v.said(words)
            if isinstance(v, Said) else v for k, v in self.fields.items()})


class RocksweepError(Said, Exception):
    """A problem the user can fix; ``str()`` is one line, its arguments said as ``Said``
    says them."""


def _filled(template: str, fields: dict[str, Any]) -> str:
    """``template`` with its fields; as it is if it has none (or is no template: a brace
    that came with a value)."""
    if not fields:
        return template
    try:
        return template.format(**fields)
    except (KeyError, IndexError, ValueError):
        return template


_NO_VALUE = object()


@dataclasses.dataclass(frozen=True)
class Arg:
    """An argument a message names, said by ``str()`` as the Python API's keyword.

    name: the keyword (``rtol``, ``resume``; ``overrides`` for a scene key set by the
    caller); value: as given, or none. kind:
    - ``value``: ``rtol = 0.3`` (the name alone without a value),
    - ``flag``: a flag to switch on, ``resume=True`` (value True), or off, ``joint=False``
      (value False),
    - ``keyword``: an argument to give, its value the caller's, ``p=...``,
    - ``set_key``: a scene key set by ``overrides`` (value: the key),
      ``overrides['pulse.A_ratio']``,
    - ``set_fix``: the same as a remedy, ``overrides={'pulse.A_ratio': ...}``,
    - ``set_entry``: an entry of ``overrides`` as given, ``overrides entry 'x'``."""

    name: str
    value: Any = _NO_VALUE
    kind: str = "value"

    @property
    def given(self) -> bool:
        """Whether a value is named."""
        return self.value is not _NO_VALUE

    def __str__(self) -> str:
        if self.kind == "flag":
            return f"{self.name}={self.value}"
        if self.kind == "keyword":
            return f"{self.name}=..."
        if self.kind == "set_key":
            return f"overrides[{self.value!r}]"
        if self.kind == "set_fix":
            return f"overrides={{{self.value!r}: ...}}"
        if self.kind == "set_entry":
            return f"overrides entry {self.value!r}"
        return f"{self.name} = {self.value!r}" if self.given else self.name


def flag(name: str, on: bool = True) -> Arg:
    """A flag the message asks for (``resume=True``), or asks to leave off (``on=False``:
    ``joint=False``)."""
    return Arg(name, bool(on), "flag")


def set_key(key: str, kind: str = "set_key") -> Arg:
    """A scene key set through ``overrides`` (``set_key``), or to set (``set_fix``)."""
    return Arg("overrides", key, kind)


class OutputError(RocksweepError, OSError):
    """An output path that cannot be written (exists, is a device, no such directory...)."""


# Every error class of the package, lowest layer first, each with the module that raises it
# (imported from here: tests/test_errors.py fails on an error class defined anywhere else).

class BodyError(RocksweepError, ValueError):
    """A body that is not physical; names the key and value (physics.bodies)."""


class RecordError(RocksweepError, ValueError):
    """A ground-motion record that cannot be read; names the file and line
    (physics.records)."""


class SuiteError(RocksweepError, ValueError):
    """A record that cannot be scaled; names the file (physics.suite)."""


class SceneError(RocksweepError, ValueError):
    """A scene that cannot be run (scene.model, scene.parse)."""


class SweepError(RocksweepError, ValueError):
    """A sweep that cannot run as asked: workers, cluster (compute.arguments)."""


class AdaptiveError(RocksweepError, ValueError):
    """Bad adaptive settings: axes, coarse level, margin, audit share (compute.adaptive)."""


class StoreError(RocksweepError):
    """A result file that cannot be made, read or resumed (store)."""


class BoundaryError(AdaptiveError):
    """A result whose boundaries cannot be drawn; names the file (analysis.boundaries)."""


class SpectrumError(RocksweepError, ValueError):
    """A result that has no spectra: wrong axes, incomplete (analysis.spectrum)."""


class FragilityError(RocksweepError, ValueError):
    """A Dataset or a request that fragility cannot answer (analysis.fragility)."""


class IdaError(RocksweepError, ValueError):
    """A result that has no IDA: not a scaled suite, not finished (analysis.ida)."""


class FloorError(RocksweepError):
    """A Dataset that has no floor spectrum or orientation to give (analysis.floors), or
    a building whose floor motion would exceed its memory bound (physics.floor)."""


class EfficiencyError(RocksweepError, ValueError):
    """A Dataset that has no IM efficiency (analysis.efficiency)."""


class RiskError(RocksweepError, ValueError):
    """A hazard curve or a request that risk cannot answer (analysis.risk)."""


class TableError(RocksweepError, ValueError):
    """A Dataset that has no table (analysis.table)."""


class FigureError(RocksweepError, ValueError):
    """Something that cannot be drawn as asked (figures)."""


class DiagramError(FigureError):
    """A result that cannot be drawn as a diagram as asked (figures.diagrams)."""


class FragilityFigureError(RocksweepError, ValueError):
    """A fragility Dataset that cannot be drawn as asked (figures.fragility)."""


class PlotError(RocksweepError, ValueError):
    """A Dataset that has no figure (figures.by_kind)."""


class AnalysisWarning(Said, UserWarning):
    """An analysis of points that cannot all be trusted (``analysis.states.trust``: not
    computed, flagged): the result is marked, and this warning says why (the command line
    prints it as one ``Warning:`` line, its arguments said as options, as an error's)."""


class FragilityWarning(AnalysisWarning):
    """A fitted fragility curve that should not be trusted as it is (its ``reason`` is
    not "ok")."""


class ApiError(RocksweepError, ValueError):
    """An argument of the Python API that cannot be used (api)."""


class MeasuredError(RocksweepError, ValueError):
    """A measured history that cannot be used (physics.measured)."""


class CalibrationError(RocksweepError, ValueError):
    """A calibration that cannot run as asked (analysis.calibrate)."""


class BudgetExceededError(RocksweepError):
    """A reference run past its budget of right-hand-side evaluations
    (``physics.sliding_reference.MAX_EVALUATIONS``): raised from inside scipy's solver and
    caught where the run stops (status step_cap); never reaches a user."""


# ---------------------------------------------------------------------------------------
# Argument checks shared by every layer, written once with one wording
# ---------------------------------------------------------------------------------------

def is_integer(v: Any) -> bool:
    """An integer (Python's or numpy's), not a bool."""
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


def is_real(v: Any) -> bool:
    """A real number (Python's or numpy's), not a bool."""
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def check_type(name: str, value: Any, ok: bool, allowed: str) -> None:
    """The Python API's one type check of an argument: unless ``ok``, a one-line TypeError
    naming it, the value (shortened) and what is ``allowed``."""
    if not ok:
        text = repr(value)
        text = text if len(text) <= 60 else f"{text[:40]}...{text[-12:]}"
        raise TypeError(f"{name} = {text}: must be {allowed}")


def check_integer(name: str, v: Any, error: type[Exception] = TypeError) -> int:
    """``int(v)``, or ``error("NAME = V: must be an integer")``."""
    if not is_integer(v):
        raise error(f"{name} = {v!r}: must be an integer")
    return int(v)


MAX_RTOL = 0.1  # rtol is in (0, MAX_RTOL]: a "minimum" looser than 10% is not one


def check_rtol(rtol: Any, error: type[RocksweepError] = ApiError) -> float:
    """A bisection's relative tolerance as a float in (0, MAX_RTOL], or ``error`` (one line
    naming ``rtol``)."""
    if (isinstance(rtol, bool) or not isinstance(rtol, numbers.Real)
            or not 0 < rtol <= MAX_RTOL):
        raise error(f"{{rtol}}: must be a relative tolerance in (0, {MAX_RTOL:g}]",
                    rtol=Arg("rtol", rtol))
    return float(rtol)


def one_line(text: str) -> str:
    """``text`` as one printable line: control characters (a newline, ESC), lone
    surrogates (undecodable bytes of a damaged file) and other unprintable characters
    escaped as in Python (``\\n``, ``\\udc91``); printable non-ASCII kept."""
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii")
                   for c in text)
