"""The sweep driver: compute the missing points of an open sink and record the session
(``drive``), every point (``every_point_loop``) or adaptively near the class boundaries
(``adaptive_loop``), with the kernel compiled or loaded first (``prepare_kernel``).

The sink is a result file or one in memory (``rocksweep.store.writer.SweepFile``; the
driver needs only its ``grid`` and its methods ``done``, ``write``, ``state``,
``write_points``, ``write_filled``, ``finish``, ``image`` and ``close``): made, and every
argument checked, by the sweep session (``rocksweep.compute.session``), the one way in
for ``rocksweep.run`` and ``rocksweep sweep``. Light at import (numpy, the kernel and
tqdm load inside the functions).
"""

from __future__ import annotations

import functools
import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rocksweep.compute import compile_cost
from rocksweep.compute.arguments import WRITE_EVERY
from rocksweep.interrupts import pending as interrupt_pending
from rocksweep.interrupts import raise_pending

if TYPE_CHECKING:
    from rocksweep.compute.adaptive import AdaptiveStats, Options, Validation
    from rocksweep.scene.model import Scene


@dataclass
class SweepReport:
    """What a sweep session did. Times in seconds.

    points_done: points in the file now; computed: points computed in this session;
    done_before: points the file held when the session started; compile_s: kernel
    compile or cache load; cpu_s: the workers' CPU time on this session's points;
    refine_evaluations: the RK4 evaluations of the certification's runs among this
    session's (``compute.certify``); attrs: the file's totals (``SweepFile.finish``).
    """

    path: Path
    points_total: int
    done_before: int
    computed: int
    wall_s: float
    cpu_s: float
    compile_s: float
    refine_evaluations: int = 0
    attrs: dict = field(default_factory=dict)
    adaptive: AdaptiveStats | None = None  # adaptive sweeps: the file's counts
    validation: Validation | None = None  # adaptive sweeps with validate=True
    image: bytes | None = None  # a sweep into an in-memory file: the file's bytes

    @property
    def points_done(self) -> int:
        return self.done_before + self.computed

    @property
    def complete(self) -> bool:
        return self.points_done == self.points_total

    @property
    def rate(self) -> float:
        """Points computed per second of wall time."""
        return self.computed / self.wall_s if self.wall_s > 0 else math.nan


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during a sweep, after every finished chunk was written (``report``)."""

    def __init__(self, report: SweepReport) -> None:
        super().__init__(f"interrupted: {report.points_done} of {report.points_total} "
                         f"points saved in {report.path}")
        self.report = report


def accuracy_words(scene: Scene) -> str:
    """The numerics of a sweep as its header line says them."""
    return (f"accuracy {scene.numerics.describe()}"
            + ("; each point rerun at half the step (outputs.check)" if scene.check else ""))


def drive(sf, path: Path | None, report: SweepReport, t0: float,
           adaptive: Options | None, validate: bool, **loop_options: Any) -> SweepReport:
    """Compute the missing points of an open sink (a result file, or one in memory when
    ``path`` is None: its image lands in ``report.image``), then record the session.
    The arguments were checked before the sink was made (``compute.arguments``)."""
    pending: list = []  # finished chunks not yet in the sink (each loop writes its own)
    loop = (every_point_loop if adaptive is None
            else functools.partial(adaptive_loop, validate=validate))
    try:
        loop(sf, report, adaptive, pending=pending, **loop_options)
    except BaseException as err:
        try:
            report.wall_s = time.perf_counter() - t0
            report.attrs = sf.finish(report.wall_s, report.cpu_s,
                                     refine_evaluations=report.refine_evaluations)
        finally:
            sf.close()
        if (isinstance(err, KeyboardInterrupt) or interrupt_pending()) and not isinstance(
                err, SweepInterrupted | SystemExit):
            # any error after a Ctrl-C is the Ctrl-C (a library half-loaded by it)
            raise SweepInterrupted(report) from None
        raise
    report.wall_s = time.perf_counter() - t0
    report.attrs = sf.finish(report.wall_s, report.cpu_s,
                             refine_evaluations=report.refine_evaluations)
    if path is None:
        report.image = sf.image()
    sf.close()
    return report


class ArraySink:
    """A sink of plain arrays in memory (the grid's variables, flat, at their fill values
    until written; ``computed`` flags of an adaptive sweep): what ``sweep_arrays`` drives
    for the library's own in-memory sweeps, with the same loops as a result file. Not the
    in-memory result file (``store.writer.SweepFile`` with no path, ``rocksweep.run``):
    that one writes an HDF5 image and reads it back into a Dataset, several times the
    cost of a small sweep, which the accuracy study and the tests would pay on every
    call."""

    def __init__(self, grid: Any) -> None:
        import numpy as np  # lazy: numpy (+51 ms)

        self.grid = grid
        # zeros where the fill is 0: pages the kernel maps on first write, not touched here
        # (np.full writes every page: ~0.1 s of the main thread before the first chunk of
        # an adaptive figure at 1000 x 1000 x 3 lam, whose points are 4% computed)
        self.flat = {k: np.zeros(grid.size, dtype) if fill == 0 else np.full(grid.size, fill, dtype)
                     for k, (dtype, fill, _) in grid.scene.variables().items()}
        self._done = np.zeros(grid.size, bool)
        self.computed = np.zeros(grid.size, np.int8)  # adaptive.FILLED
        self.counts: dict = {}

    def done(self) -> Any:
        return self._done.copy()

    def write(self, res: Any) -> None:
        for k, v in res.arrays.items():
            self.flat[k][res.start:res.stop] = v
        self._done[res.start:res.stop] = True

    def state(self) -> tuple[Any, Any]:
        return self.flat["outcome"].copy(), self.computed.copy()

    def write_points(self, flat: Any, arrays: dict, flags: Any) -> None:
        for k, v in arrays.items():
            self.flat[k][flat] = v
        self.computed[flat] = flags
        self._done[flat] = True

    def write_filled(self, outcome: Any, counts: dict) -> None:
        self.flat["outcome"][:] = outcome
        self.counts = counts

    def finish(self, wall_s: float, cpu_s: float, refine_evaluations: int = 0) -> dict:
        return dict(self.counts)

    def image(self) -> None:
        return None

    def close(self) -> None:
        pass

    def arrays(self, adaptive: bool) -> dict:
        """name -> array of the grid's shape (``Grid.shape``); ``computed`` too when
        ``adaptive``."""
        out = {k: v.reshape(self.grid.shape) for k, v in self.flat.items()}
        if adaptive:
            out["computed"] = self.computed.reshape(self.grid.shape)
        return out


def sweep_arrays(scene: Scene, jobs: int = 1, chunk_size: int | None = None,
                 backend: str = "threads", scheduler: str | None = None,
                 adaptive: Options | None = None) -> tuple[dict, SweepReport]:
    """Sweep a whole scene in memory through the one driver (``drive``, the loops of
    ``rocksweep sweep``) into plain arrays: (name -> array of the grid's shape
    (``Grid.shape``), the session's report). Every variable of ``Scene.variables``; with
    ``adaptive`` (``adaptive.Options``) also ``computed`` (int8 flags,
    ``adaptive.COMPUTED_MEANING``), ``outcome`` filled everywhere, the other variables at
    their "not computed" fill values at filled points, and ``report.adaptive`` the counts.
    Identical, bit for bit, whatever ``jobs``, ``chunk_size`` and backend, and to the
    result file of ``rocksweep sweep``. For the library's own studies and tests;
    ``rocksweep.run`` returns the same as a Dataset."""
    from rocksweep.scene.grid import Grid  # lazy: yaml (+0.1 s)

    sink = ArraySink(Grid(scene))
    report = SweepReport(Path("memory"), sink.grid.size, 0, 0, 0.0, 0.0, 0.0)
    # chunks written in batches, as to a file: one by one, their sorting and copying into
    # every variable took the main thread ~0.2 s of an adaptive figure at 1000 x 1000 x 3
    drive(sink, None, report, time.perf_counter(), adaptive, False, jobs=jobs,
          backend=backend, scheduler=scheduler, chunk_size=chunk_size, where="memory",
          write_every=WRITE_EVERY, progress=False, say=lambda _line: None)
    return sink.arrays(adaptive is not None), report


class NoBar:
    """What ``progress_class`` gives when no bar is shown: tqdm's calls, doing nothing
    (tqdm's import is ~10 ms of a quiet command; no notebook warning about ipywidgets)."""

    def __init__(self, *_args: object, total: int = 0, **_kwargs: object) -> None:
        self.total = total

    def __enter__(self) -> NoBar:
        return self

    def __exit__(self, *_exc: object) -> None:
        return None

    def update(self, _n: int = 1) -> None:
        pass

    def set_description(self, _desc: str) -> None:
        pass

    def refresh(self) -> None:
        pass


def progress_class(progress: bool = True) -> type:
    """The progress bar: a widget in a notebook (``tqdm.auto``'s choice), else the
    terminal's bar (without ``tqdm.auto``'s asyncio import: ~10 ms of every command).
    No bar shown (``progress`` false): ``NoBar``."""
    if not progress:
        return NoBar
    # tqdm here, not at the top: ~10 ms that a quiet command does not pay
    if "ipykernel" in sys.modules:
        from tqdm.auto import tqdm  # lazy: tqdm (+39 ms)
    else:
        from tqdm import tqdm  # lazy: tqdm (+35 ms)
    return tqdm


def every_point_loop(sf, report: SweepReport, _options: None, *, jobs: int, backend: str,
                      scheduler: str | None, chunk_size: int | None, where: str,
                      write_every: float, progress: bool, say: Callable[[str], None],
                      pending: list) -> None:
    """Compute every missing point of an open file, writing finished chunks every
    ``write_every`` seconds (and the pending ones whatever ends the loop)."""
    from rocksweep.compute import sweep as sw  # lazy: yaml (+0.1 s)

    tqdm = progress_class(progress)

    scene = sf.grid.scene

    def write_pending() -> None:
        for merged in sw.merge_contiguous(pending):
            sf.write(merged)
            # counted once written: the interrupt's message says what the file holds (a
            # Ctrl-C between a chunk's arrival and its count had it written, not counted)
            report.computed += merged.stop - merged.start
        pending.clear()

    try:
        done = sf.done()
        report.done_before = int(done.sum())
        todo = int((~done).sum())
        n_workers = sw.effective_jobs(jobs) if backend == "threads" else 1
        size = chunk_size or sw.auto_chunk_size(todo, n_workers)
        chunks = sw.plan_chunks(~done, size)
        dims = " x ".join(f"{len(a.values)} {a.name}" for a in scene.swept) or "1 point"
        say(f"{scene.name}: {sf.grid.size} points ({dims}); {report.done_before} done, "
            f"{todo} to compute on {where}; {accuracy_words(scene)}")
        lvl = sw.level(scene)
        if todo:
            prepare_kernel(sf, lvl, report, say)
        with tqdm(total=todo, unit="pt", disable=not progress, file=sys.stderr,
                  smoothing=0.1, dynamic_ncols=True) as bar:
            t_write = time.perf_counter()
            for res in sw.run_chunks(sf.grid, chunks, lvl, jobs, backend, scheduler):
                pending.append(res)
                report.cpu_s += res.cpu_seconds
                if res.refine_evaluations is not None:
                    report.refine_evaluations += int(res.refine_evaluations.sum())
                bar.update(res.stop - res.start)
                raise_pending()  # this chunk is kept: written on the way out
                if time.perf_counter() - t_write >= write_every:
                    write_pending()
                    t_write = time.perf_counter()
    finally:
        write_pending()


def prepare_kernel(sf, lvl: int, report: SweepReport, say: Callable[[str], None]) -> None:
    """Compile or load the kernel variants the grid needs, saying what happens: the
    variants to compile, named, and what they took here before
    (``compile_cost.prepare``)."""
    from rocksweep.compute import sweep as sw  # lazy: yaml (+0.1 s)

    report.compile_s = compile_cost.prepare(sw.chunk_variants(sf.grid, lvl),
                                            lambda: sw.prepare(sf.grid, lvl), say)
    raise_pending()  # a Ctrl-C that numba's callbacks swallowed while loading


def adaptive_loop(sf, report: SweepReport, options: Options, *, jobs: int, backend: str,
                   scheduler: str | None, chunk_size: int | None, where: str,
                   write_every: float, progress: bool, say: Callable[[str], None],
                   pending: list, validate: bool = False) -> None:
    """The adaptive sweep of an open file (``rocksweep.compute.adaptive``).

    The state (outcome, computed) is read from the file; ``adaptive.run_plan`` plans
    batches from it and runs each through ``adaptive.run_batch`` (the chunk machinery:
    threads or dask); each chunk's points are written with their ``computed`` flags
    (batched every ``write_every`` seconds and whatever ends the loop); until the plan
    says "done". Then the filled classes go into ``outcome`` and the counts into the
    attributes, so a resume of a finished file stops at once. A file killed at any
    moment resumes to the same result (see ``adaptive.next_step``).
    """
    import numpy as np  # lazy: numpy (+51 ms)

    # lazy: yaml (+0.2 s)
    from rocksweep.compute import adaptive as ad
    from rocksweep.compute import sweep as sw
    from rocksweep.compute.overlap import Runner

    t_start = time.perf_counter()
    tqdm = progress_class(progress)
    scene = sf.grid.scene
    plan = options.plan(sf.grid)
    outcome, computed = sf.state()
    report.done_before = int((computed > ad.FILLED).sum())
    dims = " x ".join(f"{len(a.values)} {a.name}" for a in scene.swept)
    say(f"{scene.name}: {sf.grid.size} points ({dims}); adaptive over {plan.names[0]} x "
        f"{plan.names[1]} (coarse level {plan.coarse}: stride {2 ** plan.coarse}, "
        f"audit {100 * plan.audit:g}%); {report.done_before} computed before; on {where}; "
        f"{accuracy_words(scene)}")
    lvl = sw.level(scene)
    pending_flags: list = []

    def write_pending() -> None:
        if not pending:
            return
        flat = np.concatenate([r.flat for r in pending])
        order = np.argsort(flat, kind="stable")
        arrays = {k: np.concatenate([r.arrays[k] for r in pending])[order]
                  for k in pending[0].arrays}
        flags = np.concatenate(pending_flags)[order]
        sf.write_points(flat[order], arrays, flags)
        report.computed += len(flat)  # once written (``every_point_loop``'s)
        pending.clear()
        pending_flags.clear()

    prepared = False
    batches: list = []  # (kind, stride, points) per batch: AdaptiveStats.batches
    # worker threads kept busy with the audit candidates between batches (``Runner``)
    runner = (Runner(sf.grid, plan, computed, jobs, chunk_size)
              if backend == "threads" else None)
    with tqdm(total=0, unit="pt", disable=not progress, file=sys.stderr, smoothing=0.1,
              dynamic_ncols=True) as bar:

        def run(b: Any) -> Any:  # a batch through the chunk machinery
            nonlocal prepared
            if not prepared:
                prepare_kernel(sf, lvl, report, say)
                prepared = True
            batches.append((b.kind, b.stride, len(b)))
            bar.total += len(b)  # the work grows as refinement finds boundaries
            bar.set_description(b.kind if b.kind != "refine" else f"refine {b.stride}")
            bar.refresh()
            # written with the others every ``write_every`` seconds, not at the end of
            # each batch: a write of scattered points is ~20 ms of HDF5 on the main
            # thread, between two batches (Figure 3(b) at 1000 x 1000 x 3 lam: 34
            # batches, 0.7 s); the next batch is planned from the state in memory
            yield from ad.run_batch(sf.grid, b.flat, jobs, chunk_size, backend, scheduler,
                                    runner, b.ahead)

        t_write = time.perf_counter()
        try:
            for _batch, res, flags in ad.run_plan(plan, outcome, computed, run):
                pending.append(res)
                pending_flags.append(flags)
                report.cpu_s += res.cpu_seconds
                report.refine_evaluations += res.refine_total
                bar.update(len(res.flat))
                raise_pending()  # this chunk is kept: written on the way out
                if time.perf_counter() - t_write >= write_every:
                    write_pending()
                    t_write = time.perf_counter()
        finally:
            if runner is not None:
                runner.close()
            write_pending()
    stats = ad.stats_of(computed, options.threshold)
    stats.batches, stats.seconds = batches, time.perf_counter() - t_start  # this session's
    filled = ad.fill(plan, outcome, computed)
    sf.write_filled(filled,
                    {"points_computed": stats.computed,
                     "points_filled": stats.points - stats.computed,
                     "points_audited": stats.audited, "audit_misses": stats.audit_misses})
    report.adaptive = stats
    if validate:
        say("validating: computing the filled points of a coarse uniform lattice...")
        report.validation = ad.validate(sf.grid, plan, filled, computed, None, jobs,
                                        chunk_size, backend, scheduler)
