"""The one error base of rocksweep: everything a user can fix, reported as one line.

Every module raises a subclass of ``RocksweepError`` for a problem the user can fix (a bad
scene, a body that is not physical, a result file that cannot be made or read, an output
path that cannot be written). ``str(err)`` is one line naming the key or path, the value
and what is allowed. The command line prints it as ``Error: ...`` with a non-zero exit and
no traceback; from Python it is an ordinary exception (``except rocksweep.RocksweepError``).
"""

from __future__ import annotations


class RocksweepError(Exception):
    """A problem the user can fix; ``str()`` is one line."""


class OutputError(RocksweepError, OSError):
    """An output path that cannot be written (exists, is a device, no such directory...)."""


def one_line(text: str) -> str:
    """``text`` as one printable line: control characters (a newline, ESC), lone
    surrogates (undecodable bytes of a damaged file) and other unprintable characters
    escaped as in Python (``\\n``, ``\\udc91``); printable non-ASCII kept."""
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii")
                   for c in text)
