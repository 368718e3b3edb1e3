"""Reading result files (plot, info, analyses) and validating them (every reader and
resume): readers rely only on what is checked here (attributes, coordinates, shapes,
dtypes, outcome codes); every problem is a one-line ``StoreError`` naming the file."""

from __future__ import annotations

import contextlib
import errno
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import NoReturn

import h5py
import numpy as np

from rocksweep import fields
from rocksweep.errors import RecordError, RocksweepError, StoreError, flag
from rocksweep.fields import plain
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.outputs import shown
from rocksweep.physics.records import digest, parse_record, read_record
from rocksweep.scene.model import Scene
from rocksweep.scene.parse import parse_scene
from rocksweep.store._common import H5_ERRORS, close_quietly, cut_repr, damaged, error_reason
from rocksweep.store.format import (
    FORMAT,
    FORMAT_VERSION,
    RECORD_GROUP,
    SUITE_GROUP,
    VERTICAL_GROUP,
    variables_for,
)
from rocksweep.store.identity import resolved_scene, scene_differences
from rocksweep.vocab.axes import axis_name
from rocksweep.vocab.kinds import KIND_ATTR, KINDS, SWEEP
from rocksweep.vocab.outcomes import CLASSES, COMPUTED_FLAGS, OUTCOME_CODE, OUTCOME_WORDS
from rocksweep.vocab.settings import ADAPTIVE_RESOLVED


@dataclass
class FileLayout:
    """What a valid file holds: its resolved scene, swept dims and their sizes."""

    scene: dict
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    names: list[str]


def _attr_str(f: h5py.File, key: str) -> str:
    v = f.attrs[key]
    if isinstance(v, bytes | np.bytes_):
        return bytes(v).decode("utf-8", "replace")
    if not isinstance(v, str):
        raise TypeError(f"attribute {key} is {cut_repr(plain(v))}, not text")
    return v


def _check_scene(stored, path: Path) -> None:
    """The resolved scene dict as ``resolved_scene`` makes it, or StoreError."""
    def bad(what: str) -> StoreError:
        return damaged(path, f"attribute scene_resolved: {what}")

    if not isinstance(stored, dict):
        raise bad(f"{cut_repr(stored)} is not a JSON object")
    for key, typ in (("name", str), ("kind", str), ("energy", bool), ("axes", dict),
                     ("numerics", dict)):
        if not isinstance(stored.get(key), typ):
            raise bad(f"'{key}' is {cut_repr(stored.get(key))}, not a {typ.__name__}")
    if not stored["axes"]:
        raise bad("no axes")
    for key, ax in stored["axes"].items():
        if not (isinstance(key, str) and "." in key and isinstance(ax, dict)
                and isinstance(ax.get("swept"), bool) and isinstance(ax.get("values"), list)
                and ax["values"]):
            raise bad(f"axis {cut_repr(key)} is {cut_repr(ax)}")
        words = key in fields.WORD_KEYS
        kinds = (str,) if words else (int, float)
        if not all(isinstance(v, kinds) and not isinstance(v, bool) for v in ax["values"]):
            raise bad(f"axis {key} has values {cut_repr(ax['values'])}")
        if not ax["swept"] and len(ax["values"]) != 1:
            raise bad(f"unswept axis {key} has {len(ax['values'])} values")
    if "adaptive" in stored:
        a = stored["adaptive"]
        ok = (isinstance(a, dict) and set(a) == set(ADAPTIVE_RESOLVED)
              and isinstance(a["axes"], list) and len(a["axes"]) == 2
              and all(isinstance(v, str) for v in a["axes"])
              and all(isinstance(a[k], int) and not isinstance(a[k], bool) and a[k] >= 0
                      for k in ("coarse", "margin", "final_margin", "seed"))
              and all(isinstance(a[k], int | float) and not isinstance(a[k], bool)
                      and 0 <= a[k] <= 1 for k in ("audit", "threshold")))
        if not ok:
            raise bad(f"'adaptive' is {cut_repr(a)}")


