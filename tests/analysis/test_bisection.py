"""The bisection behind A_min and the IDA: it converges to the threshold, and a bracket
its step cap leaves open says so."""

from __future__ import annotations

import math

import numpy as np

from rocksweep.analysis.bisection import bisect_thresholds


def classify(idx, mid):
    return [1 if m >= math.sqrt(2.0) else 0 for m in mid]


def test_a_bracket_left_open_by_the_step_cap_is_unresolved():
    lo, hi, mode = np.array([1.0, 1.0]), np.array([2.0, 2.0]), np.zeros(2, np.int64)
    runs, unresolved = bisect_thresholds(lo, hi, mode, 1e-12, classify, [1], max_iter=3)
    assert runs.tolist() == [3, 3] and unresolved.all()
    assert hi[0] - lo[0] == 0.125
    lo, hi = np.array([1.0]), np.array([2.0])
    runs, unresolved = bisect_thresholds(lo, hi, np.zeros(1, np.int64), 1e-12, classify, [1])
    assert not unresolved[0] and lo[0] < math.sqrt(2.0) <= hi[0]
    assert hi[0] - lo[0] <= 1e-12 * hi[0]
    # a cap that is not reached leaves nothing unresolved
    lo, hi = np.array([1.0]), np.array([2.0])
    _, unresolved = bisect_thresholds(lo, hi, np.zeros(1, np.int64), 0.1, classify, [1],
                                      max_iter=60)
    assert not unresolved[0]
