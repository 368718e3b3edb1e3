"""Sweep results on disk (HDF5 through h5py; the only module that writes them).

Layout (netCDF-4 / CF-1.10, so ``xarray.open_dataset(path, engine="h5netcdf")`` and
netCDF-4 readers open it):

- one dataset per swept axis, named after it (``shape``, a body key, ``lam``, ``A_ratio``,
  ``w_over_p``), holding its values and made an HDF5 dimension scale;
- one 0-d dataset per unswept axis (a scalar coordinate, listed in each variable's
  ``coordinates`` attribute);
- one dataset per stored variable (``rocksweep.compute.sweep.VARIABLES``) with the grid's
  dimensions attached; ``outcome`` is -1 where a point is not computed yet;
- every variable and coordinate has ``long_name`` and (but the pulse shape and the flag
  variables ``outcome``, ``status``) CF ``units``: ``"rad"`` for angles, ``"1"`` for
  everything else, which is a pure number: Pi groups, counts, theta/alpha_ref, energies
  / E_ref, and times p*t (``t_overturn``: its ``long_name`` says p*t, its
  ``rocksweep_units`` the scale, here ``"1/p"``);
- adaptive sweeps (``rocksweep sweep --adaptive``, ``rocksweep.compute.adaptive``) add an int8
  variable ``computed`` (0 filled: the point was not computed, its ``outcome`` is the class
  of the uniform cell around it and every other variable keeps its "not computed" fill
  value; 1 computed; 2 an audit point that agreed with its fill; 3 one that disagreed; CF
  ``flag_values``/``flag_meanings``), the settings as attributes ``adaptive`` (int8 1),
  ``adaptive_axes``, ``adaptive_coarse``, ``adaptive_margin``, ``adaptive_final_margin``,
  ``adaptive_audit``, ``adaptive_seed``, ``adaptive_threshold`` (also in the resolved
  scene, so a resume with other settings is refused), and the counts ``points_computed``,
  ``points_filled``, ``points_audited``, ``audit_misses`` (fixed size, updated in place).
  While an adaptive sweep runs, ``outcome`` is -1 at the points not decided yet; its
  last session writes the filled classes;
- global attributes: ``Conventions`` (``CF-1.10``), ``title``, ``source``, ``history``
  (one line per session: time, host, backend, rocksweep version, points done), the scene
  YAML verbatim and its resolved form, the resolved numerics, versions, times, totals,
  ``host`` and ``backend`` of the latest session and the format version. ``complete``
  and ``energy`` are int8 0/1 (netCDF has no boolean attribute; HDF5 enums are lost).

Only the parent process writes. Datasets are allocated in full when the file is made,
under a temporary name unique to the process, renamed when complete, so later writes
touch raw data only: a killed run leaves a well-formed file whose ``outcome`` marks
exactly the finished points (each chunk's other variables are flushed before its
``outcome``). ``--resume`` reopens it and computes the rest.

Safety (issue 16):

- The attributes a session changes (``SESSION_ATTRS``) have fixed-size types (numbers,
  fixed-length strings) and are overwritten in place (``attrs.modify``): reopening,
  writing results and finishing never need new space in the file, so a full disk cannot
  damage what is there, and resuming on a full disk works.
- A new file's size is known (every dataset is allocated at creation): a grid larger
  than the free space is refused before anything is written.
- A writer holds HDF5's exclusive lock (``flock``) on its file; ``create`` takes the same
  lock on a file it overwrites, and holds the new file's lock before it is renamed into
  place, so no two processes write one path, whatever ``--resume``/``--overwrite`` they
  are given. Without ``overwrite`` the rename is a hard link, which fails if another
  process made the path meanwhile.
- Readers validate what they rely on (attributes, coordinates, shapes, dtypes, outcome
  codes); every problem is a one-line ``StoreError`` naming the file.
"""

from __future__ import annotations

import contextlib
import errno
import json
import math
import os
import platform
import re
import shutil
import stat
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rocksweep import fields
from rocksweep.compute.grid import Grid
from rocksweep.compute.sweep import ChunkResult, variables
from rocksweep.errors import OutputError, RocksweepError
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.outcomes import OUTCOME_WORDS, STATUS_WORDS
from rocksweep.outputs import _reason, check_output, shown
from rocksweep.scene.scene import Scene

if TYPE_CHECKING:
    import h5py

FORMAT = "rocksweep-sweep"
# 1: first release; 2: CF attributes (units, Conventions, int8 flags), fixed-size session
# attributes, history/host/backend. This version reads both and resumes both.
FORMAT_VERSION = 2
CONVENTIONS = "CF-1.10"

# Free space required beyond the space a new file reserves (``_space_needed``): a share of
# the file, at least this many bytes [bytes], so that a small sweep fits a small disk and
# a large one leaves room for the file system's own blocks.
SPACE_MARGIN = 64 << 10
SPACE_SHARE = 1 / 64
# Space for attribute updates of a format-1 file on resume [bytes].
UPDATE_MARGIN = 1 << 20
# Space reserved for HDF5's metadata when a file is made [bytes], beyond the datasets and
# the scene text: HDF5 fails badly when a metadata write hits a full disk (a segmentation
# fault in the next flush), so the whole file's space is reserved before it is written.
METADATA_RESERVE = 256 << 10
# Size of the ``history`` attribute [bytes]: fixed, so a session rewrites it in place;
# about 30 sessions of one line each (the oldest are dropped beyond that).
HISTORY_BYTES = 4096

# The attributes a session changes -> fixed-size dtype (written in place, never resized).
SESSION_ATTRS: dict[str, str] = {
    "sessions": "int64",
    "last_started": "S32",
    "last_finished": "S32",
    "finished": "S32",
    "wall_time": "float64",
    "cpu_time": "float64",
    "points_done": "int64",
    "complete": "int8",
    "steps_total": "int64",
    "event_steps_total": "int64",
    "host": "S256",
    "backend": "S256",
    "history": f"S{HISTORY_BYTES}",
}

# Counts an adaptive sweep updates at the end of every session (in place, like
# SESSION_ATTRS): from ``rocksweep.compute.adaptive.stats_of`` of the ``computed`` flags.
ADAPTIVE_COUNT_ATTRS: dict[str, str] = {
    "points_computed": "int64",
    "points_filled": "int64",
    "points_audited": "int64",
    "audit_misses": "int64",
}
# The ``computed`` variable of adaptive sweeps: (dtype, fill, description), flag meanings.
COMPUTED_VARIABLE = ("int8", 0, "adaptive sweep: 0 filled (not computed; outcome from the "
                     "uniform cell around the point, other variables at their fill "
                     "values), 1 computed, 2 audit point that agreed with its fill, 3 "
                     "audit point that disagreed (region refined)")
COMPUTED_FLAGS = {0: "filled", 1: "computed", 2: "audit_agreed", 3: "audit_disagreed"}

# Variables whose values are codes (CF flag_values / flag_masks): no units.
FLAG_VARIABLES = ("outcome", "status", "computed")
# What h5py raises for I/O and damaged files (HDF5 errors surface as any of these).
_H5_ERRORS = (OSError, RuntimeError, ValueError, KeyError, TypeError, IndexError)


class StoreError(RocksweepError):
    """A result file that cannot be made, read or resumed; ``str()`` is one line."""


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


def _why(err: BaseException) -> str:
    """One short phrase for an OS or HDF5 error (from its errno where it has one)."""
    if isinstance(err, KeyError) and err.args:
        err = RuntimeError(str(err.args[0]))  # KeyError's str() adds quotes
    no = getattr(err, "errno", None)
    if not isinstance(no, int):
        m = re.search(r"errno = (\d+)", str(err))
        no = int(m.group(1)) if m else None
    if no:
        return _reason(OSError(no, os.strerror(no)))
    text = str(err).strip().splitlines()
    if not text:
        return type(err).__name__
    # HDF5: "Unable to ... (the reason)": the reason is what helps
    m = re.search(r"\(([^()]+)\)\s*$", text[0])
    return (m.group(1) if m else text[0])[:160]


def _mib(n: float) -> str:
    return f"{n / 2**20:.1f} MiB"


def versions() -> dict[str, str]:
    """Versions of rocksweep and the libraries that shape its results."""
    from importlib.metadata import PackageNotFoundError, version

    import h5py
    import numba

    try:
        rs = version("rocksweep")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        rs = "unknown"
    return {"rocksweep": rs, "numba": numba.__version__, "numpy": np.__version__,
            "h5py": h5py.__version__, "hdf5": h5py.version.hdf5_version,
            "python": platform.python_version()}


