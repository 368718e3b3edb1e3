"""Sweep results on disk (HDF5 through h5py; the only module that writes them).

Layout (netCDF-4 style, so ``xarray.open_dataset(path, engine="h5netcdf")`` opens it):

- one dataset per swept axis, named after it (``shape``, a body key, ``lam``, ``A_ratio``,
  ``w_over_p``), holding its values and made an HDF5 dimension scale;
- one 0-d dataset per unswept axis (a scalar coordinate, listed in each variable's
  ``coordinates`` attribute);
- one dataset per stored variable (``rocksweep.sweep.VARIABLES``) with the grid's
  dimensions attached; ``outcome`` is -1 where a point is not computed yet;
- attributes: the scene YAML verbatim and its resolved form, the resolved numerics,
  versions, times, totals and the format version.

Only the parent process writes. Datasets are allocated in full when the file is made
(under a temporary name, renamed when complete), so later writes touch raw data only: a
killed run leaves a well-formed file whose ``outcome`` marks exactly the finished points
(each chunk's other variables are flushed before its ``outcome``). ``--resume`` reopens it
and computes the rest.
"""

from __future__ import annotations

import json
import math
import os
import platform
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rocksweep.errors import RocksweepError
from rocksweep.grid import Grid
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.outcomes import OUTCOME_WORDS, STATUS_WORDS
from rocksweep.scene import Scene
from rocksweep.sweep import ChunkResult, variables

if TYPE_CHECKING:
    import h5py

FORMAT = "rocksweep-sweep"
FORMAT_VERSION = 1

# long names of the coordinates (the paper's symbols)
COORD_LONG_NAMES = {
    "shape": "pulse shape",
    "w_over_p": "omega/p (Pi5)",
    "A_ratio": "A/(g tan alpha_ref) (Pi6)",
    "lam": "lambda: impulse position / b (Pi10)",
    "wn_over_p": "omega_n/p (Pi1)",
    "zeta": "zeta (Pi2)",
    "alpha_cg": "alpha_cg [rad] (Pi3)",
    "alpha_A": "alpha_A [rad] (Pi4)",
    "mA_over_m": "m_A/m (Pi8)",
    "IA_ratio": "I_A/(m_A R_A^2) (Pi9)",
    "alpha": "alpha [rad]",
    "inertia": "I_O/(M R^2)",
}


class StoreError(RocksweepError):
    """A result file that cannot be made, read or resumed; ``str()`` is one line."""


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


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


def resolved_scene(scene: Scene, overrides: tuple[str, ...] | list[str] = ()) -> dict:
    """What decides a sweep's results (plus its name): the basis of resume checks."""
    return {
        "name": scene.name,
        "kind": scene.kind,
        "axes": {a.key: {"values": list(a.values), "swept": a.swept} for a in scene.axes},
        "numerics": scene.numerics.as_dict(),
        "energy": scene.energy,
        "overrides": list(overrides),
    }


def _short(v) -> str:
    if isinstance(v, dict) and "values" in v:
        vals = v["values"]
        text = (repr(vals[0]) if not v["swept"] else
                f"[{', '.join(map(repr, vals))}]" if len(vals) <= 6 else
                f"{len(vals)} values {vals[0]!r}..{vals[-1]!r}")
        return text
    return repr(v)


def scene_differences(stored: dict, new: dict) -> list[str]:
    """One phrase per difference between two ``resolved_scene`` dicts."""
    diffs = []
    for section in ("name", "kind", "energy"):  # --set overrides show in the axes
        if stored.get(section) != new.get(section):
            key = "outputs.energy" if section == "energy" else section
            diffs.append(f"{key}: file {_short(stored.get(section))}, "
                         f"scene {_short(new.get(section))}")
    for key in dict.fromkeys([*stored.get("axes", {}), *new.get("axes", {})]):
        a, b = stored.get("axes", {}).get(key), new.get("axes", {}).get(key)
        if a != b:
            diffs.append(f"{key}: file {_short(a) if a else 'absent'}, "
                         f"scene {_short(b) if b else 'absent'}")
    sn, nn = stored.get("numerics", {}), new.get("numerics", {})
    for key in dict.fromkeys([*sn, *nn]):
        if sn.get(key) != nn.get(key):
            diffs.append(f"numerics.{key}: file {sn.get(key)!r}, scene {nn.get(key)!r}")
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


