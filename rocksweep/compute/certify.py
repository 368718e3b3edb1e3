"""Outcomes certified near their thresholds: close calls re-run finer until they are stable.

A run decides between overturning and not by a margin of energy. Where that margin is
small, the step's error can decide the class: at 5 steps per spring period the top mass's
spring loses ~2% of its energy to RK4 each step, and on Figure 3(a) 73 of 19 200 points
went safe where the reference overturns in mode 1 (docs/accuracy.md). The kernel reports how
close the free rocking came to the overturning saddle (``OUT_MARGIN``, ``loop._saddle``:
the vertex of the hyperbola it rocks on, in alpha_ref, ~ sqrt(|E - E_barrier|/E_ref)); a
run below the row's PAR_CLOSE (``numerics.close_margin``) is a close call, and so is an
overturn below ``numerics.OVERTURN_CLOSE`` x PAR_CLOSE: the overturn side of the
threshold is certified as the safe side is. A close call
is run again at half the steps (``refine_rows``: every step and the rotation limit
halved, the step cap doubled), and again, until two consecutive runs give the same
outcome (the finer one is kept) or ``Numerics.refine`` refinements were made. Only the
close calls pay: ~1-2% of the paper figures' points, whose reruns cost 1-3x what the
point did (``scripts/bench_certify.py``).

Every refined point has STATUS_REFINED in its status; one whose outcome still changed at
the last refinement also STATUS_UNCERTIFIED (flagged: not a reliable classification).
Its steps and event_steps count every run it took. The same rule runs wherever rows meet
the kernel, through the one dispatch (``compute.dispatch.run_variant``): sweeps
(``compute.sweep.run_rows``), adaptive sweeps (through the sweep's chunks), the A_min
searches (``analysis.boundaries.kernel_rows``), single runs (``compute.single.run_point``)
and the accuracy study (``analysis.accuracy.run_kernel``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rocksweep.fields import CHECK_SCALE
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import OVERTURN_CLOSE


def close_calls(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: the runs (parameter rows float64[n, >= N_PAR], result rows float64[n,
    N_OUT]) whose outcome was a close call on either side of the saddle: their free
    rocking came within the row's PAR_CLOSE x alpha_ref of the overturning saddle
    (``numerics.close_margin``), or they overturned with a margin below
    ``numerics.OVERTURN_CLOSE`` times that (an overturn commits to falling on one
    approach, with the error of every step before it)."""
    fell = (outs[:, L.OUT_OUTCOME] == L.OUTCOME_MODE1) | (
        outs[:, L.OUT_OUTCOME] == L.OUTCOME_MODE2)
    bound = np.where(fell, OVERTURN_CLOSE, 1.0) * rows[:, L.PAR_CLOSE]
    return outs[:, L.OUT_MARGIN] < bound


def refine_rows(rows: np.ndarray, level: int) -> np.ndarray:
    """Parameter rows (float64[n, >= N_PAR]) of the same points at 2**level times the
    steps (the slots of ``fields.CHECK_SCALE``: the steps after and while the ground moves,
    a record's sample step, the rotation limit; the step cap grows as the steps do).
    Powers of two are exact in float64: level 1 is the half-step rerun of ``check_rows``."""
    out = rows.copy()
    for slot, factor in CHECK_SCALE.items():
        out[:, slot] *= factor ** level
    return out


def certify(rows: np.ndarray, outs: np.ndarray, run: Callable[[np.ndarray, np.ndarray],
            np.ndarray], levels: int) -> np.ndarray:
    """Re-run the close calls among ``outs`` finer until their outcome is stable.

    rows: float64[n, N_PAR] the runs' parameter rows; outs: float64[n, N_OUT] their
    results (updated in place and returned); run(rows_subset, index) -> result rows: the
    kernel on rows float64[k, N_PAR] of the points ``index`` (int64[k], into rows);
    levels: most refinements a point may take (``Numerics.refine``; 0: none). Returns
    outs.
    """
    if levels <= 0 or outs.shape[0] == 0:
        return outs
    idx = np.flatnonzero(close_calls(rows, outs))
    for level in range(1, levels + 1):
        if idx.size == 0:
            break
        spent_now = outs[idx][:, [L.OUT_STEPS, L.OUT_EVENT_STEPS]]
        new = run(refine_rows(rows[idx], level), idx)
        stable = new[:, L.OUT_OUTCOME] == outs[idx, L.OUT_OUTCOME]
        status = new[:, L.OUT_STATUS].astype(np.int64) | L.STATUS_REFINED
        new[:, L.OUT_STATUS] = status
        new[:, L.OUT_STEPS] += spent_now[:, 0]
        new[:, L.OUT_EVENT_STEPS] += spent_now[:, 1]
        outs[idx] = new
        idx = idx[~stable]
    if idx.size:
        outs[idx, L.OUT_STATUS] = (outs[idx, L.OUT_STATUS].astype(np.int64)
                                   | L.STATUS_UNCERTIFIED)
    return outs

