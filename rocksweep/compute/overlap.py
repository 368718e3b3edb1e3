"""The adaptive sweep's worker threads kept busy between its serial batches.

Each batch of an adaptive sweep (``compute.adaptive``) is planned from the results of the
one before, so between batches the workers wait: for the last chunks of a batch, then
while the next one is planned and the finished chunks are written. ``Runner`` fills that
time with the points the next batch will want that the results so far already show
(``Batch.ahead``), and with the audit candidates, which are known before the sweep starts.
"""

from __future__ import annotations

import itertools
import queue
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, wait

import numpy as np

from rocksweep.compute import sweep as sw
from rocksweep.compute.adaptive import FILLED, BatchResult, Plan, Subset, audit_mask
from rocksweep.scene.grid import Grid

# A spare chunk's length [s] at the pace of the chunks so far: a batch planned meanwhile
# may wait this long for a worker; at ~50 us a point (the four figures) about 2000 points.
# A chunk's own Python (its rows, the certification's bookkeeping: ~4 ms, most of it the
# same whatever the chunk's length) and kernel calls are paid per chunk: shorter chunks
# cost more CPU (~1 s more on Figure 3(b) at 1000 x 1000 x 3 lam at 0.02 s)
SPARE_SECONDS = 0.1
# ... at least this many points
SPARE_MIN = 16
# A batch's chunks per worker (``sweep.auto_chunk_size``): 4, not a full sweep's 32. At 32
# a worker the chunks' own Python was 10-17% of the workers' CPU on the four figures at
# 1000 x 1000 x 3 lam; at 8 about half that. The longer last chunk of a batch is what the
# queued spare chunks fill (``Pool``), so 4 a worker and spare chunks of 0.1 s, not 8 and
# 0.05 s: 596 chunks instead of 1003 for the four figures, at the price of longer idle
# workers in the tail passes once the spares are done; the four figures, settings
# alternated round by round in one process, in 20.46 s against 23.87 s in memory (median
# of 4 rounds, ``Pool`` both ways) and 23.72 s against 24.77 s into a file (median of 8,
# against the executor before ``Pool``): a few per cent, about one run's noise here.
BATCH_CHUNKS = 4
# Spare chunks queued behind the running ones, per worker: a worker that finishes takes
# one at once, while the main thread plans the next batch (next_step: ~40-110 ms of the
# four figures at 1000 x 1000 x 3 lam, longer than a spare chunk) or writes. With one
# spare started only when a worker was free, both workers sat idle 0.6-0.9 s of CPU a
# figure, between batches. A batch's chunks go ahead of them (``Pool``).
SPARE_QUEUED = 2


# The next batch's points are asked for (``Runner.run``'s ``ahead``: a planning pass, ~2-40
# ms of the main thread at 1000 x 1000 x 3) only while this much of the batch's work [s,
# at the points' pace] is still to come: at its end, the next batch is planned anyway
AHEAD_SECONDS = 0.02

# ``Pool``'s priorities (lower first): a batch's chunks, the next batch's points computed
# ahead (``Runner._ahead``), spare chunks (the audit's), the workers' stop
BATCH, AHEAD, SPARE, STOP = 0, 1, 2, 3


class Pool:
    """Worker threads taking tasks by priority (lower first; in order of submission within
    one): a batch's chunks go ahead of queued spare chunks, which no worker waits for
    while a batch's chunk is queued. ``concurrent.futures``' executor has one queue,
    first in, first out."""

    def __init__(self, workers: int) -> None:
        self.tasks: queue.PriorityQueue = queue.PriorityQueue()
        self.order = itertools.count()
        self.threads = [threading.Thread(target=self._work, daemon=True)
                        for _ in range(workers)]
        for t in self.threads:
            t.start()

    def submit(self, priority: int, fn: Callable, *args: object) -> Future:
        f: Future = Future()
        self.tasks.put((priority, next(self.order), f, fn, args))
        return f

    def _work(self) -> None:
        while True:
            _p, _n, f, fn, args = self.tasks.get()
            if f is None:  # shutdown
                return
            if not f.set_running_or_notify_cancel():  # cancelled while queued
                continue
            try:
                f.set_result(fn(*args))
            except BaseException as err:  # the caller's wait gets it
                f.set_exception(err)

    def shutdown(self) -> None:
        """Stop once the running tasks finish (queued ones must be cancelled first)."""
        for _ in self.threads:  # after every queued task
            self.tasks.put((STOP, next(self.order), None, None, ()))
        for t in self.threads:
            t.join()