def resolved_scene(scene: Scene, overrides: tuple[str, ...] | list[str] = (),
                   adaptive: dict | None = None) -> dict:
    """What decides a sweep's results (plus its name): the basis of resume checks.
    adaptive: the resolved settings of an adaptive sweep (``adaptive.Options.resolved``),
    None for a sweep of every point (then no ``adaptive`` key)."""
    d = {
        "name": scene.name,
        "kind": scene.kind,
        "axes": {a.key: {"values": list(a.values), "swept": a.swept} for a in scene.axes},
        "numerics": scene.numerics.as_dict(),
        "energy": scene.energy,
        "overrides": list(overrides),
        # only when asked: files without contact outputs keep their resolved scene
        **({"contact": True} if scene.contact else {}),
        **({"check": True} if scene.check else {}),
        **({"record": record_attrs(scene.record)} if scene.record is not None else {}),
        **({"suite": suite_attrs(scene.suite)} if scene.suite is not None else {}),
    }
    if adaptive is not None:
        d["adaptive"] = dict(adaptive)
    return d


def _adaptive_words(a: dict) -> str:
    """Adaptive settings as the command-line options that give them."""
    return (f"--adaptive --axes {','.join(a.get('axes', []))} --coarse {a.get('coarse')} "
            f"--audit {a.get('audit')!r} --margin {a.get('margin')} --final-margin "
            f"{a.get('final_margin')} --seed {a.get('seed')} --threshold "
            f"{a.get('threshold')!r}")


def record_attrs(record) -> dict:
    """A record scene's record as the file states it (``record_*`` attributes): name,
    SHA-256 of the file's bytes, NPTS, DT [s], PGA [g], title and the path read."""
    return {"name": record.name, "sha256": record.sha256, "npts": int(record.npts),
            "dt": float(record.dt), "pga": float(record.pga), "title": record.title,
            "source": str(record.source)}


def suite_attrs(suite) -> dict:
    """A suite scene's records and scaling as the resolved scene states them: the stripe
    IM (None: a cloud), Sa's period [s], the cloud's factor, the stored Sa periods [s] and
    every record's file name, SHA-256 and the path read (a resume compares names and
    SHA-256s: the files' bytes, wherever they are)."""
    def num(v: float):
        return None if math.isnan(v) else float(v)

    return {"im": suite.im, "period": num(suite.period), "factor": num(suite.factor),
            "periods": list(suite.periods),
            "records": [{"name": n, "sha256": r.sha256, "source": str(r.source)}
                        for n, r in zip(suite.names, suite.records, strict=True)]}


def _suite_differences(ss: dict, sn: dict) -> list[str]:
    """One phrase per difference between two ``suite_attrs`` dicts (records by name)."""
    diffs = []
    for k in ("im", "period", "factor", "periods"):
        if ss.get(k) != sn.get(k):
            diffs.append(f"ground.scale {k}: file {ss.get(k)!r}, scene {sn.get(k)!r}"
                         if k != "periods" else
                         f"ground.periods: file {ss.get(k)!r}, scene {sn.get(k)!r}")
    new = {r.get("name"): r for r in sn.get("records") or []}
    for r in ss.get("records") or []:
        m = new.get(r.get("name"))
        if m is not None and m.get("sha256") != r.get("sha256"):
            diffs.append(f"ground.records: {r.get('name')} changed since the sweep (sha256 "
                         f"{str(r.get('sha256'))[:12]} in the file, {str(m.get('sha256'))[:12]}"
                         f" now, read from {m.get('source')})")
    return diffs


def _short(v) -> str:
    if isinstance(v, dict) and "values" in v:
        vals = v["values"]
        text = (repr(vals[0]) if not v["swept"] else
                f"[{', '.join(map(repr, vals))}]" if len(vals) <= 6 else
                f"{len(vals)} values {vals[0]!r}..{vals[-1]!r}")
        return text
    return repr(v)


# Axes a scene need not give, with the value they then have: the impact law's (eq. 1)
AXIS_DEFAULTS = {"impact.law": "vertical", "impact.e_factor": 1.0}


def scene_differences(stored: dict, new: dict) -> list[str]:
    """One phrase per difference between two ``resolved_scene`` dicts."""
    diffs = []
    outputs = ("energy", "contact", "check")  # absent: false
    for section in ("name", "kind", *outputs):  # --set overrides show in the axes
        a, b = stored.get(section), new.get(section)
        if section in outputs:
            a, b = str(bool(a)).lower(), str(bool(b)).lower()
        if a != b:
            key = f"outputs.{section}" if section in outputs else section
            diffs.append(f"{key}: file {a if section in outputs else _short(a)}, "
                         f"scene {b if section in outputs else _short(b)}")
    for key in dict.fromkeys([*stored.get("axes", {}), *new.get("axes", {})]):
        a, b = stored.get("axes", {}).get(key), new.get("axes", {}).get(key)
        if key in AXIS_DEFAULTS:  # a key not given is its default (files before it existed)
            a = a or {"values": [AXIS_DEFAULTS[key]], "swept": False}
            b = b or {"values": [AXIS_DEFAULTS[key]], "swept": False}
        if a != b:
            diffs.append(f"{key}: file {_short(a) if a else 'absent'}, "
                         f"scene {_short(b) if b else 'absent'}")
    rs, rn = stored.get("record") or {}, new.get("record") or {}
    if rs.get("sha256") != rn.get("sha256"):  # the record's bytes, wherever the file is
        diffs.append(f"ground.record: file {rs.get('name', 'absent')} (sha256 "
                     f"{str(rs.get('sha256'))[:12]}), scene {rn.get('name', 'absent')} "
                     f"(sha256 {str(rn.get('sha256'))[:12]})")
    if stored.get("suite") is not None or new.get("suite") is not None:
        if stored.get("suite") is None or new.get("suite") is None:
            diffs.append("ground.records: file " + ("a suite" if stored.get("suite") else
                                                    "no suite") + ", scene " +
                         ("a suite" if new.get("suite") else "no suite"))
        else:
            diffs += _suite_differences(stored["suite"], new["suite"])
    sn, nn = stored.get("numerics", {}), new.get("numerics", {})
    for key in dict.fromkeys([*sn, *nn]):
        if sn.get(key) != nn.get(key):
            diffs.append(f"numerics.{key}: file {sn.get(key)!r}, scene {nn.get(key)!r}")
    sa, na = stored.get("adaptive"), new.get("adaptive")
    if sa is not None and na is None:
        diffs.append(f"adaptive: file adaptive ({_adaptive_words(sa)}), this run not")
    elif sa is None and na is not None:
        diffs.append("adaptive: file of every point, this run adaptive")
    elif sa != na:
        for key in dict.fromkeys([*sa, *na]):
            if sa.get(key) != na.get(key):
                diffs.append(f"adaptive.{key}: file {sa.get(key)!r}, this run "
                             f"{na.get(key)!r}")
    return diffs


def flat_slabs(shape: tuple[int, ...], start: int, stop: int) -> list[tuple[tuple, int, int]]:
    """Split the flat (C-order) range [start, stop) of an array of ``shape`` into boxes.

    Returns ``(index, a, b)``: ``array[index]`` holds the flat elements a..b-1 (in order).
    At most 2 * len(shape) - 1 boxes.
    """
    if start >= stop:
        return []
    if len(shape) == 0:
        return [((), 0, 1)]
    if len(shape) == 1:
        return [((slice(start, stop),), start, stop)]
    inner = math.prod(shape[1:])
    i0, r0 = divmod(start, inner)
    if i0 == (stop - 1) // inner:  # within one sub-array
        return [((slice(i0, i0 + 1), *idx), i0 * inner + a, i0 * inner + b)
                for idx, a, b in flat_slabs(shape[1:], r0, stop - i0 * inner)]
    out = []
    if r0:
        out += flat_slabs(shape, start, (i0 + 1) * inner)
        i0 += 1
    i1, r1 = divmod(stop, inner)
    if i1 > i0:
        out.append(((slice(i0, i1), *(slice(None),) * (len(shape) - 1)),
                    i0 * inner, i1 * inner))
    if r1:
        out += flat_slabs(shape, i1 * inner, stop)
    return out


def file_bytes(scene: Scene, adaptive: bool = False) -> int:
    """Bytes the datasets of a result file of ``scene`` take (all allocated when the
    file is made): every variable's dtype size x grid points, plus the coordinates;
    adaptive: with the ``computed`` flags."""
    grid = Grid(scene)
    per_point = sum(np.dtype(dt).itemsize for dt, _, _ in variables(scene).values())
    per_point += adaptive
    coords = sum(16 * len(a.values) for a in scene.axes)
    su = scene.suite
    if su is not None:  # the per-record variables (sha256: 64 characters) and factors
        R = len(su.records)
        coords += R * (8 * (5 + len(su.periods)) + 96) + 8 * R * max(1, len(su.levels))
    return per_point * grid.size + coords


def _reserve(path: Path, nbytes: int) -> None:
    """Allocate ``nbytes`` of disk space to the file at ``path`` (``posix_fallocate``):
    writes within them cannot fail for want of space. OSError(ENOSPC) if there is no
    room; file systems without the call are left as they are."""
    fd = os.open(path, os.O_WRONLY | getattr(os, "O_CLOEXEC", 0))
    try:
        os.posix_fallocate(fd, 0, nbytes)
    except OSError as err:
        if err.errno not in (errno.EOPNOTSUPP, errno.EINVAL, errno.ENOSYS):
            raise
    finally:
        os.close(fd)


