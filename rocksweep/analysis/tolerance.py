"""The relative tolerance of a bisected threshold (A_min): its default, its range and the
one check of it (the API, the CLI and the analyses call ``check_rtol``). A light module:
the command line reads it while parsing options (no numba, h5py or matplotlib)."""

from __future__ import annotations

from typing import Any

from rocksweep.errors import RocksweepError

DEFAULT_RTOL = 1e-3
MAX_RTOL = 0.1  # rtol is in (0, MAX_RTOL]: a "minimum" looser than 10% is not one


class RtolError(RocksweepError, ValueError):
    """An rtol outside (0, MAX_RTOL] (one line, naming the argument and the value)."""


def check_rtol(rtol: Any, name: str = "rtol") -> float:
    """rtol as a float, or a one-line RtolError naming ``name`` (``rtol``, ``--rtol``), the
    value and what is allowed: a relative tolerance in (0, MAX_RTOL]."""
    number = isinstance(rtol, int | float) and not isinstance(rtol, bool)
    if not (number and 0 < rtol <= MAX_RTOL):
        raise RtolError(f"{name} = {rtol!r}: must be a relative tolerance in "
                        f"(0, {MAX_RTOL:g}]")
    return float(rtol)
