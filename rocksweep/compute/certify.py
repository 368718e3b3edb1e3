"""Outcomes certified near their thresholds: close calls re-run finer until they are stable.

A run decides between overturning and not by a margin of energy. Where that margin is
small, the step's error can decide the class: at 5 steps per spring period the top mass's
spring loses ~2% of its energy to RK4 each step, and on Figure 3(a) 73 of 19 200 points
went safe where the reference overturns in mode 1 (docs/accuracy.md). The kernel reports how
close the free rocking came to the overturning saddle (``OUT_MARGIN``, ``loop._saddle``:
the vertex of the hyperbola it rocks on, in alpha_ref, ~ sqrt(|E - E_barrier|/E_ref)) and
when it was last near it (``OUT_T_CLOSE``). Close calls, on both sides of the threshold:

- a safe run below ``numerics.close_margin``, or an overturn below OVERTURN_BAND times
  it, is run again at half the steps (``fields.refined_rows``: every step and the
  rotation limit halved, the step cap doubled, the event tolerance a 16th), and again,
  until two consecutive runs give the same outcome (an overturn on the same approach,
  within ``numerics.SAME_FALL``) and the finer one is no close call at its own step (its
  margins scale with the step, ``numerics.close_margin``: a knife edge repeats itself at
  every step it is a close call at) and, below the last level, clears that margin
  ``numerics.CLEARANCE`` times (``clear``: where impacts lead to the approach, the
  margin's error can fall slower than ``close_margin`` assumes) with a margin that did
  not move between them by more than itself (``settled``), or ``Numerics.refine``
  refinements were made; the finest run is kept.
  A repeated overturn still inside the band at its own step is certified too where its
  margin converged between the two runs (``converged``: the same fall, the finer margin
  ``clear``, and its square, ~ the energy past the barrier, clear of Richardson's estimate
  of its error) and a finer run would follow (at the last level the verdict is as
  before): most of the knife-edge rule's reruns were overturns whose margin had already
  settled at level 1, the coarse step's band being far wider than its error there;
- a safe run between the close-call margin and the row's PAR_CLOSE (``numerics.
  close_band``, CLOSE_BAND times it: a near-miss, which turned back with a margin a
  coarse step's error can still reverse) is checked by a run at half the steps that stops
  ``numerics.CLOSE_AFTER`` after OUT_T_CLOSE, its last time within the band
  (``probe_rows``): past its last approach, not through the rocking to rest that holds
  most of its steps. If the finer run overturns, or does not ``clear`` its own step's
  close-call margin CLEARANCE times, or its squared margin fell below twice Richardson's
  estimate of its own error (``energy_clear``), the point is a close call as above
  (its full runs from the first refinement on);
  if not, the run's own result is kept;
- a body whose spring rings long (``ringing``: PAR_MEMORY above
  ``numerics.RINGING_MEMORY``) is not probed: its runs part from finer ones over many
  impacts, and the finer run falls on a later approach the coarse one passed wide. Its
  safe runs up to RINGING_BAND x PAR_CLOSE and its overturns up to RINGING_BAND x
  OVERTURN_BAND x the close-call margin are close calls (``ringing_calls``; their finer
  runs answer to the bands above); its class comes from two refined runs (levels 1 and
  2: not from the first one's agreement with the coarse run), and a repeated safe
  outcome below the last level is trusted only where both runs made as many impacts
  (``same_path``, within ``numerics.IMPACT_AGREE``) (docs/accuracy.md, "Springs that
  ring long", "Two paths, one class").

An overturn is a close call too where its mode hung on a graze (``mode_close``): a mode
2 whose rocking came within ``numerics.MODE_BAND`` x PAR_CLOSE of theta = 0 (a turn back
just short of an impact, after the pulse as while it acts), or a mode 1 whose deepest
impact was that shallow (OUT_MODE_GRAZE): a finer run may make the impact, or miss them
all, and fall in the other mode. So is a mode 2 whose body, in full contact before it
uplifted, came within ``numerics.LIFT_BAND`` x PAR_CLOSE of uplifting (OUT_LIFT_GRAZE, a
fraction of M g b): a finer run may uplift there by a hair, impact, and fall in mode 1.
Such a close call is trusted once two runs agree and the finer one's graze clears its own
step's band, converged margin or not. Any run, safe or overturned, whose rocking turned
back within ``numerics.GRAZE_BAND`` x PAR_CLOSE of an impact while the ground moved
(OUT_GRAZE; ``graze_close``) is re-run as well, however far from the saddle: a finer run
may make that impact and take another path (its finer runs answer to ``grazed`` below).
So is one that made an impact that shallow then (OUT_SHALLOW; ``shallow_close``), which a
finer run may miss, where it came within ``numerics.PATH_REACH`` alpha_ref of the
saddle (under a record most runs make such impacts far from it); and a run of a base
that may slide which rocked on a slipping corner (``slide_rock_close``), whose path a
finer run may not share, within that reach. So is a run of a base that may slide whose
rocking corner's normal force fell to zero, or nearly (``lifted_off``: where the corner
is held hangs on the step), while the ground moved or within ``numerics.LIFT_PAST``
alpha_ref of theta = 0 (not a falling body's); within that reach its class comes from
two refined runs.

Below the last level, a repeated outcome is not trusted either where the finer run came
within its own band of the saddle (its row's PAR_CLOSE) after a phase (event to event)
longer than ``numerics.UNSPLIT_SHARE`` of its step that one step took, before its last
approach or its fall (``unsplit``, OUT_UNSPLIT): the coarser run took the same single step
over it, so the two agree on it whatever its error (threshold seeds 37, 116 and 168:
chatters before the approach, docs/accuracy.md, "A phase no step split"). Nor where the
finer run grazed an impact it did not make (OUT_GRAZE below ``numerics.GRAZE_MARGIN``) by
an amount that moved by more than itself between the two runs (``grazed``): a coming
impact, which a finer run makes.

Only the runs near a threshold pay: on the paper's figures' full grids 39-80% more RK4
evaluations than the points' own, on their adaptive sweeps (almost only points near a
boundary) 2.3-3.1x in all (``scripts/bench_certify.py``, 2026-11-30; the points' own runs
are short: a safe flexible run ends once its energy decides it,
``kernel.transitions.flexible_bounded``: the certification is now mostly overturns);
within 0.5% of a threshold, where every run pays, the certified runs take 4.0-5.8x the
bare ones' (``scripts/threshold_sample.py``; docs/accuracy.md, "Decided by its
energy"). A base that may slide pays for the lift-offs that can change a class: Figure
3(a)'s sliding grid +0.8%, +0.7% and +0.4% at mu 0.3, 0.5 and 0.7 (re-running every
lift-off, most of them a falling body's, had cost +29% at mu 0.3; docs/sliding.md, "Near
thresholds").

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

from rocksweep.fields import refined_rows
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import (
    CLEARANCE,
    CLOSE_AFTER,
    CLOSE_BAND,
    ENERGY_ORDER,
    GRAZE_BAND,
    GRAZE_MARGIN,
    IMPACT_AGREE,
    LIFT_BAND,
    LIFT_PAST,
    MODE_BAND,
    OVERTURN_BAND,
    PATH_REACH,
    RICHARDSON_SAFETY,
    RINGING_BAND,
    RINGING_MEMORY,
    SAME_FALL,
    UNSPLIT_SHARE,
)
from rocksweep.vocab.phases import PHASE_CODE, SLIDE_ROCK


def _fell(outs: np.ndarray) -> np.ndarray:
    return ((outs[:, L.OUT_OUTCOME] == L.OUTCOME_MODE1)
            | (outs[:, L.OUT_OUTCOME] == L.OUTCOME_MODE2))


def _evaluations(outs: np.ndarray) -> np.ndarray:
    """RK4 evaluations (regular steps + event re-integrations) of result rows."""
    return outs[:, L.OUT_STEPS] + outs[:, L.OUT_EVENT_STEPS]


def _close_margin(rows: np.ndarray) -> np.ndarray:
    """float64[n]: the rows' close-call margin [alpha_ref] (``numerics.close_margin``):
    PAR_CLOSE / CLOSE_BAND."""
    return rows[:, L.PAR_CLOSE] / CLOSE_BAND


def close_calls(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: the runs (parameter rows float64[n, >= N_PAR], result rows float64[n,
    N_OUT]) re-run in full: they stayed safe with a margin below the close-call margin
    (``numerics.close_margin``: the row's PAR_CLOSE / CLOSE_BAND, in alpha_ref) or
    overturned with one below OVERTURN_BAND times it, or overturned in a mode that hung on
    a graze (``mode_close``)."""
    bound = np.where(_fell(outs), OVERTURN_BAND, 1.0) * _close_margin(rows)
    return (outs[:, L.OUT_MARGIN] < bound) | mode_close(rows, outs)


