"""``sweep``: the one way into the sweep driver (``rocksweep.compute.driver``) for
``rocksweep.run`` (``run_session``) and ``rocksweep sweep``: the arguments checked once
(``compute.arguments.SweepArguments``), the scene's grid made once, the sink made (a
result file, or one in memory), the driver handed both. ``sweep_file``: the same with
loose keyword arguments."""

from __future__ import annotations

import contextlib
import io
import sys
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from rocksweep.compute.adaptive import adaptive_options
from rocksweep.compute.arguments import (
    CONNECT_TIMEOUT,
    WRITE_EVERY,
    SweepArguments,
    check_flag,
    check_sweep_arguments,
)
from rocksweep.compute.driver import SweepInterrupted, SweepReport, drive
from rocksweep.compute.sweep import check_scheduler
from rocksweep.errors import ApiError, Arg, SweepError, flag
from rocksweep.outputs import check_output, check_path_text, exists_error
from rocksweep.scene.grid import Grid
from rocksweep.scene.inputs import load, override_strings
from rocksweep.store.dataset import open_result, result_dataset
from rocksweep.store.writer import SweepFile

if TYPE_CHECKING:
    from typing import Any

    import xarray as xr

    from rocksweep.compute.adaptive import Options
    from rocksweep.scene.inputs import Overrides, SceneLike
    from rocksweep.scene.model import Scene

def sweep_file(scene: Scene, path: str | Path | None, *, overrides: Sequence[str] = (),
               jobs: int = 1, resume: bool = False, overwrite: bool = False,
               backend: str = "threads", scheduler: str | None = None,
               chunk_size: int | None = None, write_every: float = WRITE_EVERY,
               progress: bool = False, log: Callable[[str], None] | None = None,
               inputs: Iterable[str | Path] = (), adaptive: Options | None = None,
               validate: bool = False, connect_timeout: float = CONNECT_TIMEOUT
               ) -> SweepReport:
    """Sweep ``scene`` into the result file ``path`` (``rocksweep sweep``), or with ``path``
    None into a file in memory (its bytes: ``report.image``; ``rocksweep.run``).

    Makes the file (refusing an existing one unless ``overwrite``), or with ``resume``
    reopens an existing file of the same scene and computes only its missing points.
    Finished chunks are written in batches, at most every ``write_every`` seconds; on
    Ctrl-C the pending chunks are written and ``SweepInterrupted`` (a KeyboardInterrupt)
    is raised; on any other error they are written before the error propagates.

    jobs: local worker threads (-1: one per core); backend "threads" or "dask" (with
    ``scheduler``, an address); chunk_size: points per chunk (default about 32 chunks per
    worker); progress: a progress bar on stderr; log: receives the header and kernel
    lines; inputs: the command's input files, never written over; overrides: recorded in
    the file; adaptive: compute only near the class boundaries
    (``rocksweep.compute.adaptive``, see ``compute.driver.adaptive_loop``; the file
    records the settings, and a resume must give the same); validate: with adaptive,
    also compute the filled points of a coarse uniform lattice and report those whose
    class differs from the fill (``report.validation``; the file is not changed);
    connect_timeout: seconds to wait for the dask scheduler to answer. Every argument is
    checked (``rocksweep.compute.arguments``) before the output is touched, then ``sweep``
    runs. Returns a ``SweepReport``.
    """
    args = check_sweep_arguments(
        jobs=jobs, resume=resume, overwrite=overwrite, validate=validate, backend=backend,
        scheduler=scheduler, chunk_size=chunk_size, write_every=write_every,
        connect_timeout=connect_timeout)
    if path is not None:  # None: in memory (rocksweep.run without output=)
        path = check_path_text(path)
    return sweep(scene, path, args, overrides=overrides, progress=progress, log=log,
                 inputs=inputs, adaptive=adaptive)


