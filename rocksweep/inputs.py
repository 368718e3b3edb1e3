"""Input files: one guard for every file a command reads as data (records, listings of
records, hazard curves, measured histories), so that each gets the same checks and the
same one-line refusals (no I/O libraries here; ``outputs`` has the rules of files written).

- ``read_input``: a regular file only (a FIFO, device or directory is refused before it is
  opened and, should one be swapped in meanwhile, opened without blocking and refused),
  at most ``max_bytes`` bytes (checked before reading).
- ``decode_text``: UTF-8 text (a byte-order mark is skipped); UTF-16, a NUL byte, bytes that
  are not UTF-8 and control characters are refused naming the line.
- ``csv_table``: a comma-separated table with one header line: fields separated by
  semicolons or tabs are refused naming the line and the separator (a semicolon CSV's
  decimal comma would otherwise be read as two values); column names are stripped, an
  empty or repeated name is refused; every row has the header's number of fields.
- ``number_column``: a column's values as float64, each a finite number of magnitude at
  most ``MAX_ABS`` (NaN only where the caller allows gaps), or a refusal naming the
  line, the column and the value.

Every refusal is ``error(message)`` (the caller's ``RocksweepError`` class: RecordError,
RiskError, MeasuredError, SceneError) with one line naming the file.
"""

from __future__ import annotations

import csv
import errno
import math
import os
import re
import stat
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rocksweep.outputs import input_problem, shown

# Largest value of a data file [any unit]: far beyond any measured quantity, and its
# square and products with the model's scales stay finite (1e300 would overflow them).
MAX_ABS = 1e100
# Largest text data file read [bytes] unless the reader states its own limit.
MAX_TEXT_BYTES = 1 << 30

_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")
_SEPARATORS = {";": "semicolons", "\t": "tabs"}


def read_input(path: str | Path, what: str, error: type[Exception], *,
               max_bytes: int = MAX_TEXT_BYTES) -> bytes:
    """The bytes of the regular file ``path`` (``what``: the file's role in messages, e.g.
    "hazard curve"), or ``error`` in one line: missing, a FIFO/device/directory (never
    waited on), unreadable, larger than ``max_bytes``."""
    problem = input_problem(path)
    if problem is not None:
        raise error(f"{shown(path)}: no such {what} file" if problem == "no such file"
                    else f"{shown(path)}: {problem}")
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)  # non-blocking: a FIFO swapped in after the stat
    except OSError as err:
        raise error(f"{shown(path)}: cannot be read ({_why(err)})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise error(f"{shown(path)}: not a regular file; inputs are read from regular "
                        "files only")
        if st.st_size > max_bytes:
            raise error(f"{shown(path)}: {st.st_size:,} bytes; a {what} file is read up to "
                        f"{max_bytes:,} bytes")
        chunks, total = [], 0
        while True:
            block = os.read(fd, 1 << 20)
            if not block:
                break
            total += len(block)
            if total > max_bytes:  # it grew while read
                raise error(f"{shown(path)}: more than {max_bytes:,} bytes; a {what} file "
                            f"is read up to {max_bytes:,} bytes")
            chunks.append(block)
    except OSError as err:
        raise error(f"{shown(path)}: cannot be read ({_why(err)})") from None
    finally:
        os.close(fd)
    return b"".join(chunks)


def _why(err: OSError) -> str:
    if err.errno in (errno.EACCES, errno.EPERM):
        return "permission denied"
    return err.strerror or type(err).__name__


def decode_text(data: bytes, src: str, error: type[Exception], what: str) -> str:
    """``data`` as UTF-8 text (a byte-order mark skipped), or ``error`` naming the line:
    UTF-16, a NUL byte, bytes that are not UTF-8, a control character (tabs, CR and LF
    are text)."""
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise error(f"{src}: saved as UTF-16; a {what} is UTF-8 text")
    if b"\0" in data:
        line = data.count(b"\n", 0, data.index(b"\0")) + 1
        raise error(f"{src}, line {line}: a NUL byte (UTF-16 without a byte-order mark, or "
                    f"a binary file?); a {what} is UTF-8 text")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        raise error(f"{src}, line {line}: byte {err.start} is not UTF-8; a {what} is UTF-8 "
                    "text") from None
    bad = _CONTROL.search(text)
    if bad is not None:
        line = text.count("\n", 0, bad.start()) + 1
        raise error(f"{src}, line {line}: character {ord(bad.group()):#04x} is a control "
                    f"character; a {what} is plain text")
    return text


def read_text(path: str | Path, what: str, error: type[Exception], *,
              max_bytes: int = MAX_TEXT_BYTES) -> str:
    """``read_input`` then ``decode_text``: the text of a regular UTF-8 file."""
    return decode_text(read_input(path, what, error, max_bytes=max_bytes), shown(path),
                       error, what)


