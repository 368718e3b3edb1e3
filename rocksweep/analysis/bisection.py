"""The bisection of a threshold amplitude: the one loop behind A_min
(``analysis.boundaries.a_min``) and the IDA's first overturning level (``analysis.ida``).

Each bracket [lo, hi] has a value that does not reach the target (lo) and one that does
(hi); its middle is run and replaces the end it agrees with, until hi - lo <= rtol |hi|
or float64 cannot split the bracket any further. The brackets still open are run together
at each step (one call of ``classify``), so a batched evaluator runs them in one chunk.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

#: a class that decides nothing (a flagged run): its bracket stops where it is
UNDECIDED = -99


def bisect_thresholds(lo: np.ndarray, hi: np.ndarray, mode: np.ndarray, rtol: float,
                      classify: Callable[[np.ndarray, np.ndarray], Sequence[int]],
                      target: Sequence[int], max_iter: int | None = None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Bisect the brackets (lo, hi, mode: float64[n], float64[n], int[n], updated in
    place; a bracket with NaN lo or hi is left alone) to the relative tolerance ``rtol``.

    classify(idx int[k], mid float64[k]) -> the class of a run at ``mid`` of each bracket
    ``idx`` (k of them): one of ``target`` (it reaches the threshold: hi, mode = mid,
    class), ``UNDECIDED`` (the bracket stops, unresolved), anything else (lo = mid).
    max_iter: at most this many steps (None: until every bracket is done); a bracket still
    wider than rtol |hi| when they run out (and float64 could split it) is unresolved, as
    one stopped by an undecided run. Returns (runs int64[n], unresolved bool[n])."""
    n = lo.size
    runs = np.zeros(n, np.int64)
    unresolved = np.zeros(n, bool)
    todo = np.flatnonzero(np.isfinite(lo) & np.isfinite(hi))
    step = 0
    while max_iter is None or step < max_iter:
        step += 1
        active = [i for i in todo if not unresolved[i] and hi[i] - lo[i] > rtol * abs(hi[i])]
        mids = [0.5 * (lo[i] + hi[i]) for i in active]
        # float64 cannot split the bracket any further: done to its resolution
        live = [(i, m) for i, m in zip(active, mids, strict=True) if lo[i] < m < hi[i]]
        if not live:
            break
        idx = np.array([i for i, _ in live], np.int64)
        cls = classify(idx, np.array([m for _, m in live]))
        for (i, m), k in zip(live, cls, strict=True):
            runs[i] += 1
            if int(k) == UNDECIDED:
                unresolved[i] = True
            elif int(k) in target:
                hi[i], mode[i] = m, k
            else:
                lo[i] = m
    else:  # the step cap ran out: brackets still open did not converge
        for i in todo:
            m = 0.5 * (lo[i] + hi[i])
            if not unresolved[i] and hi[i] - lo[i] > rtol * abs(hi[i]) and lo[i] < m < hi[i]:
                unresolved[i] = True
    return runs, unresolved
