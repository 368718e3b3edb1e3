"""The one error base of rocksweep: everything a user can fix, reported as one line.

Every module raises a subclass of ``RocksweepError`` for a problem the user can fix (a bad
scene, a body that is not physical, a result file that cannot be made or read, an output
path that cannot be written). ``str(err)`` is one line naming the key or path, the value
and what is allowed. The command line prints it as ``Error: ...`` with a non-zero exit and
no traceback; from Python it is an ordinary exception (``except rocksweep.RocksweepError``).
"""

from __future__ import annotations

import functools
import numbers
import re
from collections.abc import Callable
from typing import Any


class RocksweepError(Exception):
    """A problem the user can fix; ``str()`` is one line."""


class OutputError(RocksweepError, OSError):
    """An output path that cannot be written (exists, is a device, no such directory...)."""


# Every error class of the package, lowest layer first, each with the module that raises it.
# Each module re-exports its own (``from rocksweep.scene.model import SceneError`` keeps
# working); tests/test_errors.py fails on an error class defined anywhere else.

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


class FloorError(RocksweepError, ValueError):
    """A Dataset with no floor spectrum or orientation to give (analysis.floors)."""


class FragilityError(RocksweepError, ValueError):
    """A Dataset or a request that fragility cannot answer (analysis.fragility)."""


class IdaError(RocksweepError, ValueError):
    """A result that has no IDA: not a scaled suite, not finished (analysis.ida)."""


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


class AnalysisWarning(UserWarning):
    """An analysis of points that cannot all be trusted (``analysis.states.trust``: not
    computed, flagged): the result is marked, and this warning says why (the command line
    prints it as one ``Warning:`` line)."""


class FragilityWarning(AnalysisWarning):
    """A fitted fragility curve that should not be trusted as it is (its ``reason`` is
    not "ok")."""


class ApiError(RocksweepError, ValueError):
    """An argument of the Python API that cannot be used (api)."""


class MeasuredError(RocksweepError, ValueError):
    """A measured history that cannot be used (physics.measured)."""


class CalibrationError(RocksweepError, ValueError):
    """A calibration that cannot run as asked (analysis.calibrate)."""


# ---------------------------------------------------------------------------------------
# Argument checks shared by every layer, written once with one wording
# ---------------------------------------------------------------------------------------

def is_integer(v: Any) -> bool:
    """An integer (Python's or numpy's), not a bool."""
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


def check_integer(name: str, v: Any, error: type[Exception] = TypeError) -> int:
    """``int(v)``, or ``error("NAME = V: must be an integer")``."""
    if not is_integer(v):
        raise error(f"{name} = {v!r}: must be an integer")
    return int(v)


MAX_RTOL = 0.1  # rtol is in (0, MAX_RTOL]: a "minimum" looser than 10% is not one


def check_rtol(rtol: Any, error: type[Exception] = ApiError, name: str = "rtol") -> float:
    """A bisection's relative tolerance as a float in (0, MAX_RTOL], or ``error`` (one line
    naming ``name``: ``rtol`` in Python, ``--rtol`` on the command line)."""
    if (isinstance(rtol, bool) or not isinstance(rtol, numbers.Real)
            or not 0 < rtol <= MAX_RTOL):
        raise error(f"{name} = {rtol!r}: must be a relative tolerance in (0, {MAX_RTOL:g}]")
    return float(rtol)


def one_line(text: str) -> str:
    """``text`` as one printable line: control characters (a newline, ESC), lone
    surrogates (undecodable bytes of a damaged file) and other unprintable characters
    escaped as in Python (``\\n``, ``\\udc91``); printable non-ASCII kept."""
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii")
                   for c in text)


# ---------------------------------------------------------------------------------------
# Errors in Python's words (the API's functions)
# ---------------------------------------------------------------------------------------

# The library's messages name command-line flags where the CLI is the usual way in; the
# API says the same in its own arguments.
_FLAG_WORDS = (
    (re.compile(r"--set '([^']*)'"), r"overrides entry '\1'"),
    (re.compile(r"--set ([\w.]+)=VALUE"), r"overrides={'\1': ...}"),
    (re.compile(r"--set ([\w.]+)=(\S+)"), r"overrides={'\1': \2}"),
    (re.compile(r"--set ([\w.]+)"), r"overrides['\1']"),
    (re.compile(r"--resume\b"), "resume=True"),
    (re.compile(r"--overwrite\b"), "overwrite=True"),
    (re.compile(r"--adaptive\b"), "adaptive=True"),
    (re.compile(r"--jobs\b"), "jobs"),
)


def _pythonic(message: str) -> str:
    """A one-line message with the command line's flags said as API arguments."""
    for pattern, words in _FLAG_WORDS:
        message = pattern.sub(words, message)
    return message


def speaks_python(fn: Callable) -> Callable:
    """Re-raise the library's one-line errors with the flags they name said as the API's
    arguments (``--set impact.lam=VALUE`` -> ``overrides={'impact.lam': ...}``)."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return fn(*args, **kwargs)
        except RocksweepError as err:
            text = str(err)
            said = _pythonic(text)
            if said == text:
                raise
            try:
                new = type(err)(said)
            except TypeError:  # an error class with another constructor: as it is
                raise err from None
            raise new from None

    return wrapper
