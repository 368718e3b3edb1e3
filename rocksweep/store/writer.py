"""Writing result files: ``SweepFile`` (the only writer; the parent process only).

Datasets are allocated in full when the file is made, under a temporary name unique to
the process, renamed when complete (``rocksweep.store.safety``), so later writes touch
raw data only: a killed run leaves a well-formed file whose ``outcome`` marks exactly the
finished points (each chunk's other variables are flushed before its ``outcome``).
A resume reopens it and computes the rest.

The attributes a session changes (``SESSION_ATTRS``) are overwritten in place
(``attrs.modify``): reopening, writing results and finishing never need new space in the
file, so a full disk cannot damage what is there, and resuming on a full disk works.
"""

from __future__ import annotations

import contextlib
import os
import platform
import re
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import h5py
import numpy as np

from rocksweep.errors import Arg, OutputError, RocksweepError, StoreError, flag
from rocksweep.fields import plain
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.outputs import (
    check_output,
    clean_stale_partials,
    exists_error,
    is_input,
    partial_prefix,
    shown,
)
from rocksweep.scene.grid import ChunkResult, Grid
from rocksweep.scene.model import Scene
from rocksweep.store._common import (
    H5_ERRORS,
    close_quietly,
    damaged,
    error_reason,
    fixed_ascii,
    mib,
    utc_now,
)
from rocksweep.store.format import (
    ADAPTIVE_COUNT_ATTRS,
    HISTORY_BYTES,
    SESSION_ATTRS,
    flat_slabs,
    initialise,
    metadata,
    versions,
)
from rocksweep.store.identity import resolved_scene, scene_differences
from rocksweep.store.reader import (
    check_computed,
    check_outcome,
    checked_attrs,
    open_h5,
    read_layout,
)
from rocksweep.store.safety import (
    UPDATE_MARGIN,
    check_space,
    lock_existing,
    publish_result,
    reserve_bytes,
    reserve_space,
    space_needed,
)

if TYPE_CHECKING:
    import h5py


def _put(f: h5py.File, name: str, value) -> None:
    """Overwrite a session attribute in place (its fixed type and size)."""
    dtype = SESSION_ATTRS.get(name) or ADAPTIVE_COUNT_ATTRS[name]
    arr = fixed_ascii(value, dtype) if dtype.startswith("S") else np.array(value, dtype=dtype)
    f.attrs.modify(name, arr)


def _in_place(f: h5py.File) -> bool:
    """Whether every session attribute exists with its fixed type (format 2)."""
    a = f.attrs
    for name, dtype in SESSION_ATTRS.items():
        try:
            if name not in a or a.get_id(name).dtype != np.dtype(dtype):
                return False
        except H5_ERRORS:
            return False
    return True


def _upgrade_session_attrs(f: h5py.File) -> None:
    """Give a format-1 file's session attributes their fixed types, and an older format-2
    file the ones it lacks (needs a little space, checked before; only the first resume
    of such a file does this)."""
    a = f.attrs
    for name, dtype in SESSION_ATTRS.items():
        if name in a and a.get_id(name).dtype == np.dtype(dtype):
            continue
        old = plain(a[name]) if name in a else None
        if name == "complete":
            old = int(bool(old))
        elif name == "refine_evaluations" and old is None:
            old = -1  # the sessions before did not count it
        elif old is None or (dtype.startswith("S") and not isinstance(old, str)):
            old = "" if dtype.startswith("S") else 0
        if name in a:
            del a[name]
        a.create(name, fixed_ascii(old, dtype) if dtype.startswith("S")
                 else np.array(old, dtype=dtype))