def _reserve_bytes(scene: Scene, nbytes: int) -> int:
    """Bytes a new result file of ``scene`` reserves: its datasets (``nbytes``), HDF5's
    metadata, the scene text and the record (its file and samples, ``_store_record``)."""
    rec = (8 * int(scene.record.npts) + len(scene.record.data) + (16 << 10)
           if scene.record is not None else 0)
    return nbytes + METADATA_RESERVE + 4 * len(scene.text.encode()) + rec


def _space_needed(reserve: int) -> int:
    """Free space required to make a file that reserves ``reserve`` bytes: those and a
    margin that scales with them (``SPACE_SHARE``, at least ``SPACE_MARGIN``)."""
    return reserve + max(SPACE_MARGIN, int(reserve * SPACE_SHARE))


_PARTIAL = re.compile(r"\.(?:(\d+)-)?[a-z0-9_]{8}\.partial")
STALE_AGE = 60.0  # [s] a partial file without a writer's pid is stale when this old


def partial_prefix(path: Path) -> str:
    """The prefix of the temporary names a new result file at ``path`` is made under: the
    writer's pid is part of the name (``.out.h5.1234-abcd1234.partial``)."""
    return f".{path.name[:40]}.{os.getpid()}-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, another user's
        return True
    return True


def clean_stale_partials(path: Path) -> list[tuple[str, int]]:
    """Remove the temporary files of earlier attempts to make ``path`` that no live writer
    owns (a sweep killed while the file was made leaves one of the reserved size): its
    writer's process is gone (or, for a name without a pid, it is older than STALE_AGE)
    and no process holds its lock. Returns (name, bytes) of each file removed."""
    import fcntl

    parent = path.parent if str(path.parent) else Path(".")
    head = f".{path.name[:40]}"
    removed = []
    try:
        names = [n for n in os.listdir(parent) if n.startswith(head) and n.endswith(".partial")]
    except OSError:
        return []
    for name in names:
        m = _PARTIAL.fullmatch(name[len(head):])
        if m is None:
            continue
        full = parent / name
        try:
            st = os.lstat(full)
        except OSError:
            continue
        if not stat.S_ISREG(st.st_mode):
            continue
        if m.group(1) is not None:
            if int(m.group(1)) == os.getpid() or _alive(int(m.group(1))):
                continue
        elif time.time() - st.st_mtime < STALE_AGE:
            continue
        try:
            fd = os.open(full, os.O_RDONLY | getattr(os, "O_CLOEXEC", 0))
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # HDF5's writer lock
            os.unlink(full)
            removed.append((name, st.st_size))
        except OSError:  # locked: a live writer (or no flock here: leave it)
            pass
        finally:
            os.close(fd)
    return removed


def _check_space(path: Path, need: int, what: str) -> None:
    """Refuse (StoreError) when the file system of ``path`` has less than ``need`` bytes
    free."""
    parent = path.parent if str(path.parent) else Path(".")
    try:
        free = shutil.disk_usage(parent).free
    except OSError:
        return  # cannot tell: the writes themselves will say
    if free < need:
        raise StoreError(f"{shown(path)}: not enough free space for {what}: needs about "
                         f"{_mib(need)} ({need} bytes), {_mib(free)} free in {parent}")


# ---------------------------------------------------------------------------------------
# Validation (every reader and resume): what the code relies on, one line per problem
# ---------------------------------------------------------------------------------------

@dataclass
class _Layout:
    """What a valid file holds: its resolved scene, swept dims and their sizes."""

    scene: dict
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    names: list[str]


def _damaged(path: Path, what: str) -> StoreError:
    return StoreError(f"{shown(path)}: damaged rocksweep result ({what})")


def _cut(v, n: int = 40) -> str:
    text = repr(v)
    return text if len(text) <= n else text[: n - 3] + "..."


def _attr_str(f: h5py.File, key: str) -> str:
    v = f.attrs[key]
    if isinstance(v, bytes | np.bytes_):
        return bytes(v).decode("utf-8", "replace")
    if not isinstance(v, str):
        raise TypeError(f"attribute {key} is {_cut(_plain(v))}, not text")
    return v


def _check_scene(stored, path: Path) -> None:
    """The resolved scene dict as ``resolved_scene`` makes it, or StoreError."""
    def bad(what: str) -> StoreError:
        return _damaged(path, f"attribute scene_resolved: {what}")

    if not isinstance(stored, dict):
        raise bad(f"{_cut(stored)} is not a JSON object")
    for key, typ in (("name", str), ("kind", str), ("energy", bool), ("axes", dict),
                     ("numerics", dict)):
        if not isinstance(stored.get(key), typ):
            raise bad(f"'{key}' is {_cut(stored.get(key))}, not a {typ.__name__}")
    if not stored["axes"]:
        raise bad("no axes")
    for key, ax in stored["axes"].items():
        if not (isinstance(key, str) and "." in key and isinstance(ax, dict)
                and isinstance(ax.get("swept"), bool) and isinstance(ax.get("values"), list)
                and ax["values"]):
            raise bad(f"axis {_cut(key)} is {_cut(ax)}")
        words = key in fields.WORD_KEYS
        kinds = (str,) if words else (int, float)
        if not all(isinstance(v, kinds) and not isinstance(v, bool) for v in ax["values"]):
            raise bad(f"axis {key} has values {_cut(ax['values'])}")
        if not ax["swept"] and len(ax["values"]) != 1:
            raise bad(f"unswept axis {key} has {len(ax['values'])} values")
    if "adaptive" in stored:
        a = stored["adaptive"]
        from rocksweep.compute.adaptive import RESOLVED_KEYS

        ok = (isinstance(a, dict) and set(a) == set(RESOLVED_KEYS)
              and isinstance(a["axes"], list) and len(a["axes"]) == 2
              and all(isinstance(v, str) for v in a["axes"])
              and all(isinstance(a[k], int) and not isinstance(a[k], bool) and a[k] >= 0
                      for k in ("coarse", "margin", "final_margin", "seed"))
              and all(isinstance(a[k], int | float) and not isinstance(a[k], bool)
                      and 0 <= a[k] <= 1 for k in ("audit", "threshold")))
        if not ok:
            raise bad(f"'adaptive' is {_cut(a)}")


def _json_attr(f: h5py.File, key: str, path: Path, typ: type):
    try:
        text = _attr_str(f, key)
    except KeyError:
        raise _damaged(path, f"attribute {key} missing") from None
    except TypeError as err:
        raise _damaged(path, str(err)) from None
    try:
        value = json.loads(text)
    except ValueError:
        raise _damaged(path, f"attribute {key} is not JSON: {_cut(text)}") from None
    if not isinstance(value, typ):
        raise _damaged(path, f"attribute {key} is {_cut(text)}, not a JSON "
                       f"{'object' if typ is dict else 'list'}")
    return value


def _looks_like_ours(f: h5py.File, fmt) -> bool:
    """Whether a file without a valid rocksweep_format attribute still shows the marks of a
    rocksweep result (then it is damaged, not foreign)."""
    if isinstance(fmt, str) and fmt.startswith("rocksweep"):
        return True
    try:
        a = f.attrs
        return "scene_resolved" in a or ("format_version" in a and "outcome" in f)
    except _H5_ERRORS:
        return False


def _layout(f: h5py.File, path: Path) -> _Layout:
    """Validate the format, the resolved scene, the coordinates and the variables."""
    import h5py

    try:  # h5py's attrs.get hides damage as "missing"
        fmt = f.attrs["rocksweep_format"] if "rocksweep_format" in f.attrs else None
    except _H5_ERRORS as err:
        raise StoreError(f"{shown(path)}: damaged HDF5 file, its attributes cannot be read "
                         f"({_why(err)})") from None
    if isinstance(fmt, bytes | np.bytes_):
        fmt = bytes(fmt).decode("utf-8", "replace")
    if fmt != FORMAT:
        if _looks_like_ours(f, fmt):  # a damaged result is not a foreign file
            raise _damaged(path, "attribute rocksweep_format " + (
                "missing" if fmt is None else f"is {_cut(_plain(fmt))}"))
        raise StoreError(f"{shown(path)}: an HDF5 file, but not a rocksweep sweep result "
                         "(no rocksweep_format attribute)")
    try:
        ver = int(f.attrs.get("format_version", -1))
    except (TypeError, ValueError):
        raise _damaged(path, f"format_version = {_cut(_plain(f.attrs['format_version']))}"
                       ) from None
    if ver > FORMAT_VERSION:
        raise StoreError(f"{shown(path)}: written in result format {ver} by a newer "
                         f"rocksweep; this version reads formats 1 to {FORMAT_VERSION}; "
                         "upgrade rocksweep")
    if ver < 1:
        raise _damaged(path, f"format_version = {ver}")
    stored = _json_attr(f, "scene_resolved", path, object)
    _check_scene(stored, path)
    swept = {k.split(".", 1)[1]: v["values"] for k, v in stored["axes"].items() if v["swept"]}
    dims = tuple(swept)
    shape = tuple(len(v) for v in swept.values())
    for d, values in swept.items():
        ds = f.get(d)
        if not isinstance(ds, h5py.Dataset):
            raise _damaged(path, f"coordinate '{d}' missing")
        if ds.shape != (len(values),):
            raise _damaged(path, f"coordinate '{d}' has shape {ds.shape}, the scene "
                           f"{len(values)} values")
        data = ds[()]
        if d in fields.WORD_AXES:
            ok = [_plain(v) for v in data] == values
        else:
            ok = data.dtype.kind == "f" and np.array_equal(data, np.asarray(values, float))
        if not ok:
            raise _damaged(path, f"coordinate '{d}' holds {_cut(data.tolist())}, the scene "
                           f"{_cut(values)}")
    names = ["outcome", *(n for n in variables_for(stored) if n != "outcome")]
    specs = variables_for(stored)
    for name in names:
        ds = f.get(name)
        if not isinstance(ds, h5py.Dataset):
            raise _damaged(path, f"variable '{name}' missing")
        if ds.shape != shape:
            raise _damaged(path, f"variable '{name}' has shape {ds.shape}, the grid {shape}")
        if ds.dtype != np.dtype(specs[name][0]):
            raise _damaged(path, f"variable '{name}' has dtype {ds.dtype}, expected "
                           f"{specs[name][0]}")
    return _Layout(stored, dims, shape, names)


