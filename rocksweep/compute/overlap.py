"""The adaptive sweep's worker threads kept busy between its serial batches.

Each batch of an adaptive sweep (``compute.adaptive``) is planned from the results of the
one before, so between batches the workers wait: for the last chunks of a batch, then
while the next one is planned and the finished chunks are written. ``Runner`` fills that
time with the audit candidates, which are known before the sweep starts.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

import numpy as np

from rocksweep.compute import sweep as sw
from rocksweep.compute.adaptive import FILLED, BatchResult, Plan, Subset, audit_mask
from rocksweep.scene.grid import Grid


class Runner:
    """The batches of one adaptive sweep on a pool of worker threads, the pool kept busy
    meanwhile with the audit candidates (``audit_mask``) not computed yet.

    The audit sample is fixed before the sweep starts, and every candidate is computed by
    the time the sweep ends (by a refinement, or by the audit batch), so computing them
    early costs nothing: it fills the time a worker would otherwise wait at the end of a
    batch while the others finish its last chunks and the next batch is planned (the
    passes are serial: each batch is planned from the results of the one before). Their
    results wait in memory until a batch asks for their points (``run``), which then gets
    them as if they had just been computed: what the state machine sees, and so the
    result, is unchanged (a point's result depends only on the point). A batch's own
    chunks go first: a spare chunk is started only while fewer chunks than workers run.
    """

    def __init__(self, grid: Grid, plan: Plan, computed: np.ndarray, jobs: int = 2,
                 chunk_size: int | None = None) -> None:
        self.grid, self.level = grid, sw.level(grid.scene)
        self.workers = sw.effective_jobs(jobs)
        self.chunk_size = chunk_size
        spare = np.flatnonzero(audit_mask(plan) & (np.asarray(computed).ravel() == FILLED))
        size = chunk_size or sw.auto_chunk_size(spare.size, self.workers)
        self.spare = deque(spare[i:i + size] for i in range(0, spare.size, size))
        self.ready: list[BatchResult] = []  # spare chunks done, points not asked for yet
        self.running: dict = {}  # future -> (flat, spare?)
        self.pool = ThreadPoolExecutor(self.workers)

    def _submit(self, flat: np.ndarray, spare: bool) -> None:
        self.running[self.pool.submit(self._chunk, flat)] = (flat, spare)

    def _chunk(self, flat: np.ndarray) -> BatchResult:
        r = sw.run_chunk(Subset(self.grid, flat), 0, flat.size, self.level)
        return BatchResult(flat, r.arrays, r.seconds, r.cpu_seconds, r.refine_evaluations)

    def _top_up(self) -> None:
        while self.spare and len(self.running) < self.workers:
            self._submit(self.spare.popleft(), True)

    def _take(self, want: np.ndarray, res: BatchResult) -> tuple[BatchResult | None,
                                                                    BatchResult | None]:
        """(the part of res at points in want, the rest), each None if empty."""
        hit = np.isin(res.flat, want)
        parts = []
        for m in (hit, ~hit):
            if not m.any():
                parts.append(None)
            elif m.all():
                parts.append(res)
            else:  # times and certification counted with the part asked for first
                share = m.mean() if m is hit else 0.0
                sub = {k: v[m] for k, v in res.arrays.items()}
                parts.append(BatchResult(res.flat[m], sub, res.seconds * share,
                                         res.cpu_seconds * share,
                                         int(round(res.refine_evaluations * share))
                                         if m is hit else 0))
        if parts[0] is not None and parts[1] is not None:  # the rest keeps what is left
            rest = parts[1]
            parts[1] = BatchResult(rest.flat, rest.arrays, res.seconds - parts[0].seconds,
                                   res.cpu_seconds - parts[0].cpu_seconds,
                                   res.refine_evaluations - parts[0].refine_evaluations)
        return parts[0], parts[1]

    def run(self, flat: np.ndarray) -> Iterator[BatchResult]:
        """The results of the points ``flat`` (int64[n], increasing), in chunks, as they
        are ready (spare results first)."""
        want = np.asarray(flat, np.int64)
        todo = np.ones(want.size, bool)
        kept = []
        for res in self.ready:
            got, rest = self._take(want, res)
            if rest is not None:
                kept.append(rest)
            if got is not None:
                todo[np.searchsorted(want, got.flat)] = False
                yield got
        self.ready = kept
        for part, spare in list(self.running.values()):  # spare chunks on their way
            if spare and np.isin(part, want).any():
                todo[np.isin(want, part)] = False
        need = want[todo]
        size = self.chunk_size or sw.auto_chunk_size(need.size, self.workers)
        for i in range(0, need.size, size):
            self._submit(need[i:i + size], False)
        self.spare = type(self.spare)(c[~np.isin(c, want)] for c in self.spare)
        self.spare = type(self.spare)(c for c in self.spare if c.size)
        left = int(todo.sum()) + sum(int(np.isin(p, want).sum())
                                      for p, sp in self.running.values() if sp)
        self._top_up()
        while left > 0:
            done, _ = wait(list(self.running), return_when=FIRST_COMPLETED)
            for f in done:
                part, spare = self.running.pop(f)
                res = f.result()
                if spare:
                    got, rest = self._take(want, res)
                    if rest is not None:
                        self.ready.append(rest)
                else:
                    got = res
                if got is not None:
                    left -= got.flat.size
                    yield got
            self._top_up()

    def close(self) -> None:
        """Stop: spare chunks not started are dropped, running ones finish."""
        self.spare.clear()
        for f in list(self.running):
            f.cancel()
        self.pool.shutdown(wait=True)