def _check_format(f: h5py.File, path: Path) -> None:
    import h5py
    fmt = f.attrs.get("rocksweep_format")
    if isinstance(fmt, bytes):
        fmt = fmt.decode()
    if fmt != FORMAT:
        raise StoreError(f"{path}: an HDF5 file, but not a rocksweep sweep result "
                         "(no rocksweep_format attribute)")
    ver = int(f.attrs.get("format_version", -1))
    if ver > FORMAT_VERSION:
        raise StoreError(f"{path}: written in result format {ver} by a newer rocksweep; "
                         f"this version reads format {FORMAT_VERSION}; upgrade rocksweep")
    if ver < 1:
        raise StoreError(f"{path}: damaged rocksweep result (format_version = {ver})")
    try:
        stored = json.loads(_attr_str(f, "scene_resolved"))
    except (KeyError, ValueError):
        raise StoreError(f"{path}: damaged rocksweep result "
                         "(scene_resolved attribute missing or unreadable)") from None
    dims = tuple(k.split(".", 1)[1] for k, v in stored["axes"].items() if v["swept"])
    shape = tuple(len(v["values"]) for v in stored["axes"].values() if v["swept"])
    names = ["outcome", *(n for n in variables_for(stored) if n != "outcome")]
    for name in names:
        ds = f.get(name)
        if not isinstance(ds, h5py.Dataset):
            raise StoreError(f"{path}: damaged rocksweep result (variable '{name}' missing)")
        if ds.shape != shape:
            raise StoreError(f"{path}: damaged rocksweep result (variable '{name}' has shape "
                             f"{ds.shape}, the grid {shape})")
    for d in dims:
        if not isinstance(f.get(d), h5py.Dataset):
            raise StoreError(f"{path}: damaged rocksweep result (coordinate '{d}' missing)")


def variables_for(stored: dict) -> dict:
    """The per-point variables of a file from its resolved scene."""
    from rocksweep.sweep import ENERGY_VARIABLES, VARIABLES

    return {**VARIABLES, **(ENERGY_VARIABLES if stored.get("energy") else {})}


def _attr_str(f: h5py.File, key: str) -> str:
    v = f.attrs[key]
    return v.decode() if isinstance(v, bytes) else str(v)


def _open(path: Path, mode: str) -> h5py.File:
    """Open an existing file; foreign or damaged files give a one-line StoreError."""
    import h5py
    if not path.exists():
        raise StoreError(f"{path}: no such file")
    if path.is_dir():
        raise StoreError(f"{path}: is a directory, not a sweep result")
    try:
        # readers do not lock: `info` and `plot` work while a sweep writes (datasets are
        # allocated up front, so a running sweep changes raw data only)
        return h5py.File(path, mode, locking=(mode != "r"))
    except OSError as err:
        if not h5py.is_hdf5(path):
            raise StoreError(f"{path}: not an HDF5 file (expected a rocksweep sweep "
                             "result)") from None
        if "unable to lock" in str(err).lower():
            raise StoreError(f"{path}: open for writing by another process (a sweep still "
                             "running?)") from None
        raise StoreError(f"{path}: damaged or truncated HDF5 file, cannot be opened "
                         "(rerun the sweep with --overwrite)") from None


