"""Outcomes certified near their thresholds: close calls re-run finer until they are stable.

A run decides between overturning and not by a margin of energy. Where that margin is
small, the step's error can decide the class: at 5 steps per spring period the top mass's
spring loses ~2% of its energy to RK4 each step, and on Figure 3(a) 73 of 19 200 points
went safe where the reference overturns in mode 1 (docs/accuracy.md). The kernel reports how
close the free rocking came to the overturning saddle (``OUT_MARGIN``, ``loop._saddle``:
the vertex of the hyperbola it rocks on, in alpha_ref, ~ sqrt(|E - E_barrier|/E_ref)) and
when it was last near it (``OUT_T_CLOSE``). Close calls, on both sides of the threshold:

- a safe run below ``numerics.close_margin``, or an overturn below OVERTURN_BAND times
  it, is run again at half the steps (``refine_rows``: every step and the rotation limit
  halved, the step cap doubled), and again, until two consecutive runs give the same
  outcome and the finer one is no close call at its own step (its margins scale with the
  step, ``numerics.close_margin``: a knife edge repeats itself at every step it is a
  close call at) or ``Numerics.refine`` refinements were made; the finest run is kept;
- a safe run between the close-call margin and the row's PAR_CLOSE (``numerics.
  close_band``, CLOSE_BAND times it: a near-miss, which turned back with a margin a
  coarse step's error can still reverse) is checked by a run at half the steps that stops
  ``numerics.CLOSE_AFTER`` after OUT_T_CLOSE, its last time within the band
  (``probe_rows``): past its last approach, not through the rocking to rest that holds
  most of its steps. If the finer run overturns, the point is a close call as above (its
  full runs from the first refinement on); if not, the run's own result is kept.

Only the runs near a threshold pay: on the paper's figures 5-17% more RK4 evaluations
(``scripts/fingerprint.py diff``); within 0.5% of a threshold, where every run pays, the
certified runs take ~2x the bare ones' (``scripts/threshold_sample.py``).

Every refined or checked point has STATUS_REFINED in its status; one whose outcome still
changed at the last refinement, or which was still a close call there, also
STATUS_UNCERTIFIED (flagged: not a reliable classification). Its steps and event_steps
count every run it took; OUT_REFINE_EVALS those of the certification's runs alone (the
price of the certification, ``rocksweep info``). The same rule runs wherever rows meet
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
from rocksweep.numerics import CLOSE_AFTER, CLOSE_BAND, OVERTURN_BAND


def _fell(outs: np.ndarray) -> np.ndarray:
    return ((outs[:, L.OUT_OUTCOME] == L.OUTCOME_MODE1)
            | (outs[:, L.OUT_OUTCOME] == L.OUTCOME_MODE2))


def _evaluations(outs: np.ndarray) -> np.ndarray:
    """RK4 evaluations (regular steps + event re-integrations) of result rows."""
    return outs[:, L.OUT_STEPS] + outs[:, L.OUT_EVENT_STEPS]


def close_calls(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: the runs (parameter rows float64[n, >= N_PAR], result rows float64[n,
    N_OUT]) re-run in full: they stayed safe with a margin below the close-call margin
    (``numerics.close_margin``: the row's PAR_CLOSE / CLOSE_BAND, in alpha_ref) or
    overturned with one below OVERTURN_BAND times it."""
    bound = np.where(_fell(outs), OVERTURN_BAND, 1.0) * (rows[:, L.PAR_CLOSE] / CLOSE_BAND)
    return outs[:, L.OUT_MARGIN] < bound