def _member(x: np.ndarray, sorted_want: np.ndarray) -> np.ndarray:
    """bool[len(x)]: which of x are in sorted_want (increasing): a binary search each, not
    a sort of both (np.isin) for every small chunk."""
    if sorted_want.size == 0:
        return np.zeros(x.shape, bool)
    pos = np.minimum(np.searchsorted(sorted_want, x), sorted_want.size - 1)
    return sorted_want[pos] == x


class Runner:
    """The batches of one adaptive sweep on a pool of worker threads, the pool kept busy
    meanwhile with points computed before a batch asks for them: the next batch's, that the
    results so far already want (``_ahead``), and the audit candidates (``audit_mask``) not
    computed yet.

    Both are computed by the time the sweep ends whatever else is computed: the refinement
    only ever adds wanted points (``compute.adaptive``'s least fixed point: a point the
    rules want once some of a batch's results are in is wanted once all are, if not one of
    that batch), and every audit candidate is computed (by a refinement, or by the audit
    batch). So computing them early costs nothing: it fills the time a worker would
    otherwise wait at the end of a batch while the others finish its last chunks and the
    next batch is planned (the passes are serial: each batch is planned from the results
    of the one before). Their results wait in memory until a batch asks for their points
    (``run``), which then gets them as if they had just been computed: what the state
    machine sees, and so the result, is unchanged (a point's result depends only on the
    point), and a point computed early and never asked for would only have cost its run.
    A batch's own chunks go first (``Pool``: the others wait in the queue behind them,
    the next batch's points before the audit's, and SPARE_QUEUED audit chunks a worker
    wait there for a worker to come free), and an audit chunk is short (``SPARE_SECONDS``
    at the points' pace so far), so that the next batch, on the sweep's critical path,
    waits for no long one.
    """

    def __init__(self, grid: Grid, plan: Plan, computed: np.ndarray, jobs: int = 2,
                 chunk_size: int | None = None) -> None:
        self.grid, self.level = grid, sw.level(grid.scene)
        self.workers = sw.effective_jobs(jobs)
        self.chunk_size = chunk_size
        # the audit candidates not computed yet, in order (int64[k])
        self.spare = np.flatnonzero(audit_mask(plan)
                                    & (np.asarray(computed).ravel() == FILLED))
        self.claimed = np.zeros(plan.size, bool)  # points in a chunk of this sweep
        self.pace = [0.0, 0]  # seconds, points of the chunks so far
        self.ready: list[BatchResult] = []  # early chunks done, points not asked for yet
        self.running: dict = {}  # future -> (flat, priority)
        self.pool = Pool(self.workers)
        self.ahead_points = 0  # points computed ahead of their batch (``_ahead``)

    def _submit(self, flat: np.ndarray, priority: int) -> None:
        self.claimed[flat] = True
        self.running[self.pool.submit(priority, self._chunk, flat)] = (flat, priority)

    def _chunk(self, flat: np.ndarray) -> BatchResult:
        r = sw.run_chunk(Subset(self.grid, flat), 0, flat.size, self.level)
        return BatchResult(flat, r.arrays, r.seconds, r.cpu_seconds, r.refine_evaluations)

    def _top_up(self) -> None:
        """Keep SPARE_QUEUED spare chunks a worker queued, beyond the workers themselves
        (running or waiting chunks of a batch count as busy workers)."""
        while self.spare.size and len(self.running) < self.workers * (1 + SPARE_QUEUED):
            n = max(SPARE_MIN, int(SPARE_SECONDS / max(self._per_point(), 1e-9)))
            n = min(n, self.chunk_size or n)
            self._submit(self.spare[:n], SPARE)
            self.spare = self.spare[n:]

    def _per_point(self) -> float:
        """A point's seconds at the pace of the chunks so far (1 ms before the first)."""
        return self.pace[0] / self.pace[1] if self.pace[1] else 1e-3

    def _queued(self, below: int) -> bool:
        """Whether a chunk of priority below ``below`` waits for a worker."""
        return any(pr < below and not f.running() and not f.done()
                   for f, (_flat, pr) in self.running.items())

    def _ahead(self, points: np.ndarray) -> None:
        """Queue the points (flat, int64[k], increasing) the next batch will want, those no
        chunk holds yet, behind the running batch's chunks (``AHEAD``), cut as a batch's."""
        pts = points[~self.claimed[points]]
        if pts.size == 0:
            return
        size = self.chunk_size or sw.auto_chunk_size(pts.size, self.workers, BATCH_CHUNKS)
        for i in range(0, pts.size, size):
            self._submit(pts[i:i + size], AHEAD)
        self.spare = self.spare[~self.claimed[self.spare]]  # audit candidates among them
        self.ahead_points += int(pts.size)

    def _take(self, want: np.ndarray, res: BatchResult
              ) -> tuple[BatchResult | None, BatchResult | None]:
        """(the part of res at points in want, the rest), each None if empty; the chunk's
        times go with the part asked for first."""
        hit = _member(res.flat, want)
        if hit.all() or not hit.any():
            return (res, None) if hit.all() else (None, res)

        def part(m: np.ndarray, seconds: float, cpu: float) -> BatchResult:
            r = res.refine_evaluations
            return BatchResult(res.flat[m], {k: v[m] for k, v in res.arrays.items()},
                               seconds, cpu, None if r is None else r[m])

        return part(hit, res.seconds, res.cpu_seconds), part(~hit, 0.0, 0.0)

    def run(self, flat: np.ndarray, ahead: Callable[[], np.ndarray] | None = None
            ) -> Iterator[BatchResult]:
        """The results of the points ``flat`` (int64[n], increasing), in chunks, as they
        are ready (those computed early first). ahead: the points (flat, int64[k],
        increasing) the next batch will want, from the results so far (``Batch.ahead``):
        asked whenever results came in since it was last asked and no chunk of this batch
        or of the next waits for a worker."""
        want = np.asarray(flat, np.int64)
        todo = np.ones(want.size, bool)
        kept = []
        for res in self.ready:  # chunk by chunk, as if computed now
            got, rest = self._take(want, res)
            if rest is not None:
                kept.append(rest)
            if got is not None:
                todo[np.searchsorted(want, got.flat)] = False
                yield got
        self.ready = kept
        for part, pr in list(self.running.values()):  # early chunks on their way
            if pr != BATCH:
                todo[np.searchsorted(want, part[_member(part, want)])] = False
        need = want[todo]
        size = self.chunk_size or sw.auto_chunk_size(need.size, self.workers, BATCH_CHUNKS)
        for i in range(0, need.size, size):
            self._submit(need[i:i + size], BATCH)
        self.spare = self.spare[~self.claimed[self.spare]]  # every point of want is in a chunk
        left = int(todo.sum()) + sum(int(_member(p, want).sum())
                                      for p, pr in self.running.values() if pr != BATCH)
        self._top_up()
        fresh = False  # results in since ``ahead`` was last asked
        while left > 0:
            done, _ = wait(list(self.running), return_when=FIRST_COMPLETED)
            for f in done:
                part, pr = self.running.pop(f)
                res = f.result()
                self.pace[0] += res.seconds
                self.pace[1] += res.flat.size
                got = res
                if pr != BATCH:
                    got, rest = self._take(want, res)
                    if rest is not None:
                        self.ready.append(rest)
                if got is not None:
                    left -= got.flat.size
                    fresh = True
                    yield got
            if (ahead is not None and fresh and not self._queued(SPARE)
                    and left * self._per_point() >= AHEAD_SECONDS):
                self._ahead(ahead())  # (the state holds the results yielded so far)
                fresh = False
            self._top_up()

    def close(self) -> None:
        """Stop: early chunks not started are dropped, running ones finish."""
        self.spare = self.spare[:0]
        for f in list(self.running):
            f.cancel()
        self.pool.shutdown()
