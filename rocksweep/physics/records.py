"""Recorded ground motions: read a PEER ``.AT2`` file or a two-column file (no numba here).

Formats read:

- PEER NGA-West2 ``.AT2``: four header lines (database, event/station/component,
  ``ACCELERATION TIME SERIES IN UNITS OF G``, ``NPTS=  4000, DT=   .0100 SEC``), then the
  accelerations in g, five per line (the last line may hold fewer).
- The older PEER strong-motion database ``.AT2``: the same, but the fourth line gives the
  two numbers first: ``4000    0.01000   NPTS, DT``.
  In both, values may be Fortran-style (``.1234E-02``, ``-.5E-03``, ``1.0D-02``, and two
  negative values written without a space between them), lines may end in CRLF, and
  a file is recognised by its fourth line (or by the suffix ``.AT2``, which then requires
  that header).
- A plain two-column file: ``t [s]  xg'' [g]`` per line, whitespace or comma separated,
  lines starting with ``#`` (a header) and blank lines ignored. Times must increase
  uniformly (each step within 1e-3 of the first step: printed times may be rounded); the
  first row is the record's t = 0.

Why a parser of our own: the AT2 readers in the packages available here have known
defects (one drops the last line of values, one rounds DT to three decimals, one reads DT
from fixed columns that the older header does not use, one is GPL and wants the record
number in the file name). This one is ~150 lines with its own tests (both header orders, a
partial last line, CRLF, Fortran exponents, every malformed case).

Any malformed file (missing header, NPTS not matching the number of values, non-uniform or
decreasing times, NaN/inf, no motion at all, a peak outside [PGA_MIN, PGA_MAX] g, empty)
is a ``RecordError``: one line naming the file and the line.

The parsed record (``GroundRecord``) holds the samples acc[i] [g] at t_i = i * dt [s].
Between samples the ground acceleration is linearly interpolated; after the last sample
(t > (npts - 1) dt) the ground is at rest (acceleration 0). A scene scales it to a peak of
A_ratio * g tan(alpha_cg): xg''(t) = A_ratio g tan(alpha_cg) acc(t) / pga. For a body of
rocking frequency p [rad/s] the kernel's time is p t, so the record's samples fall every
p * dt in kernel time (``kernel_series``).

Each component of a record (the two horizontals, the up component, positive upwards) is
read by the same ``read_record``; how the kernel takes them: ``physics.ground_motion``.
"""

from __future__ import annotations

import hashlib
import math
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rocksweep.errors import RecordError
from rocksweep.inputs import read_input
from rocksweep.outputs import check_output, input_problem, shown, write_atomic


@dataclass(frozen=True, eq=False)
class GroundRecord:
    """A uniformly sampled ground acceleration record (compare records by ``sha256``).

    name: the file's stem; dt [s]: sample interval; acc [g]: (npts,) float64, read-only,
    acc[i] at t = i dt; npts: number of samples; pga [g]: max |acc| (> 0); sha256: hex
    digest of the file's bytes; source: the path read; title: the AT2 file's second
    header line (event, station, component), '' for a two-column file; data: the file's
    bytes (a result file keeps them, so that it stands alone).
    """

    name: str
    dt: float
    acc: np.ndarray
    npts: int
    pga: float
    sha256: str
    source: str
    title: str = ""
    data: bytes = field(default=b"", repr=False)  # the file's bytes (stored in results)

    @property
    def duration(self) -> float:
        """Time of the last sample, (npts - 1) dt [s]; the ground is at rest after it."""
        return (self.npts - 1) * self.dt

    def times(self) -> np.ndarray:
        """Sample times i dt [s], shape (npts,)."""
        return np.arange(self.npts, dtype=np.float64) * self.dt

    def acc_at(self, t) -> np.ndarray:
        """xg''(t) [g]: linear interpolation of the samples, 0 for t < 0 or t > duration."""
        t = np.asarray(t, dtype=np.float64)
        inside = (t >= 0.0) & (t <= self.duration)
        return np.where(inside, np.interp(t, self.times(), self.acc), 0.0)


def digest(data: bytes) -> str:
    """Hex SHA-256 of a record file's bytes: what a scene, a result file and a resume
    compare (``GroundRecord.sha256``)."""
    return hashlib.sha256(data).hexdigest()