def _json_attr(f: h5py.File, key: str, path: Path, typ: type):
    try:
        text = _attr_str(f, key)
    except KeyError:
        raise damaged(path, f"attribute {key} missing") from None
    except TypeError as err:
        raise damaged(path, str(err)) from None
    try:
        value = json.loads(text)
    except ValueError:
        raise damaged(path, f"attribute {key} is not JSON: {cut_repr(text)}") from None
    if not isinstance(value, typ):
        raise damaged(path, f"attribute {key} is {cut_repr(text)}, not a JSON "
                       f"{'object' if typ is dict else 'list'}")
    return value


# The attribute the netCDF-4 library and h5netcdf put on every file they write (xarray's
# to_netcdf); rocksweep's writer (h5py) never does.
NETCDF_MARK = "_NCProperties"


def _looks_like_ours(f: h5py.File, fmt) -> bool:
    """Whether a file without a valid rocksweep_format attribute still shows the marks of a
    rocksweep result (then it is damaged, not foreign)."""
    if isinstance(fmt, str) and fmt.startswith("rocksweep"):
        return True
    try:
        a = f.attrs
        return "scene_resolved" in a or ("format_version" in a and "outcome" in f)
    except H5_ERRORS:
        return False


def _analysis_kind(f: h5py.File) -> str | None:
    """The kind of an analysis's result file (``vocab.kinds``: its ``rocksweep_kind``
    attribute, but a sweep's), else None."""
    try:
        kind = f.attrs.get(KIND_ATTR)
    except H5_ERRORS:
        return None
    if isinstance(kind, bytes | np.bytes_):
        kind = bytes(kind).decode("utf-8", "replace")
    return kind if isinstance(kind, str) and kind in KINDS and kind != SWEEP else None


def read_layout(f: h5py.File, path: Path) -> FileLayout:
    """Validate the format, the resolved scene, the coordinates and the variables."""
    try:  # h5py's attrs.get hides damage as "missing"
        fmt = f.attrs["rocksweep_format"] if "rocksweep_format" in f.attrs else None
    except H5_ERRORS as err:
        raise StoreError(f"{shown(path)}: damaged HDF5 file, its attributes cannot be read "
                         f"({error_reason(err)})") from None
    if isinstance(fmt, bytes | np.bytes_):
        fmt = bytes(fmt).decode("utf-8", "replace")
    try:
        resaved = NETCDF_MARK in f.attrs
    except H5_ERRORS:
        resaved = False
    kind = _analysis_kind(f) if resaved else None
    if kind is not None:  # an analysis's result (written with xarray): not a sweep's file
        raise StoreError(f"{shown(path)}: a {kind} result ({KINDS[kind]}), not a sweep "
                         "result; this reads the file a sweep writes (rocksweep.open reads "
                         "both)")
    if resaved:  # the netCDF library's mark: rocksweep writes with h5py, never sets it
        raise StoreError(f"{shown(path)}: not written by rocksweep: a result saved again by "
                         "xarray (to_netcdf) or another netCDF writer, which changes its "
                         "layout; rocksweep reads the files its sweeps write (the original "
                         "file; this one opens with xarray.open_dataset)")
    if fmt != FORMAT:
        if _looks_like_ours(f, fmt):  # a damaged result is not a foreign file
            raise damaged(path, "attribute rocksweep_format " + (
                "missing" if fmt is None else f"is {cut_repr(plain(fmt))}"))
        raise StoreError(f"{shown(path)}: an HDF5 file, but not a rocksweep sweep result "
                         "(no rocksweep_format attribute)")
    try:
        ver = int(f.attrs.get("format_version", -1))
    except (TypeError, ValueError):
        raise damaged(path, f"format_version = {cut_repr(plain(f.attrs['format_version']))}"
                       ) from None
    if ver > FORMAT_VERSION:
        raise StoreError(f"{shown(path)}: written in result format {ver} by a newer "
                         f"rocksweep; this version reads formats 1 to {FORMAT_VERSION}; "
                         "upgrade rocksweep")
    if ver < 1:
        raise damaged(path, f"format_version = {ver}")
    stored = _json_attr(f, "scene_resolved", path, object)
    _check_scene(stored, path)
    swept = {axis_name(k): v["values"] for k, v in stored["axes"].items() if v["swept"]}
    dims = tuple(swept)
    shape = tuple(len(v) for v in swept.values())
    for d, values in swept.items():
        ds = f.get(d)
        if not isinstance(ds, h5py.Dataset):
            raise damaged(path, f"coordinate '{d}' missing")
        if ds.shape != (len(values),):
            raise damaged(path, f"coordinate '{d}' has shape {ds.shape}, the scene "
                           f"{len(values)} values")
        data = ds[()]
        if d in fields.WORD_AXES:
            ok = [plain(v) for v in data] == values
        else:
            ok = data.dtype.kind == "f" and np.array_equal(data, np.asarray(values, float))
        if not ok:
            raise damaged(path, f"coordinate '{d}' holds {cut_repr(data.tolist())}, the scene "
                           f"{cut_repr(values)}")
    names = ["outcome", *(n for n in variables_for(stored) if n != "outcome")]
    specs = variables_for(stored)
    for name in names:
        ds = f.get(name)
        if not isinstance(ds, h5py.Dataset):
            raise damaged(path, f"variable '{name}' missing")
        if ds.shape != shape:
            raise damaged(path, f"variable '{name}' has shape {ds.shape}, the grid {shape}")
        if ds.dtype != np.dtype(specs[name][0]):
            raise damaged(path, f"variable '{name}' has dtype {ds.dtype}, expected "
                           f"{specs[name][0]}")
    return FileLayout(stored, dims, shape, names)