@dataclass(frozen=True)
class Table:
    """A CSV table as read: columns (stripped names, in order, each once), rows (the
    fields of each data row, as text), lines (each row's line number in the file) and
    src (the file as messages name it)."""

    columns: list[str]
    rows: list[list[str]]
    lines: list[int]
    src: str

    def column(self, name: str) -> list[str]:
        k = self.columns.index(name)
        return [r[k] for r in self.rows]


def separator_problem(line: str) -> str | None:
    """The separator ``line`` uses instead of commas (semicolons, tabs), or None."""
    if "," in line:
        return None
    for sep, name in _SEPARATORS.items():
        if sep in line.strip():
            return name
    return None


def csv_table(text: str, src: str, error: type[Exception], what: str, *,
              comment: str = "#", expect: str = "") -> Table:
    """The comma-separated table in ``text`` (``src`` names the file, ``what`` its role):
    blank lines and lines starting with ``comment`` skipped, the first other line the
    header. ``expect`` (e.g. "'PGA [g],annual_rate'") is shown with a refused header.
    Refused in one line: no header, other separators (semicolons, tabs), an empty or
    repeated column name, a row whose number of fields is not the header's."""
    numbered = [(k + 1, ln) for k, ln in enumerate(text.splitlines())
                if ln.strip() and not ln.lstrip().startswith(comment)]
    if not numbered:
        raise error(f"{src}: no header line" + (f" (expected {expect})" if expect else ""))
    parsed = []
    for (line, raw), fields in zip(numbered, csv.reader([ln for _, ln in numbered]),
                                   strict=True):
        if len(fields) == 1 and (sep := separator_problem(raw)) is not None:
            raise error(f"{src}, line {line}: fields separated by {sep}; a {what} "
                        "separates them by commas (CSV)")
        parsed.append((line, fields))
    (hline, head), body = parsed[0], parsed[1:]
    columns = [h.strip() for h in head]
    for k, name in enumerate(columns):
        if not name:
            raise error(f"{src}, line {hline}: column {k + 1} has no name; every column of "
                        f"a {what} is named in the header")
        if name in columns[:k]:
            raise error(f"{src}, line {hline}: column {name!r} appears twice; each column "
                        "once")
    for line, fields in body:
        if len(fields) != len(columns):
            raise error(f"{src}, line {line}: {len(fields)} value{'s' * (len(fields) != 1)}"
                        f", the header (line {hline}) has {len(columns)} columns")
    return Table(columns, [f for _, f in body], [ln for ln, _ in body], src)


def check_columns(columns: Sequence[object], src: str, error: type[Exception]) -> list[str]:
    """Column names of a table given as a DataFrame: text, stripped, each once."""
    out = []
    for k, c in enumerate(columns):
        if not isinstance(c, str) or not c.strip():
            raise error(f"{src}: column {k + 1} = {c!r}: columns are named by text")
        name = c.strip()
        if name in out:
            raise error(f"{src}: column {name!r} appears twice; each column once")
        out.append(name)
    return out


def number(cell: object, where: str, name: str, error: type[Exception], *,
           gaps: bool = False, limit: float = MAX_ABS) -> float:
    """One value as a float: a finite number of magnitude <= ``limit`` (NaN, or an empty
    cell, only with ``gaps``), else ``error`` naming ``where`` (file and line), the
    column and the value."""
    text = cell.strip() if isinstance(cell, str) else cell
    if gaps and (text == "" or text is None):
        return math.nan
    try:
        x = float(text)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        raise error(f"{where}: {name} = {shown(str(cell))!r}: not a number") from None
    if math.isnan(x) and gaps:
        return x
    if not (math.isfinite(x) and abs(x) <= limit):
        raise error(f"{where}: {name} = {shown(str(cell))!r}: must be a finite number of "
                    f"magnitude at most {limit:g}" + ("" if not gaps else " (NaN for a gap)"))
    return x


def number_column(values: Sequence[object], where: Sequence[str], name: str,
                  error: type[Exception], *, gaps: bool = False,
                  limit: float = MAX_ABS) -> np.ndarray:
    """A column's values as float64[n] (``number`` each; ``where[i]`` names row i)."""
    if not isinstance(values, list | tuple):
        arr = np.asarray(values)
        if arr.dtype.kind in "fiu":  # a numeric array (a DataFrame's column): checked whole
            x = arr.astype(np.float64)
            bad = ~np.isfinite(x) | (np.abs(x) > limit)
            if gaps:
                bad &= ~np.isnan(x)
            if not bad.any():
                return x
            i = int(np.argmax(bad))
            number(x[i], where[i], name, error, gaps=gaps, limit=limit)  # raises
        values = list(arr)
    return np.array([number(v, w, name, error, gaps=gaps, limit=limit)
                     for v, w in zip(values, where, strict=True)], dtype=np.float64)
