"""Run a scene's grid in chunks across joblib workers (threads, or dask.distributed).

No I/O here: ``run_chunks`` yields each chunk's result arrays as it finishes and the
parent process (``rocksweep sweep``) writes them (``rocksweep.store``). A chunk is a
contiguous range of flat point indices (``rocksweep.grid``) and costs one call into the
jitted kernel per kernel kind present in the chunk; there is no Python per point.

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
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass

import numpy as np

from rocksweep.grid import Grid
from rocksweep.kernel import chunk_kernel, warm_up
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.scene import Scene

# Stored per point: name -> (dtype, fill value for "not computed", description).
VARIABLES: dict[str, tuple[str, float, str]] = {
    "outcome": ("int8", L.OUTCOME_NOT_RUN,
                "-1 not computed, 0 safe, 1 mode 1 (overturned after impacts), "
                "2 mode 2 (overturned without impact)"),
    "impacts": ("int32", -1, "number of impacts"),
    "uplifts": ("int32", -1, "number of uplifts (rocking starts from full contact)"),
    "theta_max_over_alpha": ("float64", math.nan, "max |theta| / alpha_ref"),
    "t_overturn": ("float64", math.nan, "overturning time p*t (NaN if none)"),
    "status": ("int32", 0, "bit flags (rocksweep.outcomes.STATUS_WORDS); flagged = "
               "status & (horizon | step_cap | event_cap | nonfinite)"),
    "steps": ("int64", 0, "regular RK4 steps taken"),
    "event_steps": ("int64", 0, "RK4 re-integrations spent locating events"),
}
# Stored when the scene asks for energy metrics (outputs.energy: true).
ENERGY_VARIABLES: dict[str, tuple[str, float, str]] = {
    "work_in_over_Eref": ("float64", math.nan, "work of the ground motion / E_ref"),
    "damper_loss_over_Eref": ("float64", math.nan, "energy dissipated by the damper / E_ref"),
    "impact_loss_over_Eref": ("float64", math.nan, "energy lost in impacts (net) / E_ref"),
}

# Upper bound of the automatic chunk size [points]; see ``auto_chunk_size``.
MAX_CHUNK = 1024


def variables(scene: Scene) -> dict[str, tuple[str, float, str]]:
    """The per-point variables a sweep of this scene stores."""
    return {**VARIABLES, **(ENERGY_VARIABLES if scene.energy else {})}


def level(scene: Scene) -> int:
    """Bookkeeping level of the kernel a sweep of this scene runs."""
    return L.LEVEL_ENERGY if scene.energy else L.LEVEL_OUTCOME


@dataclass
class ChunkResult:
    """Results of the points ``start <= i < stop`` (flat indices).

    arrays: name -> array[stop - start] (see ``VARIABLES``); seconds: wall time of the
    chunk in its worker; cpu_seconds: CPU time of the worker thread that ran it.
    """

    start: int
    stop: int
    arrays: dict[str, np.ndarray]
    seconds: float
    cpu_seconds: float = 0.0


def run_chunk(grid: Grid, start: int, stop: int, level: int) -> ChunkResult:
    """Compute one chunk (what a worker runs): rows, one kernel call per kind, results."""
    t0, c0 = time.perf_counter(), time.thread_time()
    cr = grid.rows(start, stop)
    outs = np.empty((stop - start, L.N_OUT))
    for kind in np.unique(cr.kinds):
        sel = cr.kinds == kind
        if sel.all():
            chunk_kernel(int(kind), level)(cr.rows, outs)
        else:
            part = np.empty((int(sel.sum()), L.N_OUT))
            chunk_kernel(int(kind), level)(np.ascontiguousarray(cr.rows[sel]), part)
            outs[sel] = part
    arrays = {
        "outcome": outs[:, L.OUT_OUTCOME].astype(np.int8),
        "impacts": outs[:, L.OUT_IMPACTS].astype(np.int32),
        "uplifts": outs[:, L.OUT_UPLIFTS].astype(np.int32),
        "theta_max_over_alpha": outs[:, L.OUT_THETA_MAX] / cr.alpha_ref,
        "t_overturn": outs[:, L.OUT_T_OVERTURN].copy(),
        "status": outs[:, L.OUT_STATUS].astype(np.int32),
        "steps": outs[:, L.OUT_STEPS].astype(np.int64),
        "event_steps": outs[:, L.OUT_EVENT_STEPS].astype(np.int64),
    }
    if level == L.LEVEL_ENERGY:
        arrays["work_in_over_Eref"] = outs[:, L.OUT_W_IN] / cr.E_ref
        arrays["damper_loss_over_Eref"] = outs[:, L.OUT_D_DAMP] / cr.E_ref
        arrays["impact_loss_over_Eref"] = outs[:, L.OUT_E_IMPACT] / cr.E_ref
    return ChunkResult(start, stop, arrays, time.perf_counter() - t0,
                       time.thread_time() - c0)


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
                last.seconds + r.seconds, last.cpu_seconds + r.cpu_seconds)
        else:
            merged.append(r)
    return merged


def effective_jobs(jobs: int) -> int:
    """Number of local workers for ``--jobs`` (-1 or 0: all cores)."""
    import os

    n = os.cpu_count() or 1
    return n if jobs <= 0 else jobs


def auto_chunk_size(n_todo: int, n_workers: int) -> int:
    """About 32 chunks per worker, between 8 and MAX_CHUNK points each."""
    return int(min(MAX_CHUNK, max(8, math.ceil(n_todo / (32 * max(1, n_workers))))))


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
        warm_up(kind, level)


def run_chunks(grid: Grid, chunks: Iterable[tuple[int, int]], level: int, jobs: int = 1,
               backend: str = "threads", scheduler: str | None = None
               ) -> Iterator[ChunkResult]:
    """Yield the result of every chunk, in the order they finish.

    backend "threads": ``jobs`` worker threads of this process (1: this thread). "dask":
    the chunks run on the dask.distributed cluster at ``scheduler`` through joblib's dask
    backend.
    """
    chunks = list(chunks)
    if not chunks:
        return
    prepare(grid, level)
    if backend == "threads" and effective_jobs(jobs) == 1:
        for a, b in chunks:
            yield run_chunk(grid, a, b, level)
        return
    from joblib import Parallel, delayed, parallel_config

    tasks = (delayed(run_chunk)(grid, a, b, level) for a, b in chunks)
    if backend == "threads":
        with parallel_config(backend="threading", n_jobs=effective_jobs(jobs)):
            yield from Parallel(return_as="generator_unordered", batch_size=1)(tasks)
    elif backend == "dask":
        if not scheduler:
            raise ValueError("the dask backend needs a scheduler address")
        from distributed import Client

        with Client(scheduler) as client, parallel_config(backend="dask"):
            n = max(1, sum(client.nthreads().values()))
            yield from Parallel(n_jobs=n, return_as="generator_unordered", batch_size=1,
                                pre_dispatch=f"{2 * n}")(tasks)
    else:
        raise ValueError(f"backend = {backend!r}: must be threads or dask")


def compute(scene: Scene, jobs: int = 1, chunk_size: int | None = None,
            backend: str = "threads", scheduler: str | None = None,
            on_chunk: Callable[[ChunkResult], None] | None = None) -> dict[str, np.ndarray]:
    """Sweep a whole scene in memory: name -> array with the grid's shape (``Grid.shape``).

    For small grids and tests; ``rocksweep sweep`` writes chunks to a file as they finish.
    """
    grid = Grid(scene)
    lvl = level(scene)
    specs = variables(scene)
    flat = {k: np.full(grid.size, fill, dtype) for k, (dtype, fill, _) in specs.items()}
    n_workers = effective_jobs(jobs) if backend == "threads" else 1
    size = chunk_size or auto_chunk_size(grid.size, n_workers)
    for res in run_chunks(grid, plan_chunks(np.ones(grid.size, bool), size), lvl, jobs,
                          backend, scheduler):
        for k, v in res.arrays.items():
            flat[k][res.start:res.stop] = v
        if on_chunk is not None:
            on_chunk(res)
    return {k: v.reshape(grid.shape) for k, v in flat.items()}
