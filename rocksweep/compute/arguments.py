"""The arguments of a sweep, checked in one place before anything touches an output.

``rocksweep sweep`` (``rocksweep.cli.sweep``) and ``rocksweep.run``
(``rocksweep.compute.session``) call ``check_sweep_arguments`` once, first, and hand its
``SweepArguments`` down: an argument that cannot
be used is refused with one line while the output file is still as it was (an existing
result is neither removed nor changed, no new file appears). A wrong type is a
``TypeError`` naming the argument (as Python users expect); a value out of range is a
``SweepError`` (a ``RocksweepError``). The dask scheduler is probed here too, with a
bounded wait (``probe_scheduler``): a port that accepts a connection and never answers
is refused after ``connect_timeout`` seconds, not waited on for ever.

Light: no numba, no h5py (the command line's ``--help`` imports nothing heavy).
"""

from __future__ import annotations

import math
import numbers
import os
import sys
import time
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit

from rocksweep.errors import Arg, SweepError, flag, is_integer
from rocksweep.vocab.settings import BACKENDS, DEFAULT_BACKEND

# Local worker threads allowed per core: the chunk kernels keep a core busy, so threads
# beyond a few per core only wait (and a typo like 99999999999999999999 must not start them).
MAX_JOBS_PER_CORE = 4
# Seconds to wait for a dask scheduler to answer (``connect_timeout``).
CONNECT_TIMEOUT = 20.0
MAX_CONNECT_TIMEOUT = 3600.0
# Finished chunks are written to the file at most this often [s] by default
# (``write_every``): a write (several hyperslabs per variable, two flushes) costs ~10 ms, as
# much as a chunk of easy points, and holds the GIL that worker threads need between
# kernel calls.
WRITE_EVERY = 1.0
# the remedy of a scheduler that could not be reached (a message template's end: {resume})
RETRY = "then run it again (with {resume} to finish a file already started)"


def check_flag(name: str, v: Any) -> bool:
    """``v`` if it is a bool (numpy's too), else a TypeError naming ``name``."""
    np = sys.modules.get("numpy")  # a numpy bool exists only once numpy is loaded
    if isinstance(v, bool) or (np is not None and isinstance(v, np.bool_)):
        return bool(v)
    raise TypeError(f"{name} = {v!r}: must be True or False")


def check_jobs(jobs: Any) -> int:
    """Number of local worker threads for ``jobs`` (-1: one per core); a TypeError for a
    non-integer, a one-line ``SweepError`` for 0, other negatives and more than
    ``MAX_JOBS_PER_CORE`` threads per core."""
    if not is_integer(jobs):
        raise TypeError(f"jobs = {jobs!r}: must be an integer (>= 1, or -1 for all cores)")
    jobs = int(jobs)
    n = os.cpu_count() or 1
    if jobs == -1:
        return n
    if jobs < 1:
        raise SweepError("{jobs}: give a number >= 1, or -1 for all cores",
                         jobs=Arg("jobs", jobs))
    cap = MAX_JOBS_PER_CORE * n
    if jobs > cap:
        raise SweepError(f"{{jobs}}: at most {cap} ({MAX_JOBS_PER_CORE} x the {n} "
                         f"core{'s' * (n > 1)} of this machine: each thread keeps a core busy, "
                         "so more threads only wait for one)", jobs=Arg("jobs", jobs))
    return jobs


def check_seconds(name: str, seconds: Any, *, lo: float = 0.0, hi: float = math.inf,
                  what: str = "") -> float:
    """A finite number of seconds in [lo, hi] (TypeError for a non-number); name: the
    argument."""
    if isinstance(seconds, bool) or not isinstance(seconds, numbers.Real):
        raise TypeError(f"{name} = {seconds!r}: must be a number of seconds")
    s = float(seconds)
    if not (math.isfinite(s) and lo <= s <= hi):
        top = f" and <= {hi:g}" if math.isfinite(hi) else ""
        raise SweepError(f"{{arg}}: give a finite number of seconds >= {lo:g}{top}"
                         + (f" ({what})" if what else ""), arg=Arg(name, seconds))
    return s


@dataclass(frozen=True)
class SweepArguments:
    """A sweep's arguments that decide nothing about the scene, checked once
    (``check_sweep_arguments``) and handed down (``compute.session.sweep``): jobs as
    given (-1: one per core) and n_workers, the local threads it means (1 for dask);
    the others as ``sweep_file`` documents them."""

    jobs: int = 1
    n_workers: int = 1
    resume: bool = False
    overwrite: bool = False
    validate: bool = False
    backend: str = DEFAULT_BACKEND
    scheduler: str | None = None
    chunk_size: int | None = None
    write_every: float = WRITE_EVERY
    connect_timeout: float = CONNECT_TIMEOUT