def _check_format(f: h5py.File, path: Path) -> None:
    """Raise StoreError unless ``f`` is a valid rocksweep result (see ``_layout``)."""
    _layout(f, path)


def variables_for(stored: dict) -> dict:
    """The per-point variables of a file from its resolved scene (``computed`` in the
    files of adaptive sweeps)."""

    return {**fields.variables(bool(stored.get("energy")), bool(stored.get("contact")),
                               bool(stored.get("check"))),
            **({"computed": COMPUTED_VARIABLE} if stored.get("adaptive") else {})}


def _is_hdf5(path: Path) -> bool:
    import h5py
    try:
        return bool(h5py.is_hdf5(path))
    except _H5_ERRORS:
        return False


def _open(path: Path, mode: str) -> h5py.File:
    """Open an existing file; foreign, damaged, locked or unreadable files give a one-line
    StoreError. Writers (mode "r+") take HDF5's exclusive lock; readers take none."""
    import h5py
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise StoreError(f"{shown(path)}: no such file") from None
    except OSError as err:
        raise StoreError(f"{shown(path)}: cannot be read ({_why(err)})") from None
    if os.path.isdir(path):
        raise StoreError(f"{shown(path)}: is a directory, not a sweep result")
    if not os.path.isfile(path):
        raise StoreError(f"{shown(path)}: not a regular file (expected a rocksweep sweep "
                         "result)")
    if st.st_size == 0:
        raise StoreError(f"{shown(path)}: empty file (expected a rocksweep sweep result)")
    try:
        # readers do not lock: `info` and `plot` work while a sweep writes (datasets are
        # allocated up front, so a running sweep changes raw data only)
        return h5py.File(path, mode, locking=(mode != "r"))
    except _H5_ERRORS as err:
        no = getattr(err, "errno", None)
        if isinstance(err, BlockingIOError) or "unable to lock" in str(err).lower():
            raise StoreError(f"{shown(path)}: open for writing by another process (a sweep "
                             "still running?)") from None
        if no in (errno.EACCES, errno.EPERM, errno.EROFS):
            doing = "written" if mode != "r" else "read"
            raise StoreError(f"{shown(path)}: cannot be {doing} ({_why(err)})") from None
        if not _is_hdf5(path):
            raise StoreError(f"{shown(path)}: not an HDF5 file (expected a rocksweep sweep "
                             "result)") from None
        raise StoreError(f"{shown(path)}: damaged or truncated HDF5 file, cannot be opened "
                         "(rerun the sweep with --overwrite)") from None


def _close_quietly(f) -> None:
    """Close after an error: a second error must not hide the first."""
    with contextlib.suppress(Exception):
        f.close()


def _fixed(text: str, dtype: str) -> np.ndarray:
    """``text`` as a fixed-length ASCII string of ``dtype`` (cut to fit)."""
    n = np.dtype(dtype).itemsize
    return np.array(text.encode("ascii", "replace")[:n], dtype=dtype)


def _put(f: h5py.File, name: str, value) -> None:
    """Overwrite a session attribute in place (its fixed type and size)."""
    dtype = SESSION_ATTRS.get(name) or ADAPTIVE_COUNT_ATTRS[name]
    arr = _fixed(value, dtype) if dtype.startswith("S") else np.array(value, dtype=dtype)
    f.attrs.modify(name, arr)


def _in_place(f: h5py.File) -> bool:
    """Whether every session attribute exists with its fixed type (format 2)."""
    a = f.attrs
    for name, dtype in SESSION_ATTRS.items():
        try:
            if name not in a or a.get_id(name).dtype != np.dtype(dtype):
                return False
        except _H5_ERRORS:
            return False
    return True


def _upgrade_session_attrs(f: h5py.File) -> None:
    """Give a format-1 file's session attributes their fixed types (needs a little space,
    checked before; only the first resume of such a file does this)."""
    a = f.attrs
    for name, dtype in SESSION_ATTRS.items():
        if name in a and a.get_id(name).dtype == np.dtype(dtype):
            continue
        old = _plain(a[name]) if name in a else None
        if name == "complete":
            old = int(bool(old))
        elif old is None or (dtype.startswith("S") and not isinstance(old, str)):
            old = "" if dtype.startswith("S") else 0
        if name in a:
            del a[name]
        a.create(name, _fixed(old, dtype) if dtype.startswith("S")
                 else np.array(old, dtype=dtype))