class SweepFile:
    """A result file open for writing (by the parent process only)."""

    def __init__(self, path: Path, f: h5py.File, scene: Scene) -> None:
        self.path = path
        self.f = f
        self.grid = Grid(scene)
        self.names = list(variables(scene))
        self.session_start = _now()

    # -- making and reopening -------------------------------------------------------------
    @classmethod
    def create(cls, path: str | Path, scene: Scene, overrides: tuple[str, ...] = (),
               overwrite: bool = False) -> SweepFile:
        """Make a new result file (all points not computed), atomically."""
        import h5py
        path = Path(path)
        if path.exists() and not overwrite:
            raise StoreError(f"{path}: already exists; use --resume to finish it or "
                             "--overwrite to replace it")
        if path.is_dir():
            raise StoreError(f"{path}: is a directory")
        if not path.parent.is_dir():
            raise StoreError(f"{path}: directory {path.parent} does not exist")
        tmp = path.with_name(f".{path.name}.partial")
        try:
            with h5py.File(tmp, "w", track_order=True) as f:
                _initialise(f, scene, overrides)
            os.replace(tmp, path)
        except OSError as err:
            raise StoreError(f"{path}: cannot write ({err.strerror or err})") from None
        finally:
            tmp.unlink(missing_ok=True)
        return cls._reopen(path, scene)

    @classmethod
    def resume(cls, path: str | Path, scene: Scene,
               overrides: tuple[str, ...] = ()) -> SweepFile:
        """Reopen a result file of the same scene to finish it."""
        path = Path(path)
        with _open(path, "r") as f:
            _check_format(f, path)
            stored = json.loads(_attr_str(f, "scene_resolved"))
        diffs = scene_differences(stored, resolved_scene(scene, overrides))
        if diffs:
            raise StoreError(f"{path}: cannot resume, the scene differs from the file's: "
                             + "; ".join(diffs) + " (use --overwrite to start again)")
        return cls._reopen(path, scene)

    @classmethod
    def _reopen(cls, path: Path, scene: Scene) -> SweepFile:
        f = _open(path, "r+")
        self = cls(path, f, scene)
        f.attrs["sessions"] = int(f.attrs.get("sessions", 0)) + 1
        f.attrs["last_started"] = self.session_start
        f.flush()
        return self

    # -- state ------------------------------------------------------------------------
    def done(self) -> np.ndarray:
        """bool[size]: points already computed (flat order)."""
        return self.f["outcome"][()].reshape(-1) != L.OUTCOME_NOT_RUN

    def write(self, res: ChunkResult) -> None:
        """Write one chunk's results; ``outcome`` last, each step flushed to the OS."""
        boxes = flat_slabs(self.grid.shape, res.start, res.stop)
        for name in [*(n for n in self.names if n != "outcome"), "outcome"]:
            if name == "outcome":
                self.f.flush()
            ds = self.f[name]
            arr = res.arrays[name]
            for index, a, b in boxes:
                box = tuple(len(range(*s.indices(n))) for s, n in zip(index, ds.shape, strict=True))
                ds[index] = arr[a - res.start:b - res.start].reshape(box)
        self.f.flush()

    def finish(self, wall_time: float, cpu_time: float) -> dict:
        """Record this session's wall time [s], the workers' CPU time on its points [s]
        and the file's totals; returns the attributes set."""
        f = self.f
        done = self.done()
        steps = int(f["steps"][()].sum())
        event_steps = int(f["event_steps"][()].sum())
        attrs = {
            "wall_time": float(f.attrs.get("wall_time", 0.0)) + wall_time,
            "cpu_time": float(f.attrs.get("cpu_time", 0.0)) + cpu_time,
            "points_done": int(done.sum()),
            "complete": bool(done.all()),
            "steps_total": steps,
            "event_steps_total": event_steps,
            "last_finished": _now(),
        }
        if done.all() and not _attr_str(f, "finished"):
            attrs["finished"] = attrs["last_finished"]
        for k, v in attrs.items():
            f.attrs[k] = v
        f.flush()
        return attrs

    def close(self) -> None:
        self.f.close()

    def __enter__(self) -> SweepFile:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _initialise(f: h5py.File, scene: Scene, overrides: tuple[str, ...]) -> None:
    import h5py
    grid = Grid(scene)
    a = f.attrs
    a["rocksweep_format"] = FORMAT
    a["format_version"] = FORMAT_VERSION
    a["title"] = scene.name
    a["scene"] = scene.text
    a["scene_kind"] = scene.kind
    a["scene_resolved"] = json.dumps(resolved_scene(scene, overrides))
    a["overrides"] = json.dumps(list(overrides))
    n = scene.numerics
    a["numerics"] = json.dumps(n.as_dict())
    a["accuracy"] = n.describe()
    a["steps_per_period"] = n.steps_per_period
    a["event_tol"] = n.event_tol
    a["horizon"] = n.horizon
    a["energy"] = scene.energy
    for k, v in versions().items():
        a[f"{k}_version"] = v
    a["started"] = _now()
    a["finished"] = ""
    a["wall_time"] = 0.0
    a["cpu_time"] = 0.0
    a["sessions"] = 0
    a["points_total"] = grid.size
    a["points_done"] = 0
    a["complete"] = False
    a["steps_total"] = 0
    a["event_steps_total"] = 0

    scales = []
    for axis in scene.swept:
        data = (np.array(axis.values, dtype=h5py.string_dtype()) if axis.name == "shape"
                else np.asarray(axis.values, float))
        ds = f.create_dataset(axis.name, data=data)
        ds.make_scale(axis.name)
        ds.attrs["long_name"] = COORD_LONG_NAMES.get(axis.name, axis.name)
        ds.attrs["scene_key"] = axis.key
        scales.append(ds)
    scalars = []
    for axis in scene.axes:
        if axis.swept:
            continue
        v = axis.values[0]
        ds = f.create_dataset(axis.name, data=(np.array(v, dtype=h5py.string_dtype())
                                               if axis.name == "shape" else float(v)))
        ds.attrs["long_name"] = COORD_LONG_NAMES.get(axis.name, axis.name)
        ds.attrs["scene_key"] = axis.key
        scalars.append(axis.name)

    for name, (dtype, fill, text) in variables(scene).items():
        dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
        dcpl.set_alloc_time(h5py.h5d.ALLOC_TIME_EARLY)  # no metadata changes later
        ds = f.create_dataset(name, shape=grid.shape, dtype=dtype, fillvalue=fill,
                              dcpl=dcpl, fill_time="alloc")
        ds.attrs["description"] = text
        if name == "outcome":  # CF-style flag attributes, for xarray users
            ds.attrs["flag_values"] = np.array(list(OUTCOME_WORDS), np.int8)
            ds.attrs["flag_meanings"] = " ".join(OUTCOME_WORDS.values())
        elif name == "status":
            ds.attrs["flag_masks"] = np.array(list(STATUS_WORDS), np.int32)
            ds.attrs["flag_meanings"] = " ".join(STATUS_WORDS.values())
            ds.attrs["flagged_mask"] = np.int32(L.STATUS_FLAGGED)
        if scalars:
            ds.attrs["coordinates"] = " ".join(scalars)
        for i, sc in enumerate(scales):
            ds.dims[i].attach_scale(sc)


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