def sweep(scene: Scene, path: Path | None, args: SweepArguments, *,
          overrides: Sequence[str] = (), progress: bool = False,
          log: Callable[[str], None] | None = None, inputs: Iterable[str | Path] = (),
          adaptive: Options | None = None) -> SweepReport:
    """``sweep_file`` with its arguments checked (``check_sweep_arguments``, once, by the
    caller: ``rocksweep sweep``, ``run_session``, ``sweep_file``). The scene's grid is
    made here, once, and handed to the sink and the driver; the output path is checked
    once (``outputs.check_output``) before the file is made or reopened."""
    if args.validate and adaptive is None:
        raise SweepError("{validate} checks an adaptive sweep; add {adaptive}",
                         validate=flag("validate"), adaptive=flag("adaptive"))
    if args.backend == "dask":
        check_scheduler(args.scheduler, args.connect_timeout)  # before any file is made
    grid = Grid(scene)
    # bad axes or settings: before any file
    settings = adaptive.resolved(grid) if adaptive is not None else None
    say = log or (lambda _line: None)
    n = args.n_workers
    t0 = time.perf_counter()
    where = (f"{n} worker{'s' * (n > 1)}" if args.backend == "threads"
             else f"dask cluster {args.scheduler}")
    how = f"threads x {n}" if args.backend == "threads" else f"dask {args.scheduler}"
    if path is None:  # in memory: nothing touches a disk (rocksweep.run without output)
        if args.resume:
            raise ApiError("{resume} needs {output} (the file to finish)",
                           resume=flag("resume"), output=Arg("output"))
        sf = SweepFile.in_memory(scene, overrides, backend=how, adaptive=settings, grid=grid)
    else:
        inputs = [*inputs, *scene.inputs]  # the scene's records and listings: never written over
        try:
            path.stat()
        except FileNotFoundError:
            pass
        except OSError:  # a name too long, a path through a file...: one line, no traceback
            check_output(path, overwrite=args.overwrite, inputs=inputs)
        if args.resume and path.exists():
            check_output(path, overwrite=True, inputs=inputs)
            sf = SweepFile.resume(path, scene, overrides, backend=how, adaptive=settings,
                                  grid=grid)
        else:
            if path.is_file() and not args.overwrite:
                raise exists_error(path, resumable=True)
            check_output(path, overwrite=args.overwrite, inputs=inputs)
            sf = SweepFile.make(path, scene, overrides, overwrite=args.overwrite,
                                backend=how, adaptive=settings, log=say, grid=grid)
    report = SweepReport(path or Path("memory"), grid.size, 0, 0, 0.0, 0.0, 0.0)
    try:
        return drive(sf, path, report, t0, adaptive, args.validate, jobs=args.jobs,
                     backend=args.backend, scheduler=args.scheduler,
                     chunk_size=args.chunk_size, where=where,
                     write_every=args.write_every, progress=progress, say=say)
    except KeyboardInterrupt as err:
        if isinstance(err, SweepInterrupted):
            raise
        # a Ctrl-C between the file's making and the driver's own handler: the file is
        # there (its points saved), so the answer is the interrupted sweep's, resume line
        # and all, not a bare interrupt
        with contextlib.suppress(Exception):
            sf.close()
        raise SweepInterrupted(report) from None


def _stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def client_backend(client: Any) -> dict[str, str]:
    """``sweep_file``'s backend keywords for ``rocksweep.run(client=...)``: local threads
    (client None) or the cluster of an open ``dask.distributed.Client`` (its scheduler's
    address). A closed Client is an ``ApiError``, anything else a TypeError."""
    if client is None:
        return {"backend": "threads"}
    address = getattr(getattr(client, "scheduler", None), "address", None)
    distributed = sys.modules.get("distributed")  # a Client exists only once it is loaded
    if (distributed is not None and isinstance(client, distributed.Client)
            and getattr(client, "status", None) in ("closed", "closing")):
        raise ApiError(f"client = {client!r}: this dask Client is closed; make a new one "
                       "(Client(cluster) or Client('tcp://host:8786')) and pass it")
    if not isinstance(address, str):
        raise TypeError(f"client = {client!r}: must be a dask.distributed.Client")
    return {"backend": "dask", "scheduler": address}


def run_session(scene: SceneLike | Scene, output: str | Path | None, *,
                overrides: Overrides = (), jobs: int = 1, resume: bool = False,
                overwrite: bool = False, progress: bool = False, client: Any = None,
                adaptive: bool = False, validate: bool = False,
                settings: Mapping[str, Any] | None = None) -> xr.Dataset:
    """``rocksweep.run``'s sweep (its arguments documented there). Every argument is
    checked before ``output`` is touched: types and ranges first, then the scene loaded
    with its ``overrides`` (``scene.inputs.load``) and the adaptive ``settings`` (coarse,
    audit, axes, ...; None: the scene's ``refine`` or the default) made ``Options``
    (``compute.adaptive.adaptive_options``). Then the sweep into the result file
    ``output`` (the scene's own file never written over), or with output None in memory
    (nothing touches a disk). progress: the header and kernel lines on stderr and a
    progress bar; client: see ``client_backend``. Returns the result as the loaded Dataset
    (``store.dataset``: ``open_result`` of the file, or ``result_dataset`` of the
    in-memory file's image)."""
    # types and ranges first: nothing below may touch ``output`` before all are checked
    check_flag("progress", progress)
    check_flag("adaptive", adaptive)
    where = client_backend(client)
    args = check_sweep_arguments(jobs=jobs if client is None else 1, resume=resume,
                                 overwrite=overwrite, validate=validate, **where)
    path = check_path_text(output, "output") if output is not None else None
    scene, source = load(scene, overrides)
    opts = adaptive_options(adaptive, base=scene.refine, **(settings or {}))
    overrides = override_strings(overrides)
    log = _stderr if progress else None
    report = sweep(scene, path, args, overrides=overrides, progress=progress, log=log,
                   inputs=[source] if source and path is not None else (), adaptive=opts)
    if path is None:
        return result_dataset(io.BytesIO(report.image))
    return open_result(path)