def ringing_calls(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: the first runs (parameter rows float64[n, >= N_PAR], result rows float64[n,
    N_OUT]) of bodies whose spring rings long (``ringing``) re-run in full from wider
    bands than ``close_calls``': safe up to RINGING_BAND x PAR_CLOSE (their near-misses:
    a probe up to the last approach says nothing of the approaches after it, on the path
    a finer run takes), overturned up to RINGING_BAND x OVERTURN_BAND x the close-call
    margin. Their finer runs answer to ``close_calls`` as any close call's: a band this
    wide at the last level would flag margins the finer steps resolve."""
    bound = np.where(_fell(outs), OVERTURN_BAND, CLOSE_BAND) * RINGING_BAND * _close_margin(rows)
    return ringing(rows) & (outs[:, L.OUT_MARGIN] < bound)


def mode_close(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: overturns (result rows float64[n, N_OUT] of parameter rows float64[n, >=
    N_PAR]) whose mode hung on a graze: OUT_MODE_GRAZE below ``numerics.MODE_BAND`` x
    PAR_CLOSE (a mode 2 whose rocking came that near theta = 0, a mode 1 whose deepest
    impact was that shallow), or a mode 2 whose body came within ``numerics.LIFT_BAND`` x
    PAR_CLOSE of uplifting before its first uplift (OUT_LIFT_GRAZE, over M g b): a finer
    run may make an impact this one missed (or uplift by a hair and impact), or miss
    those it made, and fall in the other mode."""
    band = rows[:, L.PAR_CLOSE]
    lifted = ((outs[:, L.OUT_OUTCOME] == L.OUTCOME_MODE2)
              & (outs[:, L.OUT_LIFT_GRAZE] < LIFT_BAND * band))
    return _fell(outs) & ((outs[:, L.OUT_MODE_GRAZE] < MODE_BAND * band) | lifted)