def _plain(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.generic):
        return v.item()
    return v


def read_result(path: str | Path, names: list[str] | None = None) -> SweepResult:
    """Read a result file (``names``: variables to load; default all)."""
    path = Path(path)
    with _open(path, "r") as f:
        _check_format(f, path)
        try:
            stored = json.loads(_attr_str(f, "scene_resolved"))
            dims, coords, scalars = [], {}, {}
            for key, ax in stored["axes"].items():
                name = key.split(".", 1)[1]
                if ax["swept"]:
                    dims.append(name)
                    vals = f[name][()]
                    if name == "shape":
                        vals = np.array([_plain(v) for v in vals])
                    coords[name] = vals
                else:
                    scalars[name] = ax["values"][0]
            wanted = names or list(variables_for(stored))
            arrays = {n: f[n][()] for n in wanted}
            attrs = {k: _plain(v) for k, v in f.attrs.items()}
        except (KeyError, OSError, ValueError, TypeError) as err:
            raise StoreError(f"{path}: damaged rocksweep result ({err})") from None
    return SweepResult(path, tuple(dims), tuple(len(coords[d]) for d in dims), coords,
                       scalars, arrays, attrs, stored)


def peek_done(path: str | Path) -> tuple[int, int] | None:
    """(points done, total) of a rocksweep result at path, None if it is not one."""
    try:
        r = read_result(path, ["outcome"])
    except StoreError:
        return None
    return int(r.done.sum()), int(r.done.size)