def kernel_series(record: GroundRecord, p: float) -> tuple[float, np.ndarray]:
    """The record as the kernel sees it for a body of rocking frequency p [rad/s].

    Returns (dt_k, shape): dt_k = p * dt, the sample interval in kernel time p t, and
    shape = acc / pga, shape (npts,) float64 in [-1, 1], so that in kernel units
    xg'' = A_ratio g tan(alpha_cg) * shape (accelerations in g-multiples are unchanged
    by the time scaling, since the kernel's g is the real g and only time is scaled).
    """
    if not (math.isfinite(p) and p > 0.0):
        raise RecordError(f"p = {p!r}: must be a finite number > 0 [rad/s]")
    return p * record.dt, np.ascontiguousarray(record.acc / record.pga, dtype=np.float64)


# ---------------------------------------------------------------------------------------
# parsing
# ---------------------------------------------------------------------------------------

# A Fortran real (D or E exponent, digits before or after the point) or nan/inf, ending
# where whitespace, a sign (two negative values written together) or the line ends.
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?"
_TOKEN = re.compile(rf"\s*({_NUMBER}|[-+]?(?:nan|inf(?:inity)?))(?=[\s+-]|$)", re.IGNORECASE)
_NGA_HEADER = re.compile(r"^\s*NPTS\s*=\s*([^\s,]+)\s*,?\s*DT\s*=\s*([^\s,]+)", re.IGNORECASE)
_OLD_HEADER = re.compile(r"^\s*([^\s,]+)\s*,?\s+([^\s,]+)\s+NPTS\s*,?\s*DT\b", re.IGNORECASE)
_NPTS_MIN = 2
# Sample spacing of a record [s]: 1 MHz to one sample every 10 s bound any ground motion
# recorder; beyond, DT is a typo (1e300 would overflow the run's length, 1e-300 its steps).
DT_MIN, DT_MAX = 1e-6, 10.0
# Peak of a record [g]: far beyond any ground motion either way (a record in g peaks
# between ~1e-4 and ~10), yet every scaling, velocity and spectral value of it stays a
# normal float: a subnormal peak (1e-310) or a huge one (1e300) would overflow the scale
# factor or the spectra (numpy's RuntimeWarnings, inf factors).
PGA_MIN, PGA_MAX = 1e-100, 1e100
# Largest record file read [bytes]: ~3e7 samples of AT2 text, hours at 1 kHz.
MAX_RECORD_BYTES = 500 << 20


def _where(src: str, line: int | None = None) -> str:
    return shown(src) if line is None else f"{shown(src)}, line {line}"


def _float(tok: str, src: str, line: int) -> float:
    try:
        x = float(tok.replace("D", "E").replace("d", "e"))
    except ValueError:
        raise RecordError(f"{_where(src, line)}: {tok!r} is not a number") from None
    if not math.isfinite(x):
        raise RecordError(f"{_where(src, line)}: value {tok!r} is not finite")
    return x


def _values(text: str, src: str, line: int) -> list[float]:
    """The numbers on one AT2 data line."""
    out = []
    pos, n = 0, len(text)
    while pos < n:
        m = _TOKEN.match(text, pos)
        if m is None:
            rest = text[pos:].strip()
            if not rest:
                break
            raise RecordError(f"{_where(src, line)}: {rest.split()[0]!r} is not a number")
        out.append(_float(m.group(1), src, line))
        pos = m.end()
    return out