def check_sweep_arguments(*, jobs: Any = 1, resume: Any = False, overwrite: Any = False,
                          validate: Any = False, backend: Any = DEFAULT_BACKEND,
                          scheduler: Any = None, chunk_size: Any = None,
                          write_every: Any = WRITE_EVERY, connect_timeout: Any = CONNECT_TIMEOUT
                          ) -> SweepArguments:
    """Check every argument of a sweep that decides nothing about the scene; return them
    as ``SweepArguments``. Raises before any file is touched. (Whether ``validate`` has
    an adaptive sweep to check depends on the scene: ``compute.session.sweep`` asks.)"""
    resume = check_flag("resume", resume)
    overwrite = check_flag("overwrite", overwrite)
    validate = check_flag("validate", validate)
    if resume and overwrite:
        raise SweepError("{resume} and {overwrite} exclude each other",
                         resume=flag("resume"), overwrite=flag("overwrite"))
    write_every = check_seconds("write_every", write_every,
                                what="0: write every chunk as it finishes")
    if chunk_size is not None:
        if not is_integer(chunk_size):
            raise TypeError(f"chunk_size = {chunk_size!r}: must be an integer >= 1")
        if chunk_size < 1:
            raise SweepError("{arg}: must be >= 1", arg=Arg("chunk_size", chunk_size))
    connect_timeout = check_seconds("connect_timeout", connect_timeout, lo=0.1,
                                    hi=MAX_CONNECT_TIMEOUT)
    checked = {"resume": resume, "overwrite": overwrite, "validate": validate,
               "backend": backend, "chunk_size": chunk_size, "write_every": write_every,
               "connect_timeout": connect_timeout}
    if backend == "threads":
        if scheduler:
            raise SweepError("{scheduler} works with {dask} only", scheduler=Arg("scheduler"),
                             dask=Arg("backend", "dask"))
        n_workers = check_jobs(jobs)
        return SweepArguments(jobs=int(jobs), n_workers=n_workers, **checked)
    if backend == "dask":
        if not (isinstance(scheduler, str) and scheduler.strip()):
            if scheduler is not None and not isinstance(scheduler, str):
                raise TypeError(f"scheduler = {scheduler!r}: must be an address string, "
                                "e.g. tcp://host:8786")
            raise SweepError("{dask} needs a {scheduler} address", dask=Arg("backend", "dask"),
                             scheduler=Arg("scheduler"))
        if any(ord(c) < 32 for c in scheduler):
            raise SweepError(f"scheduler {scheduler!r}: control characters in the address")
        _address_parts(scheduler)
        return SweepArguments(jobs=1, n_workers=1, scheduler=scheduler, **checked)
    raise SweepError(f"{{backend}}: must be {' or '.join(BACKENDS)}",
                     backend=Arg("backend", backend))


def _address_parts(address: str):
    """``address`` split as a URL (``tcp://`` when it names no protocol); a one-line
    SweepError for one that is not a URL (``tcp://[::1``: an unclosed IPv6 bracket, a
    port that is not a number)."""
    try:
        parts = urlsplit(address if "://" in address else f"tcp://{address}")
        parts.port  # noqa: B018 - parsed on access: a bad port raises here
    except ValueError as err:
        raise SweepError(f"scheduler {address!r}: not an address like tcp://host:8786 or "
                         f"tcp://[::1]:8786 ({err})") from None
    return parts


def probe_scheduler(address: str, timeout: float = CONNECT_TIMEOUT) -> None:
    """A one-line ``SweepError`` unless something at a ``tcp://`` ``address`` accepts a
    connection and starts dask's handshake within ``timeout`` seconds (a dask scheduler
    speaks first: it sends its handshake as soon as a connection is accepted). Other
    protocols are left to dask. Bounded: a port that accepts and never answers costs
    ``timeout`` seconds, no more."""
    parts = _address_parts(address)
    if parts.scheme != "tcp":
        return
    try:
        host, port = parts.hostname, parts.port
    except ValueError:
        host, port = None, None
    if not host or port is None:
        raise SweepError(f"scheduler {address}: not an address like tcp://host:8786")
    import socket  # here: the command line's options read this module's constants

    deadline = time.monotonic() + timeout
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except TimeoutError:
        raise SweepError(f"scheduler {address}: no connection within {timeout:g} s "
                         f"({{timeout}}); check the address, {RETRY}",
                         timeout=Arg("connect_timeout"), resume=flag("resume")) from None
    except OSError as err:
        raise SweepError(f"scheduler {address}: cannot connect ({err.strerror or err}); start "
                         f"the scheduler or check the address, {RETRY}",
                         resume=flag("resume")) from None
    try:
        sock.settimeout(max(0.1, deadline - time.monotonic()))
        try:
            data = sock.recv(1)
        except TimeoutError:
            data = None
        except OSError:
            data = b""
    finally:
        sock.close()
    if data is None:
        raise SweepError(f"scheduler {address}: accepts connections but no dask scheduler "
                         f"answered within {timeout:g} s ({{timeout}}); check the address, "
                         f"{RETRY}", timeout=Arg("connect_timeout"), resume=flag("resume"))
    if not data:
        raise SweepError(f"scheduler {address}: closed the connection without answering "
                         f"(not a dask scheduler?); check the address, {RETRY}",
                         resume=flag("resume"))