class SweepFile:
    """A result file open for writing (by the parent process only; it holds the file's
    exclusive lock until ``close``)."""

    def __init__(self, path: Path, f: h5py.File, grid: Grid,
                 backend: str | None = None, adaptive: dict | None = None) -> None:
        self.path = path
        self.f = f
        self.grid = grid  # the scene's points (the driver runs them; shape: the file's)
        scene = grid.scene
        self.names = list(scene.variables())
        self.adaptive = adaptive  # resolved adaptive settings, None: every point
        self.session_start = utc_now()
        self.backend = backend or "unspecified"
        self._history = ""  # the file's history before this session
        self._session_line = ""
        self._broken: StoreError | None = None  # the error that closed the file

    def _fail(self, err: StoreError) -> StoreError:
        """Close the file after a failed write (nothing more is written) and remember why:
        later calls repeat this error, not a second one about a closed file."""
        close_quietly(self.f)
        self._broken = err
        return err

    # -- making and reopening -------------------------------------------------------------
    @classmethod
    def create(cls, path: str | Path, scene: Scene, overrides: tuple[str, ...] = (),
               overwrite: bool = False, *, backend: str | None = None,
               adaptive: dict | None = None,
               log: Callable[[str], None] | None = None,
               grid: Grid | None = None) -> SweepFile:
        """Make a new result file (all points not computed), atomically, and open it.
        adaptive: resolved settings of an adaptive sweep (``adaptive.Options.resolved``):
        the file gets the ``computed`` flags and the settings' attributes; grid: the
        scene's ``Grid`` when the caller has made it (made here otherwise).

        Refused before anything is written: an existing path without ``overwrite``, a
        directory, device or FIFO, a missing directory (``OutputError``, as every output
        path); a grid larger than the free space, a file another process is writing
        (``StoreError``). ``backend``: how the
        points are computed (e.g. "threads x 2"), recorded with the host in the file.
        """
        path = Path(path)
        # devices, directories, missing dirs, the scene's own files (OutputError)
        check_output(path, overwrite=True, inputs=scene.inputs)
        return cls.make(path, scene, overrides, overwrite, backend=backend,
                        adaptive=adaptive, log=log, grid=grid)

    @classmethod
    def make(cls, path: Path, scene: Scene, overrides: tuple[str, ...] = (),
             overwrite: bool = False, *, backend: str | None = None,
             adaptive: dict | None = None, log: Callable[[str], None] | None = None,
             grid: Grid | None = None) -> SweepFile:
        """``create`` at a path its caller has checked (``outputs.check_output``, as the
        sweep session does, naming the command's inputs): refused are only what may have
        changed since, an existing path without ``overwrite`` (``OutputError``, the one
        "already exists") or a file made or replaced at it meanwhile (``OutputError``, as
        ``outputs.publish`` says for every output), too little free space, a file another
        process is writing (``StoreError``)."""
        grid = grid if grid is not None else Grid(scene)
        existed = os.path.lexists(path)
        if existed and not overwrite:
            raise exists_error(path, resumable=True)
        meta = metadata(scene, overrides, adaptive)  # before anything is made
        reserve = reserve_bytes(scene, meta.nbytes)
        removed = clean_stale_partials(path)  # a killed attempt's reserved space back
        if removed and log is not None:
            log(f"removed {len(removed)} stale temporary file{'s' * (len(removed) > 1)} of "
                f"{shown(path)} left by a sweep killed while making it ({removed[0][0]}"
                f"{', ...' if len(removed) > 1 else ''}; "
                f"{mib(sum(n for _, n in removed))})")
        check_space(path, space_needed(reserve), f"a grid of {grid.size} points")
        old_fd = lock_existing(path) if existed else None
        tmp: Path | None = None
        f = None
        try:
            parent = path.parent if str(path.parent) else Path(".")
            fd, name = tempfile.mkstemp(prefix=partial_prefix(path), suffix=".partial",
                                        dir=parent)
            os.close(fd)
            tmp = Path(name)
            reserve_space(tmp, reserve)  # room for all of it, or ENOSPC before HDF5 writes
            g = h5py.File(tmp, "w", track_order=True)  # truncates: reserve again
            try:
                reserve_space(tmp, reserve)
                initialise(g, meta)
                g.flush()
                size = g.id.get_filesize()  # HDF5's end of allocation (eof is stale)
            except BaseException:
                close_quietly(g)
                raise
            g.close()
            if 0 < size < reserve:
                os.truncate(tmp, size)  # give back what the metadata did not use
            f = h5py.File(tmp, "r+", locking=True)  # locked before anyone can see it
            self = cls(path, f, grid, backend, adaptive)
            self._start_session()  # before the file has its name: failing leaves nothing
            publish_result(tmp, path, old_fd)
            tmp = None
            return self
        except (StoreError, OutputError):
            if f is not None:
                close_quietly(f)
            raise
        except H5_ERRORS as err:
            if f is not None:
                close_quietly(f)
            raise StoreError(f"{shown(path)}: cannot write ({error_reason(err)}); nothing written"
                             ) from None
        finally:
            if tmp is not None:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            if old_fd is not None:
                os.close(old_fd)

    @classmethod
    def in_memory(cls, scene: Scene, overrides: tuple[str, ...] = (), *,
                  backend: str | None = None, adaptive: dict | None = None,
                  grid: Grid | None = None) -> SweepFile:
        """The same result, held in memory (HDF5's core driver, no backing store): the
        sink of ``rocksweep.run`` without ``output``. Nothing touches a disk; ``image``
        gives the file's bytes, exactly what ``create`` would have written. grid: as
        for ``create``."""
        name = f"rocksweep-memory-{os.getpid()}-{id(scene)}.h5"
        f = h5py.File(name, "w", driver="core", backing_store=False, track_order=True)
        try:
            initialise(f, metadata(scene, overrides, adaptive))
            self = cls(Path("memory"), f, grid if grid is not None else Grid(scene),
                       backend, adaptive)
            self._start_session()
        except BaseException:
            close_quietly(f)
            raise
        return self

    def image(self) -> bytes:
        """The result file's bytes as it stands (flushed)."""
        self.f.flush()
        return self.f.id.get_file_image()

    @classmethod
    def resume(cls, path: str | Path, scene: Scene, overrides: tuple[str, ...] = (),
               *, backend: str | None = None, adaptive: dict | None = None,
               grid: Grid | None = None) -> SweepFile:
        """Reopen a result file of the same scene (and the same adaptive settings, None
        for a sweep of every point) to finish it (its points are kept whatever happens:
        the session's attributes are updated in place). grid: as for ``create``."""
        path = Path(path)
        if is_input(path, scene.inputs):  # written in place: only the identity rule
            raise StoreError(f"{shown(path)}: is this command's input; choose another "
                             "output path")
        f = open_h5(path, "r")
        try:
            stored = read_layout(f, path).scene
            checked_attrs(f, path)  # what readers need, before any point is computed
            outcome = f["outcome"][()]
            check_outcome(outcome, path)
            if stored.get("adaptive"):
                check_computed(f["computed"][()], outcome, path)
        except H5_ERRORS as err:
            raise damaged(path, error_reason(err)) from None
        finally:
            close_quietly(f)
        diffs = scene_differences(stored, resolved_scene(scene, overrides, adaptive))
        if diffs:
            done = int((outcome != L.OUTCOME_NOT_RUN).sum())
            keep = (f"resume with the scene, {{overrides}} values and options it was made "
                    f"with, or sweep this scene to another {{output}}; {{overwrite}} would "
                    f"discard the {done} points it holds" if done else "use {overwrite} to "
                    "start again: it holds no computed point")
            raise StoreError("{path}: cannot resume, the scene differs from the file's: "
                             "{diffs} (" + keep + ")", path=shown(path),
                             diffs="; ".join(diffs), overrides=Arg("overrides"),
                             output=Arg("output"), overwrite=flag("overwrite"))
        f = open_h5(path, "r+")
        try:
            read_layout(f, path)  # the file locked now (another may have replaced the first)
            self = cls(path, f, grid if grid is not None else Grid(scene), backend, adaptive)
            self._start_session()
        except BaseException as err:
            close_quietly(f)
            if isinstance(err, H5_ERRORS) and not isinstance(err, RocksweepError):
                raise StoreError(f"{shown(path)}: cannot update its attributes "
                                 f"({error_reason(err)}); its points are kept") from None
            raise
        return self

    def _start_session(self) -> None:
        """Count the session and record its start, host and backend (in place). Raises
        h5py's errors (the callers say what they mean for the file)."""
        f = self.f
        if not _in_place(f):  # a format-1 file: its attributes change type once
            check_space(self.path, UPDATE_MARGIN, "updating its attributes")
            _upgrade_session_attrs(f)
            f.flush()
        n = int(f.attrs["sessions"]) + 1
        self._history = plain(f.attrs["history"])
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
        except H5_ERRORS as err:
            raise self._fail(StoreError(
                "{path}: cannot write results ({why}); the points written before are kept, "
                "finish with {resume}", path=shown(self.path), why=error_reason(err),
                resume=flag("resume"))) from None

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
        except H5_ERRORS as err:
            raise self._fail(StoreError(
                "{path}: cannot write the filled outcomes ({why}); finish with {resume}",
                path=shown(self.path), why=error_reason(err), resume=flag("resume"))) from None

    def put_counts(self, counts: dict[str, int]) -> None:
        """Update the adaptive counts (``ADAPTIVE_COUNT_ATTRS``) in place."""
        for k, v in counts.items():
            _put(self.f, k, int(v))
        self.f.flush()

    def write(self, res: ChunkResult) -> None:
        """Write one chunk's results; ``outcome`` last, each step flushed to the OS.

        A failed write (StoreError) leaves the chunk's points "not computed" and every
        point written before intact; the file is closed (a resume finishes it).
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
        except H5_ERRORS as err:
            raise self._fail(StoreError(
                "{path}: cannot write results ({why}); the points written before are kept, "
                "finish with {resume}", path=shown(self.path), why=error_reason(err),
                resume=flag("resume"))) from None

    def finish(self, wall_seconds: float, cpu_seconds: float, *,
               backend: str | None = None, refine_evaluations: int = 0) -> dict:
        """Record this session's wall time [s], the workers' CPU time on its points [s],
        the RK4 evaluations its certification took (``refine_evaluations``: part of the
        points' steps) and the file's totals (in place); returns the attributes set
        (plain Python values; ``complete`` a bool)."""
        if self._broken:
            raise self._broken
        f = self.f
        try:
            done = self.done()
            a = f.attrs
            attrs = {
                "wall_time": float(a.get("wall_time", 0.0)) + wall_seconds,
                "cpu_time": float(a.get("cpu_time", 0.0)) + cpu_seconds,
                # -1 (not recorded before) stays so: the total would be short
                "refine_evaluations": (-1 if int(a.get("refine_evaluations", -1)) < 0 else
                                       int(a["refine_evaluations"]) + int(refine_evaluations)),
                "points_done": int(done.sum()),
                "complete": bool(done.all()),
                "steps_total": int(f["steps"][()].sum()),
                "event_steps_total": int(f["event_steps"][()].sum()),
                "last_finished": utc_now(),
            }
            if done.all() and not plain(a["finished"]):
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
        except H5_ERRORS as err:
            raise self._fail(StoreError(
                f"{shown(self.path)}: cannot record the session's totals ({error_reason(err)}); "
                "its points are kept")) from None
        return attrs

    def close(self) -> None:
        if self._broken:
            return  # closed when it broke
        try:
            self.f.close()
        except H5_ERRORS as err:
            raise StoreError(f"{shown(self.path)}: cannot close ({error_reason(err)})") from None

    def __enter__(self) -> SweepFile:
        return self

    def __exit__(self, *exc) -> None:
        if exc[0] is None:
            self.close()
        else:
            close_quietly(self.f)


def _history(before: str, line: str) -> str:
    """``before`` plus ``line``, the oldest lines dropped to fit HISTORY_BYTES."""
    lines = [ln for ln in before.splitlines() if ln] + [line]
    while len(lines) > 1 and len("\n".join(lines).encode()) > HISTORY_BYTES:
        lines.pop(0)
    return "\n".join(lines)