def _umask_mode() -> int:
    """Mode of a new file under this process's umask (mkstemp makes files 0600)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    return 0o644


def _lock_existing(path: Path) -> int:
    """Open the file at ``path`` and take the exclusive lock a writer holds (HDF5 locks
    with flock); returns the descriptor. StoreError if a sweep is writing it."""
    import fcntl

    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_CLOEXEC", 0))
    except OSError as err:
        raise StoreError(f"{shown(path)}: cannot be replaced ({_why(err)})") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise StoreError(f"{shown(path)}: open for writing by another process (a sweep "
                         "still running?); not overwritten") from None
    except OSError:
        pass  # no flock on this file system: HDF5 cannot lock there either
    return fd


def _publish(tmp: Path, path: Path, old_fd: int | None) -> None:
    """Rename the finished temporary file to ``path``: over the file locked by ``old_fd``,
    or, without one, only if nothing is at ``path`` (another process may have made it
    since it was checked)."""
    os.chmod(tmp, _umask_mode())
    if old_fd is not None:
        try:
            same = os.path.samestat(os.fstat(old_fd), os.stat(path))
        except OSError:
            same = False
        if not same:
            raise StoreError(f"{shown(path)}: replaced by another process meanwhile; not "
                             "overwritten")
        os.replace(tmp, path)
        return
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise StoreError(f"{shown(path)}: made by another process meanwhile (a sweep "
                         "started at the same time?); not overwritten") from None
    except OSError as err:
        if err.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV,
                             errno.EMLINK):
            raise
        if path.exists():  # no hard links here: check, then rename
            raise StoreError(f"{shown(path)}: made by another process meanwhile; not "
                             "overwritten") from None
        os.replace(tmp, path)
        return
    with contextlib.suppress(OSError):
        os.unlink(tmp)


class SweepFile:
    """A result file open for writing (by the parent process only; it holds the file's
    exclusive lock until ``close``)."""

    def __init__(self, path: Path, f: h5py.File, scene: Scene,
                 backend: str | None = None, adaptive: dict | None = None) -> None:
        self.path = path
        self.f = f
        self.grid = Grid(scene)
        self.names = list(variables(scene))
        self.adaptive = adaptive  # resolved adaptive settings, None: every point
        self.session_start = _now()
        self.backend = backend or "unspecified"
        self._history = ""  # the file's history before this session
        self._session_line = ""
        self._broken: StoreError | None = None  # the error that closed the file

    def _fail(self, err: StoreError) -> StoreError:
        """Close the file after a failed write (nothing more is written) and remember why:
        later calls repeat this error, not a second one about a closed file."""
        _close_quietly(self.f)
        self._broken = err
        return err

    # -- making and reopening -------------------------------------------------------------
    @classmethod
    def create(cls, path: str | Path, scene: Scene, overrides: tuple[str, ...] = (),
               overwrite: bool = False, *, backend: str | None = None,
               adaptive: dict | None = None,
               log: Callable[[str], None] | None = None) -> SweepFile:
        """Make a new result file (all points not computed), atomically, and open it.
        adaptive: resolved settings of an adaptive sweep (``adaptive.Options.resolved``):
        the file gets the ``computed`` flags and the settings' attributes.

        Refused (StoreError) before anything is written: an existing path without
        ``overwrite``, a directory, device or FIFO, a missing directory, a grid larger
        than the free space, a file another process is writing. ``backend``: how the
        points are computed (e.g. "threads x 2"), recorded with the host in the file.
        """
        import h5py
        path = Path(path)
        try:
            check_output(path, overwrite=True)  # devices, directories, missing dirs
        except OutputError as err:
            raise StoreError(str(err)) from None
        existed = os.path.lexists(path)
        if existed and not overwrite:
            raise StoreError(f"{shown(path)}: already exists; use --resume to finish it or "
                             "--overwrite to replace it")
        grid = Grid(scene)
        nbytes = file_bytes(scene, adaptive is not None)
        reserve = _reserve_bytes(scene, nbytes)
        removed = clean_stale_partials(path)  # a killed attempt's reserved space back
        if removed and log is not None:
            log(f"removed {len(removed)} stale temporary file{'s' * (len(removed) > 1)} of "
                f"{shown(path)} left by a sweep killed while making it ({removed[0][0]}"
                f"{', ...' if len(removed) > 1 else ''}; "
                f"{_mib(sum(n for _, n in removed))})")
        _check_space(path, _space_needed(reserve), f"a grid of {grid.size} points")
        old_fd = _lock_existing(path) if existed else None
        tmp: Path | None = None
        f = None
        try:
            parent = path.parent if str(path.parent) else Path(".")
            fd, name = tempfile.mkstemp(prefix=partial_prefix(path), suffix=".partial",
                                        dir=parent)
            os.close(fd)
            tmp = Path(name)
            _reserve(tmp, reserve)  # room for all of it, or ENOSPC before HDF5 writes
            g = h5py.File(tmp, "w", track_order=True)  # truncates: reserve again
            try:
                _reserve(tmp, reserve)
                _initialise(g, scene, overrides, adaptive)
                g.flush()
                size = g.id.get_filesize()  # HDF5's end of allocation (eof is stale)
            except BaseException:
                _close_quietly(g)
                raise
            g.close()
            if 0 < size < reserve:
                os.truncate(tmp, size)  # give back what the metadata did not use
            f = h5py.File(tmp, "r+", locking=True)  # locked before anyone can see it
            self = cls(path, f, scene, backend, adaptive)
            self._start_session()  # before the file has its name: failing leaves nothing
            _publish(tmp, path, old_fd)
            tmp = None
            return self
        except StoreError:
            if f is not None:
                _close_quietly(f)
            raise
        except _H5_ERRORS as err:
            if f is not None:
                _close_quietly(f)
            raise StoreError(f"{shown(path)}: cannot write ({_why(err)}); nothing written"
                             ) from None
        finally:
            if tmp is not None:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            if old_fd is not None:
                os.close(old_fd)

    @classmethod
    def in_memory(cls, scene: Scene, overrides: tuple[str, ...] = (), *,
                  backend: str | None = None, adaptive: dict | None = None) -> SweepFile:
        """The same result, held in memory (HDF5's core driver, no backing store): the
        sink of ``rocksweep.run`` without ``output``. Nothing touches a disk; ``image``
        gives the file's bytes, exactly what ``create`` would have written."""
        import h5py

        name = f"rocksweep-memory-{os.getpid()}-{id(scene)}.h5"
        f = h5py.File(name, "w", driver="core", backing_store=False, track_order=True)
        try:
            _initialise(f, scene, overrides, adaptive)
            self = cls(Path("memory"), f, scene, backend, adaptive)
            self._start_session()
        except BaseException:
            _close_quietly(f)
            raise
        return self

    def image(self) -> bytes:
        """The result file's bytes as it stands (flushed)."""
        self.f.flush()
        return self.f.id.get_file_image()

    @classmethod
    def resume(cls, path: str | Path, scene: Scene, overrides: tuple[str, ...] = (),
               *, backend: str | None = None, adaptive: dict | None = None) -> SweepFile:
        """Reopen a result file of the same scene (and the same adaptive settings, None
        for a sweep of every point) to finish it (its points are kept whatever happens:
        the session's attributes are updated in place)."""
        path = Path(path)
        f = _open(path, "r")
        try:
            stored = _layout(f, path).scene
            _checked_attrs(f, path)  # what readers need, before any point is computed
            outcome = f["outcome"][()]
            _check_outcome(outcome, path)
            if stored.get("adaptive"):
                _check_computed(f["computed"][()], outcome, path)
        except _H5_ERRORS as err:
            raise _damaged(path, _why(err)) from None
        finally:
            _close_quietly(f)
        diffs = scene_differences(stored, resolved_scene(scene, overrides, adaptive))
        if diffs:
            raise StoreError(f"{shown(path)}: cannot resume, the scene differs from the "
                             "file's: " + "; ".join(diffs) + " (use --overwrite to start "
                             "again)")
        f = _open(path, "r+")
        try:
            _layout(f, path)  # the file locked now (another may have replaced the first)
            self = cls(path, f, scene, backend, adaptive)
            self._start_session()
        except BaseException as err:
            _close_quietly(f)
            if isinstance(err, _H5_ERRORS) and not isinstance(err, RocksweepError):
                raise StoreError(f"{shown(path)}: cannot update its attributes "
                                 f"({_why(err)}); its points are kept") from None
            raise
        return self

    def _start_session(self) -> None:
        """Count the session and record its start, host and backend (in place). Raises
        h5py's errors (the callers say what they mean for the file)."""
        f = self.f
        if not _in_place(f):  # a format-1 file: its attributes change type once
            _check_space(self.path, UPDATE_MARGIN, "updating its attributes")
            _upgrade_session_attrs(f)
            f.flush()
        n = int(f.attrs["sessions"]) + 1
        self._history = _plain(f.attrs["history"])
        host = platform.node() or "unknown"
        self._session_line = (f"{self.session_start} session {n}: rocksweep "
                              f"{versions()['rocksweep']} on host {host}, backend "
                              f"{self.backend}")
        _put(f, "sessions", n)
        _put(f, "last_started", self.session_start)
        _put(f, "host", host)
        _put(f, "backend", self.backend)
        _put(f, "history", _history(self._history, self._session_line))
        f.flush()

    # -- state ------------------------------------------------------------------------
    def done(self) -> np.ndarray:
        """bool[size]: points already computed (flat order)."""
        return self.f["outcome"][()].reshape(-1) != L.OUTCOME_NOT_RUN

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """(outcome, computed): int8[size] each, flat order, of an adaptive file."""
        return (self.f["outcome"][()].reshape(-1).copy(),
                self.f["computed"][()].reshape(-1).copy())

    def _write_at(self, name: str, coords: np.ndarray, values: np.ndarray) -> None:
        """Write values[n] at the grid points coords (uint64[n, rank]): one HDF5 point
        selection, so scattered points cost one call."""
        import h5py

        ds = self.f[name]
        fspace = ds.id.get_space()
        fspace.select_elements(coords)
        mspace = h5py.h5s.create_simple((len(coords),))
        ds.id.write(mspace, fspace, np.ascontiguousarray(values, dtype=ds.dtype))

    def write_points(self, flat: np.ndarray, arrays: dict[str, np.ndarray],
                     computed: np.ndarray) -> None:
        """Write the results of scattered points of an adaptive sweep: flat: int64[n]
        grid indices; arrays: variable -> array[n]; computed: int8[n] flags. Order:
        the variables, ``outcome``, then ``computed``, each flushed: a point is computed
        in a killed file only when all of it is there (a point with an outcome and flag
        0 is recomputed on resume, to the same values).

        A failed write is a StoreError, as for ``write``."""
        if self._broken:
            raise self._broken
        flat = np.asarray(flat, np.int64)
        if flat.size == 0:
            return
        coords = np.stack(np.unravel_index(flat, self.grid.shape), axis=1).astype(np.uint64)
        try:
            for name in self.names:
                if name != "outcome":
                    self._write_at(name, coords, arrays[name])
            self.f.flush()
            self._write_at("outcome", coords, arrays["outcome"])
            self.f.flush()
            self._write_at("computed", coords, computed)
            self.f.flush()
        except _H5_ERRORS as err:
            raise self._fail(StoreError(
                f"{shown(self.path)}: cannot write results ({_why(err)}); the points "
                "written before are kept, finish with --resume")) from None

    def write_filled(self, outcome: np.ndarray, counts: dict[str, int]) -> None:
        """The end of an adaptive sweep: ``outcome`` (int8[size], flat: computed classes
        and fills) written over the whole variable, and the ``ADAPTIVE_COUNT_ATTRS``
        (in place)."""
        if self._broken:
            raise self._broken
        try:
            self.f["outcome"][...] = np.asarray(outcome, np.int8).reshape(self.grid.shape)
            self.f.flush()
            self.put_counts(counts)
        except _H5_ERRORS as err:
            raise self._fail(StoreError(
                f"{shown(self.path)}: cannot write the filled outcomes ({_why(err)}); "
                "finish with --resume")) from None

    def put_counts(self, counts: dict[str, int]) -> None:
        """Update the adaptive counts (``ADAPTIVE_COUNT_ATTRS``) in place."""
        for k, v in counts.items():
            _put(self.f, k, int(v))
        self.f.flush()

    def write(self, res: ChunkResult) -> None:
        """Write one chunk's results; ``outcome`` last, each step flushed to the OS.

        A failed write (StoreError) leaves the chunk's points "not computed" and every
        point written before intact; the file is closed (finish it with --resume).
        """
        if self._broken:
            raise self._broken
        boxes = flat_slabs(self.grid.shape, res.start, res.stop)
        try:
            for name in [*(n for n in self.names if n != "outcome"), "outcome"]:
                if name == "outcome":
                    self.f.flush()
                ds = self.f[name]
                arr = res.arrays[name]
                for index, a, b in boxes:
                    box = tuple(len(range(*s.indices(n)))
                                for s, n in zip(index, ds.shape, strict=True))
                    ds[index] = arr[a - res.start:b - res.start].reshape(box)
            self.f.flush()
        except _H5_ERRORS as err:
            raise self._fail(StoreError(
                f"{shown(self.path)}: cannot write results ({_why(err)}); the points "
                "written before are kept, finish with --resume")) from None

    def finish(self, wall_seconds: float, cpu_seconds: float, *,
               backend: str | None = None) -> dict:
        """Record this session's wall time [s], the workers' CPU time on its points [s]
        and the file's totals (in place); returns the attributes set (plain Python
        values; ``complete`` a bool)."""
        if self._broken:
            raise self._broken
        f = self.f
        try:
            done = self.done()
            a = f.attrs
            attrs = {
                "wall_time": float(a.get("wall_time", 0.0)) + wall_seconds,
                "cpu_time": float(a.get("cpu_time", 0.0)) + cpu_seconds,
                "points_done": int(done.sum()),
                "complete": bool(done.all()),
                "steps_total": int(f["steps"][()].sum()),
                "event_steps_total": int(f["event_steps"][()].sum()),
                "last_finished": _now(),
            }
            if done.all() and not _plain(a["finished"]):
                attrs["finished"] = attrs["last_finished"]
            if backend:
                self.backend = attrs["backend"] = backend
                self._session_line = re.sub(r"backend .*$", f"backend {backend}",
                                            self._session_line)
            line = (f"{self._session_line}; finished {attrs['last_finished']}, "
                    f"{attrs['points_done']} of {done.size} points done")
            attrs["history"] = _history(self._history, line)
            for k, v in attrs.items():
                _put(f, k, int(v) if k == "complete" else v)
            f.flush()
        except _H5_ERRORS as err:
            raise self._fail(StoreError(
                f"{shown(self.path)}: cannot record the session's totals ({_why(err)}); "
                "its points are kept")) from None
        return attrs

    def close(self) -> None:
        if self._broken:
            return  # closed when it broke
        try:
            self.f.close()
        except _H5_ERRORS as err:
            raise StoreError(f"{shown(self.path)}: cannot close ({_why(err)})") from None

    def __enter__(self) -> SweepFile:
        return self

    def __exit__(self, *exc) -> None:
        if exc[0] is None:
            self.close()
        else:
            _close_quietly(self.f)


def _history(before: str, line: str) -> str:
    """``before`` plus ``line``, the oldest lines dropped to fit HISTORY_BYTES."""
    lines = [ln for ln in before.splitlines() if ln] + [line]
    while len(lines) > 1 and len("\n".join(lines).encode()) > HISTORY_BYTES:
        lines.pop(0)
    return "\n".join(lines)


def _initialise(f: h5py.File, scene: Scene, overrides: tuple[str, ...],
                adaptive: dict | None = None) -> None:
    import h5py
    grid = Grid(scene)
    vers = versions()
    a = f.attrs
    a["Conventions"] = CONVENTIONS
    a["title"] = scene.name
    a["source"] = f"rocksweep {vers['rocksweep']} (rocksweep sweep)"
    a["comment"] = ("Stability diagram of a flexible rocking oscillator (Zhu, Chatzis & "
                    "Acikgoz). outcome -1 marks points not computed. complete and energy "
                    "are flags: int8 1 true, 0 false. Times are p*t and all variables "
                    "are dimensionless (units 1; rocksweep_units names the scale).")
    a["rocksweep_format"] = FORMAT
    a["format_version"] = FORMAT_VERSION
    a["scene"] = scene.text
    a["scene_kind"] = scene.kind
    a["scene_resolved"] = json.dumps(resolved_scene(scene, overrides, adaptive))
    a["overrides"] = json.dumps(list(overrides))
    n = scene.numerics
    a["numerics"] = json.dumps(n.as_dict())
    a["accuracy"] = n.describe()
    a["steps_per_period"] = n.steps_per_period
    a["event_tol"] = n.event_tol
    a["horizon"] = n.horizon
    a["energy"] = np.int8(bool(scene.energy))
    if scene.record is not None:  # the record: name, SHA-256, NPTS, DT [s], PGA [g]
        for k, v in record_attrs(scene.record).items():
            a[f"record_{k}"] = v
        _store_record(f, scene.record)
    if scene.suite is not None:  # the stripes' IM ("none": a cloud) and Sa's period [s]
        a["scale_im"] = scene.suite.im or "none"
        a["scale_period"] = float(scene.suite.period)
    for k, v in vers.items():
        a[f"{k}_version"] = v
    a["started"] = _now()
    a["points_total"] = np.int64(grid.size)
    # fixed-size attributes, updated in place by every session
    zeros = {"S": "", "i": 0, "f": 0.0}
    for name, dtype in SESSION_ATTRS.items():
        kind = np.dtype(dtype).kind
        a.create(name, _fixed("", dtype) if kind == "S" else np.array(zeros[kind], dtype))
    if adaptive is not None:
        a["adaptive"] = np.int8(1)
        a["adaptive_axes"] = " ".join(adaptive["axes"])
        for k in ("coarse", "margin", "final_margin", "seed"):
            a[f"adaptive_{k}"] = np.int64(adaptive[k])
        for k in ("audit", "threshold"):
            a[f"adaptive_{k}"] = np.float64(adaptive[k])
        for name, dtype in ADAPTIVE_COUNT_ATTRS.items():
            a.create(name, np.array(0, dtype))
        a["comment"] = (str(a["comment"]) + " Adaptive sweep: computed flags each point "
                        "(0 filled: outcome from the uniform cell around it, the other "
                        "variables at their fill values; 1 computed; 2/3 audit points that "
                        "agreed/disagreed with their fill).")

    scales = []
    for axis in scene.swept:
        data = (np.array(axis.values, dtype=h5py.string_dtype())
                if axis.name in fields.WORD_AXES else np.asarray(axis.values, float))
        ds = f.create_dataset(axis.name, data=data)
        ds.make_scale(axis.name)
        _coord_attrs(ds, axis, scene.kind)
        scales.append(ds)
    scalars = []
    for axis in scene.axes:
        if axis.swept:
            continue
        v = axis.values[0]
        ds = f.create_dataset(axis.name, data=(np.array(v, dtype=h5py.string_dtype())
                                               if axis.name in fields.WORD_AXES
                                               else float(v)))
        _coord_attrs(ds, axis, scene.kind)
        scalars.append(axis.name)

    specs = dict(variables(scene))
    if adaptive is not None:
        specs["computed"] = COMPUTED_VARIABLE
    for name, (dtype, fill, text) in specs.items():
        dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
        dcpl.set_alloc_time(h5py.h5d.ALLOC_TIME_EARLY)  # no metadata changes later
        ds = f.create_dataset(name, shape=grid.shape, dtype=dtype, fillvalue=fill,
                              dcpl=dcpl, fill_time="alloc")
        f_ = fields.BY_NAME.get(name)
        meta = (fields.field_attrs(f_, scene.kind) if f_ is not None
                else {"long_name": "computed flag", "description": text})
        if name in FLAG_VARIABLES:
            meta.pop("rocksweep_units", None)
        else:
            ds.attrs["units"] = "1"
        for k, v in meta.items():
            ds.attrs[k] = v
        if name == "outcome":  # CF-style flag attributes, for xarray users
            ds.attrs["flag_values"] = np.array(list(OUTCOME_WORDS), np.int8)
            ds.attrs["flag_meanings"] = " ".join(OUTCOME_WORDS.values())
        elif name == "computed":
            ds.attrs["flag_values"] = np.array(list(COMPUTED_FLAGS), np.int8)
            ds.attrs["flag_meanings"] = " ".join(COMPUTED_FLAGS.values())
        elif name == "status":
            ds.attrs["flag_masks"] = np.array(list(STATUS_WORDS), np.int32)
            ds.attrs["flag_meanings"] = " ".join(STATUS_WORDS.values())
            ds.attrs["flagged_mask"] = np.int32(L.STATUS_FLAGGED)
        if scalars:
            ds.attrs["coordinates"] = " ".join(scalars)
        for i, sc in enumerate(scales):
            ds.dims[i].attach_scale(sc)
    if scene.suite is not None:
        _write_suite(f, scene, {s.name.lstrip("/"): s for s in scales})


def suite_variables(scene: Scene) -> dict[str, tuple[tuple[str, ...], np.ndarray]]:
    """The per-record variables of a suite scene's result: name -> (dims, values):
    ``record_pga`` [g], ``record_pgv`` [m/s], ``record_sa`` (record, period) [g],
    ``record_npts``, ``record_dt`` [s], ``record_duration`` [s], ``record_sha256``, and
    ``scale_factor``: (record, stripe) when scaled, with the swept slenderness (PGA_ratio,
    PGV_ratio) and p (PGV_ratio) when the factor depends on them; (record,) for a cloud."""
    su = scene.suite
    R = len(su.records)
    out: dict[str, tuple[tuple[str, ...], np.ndarray]] = {
        "record_pga": (("record",), np.asarray(su.pga, float)),
        "record_pgv": (("record",), np.asarray(su.pgv, float)),
        "record_sa": (("record", "period"), np.asarray(su.sa, float)),
        "record_npts": (("record",), np.array([r.npts for r in su.records], np.int64)),
        "record_dt": (("record",), np.array([r.dt for r in su.records], float)),
        "record_duration": (("record",), np.array([r.duration for r in su.records], float)),
        "record_sha256": (("record",), np.array([r.sha256 for r in su.records], object)),
    }
    r = np.arange(R)
    if su.im is None:
        out["scale_factor"] = (("record",), su.factors(r, None, np.zeros(R), np.ones(R)))
        return out
    dims = ["record", su.im]
    shape = [R, len(su.levels)]
    alpha_key = "alpha" if scene.kind == "block" else "alpha_cg"
    alpha = np.asarray(scene.axis(alpha_key).values, float)
    p = np.asarray(scene.axis("p").values, float)
    dep = su.scale_dependence()
    if "alpha_ref" in dep and scene.axis(alpha_key).swept:
        dims.append(alpha_key)
        shape.append(alpha.size)
    else:
        alpha = alpha[:1]
    if "p" in dep and scene.axis("p").swept:
        dims.append("p")
        shape.append(p.size)
    else:
        p = p[:1]
    grids = np.meshgrid(r, np.arange(len(su.levels)), alpha, p, indexing="ij")
    fac = su.factors(grids[0], grids[1], grids[2], grids[3]).reshape(shape)
    out["scale_factor"] = (tuple(dims), fac)
    return out


def _write_suite(f: h5py.File, scene: Scene, scales: dict) -> None:
    """The suite's per-record variables (``suite_variables``) with their dimension scales
    (``period`` made here) and CF attributes (``fields.RECORD_VARIABLES``)."""
    import h5py

    su = scene.suite
    per = f.create_dataset("period", data=np.asarray(su.periods, float))
    per.make_scale("period")
    for k, v in fields.axis_attrs("period").items():
        per.attrs[k] = v
    scales = {**scales, "period": per}
    for name, (dims, values) in suite_variables(scene).items():
        if values.dtype == object:
            ds = f.create_dataset(name, data=values.astype(str).astype(object),
                                  dtype=h5py.string_dtype())
        else:
            ds = f.create_dataset(name, data=values)
        long_name, units, text = fields.RECORD_VARIABLES[name]
        ds.attrs["long_name"] = long_name
        if units is not None:
            ds.attrs["units"] = units
        ds.attrs["description"] = text
        for i, d in enumerate(dims):
            ds.dims[i].attach_scale(scales[d])


def _coord_attrs(ds, axis, kind: str = "flexible") -> None:
    for k, v in fields.axis_attrs(axis.name, kind).items():
        ds.attrs[k] = v
    ds.attrs["scene_key"] = axis.key


# ---------------------------------------------------------------------------------------
# Reading (plot, info)
# ---------------------------------------------------------------------------------------

@dataclass
class SweepResult:
    """A result file read into memory.

    dims/shape: swept dimensions; coords: dim -> values; scalars: unswept axis -> value;
    arrays: variable -> array[shape]; attrs: file attributes; scene: resolved scene dict.
    """

    path: Path
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    coords: dict[str, np.ndarray]
    scalars: dict[str, object]
    arrays: dict[str, np.ndarray]
    attrs: dict[str, object]
    scene: dict

    @property
    def kind(self) -> str:
        return self.scene["kind"]

    @property
    def name(self) -> str:
        return self.scene["name"]

    @property
    def done(self) -> np.ndarray:
        return self.arrays["outcome"] != L.OUTCOME_NOT_RUN

    @property
    def flagged(self) -> np.ndarray:
        return (self.arrays["status"] & L.STATUS_FLAGGED) != 0

    def counts(self) -> list[dict]:
        """Points per class for each pulse shape and lam (needs ``outcome`` and ``status``).

        One dict per (shape, lam): shape, lam, safe, mode1, mode2, not_computed, flagged.
        """
        out = self.arrays["outcome"]
        flagged = self.flagged & self.done
        groups = [d for d in ("shape", "lam") if d in self.dims]
        rest = tuple(i for i, d in enumerate(self.dims) if d not in groups)
        pos = [self.dims.index(d) for d in groups]
        order = [*pos, *rest]
        o = np.transpose(out, order).reshape(*(self.shape[i] for i in pos), -1)
        fl = np.transpose(flagged, order).reshape(o.shape)
        rows = []
        for idx in np.ndindex(*o.shape[:-1]):
            label = {}
            for d in ("shape", "lam"):
                label[d] = (_plain(self.coords[d][idx[groups.index(d)]]) if d in groups
                            else self.scalars.get(d))
            cell = o[idx]
            rows.append({**label,
                         "safe": int((cell == L.OUTCOME_SAFE).sum()),
                         "mode1": int((cell == L.OUTCOME_MODE1).sum()),
                         "mode2": int((cell == L.OUTCOME_MODE2).sum()),
                         "not_computed": int((cell == L.OUTCOME_NOT_RUN).sum()),
                         "flagged": int(fl[idx].sum())})
        return rows


def result_of(ds) -> SweepResult:
    """A result Dataset (what ``rocksweep.run`` and ``rocksweep.open`` return) as the
    ``SweepResult`` that ``read_result`` gives for its file: the analyses and figures take
    either. A Dataset that is not a rocksweep sweep result is a one-line StoreError."""
    import json

    where = Path(str(ds.encoding.get("source") or ds.attrs.get("title") or "dataset"))
    if "outcome" not in ds.data_vars or "scene_resolved" not in ds.attrs:
        raise StoreError(f"{where}: not a rocksweep result (a Dataset from rocksweep.run or "
                         "rocksweep.open has an outcome variable and a scene_resolved "
                         "attribute)")
    try:
        stored = json.loads(str(ds.attrs["scene_resolved"]))
    except ValueError:
        raise StoreError(f"{where}: attribute scene_resolved is not JSON") from None
    _check_scene(stored, where)
    dims = tuple(str(d) for d in ds["outcome"].dims)
    coords = {d: np.asarray(ds[d].values) for d in dims}
    scalars = {str(k): _plain(np.asarray(v.values).reshape(()).item())
               for k, v in ds.coords.items() if k not in dims and v.ndim == 0}
    arrays = {str(k): np.asarray(v.transpose(*dims).values) for k, v in ds.data_vars.items()
              if set(v.dims) == set(dims)}
    attrs = {str(k): _plain(v) for k, v in ds.attrs.items()}
    return SweepResult(where, dims, tuple(len(coords[d]) for d in dims), coords, scalars,
                       arrays, attrs, stored)


def as_result(data, names: list[str] | None = None) -> SweepResult:
    """A ``SweepResult`` from a result Dataset, a ``SweepResult`` or a result file's path
    (read with ``names``)."""
    if isinstance(data, SweepResult):
        return data
    if isinstance(data, str | Path):
        return read_result(data, names)
    return result_of(data)


RECORD_GROUP = "record"  # a record sweep's copy of its record: file (bytes), acceleration


def _store_record(f, record) -> None:
    """Keep the record in the result file (group ``record``): the file's bytes (``file``,
    uint8; the scene is rebuilt from them, ``result_scene``) and the samples
    (``acceleration`` [g], at ``dt`` [s]) for readers. A result then stands alone: moved
    to another machine, or kept after the record's folder is gone, it still plots and
    gives boundaries and spectra."""
    g = f.create_group(RECORD_GROUP)
    raw = np.frombuffer(record.data, dtype=np.uint8)
    if raw.size:
        d = g.create_dataset("file", data=raw, chunks=(min(raw.size, 1 << 16),),
                             compression="gzip")
        d.attrs["sha256"] = record.sha256
        d.attrs["source"] = str(record.source)
    acc = g.create_dataset("acceleration", data=np.asarray(record.acc, np.float64))
    acc.attrs["units"] = "g"
    acc.attrs["dt"] = float(record.dt)


def stored_record(path: Path, rec: dict):
    """The record a result file keeps (``_store_record``) as a ``GroundRecord`` with the
    sweep's source path, checked against the file's SHA-256; None for a file that keeps
    no copy (made before records were stored). StoreError if the copy is damaged."""
    from rocksweep.physics.records import RecordError, parse_record

    f = _open(path, "r")
    try:
        g = f.get(RECORD_GROUP)
        d = g.get("file") if g is not None else None
        if d is None:
            return None
        data = bytes(np.asarray(d[()], dtype=np.uint8).tobytes())
    except _H5_ERRORS as err:
        raise _damaged(path, f"its copy of the record: {_why(err)}") from None
    finally:
        _close_quietly(f)
    import hashlib

    if hashlib.sha256(data).hexdigest() != rec.get("sha256"):
        raise _damaged(path, "its copy of the record does not match its SHA-256")
    try:
        return parse_record(data, rec["source"])
    except RecordError as err:
        raise _damaged(path, f"its copy of the record: {err}") from None


def result_scene(result: SweepResult) -> Scene:
    """The scene a result was computed from, rebuilt from its YAML and overrides and
    checked against the result's resolved scene (axes, numerics), so that the kernel runs
    again as the sweep did (the A_min bisection, spectra). A record comes from the file's
    own copy (``stored_record``, checked against its SHA-256); a file made before records
    were stored re-reads it from where the sweep read it, checked against the SHA-256.
    One-line StoreErrors."""
    import json

    from rocksweep.scene.scene import parse_scene

    a = result.attrs
    try:
        overrides = list(json.loads(str(a.get("overrides", "[]"))))
    except ValueError:
        raise StoreError(f"{shown(result.path)}: attribute overrides is not JSON") from None
    rec = result.scene.get("record")
    suite = result.scene.get("suite")
    record = None
    if rec:
        # the file's own copy first (a result stands alone); a file without one re-reads
        # the record from where the sweep read it, checked against its SHA-256
        # a Dataset made in memory (rocksweep.run without output) has no file to read
        record = stored_record(result.path, rec) if result.path.is_file() else None
        if record is None:
            from rocksweep.physics.records import RecordError, read_record

            try:
                record = read_record(rec["source"])
            except RecordError as err:
                raise StoreError(f"{shown(result.path)}: cannot rebuild its scene (the "
                                 f"record: {err}; this file keeps no copy of it, made by an "
                                 "older rocksweep: put the record back there)") from None
            if record.sha256 != rec["sha256"]:
                raise StoreError(f"{shown(result.path)}: the record {rec['source']} changed "
                                 f"since the sweep (sha256 {record.sha256[:12]}, the result "
                                 f"has {rec['sha256'][:12]})")
    elif suite:  # the records where the sweep read them (their SHA-256s are compared)
        overrides.append("ground.records=" + json.dumps(
            [str(r.get("source")) for r in suite.get("records") or []]))
    try:
        sc = parse_scene(str(a["scene"]), str(result.path), overrides, record=record)
    except RocksweepError as err:
        raise StoreError(f"{shown(result.path)}: cannot rebuild its scene ({err})") from None
    stored = {k: v for k, v in result.scene.items() if k != "adaptive"}
    added = bool(suite) and not rec  # the override above is not the file's
    diffs = scene_differences(stored, resolved_scene(sc, overrides[:len(overrides) - added]))
    if diffs:
        raise StoreError(f"{shown(result.path)}: its scene YAML no longer gives its grid "
                         f"({'; '.join(diffs)})")
    return sc


def _plain(v):
    if isinstance(v, bytes | np.bytes_):
        return bytes(v).decode("utf-8", "replace")
    if isinstance(v, np.generic):
        return v.item()
    return v


# Attributes readers use (``rocksweep info``, ``plot``) -> what they must be.
_TEXT_ATTRS = ("scene", "accuracy", "started", "finished")
_NUMBER_ATTRS = ("wall_time", "cpu_time")
_COUNT_ATTRS = ("sessions",)
_FLAG_ATTRS = ("energy", "complete")


def _attr_ok(key: str, v) -> bool:
    if key in _TEXT_ATTRS:  # h5py decodes invalid UTF-8 to surrogates: damage
        return isinstance(v, str) and v.encode("utf-8", "replace").decode() == v
    if isinstance(v, bool) or not isinstance(v, int | float):
        return key in _FLAG_ATTRS and isinstance(v, bool)
    if key in _NUMBER_ATTRS:
        return math.isfinite(v) and v >= 0
    if key in _COUNT_ATTRS:
        return isinstance(v, int) and v >= 0
    return v in (0, 1)  # a flag: int8 (format 2) or bool (format 1)


def _check_outcome(outcome: np.ndarray, path: Path) -> None:
    codes = np.array([L.OUTCOME_NOT_RUN, *OUTCOME_WORDS], np.int8)
    bad = ~np.isin(outcome, codes)
    if bad.any():
        raise _damaged(path, f"variable 'outcome' holds {int(bad.sum())} invalid codes, "
                       f"e.g. {int(outcome[bad][0])} (valid: -1, 0, 1, 2)")


def _check_computed(computed: np.ndarray, outcome: np.ndarray | None, path: Path) -> None:
    """The ``computed`` flags of an adaptive file: codes 0..3, and no computed point
    without an outcome (outcome is written before the flag)."""
    bad = ~np.isin(computed, np.array(list(COMPUTED_FLAGS), np.int8))
    if bad.any():
        raise _damaged(path, f"variable 'computed' holds {int(bad.sum())} invalid codes, "
                       f"e.g. {int(computed[bad][0])} (valid: 0, 1, 2, 3)")
    if outcome is not None:
        lost = (computed > 0) & (outcome == L.OUTCOME_NOT_RUN)
        if lost.any():
            raise _damaged(path, f"{int(lost.sum())} points flagged computed have no "
                           "outcome")


def _checked_attrs(f: h5py.File, path: Path) -> dict:
    """The file's attributes as plain Python values, those readers use validated."""
    attrs = {}
    for k in f.attrs:
        try:
            attrs[k] = _plain(f.attrs[k])
        except _H5_ERRORS as err:
            raise _damaged(path, f"attribute {k} unreadable: {_why(err)}") from None
    _json_attr(f, "numerics", path, dict)
    overrides = _json_attr(f, "overrides", path, list)
    if not all(isinstance(o, str) for o in overrides):
        raise _damaged(path, f"attribute overrides is {_cut(overrides)}, not a list of text")
    for k in (*_TEXT_ATTRS, *_NUMBER_ATTRS, *_COUNT_ATTRS, *_FLAG_ATTRS):
        if k not in attrs:
            raise _damaged(path, f"attribute {k} missing")
        if not _attr_ok(k, attrs[k]):
            raise _damaged(path, f"attribute {k} is {_cut(attrs[k])}")
    return attrs


def read_result(path: str | Path, names: list[str] | None = None,
                optional: tuple[str, ...] = ()) -> SweepResult:
    """Read a result file (``names``: variables to load; default all; ``optional``:
    variables loaded too when the file has them, e.g. ``computed``).

    Validates what readers rely on (format, resolved scene, coordinates, variables'
    shapes and dtypes, outcome codes, the attributes ``info`` shows); any problem is a
    one-line StoreError naming the file.
    """
    path = Path(path)
    f = _open(path, "r")
    try:
        lay = _layout(f, path)
        stored = lay.scene
        known = variables_for(stored)
        wanted = list(names) if names else list(known)
        wanted += [n for n in optional if n in known and n not in wanted]
        for n in wanted:
            if n not in known:
                raise StoreError(f"{shown(path)}: no variable '{n}' in this result (it "
                                 f"holds {', '.join(known)})")
        coords, scalars = {}, {}
        for key, ax in stored["axes"].items():
            name = key.split(".", 1)[1]
            if ax["swept"]:
                vals = f[name][()]
                if name in fields.WORD_AXES:
                    vals = np.array([_plain(v) for v in vals])
                coords[name] = vals
            else:
                scalars[name] = ax["values"][0]
        arrays = {n: f[n][()] for n in wanted}
        if "outcome" in arrays:
            _check_outcome(arrays["outcome"], path)
        if "computed" in arrays:
            _check_computed(arrays["computed"], arrays.get("outcome"), path)
        attrs = _checked_attrs(f, path)
    except RocksweepError:
        raise
    except _H5_ERRORS as err:
        raise _damaged(path, _why(err)) from None
    finally:
        _close_quietly(f)
    return SweepResult(path, lay.dims, lay.shape, coords, scalars, arrays, attrs, stored)


def stored_scene(path: str | Path) -> dict:
    """The resolved scene a result file records (``resolved_scene``), validated as
    ``read_result`` validates it, without reading any variable."""
    path = Path(path)
    f = _open(path, "r")
    try:
        return _layout(f, path).scene
    except RocksweepError:
        raise
    except _H5_ERRORS as err:
        raise _damaged(path, _why(err)) from None
    finally:
        _close_quietly(f)


def peek_done(path: str | Path) -> tuple[int, int] | None:
    """(points done, total) of a rocksweep result at path, None if it is not one."""
    try:
        r = read_result(path, ["outcome"])
    except StoreError:
        return None
    return int(r.done.sum()), int(r.done.size)
