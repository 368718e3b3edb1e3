"""Ctrl-C that is never lost: a SIGINT handler that remembers the interrupt as well as
raising it.

Python runs a signal handler between bytecodes of the main thread; when that is inside a
C library's callback into Python (llvmlite's ctypes callbacks while numba loads or
compiles the kernel), the ``KeyboardInterrupt`` it raises is printed as "Exception
ignored" and dropped, or leaves a module half-imported (an ``AttributeError`` such as
llvmlite's ``PassBuilder`` later). ``install`` makes the handler also set a flag; the
sweep checks it (``raise_pending``) after the kernel is loaded and at every finished
chunk, so an interrupt the callback swallowed still stops the sweep (its finished points
saved), and the command line treats any error that follows an interrupt as the interrupt
(``pending``); such a swallowed interrupt is not printed as "Exception ignored"
(``sys.unraisablehook``). The command line installs it; the library alone leaves
Python's default.
"""

from __future__ import annotations

import signal
import sys
import threading

_pending = threading.Event()


def _handler(signum: int, frame: object) -> None:
    _pending.set()
    raise KeyboardInterrupt


def _unraisable(info: object) -> None:
    """``sys.unraisablehook``: a KeyboardInterrupt that C code could not raise (a ctypes
    callback's, a weakref callback's) is remembered, not printed as "Exception ignored";
    anything else goes to Python's hook."""
    if isinstance(getattr(info, "exc_value", None), KeyboardInterrupt):
        _pending.set()
        return
    sys.__unraisablehook__(info)


def install() -> None:
    """Handle SIGINT with the remembering handler, and let a swallowed KeyboardInterrupt
    pass silently (``_unraisable``; main thread only, a no-op elsewhere)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _handler)
        sys.unraisablehook = _unraisable


def pending() -> bool:
    """Whether a SIGINT arrived since ``install`` (whether or not its exception got
    through)."""
    return _pending.is_set()


def raise_pending() -> None:
    """Raise KeyboardInterrupt if a SIGINT arrived whose exception may have been lost (a
    checkpoint: after the kernel is loaded, between chunks)."""
    if _pending.is_set():
        raise KeyboardInterrupt
