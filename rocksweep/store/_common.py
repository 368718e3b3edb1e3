"""What the store's modules share: the one error (``StoreError``), what h5py raises
(``H5_ERRORS``), one-line reasons (``error_reason``) and small helpers for attribute values,
sizes and times."""

from __future__ import annotations

import contextlib
import os
import re
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from rocksweep.errors import StoreError
from rocksweep.outputs import os_reason, shown

# What h5py raises for I/O and damaged files (HDF5 errors surface as any of these).
H5_ERRORS = (OSError, RuntimeError, ValueError, KeyError, TypeError, IndexError)



def utc_now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


def error_reason(err: BaseException) -> str:
    """One short phrase for an OS or HDF5 error (from its errno where it has one)."""
    if isinstance(err, KeyError) and err.args:
        err = RuntimeError(str(err.args[0]))  # KeyError's str() adds quotes
    no = getattr(err, "errno", None)
    if not isinstance(no, int):
        m = re.search(r"errno = (\d+)", str(err))
        no = int(m.group(1)) if m else None
    if no:
        return os_reason(OSError(no, os.strerror(no)))
    text = str(err).strip().splitlines()
    if not text:
        return type(err).__name__
    # HDF5: "Unable to ... (the reason)": the reason is what helps
    m = re.search(r"\(([^()]+)\)\s*$", text[0])
    return (m.group(1) if m else text[0])[:160]


def mib(n: float) -> str:
    return f"{n / 2**20:.1f} MiB"


def cut_repr(v, n: int = 40) -> str:
    text = repr(v)
    return text if len(text) <= n else text[: n - 3] + "..."


def damaged(path: Path, what: str) -> StoreError:
    return StoreError(f"{shown(path)}: damaged rocksweep result ({what})")


def close_quietly(f) -> None:
    """Close after an error: a second error must not hide the first."""
    with contextlib.suppress(Exception):
        f.close()


def fixed_ascii(text: str, dtype: str) -> np.ndarray:
    """``text`` as a fixed-length ASCII string of ``dtype`` (cut to fit)."""
    n = np.dtype(dtype).itemsize
    return np.array(text.encode("ascii", "replace")[:n], dtype=dtype)