def near_misses(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: the safe runs whose margin lies in [1/CLOSE_BAND, 1) x PAR_CLOSE: checked
    by a finer run up to their last approach (``probe_rows``) before they are trusted."""
    m, band = outs[:, L.OUT_MARGIN], rows[:, L.PAR_CLOSE]
    return ~_fell(outs) & (m >= band / CLOSE_BAND) & (m < band)


def refine_rows(rows: np.ndarray, level: int) -> np.ndarray:
    """Parameter rows (float64[n, >= N_PAR]) of the same points at 2**level times the
    steps (the slots of ``fields.CHECK_SCALE``: the steps after and while the ground moves,
    a record's sample step, the rotation limit; the step cap grows as the steps do).
    Powers of two are exact in float64: level 1 is the half-step rerun of ``check_rows``."""
    out = rows.copy()
    for slot, factor in CHECK_SCALE.items():
        out[:, slot] *= factor ** level
    return out


def probe_rows(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """The first refinement of ``rows`` (float64[k, >= N_PAR]), stopping CLOSE_AFTER [p t]
    after each run's last approach to the saddle (``outs[:, OUT_T_CLOSE]``; float64[k,
    N_OUT] the runs' results)."""
    out = refine_rows(rows, 1)
    out[:, L.PAR_TEND] = np.minimum(out[:, L.PAR_TEND], outs[:, L.OUT_T_CLOSE] + CLOSE_AFTER)
    return out


def certify(rows: np.ndarray, outs: np.ndarray, run: Callable[..., np.ndarray],
            levels: int) -> np.ndarray:
    """Re-run the close calls among ``outs`` finer until their outcome is stable.

    rows: float64[n, N_PAR] the runs' parameter rows; outs: float64[n, N_OUT] their
    results (updated in place and returned); run(rows_subset, index, keep=True) -> result
    rows: the kernel on rows float64[k, N_PAR] of the points ``index`` (int64[k], into
    rows); keep=False: a probe, whose by-products (a history) are not kept; levels: most
    refinements a point may take (``Numerics.refine``; 0: none). Returns outs.
    """
    if levels <= 0 or outs.shape[0] == 0:
        return outs
    idx = np.flatnonzero(close_calls(rows, outs))
    near = np.flatnonzero(near_misses(rows, outs))
    if near.size:
        probe = run(probe_rows(rows[near], outs[near]), near, keep=False)
        outs[near, L.OUT_STEPS] += probe[:, L.OUT_STEPS]
        outs[near, L.OUT_EVENT_STEPS] += probe[:, L.OUT_EVENT_STEPS]
        outs[near, L.OUT_REFINE_EVALS] += _evaluations(probe)
        outs[near, L.OUT_STATUS] = outs[near, L.OUT_STATUS].astype(np.int64) | L.STATUS_REFINED
        # a near-miss the finer run overturns is a close call: its full runs from level 1
        # (the probe's run is not reused as level 1: a history, where one is recorded,
        # was not kept for it; such flips are rare: none on the four figures)
        idx = np.union1d(idx, near[_fell(probe)])
    for level in range(1, levels + 1):
        if idx.size == 0:
            break
        spent_now = outs[idx][:, [L.OUT_STEPS, L.OUT_EVENT_STEPS, L.OUT_REFINE_EVALS]]
        finer = refine_rows(rows[idx], level)
        new = run(finer, idx)
        # the same outcome twice, and the finer run clear of the saddle by its own step's
        # margin: a knife edge agrees with itself at every step it is a close call at
        stable = ((new[:, L.OUT_OUTCOME] == outs[idx, L.OUT_OUTCOME])
                  & ~close_calls(finer, new))
        status = new[:, L.OUT_STATUS].astype(np.int64) | L.STATUS_REFINED
        new[:, L.OUT_STATUS] = status
        new[:, L.OUT_REFINE_EVALS] = spent_now[:, 2] + _evaluations(new)
        new[:, L.OUT_STEPS] += spent_now[:, 0]
        new[:, L.OUT_EVENT_STEPS] += spent_now[:, 1]
        outs[idx] = new
        idx = idx[~stable]
    if idx.size:
        outs[idx, L.OUT_STATUS] = (outs[idx, L.OUT_STATUS].astype(np.int64)
                                   | L.STATUS_UNCERTIFIED)
    return outs