def graze_close(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: runs (result rows float64[n, N_OUT] of parameter rows float64[n, >= N_PAR])
    whose rocking came within ``numerics.GRAZE_BAND`` x PAR_CLOSE of an impact it did not
    make while the ground moved (OUT_GRAZE): a finer run may make that impact and take
    another path, to the other class (threshold seed 123: a safe run at 5 steps a period
    that turned back 2e-4 alpha_ref short of theta = 0 during the pulse, far from the
    saddle, where finer runs and the reference impact there and fall in mode 1)."""
    return outs[:, L.OUT_GRAZE] < GRAZE_BAND * rows[:, L.PAR_CLOSE]


def shallow_close(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: runs (result rows float64[n, N_OUT] of parameter rows float64[n, >= N_PAR])
    that made an impact shallower than ``numerics.GRAZE_BAND`` x PAR_CLOSE while the
    ground moved (OUT_SHALLOW) and came within ``numerics.PATH_REACH`` [alpha_ref] of
    the saddle, safe or overturned (OUT_MARGIN): a finer run may miss that impact and take
    another path, to the other class (threshold seed 36: safe with margin 0.21 alpha_ref
    after an impact pair 3.6e-4 deep during the pulse, where finer runs and the reference
    fall in mode 1). The mirror of ``graze_close``'s impact missed by a hair."""
    return (outs[:, L.OUT_SHALLOW] < GRAZE_BAND * rows[:, L.PAR_CLOSE]) & _within_reach(outs)


def slide_rock_close(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: runs of a base that may slide (result rows float64[n, N_OUT] of parameter
    rows float64[n, >= N_PAR]) that rocked on a slipping corner (slide-rock: OUT_REGIME's
    bit of ``vocab.phases``' code) and came within ``numerics.PATH_REACH`` [alpha_ref] of
    the saddle, safe or overturned: at 5 steps a period slide-rock can take another path
    than finer runs (threshold points under cosines of A 5-16: a slide of 4.26 m that
    erred by 14%, 0.9% at 10 steps a period), to the other class far outside the bands.
    A base without sliding (OUT_REGIME NaN) never is."""
    regime = np.nan_to_num(outs[:, L.OUT_REGIME], nan=0.0).astype(np.int64)
    rocked_slipping = (regime >> PHASE_CODE[SLIDE_ROCK]) & 1 == 1
    return rocked_slipping & _within_reach(outs)


def lifted_off(outs: np.ndarray) -> np.ndarray:
    """bool[n]: runs of a base that may slide (result rows float64[n, N_OUT]) whose
    rocking corner's normal force fell to zero (STATUS_LIFTS_OFF: the corner held, outside
    the model's contact), or within ``kernel.slide_loop.LIFT_NEAR`` M g of it in slide-rock
    (OUT_LIFT_ANGLE finite): where and when it does hangs on the step, and a coarse run can
    take another path from there, far from any band (sliding threshold seed 58: safe with
    no approach at 5 steps a period, mode 1 at 10 and finer; mode 2 at 5 and 10 with
    margins 0.26-0.31, safe or mode 1 from 20 on, as the reference). Re-run finer; where
    they also came within ``numerics.PATH_REACH`` of the saddle, their class comes from two
    refined runs, as a ringing body's (the two coarse runs can share the path). Not a run
    whose every lift-off came after the ground stopped, beyond ``numerics.LIFT_PAST``
    alpha_ref (OUT_LIFT_ANGLE, the least such angle, 0 for one while the ground moved): a
    falling body's. Nor a base without sliding (OUT_REGIME NaN): its lift-off (the no-slip
    model's contact outputs) changes nothing of its path."""
    sliding = ~np.isnan(outs[:, L.OUT_REGIME])
    return sliding & (outs[:, L.OUT_LIFT_ANGLE] < LIFT_PAST)


def _within_reach(outs: np.ndarray) -> np.ndarray:
    """bool[n]: runs (result rows float64[n, N_OUT]) that came within
    ``numerics.PATH_REACH`` [alpha_ref] of the saddle, safe or overturned (OUT_MARGIN):
    where a path that parts from the finer runs' can end on the other side."""
    return outs[:, L.OUT_MARGIN] < PATH_REACH


def clear(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: runs (parameter rows float64[n, >= N_PAR], result rows float64[n, N_OUT])
    whose margin is at least ``numerics.CLEARANCE`` times their step's close-call margin
    (PAR_CLOSE / CLOSE_BAND): clear of the saddle even where the margin's error falls only
    as the step^3 (impacts), not the step^5 ``close_margin`` assumes."""
    return outs[:, L.OUT_MARGIN] >= CLEARANCE * _close_margin(rows)


def same_fall(coarse: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """bool[n]: two runs of the same points (result rows float64[n, N_OUT]) that fell
    within ``numerics.SAME_FALL`` [p t] of each other, on the same approach (False where
    either did not fall: NaN)."""
    return np.abs(fine[:, L.OUT_T_OVERTURN] - coarse[:, L.OUT_T_OVERTURN]) <= SAME_FALL


def energy_clear(coarse: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """bool[n]: the finer of two runs of the same points (result rows float64[n, N_OUT], the
    second at half the first's steps) has a squared margin (~ |E - E_barrier|/E_ref) at
    least RICHARDSON_SAFETY times Richardson's estimate of its error, |m_f^2 - m_c^2| /
    (2^ENERGY_ORDER - 1): the side of the saddle does not hang on the step (False where
    neither run took a margin)."""
    m_c, m_f = coarse[:, L.OUT_MARGIN], fine[:, L.OUT_MARGIN]
    with np.errstate(invalid="ignore"):  # inf - inf: a margin never taken
        err = np.abs(m_f * m_f - m_c * m_c) / (2.0 ** ENERGY_ORDER - 1.0)
        return m_f * m_f >= RICHARDSON_SAFETY * err


def converged(coarse: np.ndarray, fine_rows: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """bool[n]: overturns whose margin has converged between two runs of the same points
    (result rows float64[n, N_OUT] of a run and of its refinement at half the steps, whose
    parameter rows float64[n, >= N_PAR] are ``fine_rows``): both fell, within
    ``numerics.SAME_FALL`` [p t] of each other (on the same approach), the finer one
    ``clear`` of its own step's close-call margin and ``energy_clear``: the class does not
    hang on the step."""
    return (_fell(coarse) & _fell(fine) & same_fall(coarse, fine)
            & clear(fine_rows, fine) & energy_clear(coarse, fine))


def unsplit(fine: np.ndarray) -> np.ndarray:
    """bool[n]: runs (result rows float64[n, N_OUT]) with a phase, before their last
    approach to the saddle or their fall, that ended inside the first step after its start
    and was longer than ``numerics.UNSPLIT_SHARE`` of that step (OUT_UNSPLIT): a coarser run
    at twice the step took the same single step over it, so the two runs' agreement
    (``settled``, ``converged``) says nothing of its error."""
    return fine[:, L.OUT_UNSPLIT] > UNSPLIT_SHARE


def settled(coarse: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """bool[n]: the finer of two runs of the same points (result rows float64[n, N_OUT], the
    second at half the first's steps) kept a margin whose square exceeds its change between
    them, |m_f^2 - m_c^2| <= m_f^2: were the margin's error to fall only as the step (not
    the step^5 of ``numerics.close_margin``), it would still not reach the saddle. A margin
    that moves by more than it is (an approach whose energy, ~ m^2, fell by two thirds
    in one halving) has not settled; such a run went on to the other class at finer steps
    on the threshold samples (``scripts/threshold_sample.py``)."""
    m_c, m_f = coarse[:, L.OUT_MARGIN], fine[:, L.OUT_MARGIN]
    with np.errstate(invalid="ignore"):  # inf - inf: a margin never taken
        return ~(np.abs(m_f * m_f - m_c * m_c) > m_f * m_f)


def grazed(coarse: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """bool[n]: the finer of two runs of the same points (result rows float64[n, N_OUT])
    grazed an impact it did not make by less than ``numerics.GRAZE_MARGIN`` (OUT_GRAZE,
    alpha_ref), with a graze that moved by more than itself between them: an impact a finer
    run may make (a graze that converges keeps its size; one that is a coming impact
    shrinks toward 0 as the step halves)."""
    g_c, g_f = coarse[:, L.OUT_GRAZE], fine[:, L.OUT_GRAZE]
    with np.errstate(invalid="ignore"):  # inf - inf: no graze in either
        return (g_f < GRAZE_MARGIN) & (np.abs(g_f - g_c) > g_f)


def ringing(rows: np.ndarray) -> np.ndarray:
    """bool[n]: the rows (float64[n, >= N_PAR]) of bodies whose spring remembers its past
    longer than ``numerics.RINGING_MEMORY`` (PAR_MEMORY): their runs part from finer ones
    over many impacts, far from the saddle."""
    return rows[:, L.PAR_MEMORY] > RINGING_MEMORY


def same_path(coarse: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """bool[n]: two runs of the same points (result rows float64[n, N_OUT]) that made the
    same number of impacts, within ``numerics.IMPACT_AGREE`` of the larger: one path, not
    two that parted over the impacts (what a spring that rings long carries the step's
    error across) and agree on the class by chance."""
    i_c, i_f = coarse[:, L.OUT_IMPACTS], fine[:, L.OUT_IMPACTS]
    return np.abs(i_f - i_c) <= IMPACT_AGREE * np.maximum(i_c, i_f)


def near_misses(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """bool[n]: the safe runs whose margin lies in [1/CLOSE_BAND, 1) x PAR_CLOSE, of
    bodies that do not ring long (``ringing`` ones are close calls there): checked by a
    finer run up to their last approach (``probe_rows``) before they are trusted."""
    m = outs[:, L.OUT_MARGIN]
    return (~_fell(outs) & ~ringing(rows) & (m >= _close_margin(rows))
            & (m < rows[:, L.PAR_CLOSE]))


def probe_rows(rows: np.ndarray, outs: np.ndarray) -> np.ndarray:
    """The first refinement of ``rows`` (float64[k, >= N_PAR]), stopping CLOSE_AFTER [p t]
    after each run's last approach to the saddle within the band (``outs[:, OUT_T_CLOSE]``;
    float64[k, N_OUT] the runs' results), or at the row's own end where the run never came
    within it (NaN)."""
    out = refined_rows(rows, 1)
    stop = outs[:, L.OUT_T_CLOSE] + CLOSE_AFTER
    out[:, L.PAR_TEND] = np.where(np.isnan(stop), out[:, L.PAR_TEND],
                                  np.minimum(out[:, L.PAR_TEND], stop))
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
    lifted = lifted_off(outs)
    lifted_near = lifted & _within_reach(outs)  # (their class from levels 1 and 2)
    idx = np.flatnonzero(close_calls(rows, outs) | ringing_calls(rows, outs)
                         | graze_close(rows, outs) | shallow_close(rows, outs)
                         | slide_rock_close(rows, outs) | lifted)
    # a near-miss re-run in full already (a graze) needs no probe
    near = np.setdiff1d(np.flatnonzero(near_misses(rows, outs)), idx, assume_unique=True)
    if near.size:
        checks = probe_rows(rows[near], outs[near])
        probe = run(checks, near, keep=False)
        outs[near, L.OUT_STEPS] += probe[:, L.OUT_STEPS]
        outs[near, L.OUT_EVENT_STEPS] += probe[:, L.OUT_EVENT_STEPS]
        outs[near, L.OUT_REFINE_EVALS] += _evaluations(probe)
        outs[near, L.OUT_STATUS] = outs[near, L.OUT_STATUS].astype(np.int64) | L.STATUS_REFINED
        # a near-miss the finer run overturns is a close call: its full runs from level 1
        # (the probe's run is not reused as level 1: a history, where one is recorded,
        # was not kept for it; such flips are rare: none on the four figures)
        # or which does not ``clear`` its own step's close-call margin CLEARANCE times, as
        # a finer run below the last level must (its approach came nearer the saddle than
        # the coarse run's: the coarse margin was not the run's to trust)
        # or whose squared margin fell below twice Richardson's estimate of its error
        # (``energy_clear``, as an overturn's in ``converged``: near the saddle the margin
        # is a square root of the energy's distance, its error falling as the step^2 at
        # best; a margin taken to fall as the step^3, then ^2, let threshold seeds 91 and
        # 108 and a Figure 3(a) point pass, where the reference overturns)
        idx = np.union1d(idx, near[_fell(probe) | ~clear(checks, probe)
                                   | ~energy_clear(outs[near], probe)])
    for level in range(1, levels + 1):
        if idx.size == 0:
            break
        before = outs[idx]
        spent_now = before[:, [L.OUT_STEPS, L.OUT_EVENT_STEPS, L.OUT_REFINE_EVALS]]
        finer = refined_rows(rows[idx], level)
        new = run(finer, idx)
        # the same outcome twice, and the finer run clear of the saddle by its own step's
        # margin (a knife edge agrees with itself at every step it is a close call at)
        # and, below the last level, by CLEARANCE times it (``clear``) with a margin that
        # did not move by more than itself (``settled``), or, where it spares a finer run,
        # an overturn whose margin converged between the two. At the last level none of
        # them would spare a run: the verdict there stays as before (knife edges whose
        # margins jitter at ~1e-4 alpha_ref would be flagged by ``settled``: 17 more of
        # 1935 on threshold sample 3, none of them wrong)
        trusted = ~close_calls(finer, new)
        if level < levels:
            trusted &= settled(before, new) & clear(finer, new)
            trusted |= converged(before, finer, new)
            # and, either way, no graze that moved (an impact the next run may make), nor
            # a mode that hangs on a graze (a converged margin says nothing of the mode)
            # (a first run's graze, ``graze_close``, answers to ``grazed`` too: one that
            # converged is a graze of the true path, whose touch-down at theta' ~ 0, or none,
            # leaves the body in nearly one state)
            trusted &= ~grazed(before, new) & ~mode_close(finer, new)
            # nor where the finer run came within its band of the saddle (PAR_CLOSE) after a
            # phase no step split (the two runs integrated it alike, whatever its error:
            # ``unsplit``)
            trusted &= ~(unsplit(new) & (new[:, L.OUT_MARGIN] < finer[:, L.PAR_CLOSE]))
            # and a spring that rings long stays safe on one path (``same_path``): its two
            # runs' margins may agree where the finer ones part from both over the impacts
            trusted &= ~(ringing(rows[idx]) & ~_fell(new) & ~same_path(before, new))
            # and its class comes from two refined runs, not from the first one's
            # agreement with the coarse run (both can have kept to a path the finer steps
            # leave: threshold seeds 69 and 78 rocked to rest at 5 and 10 steps a period,
            # 212 and 223, 5 and 5 impacts, and fell at 20 and finer)
            if level == 1:
                trusted &= ~ringing(rows[idx]) & ~lifted_near[idx]
        # a repeated overturn counts only if both runs fell on the same approach (within
        # SAME_FALL): two falls far apart are two trajectories that parted, whatever their
        # margins (wide-space.yaml's undamped bodies at lam 1 fell at 79, 195 and 102 p t
        # at levels 0-2 and the reference rocks to rest)
        apart = _fell(new) & ~same_fall(before, new)
        stable = (new[:, L.OUT_OUTCOME] == before[:, L.OUT_OUTCOME]) & trusted & ~apart
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