def _header(lines: list[str], src: str) -> tuple[int, float]:
    """(NPTS, DT) from the fourth header line, in either order."""
    if len(lines) < 4:
        raise RecordError(f"{_where(src, len(lines) or 1)}: file ends inside the 4-line "
                          "AT2 header")
    units = lines[2].upper()
    if ("VELOCITY" in units or "DISPLACEMENT" in units
            or re.search(r"UNITS OF\s+(?!G\b)", units)):
        raise RecordError(f"{_where(src, 3)}: {lines[2].strip()!r}: not an acceleration "
                          "record in units of g")
    m = _NGA_HEADER.match(lines[3]) or _OLD_HEADER.match(lines[3])
    if m is None:
        found = lines[3].strip()
        found = found if len(found) <= 32 else found[:29].rstrip() + "..."
        raise RecordError(f"{_where(src, 4)}: missing header: expected 'NPTS=  4000, DT= "
                          f".01000 SEC' or '4000  0.0100  NPTS, DT', found {found!r}")
    npts_s, dt_s = m.groups()
    try:
        npts = int(npts_s)
    except ValueError:
        npts = -1
    if npts < _NPTS_MIN:
        raise RecordError(f"{_where(src, 4)}: NPTS = {npts_s!r}: must be an integer >= "
                          f"{_NPTS_MIN}")
    dt = _float(dt_s, src, 4)
    if dt <= 0.0:
        raise RecordError(f"{_where(src, 4)}: DT = {dt_s!r}: must be > 0 [s]")
    return npts, dt


def _parse_at2(lines: list[str], src: str) -> tuple[float, np.ndarray, str]:
    npts, dt = _header(lines, src)
    acc: list[float] = []
    for k in range(4, len(lines)):
        vals = _values(lines[k], src, k + 1)
        if len(acc) + len(vals) > npts:
            raise RecordError(f"{_where(src, k + 1)}: value {npts + 1} is past NPTS = {npts} "
                              "(line 4)")
        acc.extend(vals)
    if len(acc) < npts:
        last = max((k + 1 for k in range(len(lines)) if lines[k].strip()), default=4)
        raise RecordError(f"{_where(src, last)}: the file ends after {len(acc)} values, "
                          f"but NPTS = {npts} (line 4)")
    return dt, np.array(acc, dtype=np.float64), lines[1].strip()


def _parse_two_column(lines: list[str], src: str) -> tuple[float, np.ndarray, str]:
    t: list[float] = []
    a: list[float] = []
    rows: list[int] = []
    for k, raw in enumerate(lines):
        s = raw.strip()
        if not s or s.startswith("#"):
            continue
        fields = [f for f in re.split(r"[,\s]+", s) if f]
        if len(fields) != 2 and ";" in s:
            raise RecordError(f"{_where(src, k + 1)}: fields separated by semicolons; a record's "
                              "two columns are separated by spaces or a comma")
        if len(fields) != 2:
            raise RecordError(f"{_where(src, k + 1)}: expected 2 columns (t [s], xg'' [g]), "
                              f"found {len(fields)}; a header line must start with #")
        ti, ai = (_float(f, src, k + 1) for f in fields)
        if t and ti <= t[-1]:
            raise RecordError(f"{_where(src, k + 1)}: time {fields[0]} s is not after "
                              f"{t[-1]:g} s: times must increase")
        t.append(ti)
        a.append(ai)
        rows.append(k + 1)
    if len(t) < _NPTS_MIN:
        raise RecordError(f"{_where(src, rows[-1] if rows else 1)}: {len(t)} sample(s): a "
                          f"record needs at least {_NPTS_MIN}")
    tt = np.array(t)
    steps = np.diff(tt)
    # each step against the first (printed times may be rounded: 1e-3 of a step is allowed)
    bad = np.flatnonzero(np.abs(steps - steps[0]) > 1e-3 * steps[0])
    if bad.size:
        i = int(bad[0]) + 1
        raise RecordError(f"{_where(src, rows[i])}: time step {steps[i - 1]:.6g} s differs "
                          f"from the first step {steps[0]:.6g} s (line {rows[1]}): times must "
                          "be uniformly spaced")
    dt = (tt[-1] - tt[0]) / (tt.size - 1)  # the mean step: rounding errors average out
    return float(dt), np.array(a, dtype=np.float64), ""


def _is_at2(lines: list[str], path: Path) -> bool:
    if path.suffix.lower() == ".at2":
        return True
    return len(lines) >= 4 and bool(_NGA_HEADER.match(lines[3]) or _OLD_HEADER.match(lines[3]))


