"""Run a scene's grid in chunks across joblib workers (threads, or dask.distributed).

No I/O here: ``run_chunks`` yields each chunk's result arrays as it finishes and the one
sweep driver (``rocksweep.compute.driver``) writes them to its sink: a result file
(``rocksweep.store.writer``, behind ``rocksweep sweep`` and ``rocksweep.run``) or plain
arrays in memory (``driver.sweep_arrays``, the library's own studies). A chunk is a
contiguous range of flat point indices (``rocksweep.scene.grid``) and costs one call into
the jitted kernel per kernel kind present in the chunk; there is no Python per point.

Local workers are threads of this process (joblib's threading backend): the chunk kernels
release the GIL, so threads compute in parallel with no process start-up, no second load
of the compiled kernel and no copies of the grid; only the few Python lines per chunk
(building its rows, converting its results) take turns.

Every point is independent of the others, so the results are identical, bit for bit,
whatever the number of workers and the chunking. Chunks are small (by default about 32
per worker), and workers take the next chunk as soon as they are free, so points that
take long (long pulses at small omega/p, chattering) do not leave a worker idle for long.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np

from rocksweep import (
    fields,
    kernel,  # lazy: numba loads at the first kernel.chunk_kernel
)
from rocksweep.compute import compile_cost
from rocksweep.compute.arguments import (
    CONNECT_TIMEOUT,
    RETRY,
    check_jobs,
    probe_scheduler,
)
from rocksweep.compute.dispatch import run_variant
from rocksweep.errors import SweepError, flag
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import point_seconds
from rocksweep.scene.grid import ChunkResult, ChunkRows, Grid
from rocksweep.scene.model import Scene
from rocksweep.vocab.settings import BACKENDS

# Upper bound of the automatic chunk size [points]; see ``auto_chunk_size``.
MAX_CHUNK = 1024
# A dask cluster with no worker for this long [s] ends the sweep with an error (at the
# start: none joined; mid-sweep: all left), instead of waiting for ever.
NO_WORKERS_TIMEOUT = 60.0
# How often [s] the dask driver checks the cluster while no chunk finishes.
CLUSTER_POLL = 1.0


def level(scene: Scene) -> int:
    """Bookkeeping level of the kernel a sweep of this scene runs (the contact variants
    account energy too: one variant per kind serves contact with and without energy)."""
    if scene.contact:
        return L.LEVEL_CONTACT
    return L.LEVEL_ENERGY if scene.energy else L.LEVEL_OUTCOME


def run_chunk(grid: Grid, start: int, stop: int, level: int) -> ChunkResult:
    """Compute one chunk (what a worker runs): rows, one kernel call per kind, results.
    With ``outputs.check`` every point runs a second time at half the step
    (``fields.check_rows``) through the same kernel, and the chunk's result holds the
    differences (``fields.CHECK_FIELDS``)."""
    t0, c0 = time.perf_counter(), time.thread_time()
    # a Grid, or adaptive's view of one (``adaptive.Subset``: the grid as ``.grid``)
    scene = grid.scene if hasattr(grid, "scene") else grid.grid.scene
    cr = grid.rows(start, stop)
    outs = run_rows(cr, cr.rows, level, scene)
    contact = level == L.LEVEL_CONTACT  # the contact variants account energy either way
    stored = fields.sweep_fields(scene.energy if contact else level == L.LEVEL_ENERGY,
                                 contact, scene.check, scene.slides)
    arrays = fields.convert(outs, cr.alpha_ref, cr.E_ref, stored, cr.rows[:, L.PAR_B])
    if scene.floor:  # the peak the body was driven by [g]
        arrays[fields.FLOOR_PFA] = scene.floor_pfa(cr.rows[:, L.PAR_AMP])
    if scene.check:
        half = run_rows(cr, fields.check_rows(cr.rows), level, scene)
        arrays.update(fields.convert_check(outs, half, cr.alpha_ref))
    return ChunkResult(start, stop, arrays, time.perf_counter() - t0,
                       time.thread_time() - c0, outs[:, L.OUT_REFINE_EVALS].astype(np.int64))


def run_rows(cr: ChunkRows, rows: np.ndarray, level: int, scene: Scene,
             certify: bool = True) -> np.ndarray:
    """Result rows float64[n, N_OUT] of ``rows`` (float64[n, N_PAR], those of ``cr`` or
    their half-step reruns) at bookkeeping ``level``: one call of the one dispatch
    (``compute.dispatch.run_variant``) per body kind present and batch of the chunk
    (``ChunkRows.batches``: the points of one excitation with samples, which ride on its
    rows, or every pulse), on the scene's ground variant. certify: re-run the close calls
    finer (``compute.certify``, up to the scene's ``numerics.refine`` refinements)."""
    refine = scene.numerics.refine if certify else 0
    outs = np.empty((rows.shape[0], L.N_OUT))
    for kind in np.unique(cr.kinds):
        for part, ex in cr.batches(cr.kinds == kind):
            if part.all():
                run_variant(rows, int(kind), level, scene.ground, refine, excitation=ex,
                            out=outs)
            else:
                outs[part] = run_variant(np.ascontiguousarray(rows[part]), int(kind), level,
                                         scene.ground, refine, excitation=ex)
    return outs


def merge_contiguous(results: Iterable[ChunkResult]) -> list[ChunkResult]:
    """The results sorted by start, with neighbours (one's stop is the next one's start)
    joined into one result: fewer, larger writes. Times add up."""
    merged: list[ChunkResult] = []
    for r in sorted(results, key=lambda r: r.start):
        last = merged[-1] if merged else None
        if last is not None and last.stop == r.start:
            merged[-1] = ChunkResult(
                last.start, r.stop,
                {k: np.concatenate((v, r.arrays[k])) for k, v in last.arrays.items()},
                last.seconds + r.seconds, last.cpu_seconds + r.cpu_seconds,
                None if last.refine_evaluations is None or r.refine_evaluations is None
                else np.concatenate((last.refine_evaluations, r.refine_evaluations)))
        else:
            merged.append(r)
    return merged


def effective_jobs(jobs: int) -> int:
    """Number of local workers for ``jobs`` (-1: all cores); see ``check_jobs``."""
    return check_jobs(jobs)


def auto_chunk_size(n_todo: int, n_workers: int, per_worker: int = 32) -> int:
    """About ``per_worker`` chunks per worker, between 8 and MAX_CHUNK points each."""
    return int(min(MAX_CHUNK, max(8, math.ceil(n_todo / (per_worker * max(1, n_workers))))))


def plan_chunks(todo: np.ndarray, chunk_size: int) -> list[tuple[int, int]]:
    """Contiguous ranges ``(start, stop)`` of at most ``chunk_size`` points covering the
    flat indices where ``todo`` (bool[size]) is true, each exactly once, in order."""
    if chunk_size < 1:
        raise ValueError(f"chunk_size = {chunk_size}: must be >= 1")
    t = np.concatenate(([False], np.asarray(todo, bool).ravel(), [False]))
    edges = np.flatnonzero(t[1:] != t[:-1])
    chunks = []
    for a, b in zip(edges[0::2].tolist(), edges[1::2].tolist(), strict=True):
        chunks.extend((s, min(s + chunk_size, b)) for s in range(a, b, chunk_size))
    return chunks


def prepare(grid: Grid, level: int) -> None:
    """Compile (or load from numba's cache) every kernel variant the grid needs, before
    any worker starts: worker threads share the compiled code, and dask workers load
    numba's cache instead of compiling concurrently."""
    for kind in grid.kinds():
        kernel.warm_up(kind, level, grid.scene.ground, grid.scene.contact_model)


def chunk_variants(grid: Grid, level: int) -> list:
    """The kernel variants (``kernel.chunk_kernel``) ``prepare`` compiles or loads."""
    return [kernel.chunk_kernel(kind, level, grid.scene.ground, grid.scene.contact_model)
            for kind in grid.kinds()]


def kernel_cache_state(grid: Grid, level: int) -> tuple[int, int]:
    """(variants to compile, variants of unknown state) among those ``prepare`` needs:
    what a sweep says before the kernel is compiled or loaded."""
    states = [compile_cost.in_cache(d) for d in chunk_variants(grid, level)]
    return sum(s is False for s in states), sum(s is None for s in states)


def check_scheduler(address: str, timeout: float = CONNECT_TIMEOUT) -> None:
    """A one-line ``SweepError`` unless a dask scheduler answers at ``address`` within
    ``timeout`` seconds (``arguments.probe_scheduler`` first: dask's own timeout does not
    bound a port that accepts and never answers)."""
    try:
        from distributed import Client  # lazy: distributed, dask (+0.2 s)
    except ImportError:
        raise SweepError("the dask backend needs dask and distributed: "
                         "pip install 'rocksweep[dask]'") from None
    probe_scheduler(address, timeout)
    try:
        Client(address, timeout=f"{timeout}s").close()
    except (OSError, TimeoutError, ValueError) as err:
        raise SweepError(f"scheduler {address}: cannot reach a dask scheduler there "
                         f"({type(err).__name__}); check the address, {RETRY}",
                         resume=flag("resume")) from None


def run_chunks(grid: Grid, chunks: Iterable[tuple[int, int]], level: int, jobs: int = 1,
               backend: str = "threads", scheduler: str | None = None
               ) -> Iterator[ChunkResult]:
    """Yield the result of every chunk, in the order they finish.

    backend "threads": ``jobs`` worker threads of this process (1: this thread; -1: one
    per core). "dask": every chunk runs on the dask.distributed cluster at ``scheduler``
    (never in this process), at most two chunks per worker thread in flight.
    """
    chunks = list(chunks)
    if backend not in BACKENDS:
        raise ValueError(f"backend = {backend!r}: must be {' or '.join(BACKENDS)}")
    n_jobs = check_jobs(jobs) if backend == "threads" else 1
    if not chunks:
        return
    prepare(grid, level)
    if backend == "dask":
        if not scheduler:
            raise SweepError("the dask backend needs a scheduler address")
        yield from _run_on_cluster(grid, chunks, level, scheduler)
    elif min(n_jobs, len(chunks)) == 1:  # one worker's work: no pool (joblib: ~60 ms)
        for a, b in chunks:
            yield run_chunk(grid, a, b, level)
    else:
        from joblib import Parallel, delayed, parallel_config  # lazy: joblib (+50 ms)

        tasks = (delayed(run_chunk)(grid, a, b, level) for a, b in chunks)
        with parallel_config(backend="threading", n_jobs=n_jobs):
            yield from Parallel(return_as="generator_unordered", batch_size=1)(tasks)


def _run_on_cluster(grid: Grid, chunks: list[tuple[int, int]], level: int,
                    scheduler: str) -> Iterator[ChunkResult]:
    """The chunks as dask futures (``client.submit``), two per worker thread in flight.

    Submitting directly, not through joblib's dask backend: with one worker thread in the
    cluster, joblib's n_jobs = 1 ran every chunk in this process. A cluster that has no
    worker for ``NO_WORKERS_TIMEOUT`` seconds (none joined, or all left) is a
    ``SweepError``; the caller saves what finished.
    """
    # lazy: distributed, dask (+0.2 s)
    from distributed import Client, KilledWorker, wait
    from distributed.client import FIRST_COMPLETED

    with Client(scheduler, timeout="10s") as client:
        try:
            client.wait_for_workers(1, timeout=NO_WORKERS_TIMEOUT)
        except TimeoutError:
            raise SweepError(f"dask cluster {scheduler}: no worker joined in "
                             f"{NO_WORKERS_TIMEOUT:g} s; start workers (dask worker "
                             f"{scheduler}), then rerun with {{resume}}",
                             resume=flag("resume")) from None
        in_flight = 2 * max(1, sum(client.nthreads().values()))
        todo = iter(chunks)
        running: dict = {}

        def submit(n: int) -> None:
            for a, b in (c for _, c in zip(range(n), todo, strict=False)):
                running[client.submit(run_chunk, grid, a, b, level, pure=False)] = (a, b)

        submit(in_flight)
        idle_since = None
        while running:
            try:
                wait(list(running), timeout=CLUSTER_POLL, return_when=FIRST_COMPLETED)
            except TimeoutError:
                pass
            done = [f for f in running if f.done()]
            if not done:
                if client.nthreads():
                    idle_since = None
                elif idle_since is None:
                    idle_since = time.monotonic()
                elif time.monotonic() - idle_since >= NO_WORKERS_TIMEOUT:
                    for f in running:
                        f.cancel()
                    raise SweepError(
                        f"dask cluster {scheduler}: lost all its workers (none for "
                        f"{NO_WORKERS_TIMEOUT:g} s) with {len(running)} chunks unfinished; "
                        "finished points are saved: start workers, then rerun with {resume}",
                        resume=flag("resume"))
                continue
            for f in done:
                a, b = running.pop(f)
                try:
                    # a result held by a worker that just left goes back to pending: never
                    # wait for it without a limit (the no-worker timer above ends the wait)
                    res = f.result(timeout=CLUSTER_POLL)
                except TimeoutError:
                    running[f] = (a, b)
                    continue
                except KilledWorker:
                    raise SweepError(
                        f"dask cluster {scheduler}: the chunk of points {a}..{b - 1} "
                        "killed the workers that ran it (out of memory?); finished "
                        "points are saved: rerun with {resume}", resume=flag("resume")
                    ) from None
                submit(1)
                yield res


# ---------------------------------------------------------------------------------------
# What a sweep will cost, before it runs (rocksweep.estimate; the sweep command's dry run)
# ---------------------------------------------------------------------------------------

# The price of a step when no sample can be run because the kernel is not compiled yet:
# ``numerics.SECONDS_PER_EVALUATION``.
# Points run to measure the cost when the kernel variant is compiled: ~10 ms of work.
ESTIMATE_SAMPLE = 256


@dataclass
class Estimate:
    """What a sweep of a scene will cost on this machine (``estimate``).

    points: grid points; steps_bound: RK4 steps if every point ran to its horizon (no
    overturning, events not counted; with ``outputs.check`` the half-step rerun's own
    bound, twice the first run's, added: ~3x); evaluations: expected
    RK4 evaluations (regular + event) of the whole sweep, measured on ``sampled`` random
    points when the kernel is compiled, else steps_bound; seconds: expected compute time
    [s] with ``jobs`` workers (compile excluded); compile_needed: a kernel variant must be
    compiled first, ~``compile_seconds`` [s]; variants: the kernel variants the scene runs.
    """

    points: int
    steps_bound: int
    evaluations: float
    seconds: float
    compile_needed: bool
    compile_seconds: float
    variants: int
    sampled: int
    jobs: int

    def __str__(self) -> str:
        how = (f"measured on {self.sampled} sample points" if self.sampled
               else "from the step bound (kernel not compiled: no sample run)")
        comp = (f"; compile first, ~{self.compile_seconds:.0f} s" if self.compile_needed
                else "; kernel compiled")
        return (f"{self.points} points, {self.evaluations:.3g} RK4 evaluations ({how}), "
                f"~{self.seconds:.3g} s of compute on {self.jobs} worker"
                f"{'s' * (self.jobs > 1)}{comp}")


def estimate(scene: Scene, jobs: int = 1, sample: int = ESTIMATE_SAMPLE,
             seed: int = 0) -> Estimate:
    """The cost of sweeping ``scene`` (see ``Estimate``), without compiling anything: a
    random sample of points runs through the kernel only when its variant is in memory or
    in numba's cache (then the estimate is measured; ~10 ms)."""
    grid = Grid(scene)
    lvl = level(scene)
    n = grid.size
    rng = np.random.default_rng(seed)
    flat = (np.arange(n) if n <= sample
            else np.sort(rng.choice(n, size=sample, replace=False)))
    cr = grid.rows_at(flat)
    # the runs of each point: the first, and with outputs.check its half-step rerun
    runs = [cr.rows, fields.check_rows(cr.rows)] if scene.check else [cr.rows]
    with np.errstate(divide="ignore", invalid="ignore"):
        per = 0.0
        for r in runs:  # the pulse at its own step, the rest at the free step
            t_pulse = np.minimum(r[:, L.PAR_TPULSE], r[:, L.PAR_TEND])
            per = per + (np.ceil(t_pulse / r[:, L.PAR_DT_ON])
                         + np.ceil((r[:, L.PAR_TEND] - t_pulse) / r[:, L.PAR_DT]))
    steps_bound = int(round(float(np.nanmean(per)) * n))
    variants = chunk_variants(grid, lvl)
    unready = [compile_cost.variant_name(d) for d in variants
               if compile_cost.in_cache(d) is not True]
    workers = check_jobs(jobs)
    sampled = 0
    if not unready:
        prepare(grid, lvl)  # loads the cached variant (no compile)
        c0 = time.thread_time()
        outs = [run_rows(cr, r, lvl, scene) for r in runs]
        cpu = time.thread_time() - c0
        evals = sum(o[:, L.OUT_STEPS] + o[:, L.OUT_EVENT_STEPS] for o in outs)
        evaluations = float(evals.mean()) * n
        seconds = cpu / len(flat) * n / workers
        sampled = len(flat)
    else:
        evaluations = float(steps_bound)
        seconds = point_seconds(evaluations) / workers
    return Estimate(n, steps_bound, evaluations, seconds, bool(unready),
                    compile_cost.forecast(unready)[0], len(grid.kinds()), sampled, workers)