def _is_hdf5(path: Path) -> bool:
    try:
        return bool(h5py.is_hdf5(path))
    except H5_ERRORS:
        return False


def open_h5(path: Path, mode: str) -> h5py.File:
    """Open an existing file; foreign, damaged, locked or unreadable files give a one-line
    StoreError. Writers (mode "r+") take HDF5's exclusive lock; readers take none."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise StoreError(f"{shown(path)}: no such file") from None
    except OSError as err:
        raise StoreError(f"{shown(path)}: cannot be read ({error_reason(err)})") from None
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
    except H5_ERRORS as err:
        if mode == "r" and opened_here(err):
            # open in this process through another handle (xarray's, h5py's): HDF5 wants
            # the same locking flags; a reader takes them
            for locking in READER_LOCKING:
                with contextlib.suppress(*H5_ERRORS):
                    return h5py.File(path, mode, locking=locking)
        _open_error(path, mode, err)


# The locking flags a reader tries when the file is open in this process through another
# handle (h5py's default, then HDF5's own).
READER_LOCKING = ("best-effort", True)


def _open_error(path: Path, mode: str, err: BaseException) -> NoReturn:
    """Raise the one-line StoreError for a file h5py could not open (``err``): a lock
    (another process's, or another handle in this process), permissions, a foreign file,
    damage."""
    no = getattr(err, "errno", None)
    text = str(err).lower()
    if isinstance(err, BlockingIOError) or "unable to lock" in text:
        raise StoreError(f"{shown(path)}: open for writing by another process (a sweep "
                         "still running?)") from None
    if opened_here(err):
        raise StoreError(f"{shown(path)}: already open in this process through another "
                         "HDF5 handle (HDF5's file lock: e.g. xr.open_dataset(..., "
                         "engine='h5netcdf') or h5py.File); the file is not damaged: "
                         "close that handle (ds.close()) and try again; rocksweep.open "
                         "loads the file and closes it at once") from None
    if no in (errno.EACCES, errno.EPERM, errno.EROFS):
        doing = "written" if mode != "r" else "read"
        raise StoreError(f"{shown(path)}: cannot be {doing} ({error_reason(err)})") from None
    if not _is_hdf5(path):
        raise StoreError(f"{shown(path)}: not an HDF5 file (expected a rocksweep sweep "
                         "result)") from None
    raise StoreError(f"{shown(path)}: damaged or truncated HDF5 file, cannot be opened "
                     f"({error_reason(err)}); its points cannot be read back: if it is a copy, "
                     "copy it again from the original; else sweep again to a new file "
                     "(-o NEW.h5) and remove this one after") from None


def opened_here(err: BaseException) -> bool:
    """Whether h5py's error says the file is open in this process through another handle
    with other settings (a lock, not damage)."""
    return any(w in str(err).lower() for w in _OPEN_HERE)


# What HDF5 says when the file is already open in this process with other settings (a
# lock of this process, not damage): h5py/HDF5 1.10-1.14 wordings.
_OPEN_HERE = ("locking flag values don't match", "already open for read-only",
              "already open for write", "file close degree doesn't match",
              "file is already open")


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


def check_outcome(outcome: np.ndarray, path: Path) -> None:
    codes = np.array([L.OUTCOME_NOT_RUN, *OUTCOME_WORDS], np.int8)
    bad = ~np.isin(outcome, codes)
    if bad.any():
        raise damaged(path, f"variable 'outcome' holds {int(bad.sum())} invalid codes, "
                       f"e.g. {int(outcome[bad][0])} (valid: -1, 0, 1, 2)")


def check_computed(computed: np.ndarray, outcome: np.ndarray | None, path: Path) -> None:
    """The ``computed`` flags of an adaptive file: codes 0..3, and no computed point
    without an outcome (outcome is written before the flag)."""
    bad = ~np.isin(computed, np.array(list(COMPUTED_FLAGS), np.int8))
    if bad.any():
        raise damaged(path, f"variable 'computed' holds {int(bad.sum())} invalid codes, "
                       f"e.g. {int(computed[bad][0])} (valid: 0, 1, 2, 3)")
    if outcome is not None:
        lost = (computed > 0) & (outcome == L.OUTCOME_NOT_RUN)
        if lost.any():
            raise damaged(path, f"{int(lost.sum())} points flagged computed have no "
                           "outcome")


def checked_attrs(f: h5py.File, path: Path) -> dict:
    """The file's attributes as plain Python values, those readers use validated."""
    attrs = {}
    for k in f.attrs:
        try:
            attrs[k] = plain(f.attrs[k])
        except H5_ERRORS as err:
            raise damaged(path, f"attribute {k} unreadable: {error_reason(err)}") from None
    _json_attr(f, "numerics", path, dict)
    overrides = _json_attr(f, "overrides", path, list)
    if not all(isinstance(o, str) for o in overrides):
        raise damaged(path, f"attribute overrides is {cut_repr(overrides)}, not a list of text")
    for k in (*_TEXT_ATTRS, *_NUMBER_ATTRS, *_COUNT_ATTRS, *_FLAG_ATTRS):
        if k not in attrs:
            raise damaged(path, f"attribute {k} missing")
        if not _attr_ok(k, attrs[k]):
            raise damaged(path, f"attribute {k} is {cut_repr(attrs[k])}")
    for k, v in attrs.items():  # the versions the writer records are text (info shows them)
        if k.endswith("_version") and k != "format_version" and not isinstance(v, str):
            raise damaged(path, f"attribute {k} is {cut_repr(v)}, not a version text "
                                 "(not as rocksweep writes it)")
    return attrs


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
    # read from the file at ``path`` (False: a Dataset made in memory, ``path`` only names
    # it in messages and is never opened)
    in_file: bool = True

    @property
    def kind(self) -> str:
        return self.scene["kind"]

    @property
    def name(self) -> str:
        return self.scene["name"]

    @property
    def done(self) -> np.ndarray:
        return self.arrays["outcome"] != L.OUTCOME_NOT_RUN

    def require_complete(self, error: type[RocksweepError], needs: str) -> None:
        """The one refusal of an incomplete result by an analysis that needs every point
        (``needs``: what it computes, e.g. "A_min"): ``error`` naming the file, how many
        points are missing, and the resume that finishes it."""
        missing = int((~self.done).sum())
        if missing:
            raise error(f"{shown(self.path)}: incomplete result ({missing} of "
                        f"{self.done.size} points not computed yet); {needs} needs every "
                        "point: finish the sweep with {resume}", resume=flag("resume"))

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
                label[d] = (plain(self.coords[d][idx[groups.index(d)]]) if d in groups
                            else self.scalars.get(d))
            cell = o[idx]
            rows.append({**label,
                         **{w: int((cell == OUTCOME_CODE[w]).sum()) for w in CLASSES},
                         "not_computed": int((cell == L.OUTCOME_NOT_RUN).sum()),
                         "flagged": int(fl[idx].sum())})
        return rows


@contextlib.contextmanager
def _reading(path: Path):
    """The result file open for reading; h5py's errors inside become one-line StoreErrors
    (damaged file), the library's pass as they are; closed whatever happens."""
    f = open_h5(path, "r")
    try:
        yield f
    except RocksweepError:
        raise
    except H5_ERRORS as err:
        raise damaged(path, error_reason(err)) from None
    finally:
        close_quietly(f)


def read_result(path: str | Path, names: list[str] | None = None,
                optional: tuple[str, ...] = ()) -> SweepResult:
    """Read a result file (``names``: variables to load; default all; ``optional``:
    variables loaded too when the file has them, e.g. ``computed``).

    Validates what readers rely on (format, resolved scene, coordinates, variables'
    shapes and dtypes, outcome codes, the attributes ``info`` shows); any problem is a
    one-line StoreError naming the file.
    """
    path = Path(path)
    with _reading(path) as f:
        lay = read_layout(f, path)
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
            name = axis_name(key)
            if ax["swept"]:
                vals = f[name][()]
                if name in fields.WORD_AXES:
                    vals = np.array([plain(v) for v in vals])
                coords[name] = vals
            else:
                scalars[name] = ax["values"][0]
        arrays = {n: f[n][()] for n in wanted}
        if "outcome" in arrays:
            check_outcome(arrays["outcome"], path)
        if "computed" in arrays:
            check_computed(arrays["computed"], arrays.get("outcome"), path)
        attrs = checked_attrs(f, path)
    return SweepResult(path, lay.dims, lay.shape, coords, scalars, arrays, attrs, stored)


def stored_scene(path: str | Path) -> dict:
    """The resolved scene a result file records (``resolved_scene``), validated as
    ``read_result`` validates it, without reading any variable."""
    path = Path(path)
    with _reading(path) as f:
        return read_layout(f, path).scene


def result_inputs(path: str | Path) -> tuple[str, ...]:
    """The files a command that reads the result at ``path`` never writes over: the
    result and every file its sweep read (``resolved_inputs``: an analysis may re-read
    them). Only ``(path,)`` for a file that is not a readable result (its own error comes
    when it is read)."""
    try:
        sc = stored_scene(path)
    except RocksweepError:
        return (str(path),)
    return (str(path), *resolved_inputs(sc))


def resolved_inputs(stored: dict) -> tuple[str, ...]:
    """Every file a resolved scene (``store.identity.resolved_scene``) says its sweep read:
    each ``source`` it holds, at any depth (a record, its second horizontal and vertical
    components, a suite's records), and a PEER folder suite's H2 and UP files, which it
    names beside their H1 (``scene.peer``: one folder holds a record's files)."""
    out: list[str] = []

    def walk(v) -> None:
        if isinstance(v, dict):
            if isinstance(v.get("source"), str) and v["source"]:
                out.append(v["source"])
            for x in v.values():
                walk(x)
        elif isinstance(v, list):
            for x in v:
                walk(x)

    walk(stored)
    suite = stored.get("suite") if isinstance(stored.get("suite"), dict) else {}
    records = suite.get("records") if isinstance(suite.get("records"), list) else []
    folders: dict[Path, dict[str, list[str]]] = {}
    for key in ("h2", "vertical"):
        named = suite.get(key) if isinstance(suite.get(key), list) else []
        for rec, comp in zip(records, named, strict=False):
            if not (isinstance(rec, dict) and isinstance(rec.get("source"), str)
                    and isinstance(comp, dict) and isinstance(comp.get("name"), str)):
                continue
            folder = Path(rec["source"]).parent
            if folder not in folders:  # the folder's files by stem (a name has no suffix)
                try:
                    names = os.listdir(folder)
                except OSError:
                    names = []
                folders[folder] = {}
                for n in names:
                    folders[folder].setdefault(Path(n).stem, []).append(n)
            out.extend(str(folder / n) for n in folders[folder].get(comp["name"], ()))
    return tuple(dict.fromkeys(out))


def peek_done(path: str | Path) -> tuple[int, int] | None:
    """(points done, total) of a rocksweep result at path, None if it is not one."""
    try:
        r = read_result(path, ["outcome"])
    except StoreError:
        return None
    return int(r.done.sum()), int(r.done.size)


def result_of(ds) -> SweepResult:
    """A result Dataset (what ``rocksweep.run`` and ``rocksweep.open`` return) as the
    ``SweepResult`` that ``read_result`` gives for its file: the analyses and figures take
    either. A Dataset that is not a rocksweep sweep result is a one-line StoreError."""
    source = ds.encoding.get("source")
    in_file = isinstance(source, str | Path) and bool(str(source))
    # a Dataset made in memory is named by its title in messages, never opened by it
    where = Path(str(source) if in_file else
                 f"result in memory ({ds.attrs.get('title') or 'untitled'})")
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
    grid_order = tuple(axis_name(k) for k, ax in stored["axes"].items() if ax["swept"])
    if set(grid_order) == set(dims):  # a transposed Dataset: back in the grid's order
        dims = grid_order
    coords = {d: np.asarray(ds[d].values) for d in dims}
    scalars = {str(k): plain(np.asarray(v.values).reshape(()).item())
               for k, v in ds.coords.items() if k not in dims and v.ndim == 0}
    arrays = {str(k): np.asarray(v.transpose(*dims).values) for k, v in ds.data_vars.items()
              if set(v.dims) == set(dims)}
    attrs = {str(k): plain(v) for k, v in ds.attrs.items()}
    return SweepResult(where, dims, tuple(len(coords[d]) for d in dims), coords, scalars,
                       arrays, attrs, stored, in_file)


def as_result(data, names: list[str] | None = None,
              optional: tuple[str, ...] = ()) -> SweepResult:
    """A ``SweepResult`` from a result Dataset, a ``SweepResult`` or a result file's path
    (read with ``names`` and ``optional``, as ``read_result``)."""
    if isinstance(data, SweepResult):
        return data
    if isinstance(data, str | Path):
        return read_result(data, names, optional)
    return result_of(data)


def stored_record(path: Path, rec: dict, group: str = RECORD_GROUP):
    """The record a result file keeps (``_store_record``; ``group`` VERTICAL_GROUP: its
    vertical component's) as a ``GroundRecord`` with the sweep's source path, checked
    against the file's SHA-256; None for a file that keeps no copy (made before records
    were stored). StoreError if the copy is damaged."""
    f = open_h5(path, "r")
    try:
        g = f.get(group)
        d = g.get("file") if g is not None else None
        if d is None:
            return None
        data = bytes(np.asarray(d[()], dtype=np.uint8).tobytes())
    except H5_ERRORS as err:
        raise damaged(path, f"its copy of the record: {error_reason(err)}") from None
    finally:
        close_quietly(f)
    return _stored_copy(path, data, rec, "its copy of the record")


def _stored_copy(path: Path, data: bytes, rec: dict, what: str):
    """A record's copy in a result file as a ``GroundRecord``, checked against the SHA-256
    the file states for it (``rec``: its ``sha256`` and ``source``)."""
    if digest(data) != rec.get("sha256"):
        raise damaged(path, f"{what} does not match its SHA-256")
    try:
        return parse_record(data, str(rec.get("source")))
    except RecordError as err:
        raise damaged(path, f"{what}: {err}") from None


def stored_records(path: Path, suite: dict) -> tuple | None:
    """The records a suite's result file keeps (``_store_suite_records``) as
    ``GroundRecord``s in the suite's order, each checked against the SHA-256 the resolved
    scene states; None for a file that keeps no copies (made before suites stored them).
    StoreError if a copy is damaged."""
    want = suite.get("records") or []
    f = open_h5(path, "r")
    try:
        g = f.get(SUITE_GROUP)
        if g is None:
            return None
        blobs = []
        for i, r in enumerate(want):
            d = g.get(str(i))
            if d is None:
                raise damaged(path, f"its copy of record {r.get('name')!r} is missing")
            blobs.append(bytes(np.asarray(d[()], dtype=np.uint8).tobytes()))
    except H5_ERRORS as err:
        raise damaged(path, f"its copies of the records: {error_reason(err)}") from None
    finally:
        close_quietly(f)
    return tuple(_stored_copy(path, data, r, f"its copy of record {r.get('name')!r}")
                 for r, data in zip(want, blobs, strict=True))


def result_scene(result: SweepResult) -> Scene:
    """The scene a result was computed from, rebuilt from its YAML and overrides and
    checked against the result's resolved scene (axes, numerics), so that the kernel runs
    again as the sweep did (the A_min bisection, spectra). A record comes from the file's
    own copy (``stored_record``, checked against its SHA-256); a file made before records
    were stored re-reads it from where the sweep read it, checked against the SHA-256.
    One-line StoreErrors."""
    a = result.attrs
    try:
        overrides = list(json.loads(str(a.get("overrides", "[]"))))
    except ValueError:
        raise StoreError(f"{shown(result.path)}: attribute overrides is not JSON") from None
    rec = result.scene.get("record")
    suite = result.scene.get("suite")
    record = None
    added = 0  # overrides added here, not the file's
    if rec:
        # the file's own copy first (a result stands alone); a file without one re-reads
        # the record from where the sweep read it, checked against its SHA-256
        # a Dataset made in memory (rocksweep.run without output) has no file to read
        record = stored_record(result.path, rec) if result.in_file else None
        if record is None:
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
    vert = result.scene.get("vertical")
    vertical = (stored_record(result.path, vert, VERTICAL_GROUP) if vert and result.in_file
                else None)  # None: re-read from where the sweep read it (sha256 compared)
    records = (stored_records(result.path, suite) if suite and result.in_file
               and not suite.get("h2") else None)  # a PEER folder is paired anew
    if suite and suite.get("h2"):
        overrides.append("ground.records=" + json.dumps(
            str(Path(str(suite["records"][0]["source"])).parent)))
        added += 1
    elif suite and records is None:
        # a file without copies (older rocksweep) or a Dataset made in memory: the records
        # where the sweep read them (their SHA-256s are compared below)
        overrides.append("ground.records=" + json.dumps(
            [str(r.get("source")) for r in suite.get("records") or []]))
        added += 1
    h2 = [r for r in (result.scene.get("path") or {}).get("h2") or [] if r]
    if h2 and not suite:  # the second component, read where the sweep read it
        overrides.append("ground.h2=" + json.dumps(str(h2[0]["source"])))
        added += 1
    try:
        sc = parse_scene(str(a["scene"]), str(result.path), overrides, record=record,
                         records=records, vertical=vertical)
    except RocksweepError as err:
        raise StoreError("{path}: cannot rebuild its scene ({err})", path=shown(result.path),
                         err=err) from None
    stored = {k: v for k, v in result.scene.items() if k != "adaptive"}
    diffs = scene_differences(stored, resolved_scene(sc, overrides[:len(overrides) - added]))
    if diffs:
        raise StoreError(f"{shown(result.path)}: its scene YAML no longer gives its grid "
                         f"({'; '.join(diffs)})")
    grid = {a.name: len(a.values) for a in sc.swept}
    if dict(zip(result.dims, result.shape, strict=True)) != grid:
        have = " x ".join(f"{n} {d}" for d, n in zip(result.dims, result.shape, strict=True))
        full = " x ".join(f"{n} {d}" for d, n in grid.items())
        raise StoreError(f"{shown(result.path)}: holds part of its sweep's grid ({have} of "
                         f"{full}, e.g. after .sel or .isel); this analysis reruns points of "
                         "the whole grid: give it the whole result and select afterwards")
    return sc