def parse_record(data: bytes, source: str | Path) -> GroundRecord:
    """Parse a record from the bytes of a file (``source`` names it in errors and decides,
    by its suffix ``.AT2``, that the AT2 header is required)."""
    src = str(source)
    path = Path(src)
    text = data.decode("latin-1")  # headers may hold any byte; numbers are ASCII
    lines = text.splitlines()  # \n, \r\n and \r alike
    if not text.strip():
        raise RecordError(f"{_where(src)}: empty file")
    if _is_at2(lines, path):
        dt, acc, title = _parse_at2(lines, src)
    else:
        dt, acc, title = _parse_two_column(lines, src)
    if not DT_MIN <= dt <= DT_MAX:
        raise RecordError(f"{_where(src)}: DT = {dt:g} s: the sample spacing must be in "
                          f"[{DT_MIN:g}, {DT_MAX:g}] s")
    pga = float(np.max(np.abs(acc)))
    if pga == 0.0:
        raise RecordError(f"{_where(src)}: every value is 0 (PGA = 0): no motion to scale")
    if not PGA_MIN <= pga <= PGA_MAX:
        raise RecordError(f"{_where(src)}: PGA = {pga:g} g: the peak must be in "
                          f"[{PGA_MIN:g}, {PGA_MAX:g}] g (accelerations in g); is it in "
                          "other units, or not a record?")
    acc.setflags(write=False)
    return GroundRecord(name=path.stem, dt=float(dt), acc=acc, npts=int(acc.size), pga=pga,
                        sha256=digest(data), source=src, title=title,
                        data=bytes(data))


def read_record(path: str | Path) -> GroundRecord:
    """Read a ``.AT2`` (NGA-West2 or older PEER) or two-column record file through
    ``rocksweep.inputs.read_input`` (a regular file of at most MAX_RECORD_BYTES: a FIFO,
    device or directory is refused before it is opened, never waited on)."""
    if input_problem(path) == "is a directory, not a file":
        raise RecordError(f"{_where(str(path))}: is a directory, not a record file")
    data = read_input(path, "record", RecordError, max_bytes=MAX_RECORD_BYTES)
    return parse_record(data, path)


# ---------------------------------------------------------------------------------------
# writing (NGA-West2 layout)
# ---------------------------------------------------------------------------------------


def fortran_e(x: float) -> str:
    """x in Fortran E15.7 style, as NGA-West2 files print it: ``  -.1234568E-02``."""
    if x == 0.0:
        return f"{'.0000000E+00':>15}"
    digits, exp = f"{abs(x):.6E}".split("E")
    mantissa = digits.replace(".", "")
    return f"{'-' if x < 0 else ''}.{mantissa}E{int(exp) + 1:+03d}".rjust(15)


def _dt_text(dt: float) -> str:
    """DT with at least four decimals and as many as it needs, Fortran style (.0050)."""
    for nd in range(4, 13):
        text = f"{dt:.{nd}f}"
        if float(text) == dt:
            break
    return text[1:] if text.startswith("0.") else text


def at2_text(acc: Iterable[float], dt: float, title: str) -> str:
    """The text of an NGA-West2 style ``.AT2`` file (LF line ends, 5 values per line)."""
    acc = np.asarray(list(acc), dtype=np.float64)
    if acc.ndim != 1 or acc.size < _NPTS_MIN or not np.all(np.isfinite(acc)):
        raise ValueError("acc must be a 1-D array of at least 2 finite values")
    if not (math.isfinite(dt) and dt > 0.0):
        raise ValueError(f"dt = {dt!r}: must be > 0")
    head = ["PEER NGA STRONG MOTION DATABASE RECORD", title.strip(),
            "ACCELERATION TIME SERIES IN UNITS OF G",
            f"NPTS={acc.size:6d}, DT={_dt_text(dt):>8} SEC"]
    body = ["".join(fortran_e(float(x)) for x in acc[i:i + 5]) for i in range(0, acc.size, 5)]
    return "\n".join(head + body) + "\n"


def write_at2(path: str | Path, acc: Iterable[float], dt: float, title: str, *,
              overwrite: bool = False) -> Path:
    """Write an NGA-West2 style ``.AT2`` file through ``rocksweep.outputs`` (refuses an
    existing path without ``overwrite``; atomic)."""
    path = check_output(path, overwrite=overwrite)
    text = at2_text(acc, dt, title)
    write_atomic(path, lambda tmp: tmp.write_bytes(text.encode("ascii")),
                 overwrite=overwrite)
    return path
