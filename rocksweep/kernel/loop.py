"""The loop that runs one point: steps, events, actions (jitted).

``simulate_point`` owns the phase s (0 full contact, +-1 rocking on that corner) and the
state y (``layout.Y_*``); it takes fixed RK4 steps (``stepping``), asks ``events`` for the
first event inside each step and applies the transition rules (``transitions``). The
counters of events live in the result row ``out`` (``OUT_*``) as it runs, those of every
step (steps, theta_max) in locals; the actions that update them are the small helpers
below. Those on the path of every step are inlined by LLVM (``_cache.INLINE``); those of
events are calls (``_cache.INTERNAL``). No kernel function counts references
(``_nrt=False``), so passing ``prm`` or ``out`` costs nothing beyond the call.

Compile-time specialisation: the functions take the flags FLEX, DAMPED, ENERGY and GROUND
(the ground kind, ``ground.GROUNDS``; ``simulate_point`` also REACTIONS) as literals
(``Literal[bool]``, ``Literal[int]``), so numba compiles one specialisation per flag value
and the branches a variant does not need are removed at compile time (by LLVM: numba still
types and lowers both branches of an ``if``, its own dead-branch pruning does not read
literal arguments, so they cost compile time but no run time). Where that compile time
matters the choice is made while typing instead (``_static``): the ground kind's functions
(``ground``), the ground reactions' bookkeeping (``contact``: four calls at the loop's
sample points, no-ops without REACTIONS; it was half the compile time of a variant), the
rigid bound and the energy. The time history is the other exception: ``simulate_point``
gets ``hist=None`` when there is none, and numba prunes the ``if hist is not None``
branches before typing. The entry points are made from one table in ``variants``.
"""

import math

import numpy as np
from numba import literally, njit

from rocksweep.kernel._cache import INLINE, INTERNAL
from rocksweep.kernel._static import skipped_when
from rocksweep.kernel.contact import (
    SAMPLE_EVENT,
    SAMPLE_START,
    SAMPLE_STEP,
    reactions_begin,
    reactions_end,
    reactions_impact,
    reactions_sample,
)
from rocksweep.kernel.equations import mechanical_energy, tip_moment
from rocksweep.kernel.events import (
    EV_IMPACT,
    EV_NONE,
    EV_OVERTURN,
    EV_UPLIFT_POS,
    _first_event,
    hermite_min,
)
from rocksweep.kernel.ground import ground_acc, ground_flags
from rocksweep.kernel.layout import (
    HIST_CONTACT,
    HIST_D_DAMP,
    HIST_D_FRIC,
    HIST_E,
    HIST_E_IMPACT,
    HIST_PHASE,
    HIST_T,
    HIST_THETA,
    HIST_THETA_DOT,
    HIST_U,
    HIST_U_DOT,
    HIST_W_IN,
    HIST_X,
    HIST_XG,
    OUT_CONTACTS,
    OUT_D_DAMP,
    OUT_D_FRIC,
    OUT_E_END,
    OUT_E_GAINED,
    OUT_E_IMPACT,
    OUT_E_MAX,
    OUT_EVENT_STEPS,
    OUT_GRAZE,
    OUT_HIST_ROWS,
    OUT_IMPACTS,
    OUT_LIFT_ANGLE,
    OUT_LIFT_GRAZE,
    OUT_MARGIN,
    OUT_MODE_GRAZE,
    OUT_N_GAINING,
    OUT_OUTCOME,
    OUT_REFINE_EVALS,
    OUT_REGIME,
    OUT_SHALLOW,
    OUT_SLIDE_FINAL,
    OUT_SLIDE_MAX,
    OUT_STATUS,
    OUT_STEPS,
    OUT_T_CLOSE,
    OUT_T_END,
    OUT_T_FIRST_IMPACT,
    OUT_T_OVERTURN,
    OUT_THETA_MAX,
    OUT_UNSPLIT,
    OUT_UPLIFTS,
    OUT_W_IN,
    OUTCOME_MODE1,
    OUTCOME_MODE2,
    OUTCOME_SAFE,
    PAR_ALPHA_REF,
    PAR_B,
    PAR_CLOSE,
    PAR_DT,
    PAR_DT_ON,
    PAR_G,
    PAR_HCG,
    PAR_M,
    PAR_MAXEVENTS,
    PAR_MAXSTEPS,
    PAR_MTOT,
    PAR_REC_H,
    PAR_ROT_STEP,
    PAR_T_AIR,
    PAR_TEND,
    PAR_THETA0,
    PAR_THETA_DOT0,
    PAR_TO_REST,
    PAR_TPULSE,
    PAR_U0,
    PAR_U_DOT0,
    PHASE_REST,
    PHASE_ROCK,
    STATUS_AIRBORNE,
    STATUS_BOUNDED,
    STATUS_E_ABOVE_1,
    STATUS_ENERGY_GAIN,
    STATUS_EVENT_CAP,
    STATUS_HIST_FULL,
    STATUS_HORIZON,
    STATUS_NONFINITE,
    STATUS_OVERTURNED,
    STATUS_REST,
    STATUS_SETTLED,
    STATUS_STEP_CAP,
    Y_D_DAMP,
    Y_THETA,
    Y_THETA_DOT,
    Y_U,
    Y_U_DOT,
    Y_W_IN,
)
from rocksweep.kernel.stepping import first_stage, rk4_from
from rocksweep.kernel.transitions import (
    flexible_bounded,
    impact_map,
    rest_proven,
    rigid_bounded,
    uplift_side,
)

# the outcome-only variants do not compile the energy (``_static``)
_energy = skipped_when(False, mechanical_energy, 0.0)
# nor does a flexible variant compile the rigid body's bound (its caller's branch is dead
# there; the value given instead is never used)
_rigid_bounded = skipped_when(True, rigid_bounded, -1.0)
# and a rigid one not the flexible body's (``flexible_bounded``)
_flexible_bounded = skipped_when(False, flexible_bounded, -1.0)

# _step_length: a time within this fraction of a record step of a grid time is on it (t
# sums steps of ~1e-2..1; its round-off is ~1e-16 relative, far below).
ALIGN_SLACK = 1e-7
# _near_saddle's bounds are widened by this (relative, and in rad), ~1e6 times the
# round-off of the quantities compared (|theta|, atan(b/h_cg) <= pi/2 rad)
SADDLE_SLACK = 1e-9


@njit(cache=True, **INTERNAL)
def simulate_point(prm, out, hist, FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    """Run one point from rest (or the given initial state) to a decided outcome, a cap or
    the horizon: the no-slip rocking model (``variants.CONTACTS``).

    prm: float64[N_PAR] parameter row; out: float64[N_OUT] result row (filled); hist:
    float64[n, N_HIST] history buffer, or None (no history: its code is not compiled).
    REACTIONS: track the ground reactions (``contact``: friction demand, lowest normal
    force, impulse ratio) at states the loop reaches anyway, or not (no-ops, not compiled).
    GROUND (``layout.GROUND_*``, a row of ``ground.GROUNDS``): the ground kind; one with a
    vertical also lands on PAR_T_AIR, where g + a_v reaches 0, and stops (STATUS_AIRBORNE).
    """
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    t, dt, t_pulse, t_end = 0.0, prm[PAR_DT], prm[PAR_TPULSE], prm[PAR_TEND]
    dt_on = prm[PAR_DT_ON]  # the step while the ground moves (``numerics.step_sizes``)
    max_steps, max_events = prm[PAR_MAXSTEPS], prm[PAR_MAXEVENTS]
    # > 0: a record, whose samples the steps land on while it acts (a ground kind with
    # records only; ``ground_flags``: constants of the variant)
    records, vertical = ground_flags(GROUND)
    h_rec = prm[PAR_REC_H] if records else 0.0
    t_air = prm[PAR_T_AIR] if vertical else math.inf
    on = 0.0 < t_pulse
    y, s = _start(prm, out, hist, on, FLEX, DAMPED, GROUND)
    # decide the outcome (``_decided``) at the first loop top after the pulse and after each
    # impact (PAR_TO_REST: go on to rest; a history from a tilt would end at once otherwise)
    free_check = True
    # the counters of every step stay in registers (in out: ~3% slower); the rest is in out
    steps, event_steps, theta_max = 0, 0, abs(y[Y_THETA])
    # the ground reactions' bookkeeping (``contact``): its tracker, None without REACTIONS
    track = reactions_begin(REACTIONS, t, y, s, on, prm, out, FLEX, DAMPED, ENERGY, GROUND)
    # The rotation limit (PAR_ROT_STEP, 0: off): a rocking step may turn the body by at most
    # rot, predicted from theta' and the last step's |theta''| (acc), and checked after
    # the step: a huge slow pulse or a fall is not crossed in a handful of steps.
    rot = prm[PAR_ROT_STEP]
    acc = 0.0
    margin = np.inf  # OUT_MARGIN, in a register
    graze = dip = lift = np.inf  # OUT_GRAZE, OUT_MODE_GRAZE before an impact, OUT_LIFT_GRAZE
    t_close = np.nan  # OUT_T_CLOSE
    t_ev, first, unsplit, u_close = 0.0, True, 0.0, 0.0  # OUT_UNSPLIT's (``_unsplit``)
    # ``_near_saddle``'s bounds, once per run (saddle0 = NaN: no gate, every free rocking
    # step takes ``_saddle``'s test; a row without a body, as warm_up's)
    near = _saddle_bounds(prm)

    while True:
        on = t < t_pulse
        # why the run ends before this step, if it does (a STATUS_* bit); written out here,
        # not in a helper: a helper taking the arrays costs ~15% at every step
        if s == 0 and not on and rest_proven(y, prm, FLEX):
            # rest is proven from this state; if the rest-rate rule made it (a chattering
            # sequence cut short: STATUS_SETTLED), the run ends but says so, not "rest"
            if not int(out[OUT_STATUS]) & STATUS_SETTLED:
                _flag(out, STATUS_REST)
            break
        if t >= t_end:
            if not int(out[OUT_STATUS]) & STATUS_BOUNDED:  # else: decided, went on to show
                _flag(out, STATUS_HORIZON)
            break
        if vertical and t >= t_air:
            _flag(out, STATUS_AIRBORNE)
            break
        if not on and free_check and (FLEX or s != 0):
            free_check = False
            bound, theta_max, margin, t_close = _decided(t, y, s, theta_max, margin, t_close,
                                                         prm, FLEX, ENERGY, REACTIONS)
            u_close = unsplit if t_close == t else u_close
            if bound:
                _flag(out, STATUS_BOUNDED)
                if prm[PAR_TO_REST] == 0.0:
                    break
        if steps + event_steps >= max_steps:
            _flag(out, STATUS_STEP_CAP)
            break
        if out[OUT_IMPACTS] + out[OUT_UPLIFTS] >= max_events:
            _flag(out, STATUS_EVENT_CAP)
            break
        h, lands = _step_length(t, on, dt, dt_on, t_pulse, t_end, h_rec)
        air = vertical and t + h >= t_air  # the step lands where g + a_v reaches 0
        if air:
            h, lands = t_air - t, False
        if s != 0 and rot > 0.0:
            h_rot = _rotation_step(y[Y_THETA_DOT], acc, rot)
            if h_rot < h:
                h, lands, air = h_rot, False, False
        k1 = first_stage(t, y, s, on, prm, FLEX, DAMPED, ENERGY, GROUND)  # of any step from y
        y1 = rk4_from(t, y, h, k1, s, on, prm, FLEX, DAMPED, ENERGY, GROUND)
        steps += 1
        if s != 0 and rot > 0.0:
            # theta'' was not known before the step (after an uplift, or a pulse's rise):
            # a step that turned the body by more than twice the limit is taken again,
            # shorter (the turn grows like h to h^2); NaN ends the loop (caught below)
            turn = abs(y1[Y_THETA] - y[Y_THETA])
            while turn > 2.0 * rot:
                h, lands, air = h * max(0.25, 0.9 * math.sqrt(rot / turn)), False, False
                y1 = rk4_from(t, y, h, k1, s, on, prm, FLEX, DAMPED, ENERGY, GROUND)
                steps += 1
                turn = abs(y1[Y_THETA] - y[Y_THETA])
            acc = abs(y1[Y_THETA_DOT] - y[Y_THETA_DOT]) / h
        if not _finite(y1):
            _flag(out, STATUS_NONFINITE)
            break
        ev, tau, y_ev, n, low = _first_event(t, y, k1, y1, h, s, on, prm, FLEX, DAMPED, ENERGY,
                                             GROUND)
        event_steps += n
        if s != 0:
            theta_max = _theta_max(y, y_ev, tau, s, theta_max)  # (y_ev, tau) = (y1, h) if none

        if ev == EV_NONE:
            if s != 0 and (on or out[OUT_IMPACTS] == 0.0):  # (no impact yet: mode 2)
                g = _graze(y, y1, h, s, prm, np.inf)  # one call site: one inlined copy
                graze = min(graze, g) if on else graze
                dip = min(dip, g) if out[OUT_IMPACTS] == 0.0 else dip
            elif s == 0 and out[OUT_IMPACTS] == 0.0:  # (before the first uplift)
                lift = min(lift, low)
            t, y, first = (t_pulse if lands else (t_air if air else t + h)), y1, False
            if s != 0 and not on and _near_saddle(y, s, near):
                q = _saddle(y, s, prm)
                t_close, u_close = (t, unsplit) if q < prm[PAR_CLOSE] else (t_close, u_close)
                margin = min(margin, q)
            _record(hist, t, y, s, t < t_pulse, prm, out, FLEX, GROUND)
            # the step's end, with the step's own ground motion
            track = reactions_sample(REACTIONS, track, t, y, s, on, SAMPLE_STEP, prm, out, FLEX,
                                     DAMPED, ENERGY, GROUND)
            if lands:
                s, track = _pulse_end(t, y, s, track, prm, out, hist, FLEX, DAMPED, ENERGY,
                                      REACTIONS, GROUND)
            continue

        t, y = t + tau, y_ev
        unsplit, t_ev, first = _unsplit(t - t_ev, first, dt_on if on else dt, unsplit), t, True
        _record(hist, t, y, s, on, prm, out, FLEX, GROUND)  # the event state, last of its phase
        track = reactions_sample(REACTIONS, track, t, y, s, on, SAMPLE_EVENT, prm, out, FLEX,
                                 DAMPED, ENERGY, GROUND)
        if ev == EV_OVERTURN:
            _overturned(t, out)
            break
        y, s = _act(ev, t, y, s, on, prm, out, FLEX, DAMPED, ENERGY, REACTIONS, GROUND)
        free_check = free_check or ev == EV_IMPACT
        _record(hist, t, y, s, on, prm, out, FLEX, GROUND)
        # the state after the action starts the next phase's samples
        track = reactions_sample(REACTIONS, track, t, y, s, on, SAMPLE_START, prm, out, FLEX,
                                 DAMPED, ENERGY, GROUND)
    out[OUT_MARGIN] = margin
    out[OUT_T_CLOSE] = t_close
    out[OUT_UNSPLIT] = u_close if out[OUT_OUTCOME] == OUTCOME_SAFE else unsplit
    out[OUT_GRAZE] = graze
    out[OUT_MODE_GRAZE] = dip if out[OUT_IMPACTS] == 0.0 else out[OUT_MODE_GRAZE]
    out[OUT_LIFT_GRAZE] = lift / tip_moment(prm[PAR_G], prm)
    _finish(t, y, s, steps, event_steps, theta_max, prm, out, FLEX, ENERGY)
    reactions_end(REACTIONS, prm, out)


@njit(cache=True, **INTERNAL)
def _start(prm, out, hist, on, FLEX, DAMPED, GROUND):
    """The state at t = 0 and its phase: at rest (uplifted at once if the ground's motion
    at t = 0 tips the body, a cosine pulse's peak), or the row's initial state, rocking on
    the corner theta (else theta') points to; the result row reset, the first history row
    written. Returns (y, s)."""
    y = (prm[PAR_THETA0], prm[PAR_THETA_DOT0], prm[PAR_U0], prm[PAR_U_DOT0], 0.0, 0.0)
    _reset(out)
    if y[Y_THETA] != 0.0 or y[Y_THETA_DOT] != 0.0:
        s = 1 if y[Y_THETA] > 0.0 or (y[Y_THETA] == 0.0 and y[Y_THETA_DOT] > 0.0) else -1
    else:
        s = _uplift(0.0, y, on, prm, out, FLEX, DAMPED, GROUND)
    _record(hist, 0.0, y, s, on, prm, out, FLEX, GROUND)
    return y, s


@njit(cache=True, **INTERNAL)
def _pulse_end(t, y, s, track, prm, out, hist, FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    """A step landed on the pulse's end (t = PAR_TPULSE). Returns (s, the reactions'
    tracker).

    The pulse ends with a jump of xg'' (a cosine pulse ends at its peak), and Q jumps with
    it by m_A h_A xg'': a body in full contact may now be past the uplift threshold, which
    no crossing inside the next step would show. Checked at once, as at t = 0 and after an
    impact. The contact bookkeeping starts a new segment (H jumps with xg'')."""
    off = t < t  # false: a bool value (a literal False would compile the callees again)
    if s == 0:
        s = _uplift(t, y, off, prm, out, FLEX, DAMPED, GROUND)
        if s != 0:
            _record(hist, t, y, s, off, prm, out, FLEX, GROUND)
    track = reactions_sample(REACTIONS, track, t, y, s, off, SAMPLE_START, prm, out, FLEX,
                             DAMPED, ENERGY, GROUND)
    return s, track


@njit(cache=True, **INTERNAL)
def _act(ev, t, y, s, on, prm, out, FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    """The action of an impact or an uplift located at (t, y) in phase s. Returns (y, s).

    Impact: the impact map (``_apply_impact``; its impulse into the contact outputs).
    Uplift: theta = theta' = 0 exactly, now rocking on the located corner."""
    if ev == EV_IMPACT:
        y_new, s_new = _apply_impact(t, y, s, on, prm, out, FLEX, DAMPED, ENERGY, GROUND)
        reactions_impact(REACTIONS, y, s, y_new, s_new, prm, out, FLEX)
        return y_new, s_new
    out[OUT_UPLIFTS] += 1.0
    return (0.0, 0.0, y[Y_U], y[Y_U_DOT], y[Y_W_IN], y[Y_D_DAMP]), (1 if ev == EV_UPLIFT_POS
                                                                     else -1)


# ----------------------------------------------------------------------------------------
# The loop's actions
# ----------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _flag(out, bit):
    """Set a STATUS_* bit in the result row."""
    out[OUT_STATUS] = int(out[OUT_STATUS]) | bit


@njit(cache=True, **INLINE)
def _reset(out):
    """The result row before the first step: counters 0, times NaN, safe so far."""
    out[OUT_OUTCOME] = OUTCOME_SAFE
    out[OUT_STATUS] = 0.0
    out[OUT_IMPACTS] = 0.0
    out[OUT_UPLIFTS] = 0.0
    out[OUT_CONTACTS] = 0.0
    out[OUT_T_OVERTURN] = np.nan
    out[OUT_T_FIRST_IMPACT] = np.nan
    out[OUT_T_END] = 0.0
    out[OUT_E_IMPACT] = 0.0  # net energy lost in impacts
    out[OUT_E_GAINED] = 0.0
    out[OUT_N_GAINING] = 0.0
    out[OUT_E_MAX] = 0.0
    out[OUT_HIST_ROWS] = 0.0
    out[OUT_REFINE_EVALS] = 0.0  # the certification's reruns add theirs (compute.certify)
    out[OUT_UNSPLIT] = 0.0  # (the no-slip loop sets its own at the end; a sliding base none)
    out[OUT_MODE_GRAZE] = 0.0  # the deepest impact so far (``impact_depths``)
    out[OUT_SHALLOW] = np.inf  # the shallowest while the ground moves
    out[OUT_LIFT_ANGLE] = np.inf  # (a base that may slide: ``slide_loop._lifted``)
    # the sliding base's (``slide_loop`` sets its own; the no-slip model has none)
    out[OUT_SLIDE_MAX] = np.nan
    out[OUT_SLIDE_FINAL] = np.nan
    out[OUT_REGIME] = np.nan
    out[OUT_D_FRIC] = np.nan


@njit(cache=True, **INLINE)
def _step_length(t, on, dt, dt_on, t_pulse, t_end, h_rec):
    """(h, lands): the step, dt_on while the ground moves and dt after, shortened to land
    exactly on the pulse's end (lands) or on the horizon.

    While a record acts (h_rec > 0), steps end on the grid j h_rec (h_rec = p DT / m, m an
    integer), which holds every sample time: no step straddles a sample, so the input is
    one straight line inside each step and RK4 keeps its order. A step starting off the
    grid (after an event) goes to the next grid time; one starting within ALIGN_SLACK of a
    grid time counts as on it (t is a sum of steps: round-off).
    """
    if on:
        if h_rec > 0.0:
            t_next = (math.floor(t / h_rec + ALIGN_SLACK) + 1.0) * h_rec
            if t_next >= t_pulse - ALIGN_SLACK * h_rec:
                return t_pulse - t, True
            return t_next - t, False
        if t + dt_on >= t_pulse:
            return t_pulse - t, True
        return dt_on, False
    if t + dt > t_end:
        return t_end - t, False
    return dt, False


@njit(cache=True, **INLINE)
def _rotation_step(theta_dot, acc, rot):
    """Longest step [s] whose predicted rotation |theta'| h + acc h^2 / 2 is rot [rad]
    (theta' [rad/s], acc: |theta''| [rad/s^2] estimated over the last step)."""
    w = abs(theta_dot)
    den = w + math.sqrt(w * w + 2.0 * acc * rot)
    return 2.0 * rot / den if den > 0.0 else math.inf


@njit(cache=True, **INLINE)
def _finite(y):
    return (math.isfinite(y[Y_THETA]) and math.isfinite(y[Y_THETA_DOT])
            and math.isfinite(y[Y_U]) and math.isfinite(y[Y_U_DOT]))


@njit(cache=True, **INLINE)
def impact_depths(y, on, prm, out):
    """An impact's depth at state y, how far below theta = 0 its arc would have gone, in
    alpha_ref: (theta'/alpha_ref)^2 / 2 (theta'^2 / 2 theta'', theta'' ~ p^2 alpha_ref near
    theta = 0). The deepest is OUT_MODE_GRAZE (a finer run that missed them all would
    fall in mode 2), the shallowest while the ground moves (``on``) OUT_SHALLOW (a finer
    run may miss it and take another path). Both loops' impacts call it."""
    v = y[Y_THETA_DOT] / prm[PAR_ALPHA_REF]
    depth = 0.5 * v * v
    out[OUT_MODE_GRAZE] = max(out[OUT_MODE_GRAZE], depth)
    if on:
        out[OUT_SHALLOW] = min(out[OUT_SHALLOW], depth)


@njit(cache=True, **INLINE)
def _graze(y, y_end, h, s, prm, graze):
    """OUT_GRAZE updated over a rocking step (t, y) -> (t + h, y_end) on corner s with no
    event in it: where s theta fell and rose again inside the step (an arc that turned
    back just short of an impact), the minimum of the step's cubic Hermite interpolant of
    s theta, in alpha_ref, if below ``graze``. The loops call it while the ground moves:
    a graze there decides the forced response (after it, the free rocking's grazes moved
    between runs at many points of the figures and decided no class; docs/accuracy.md,
    "Grazes while the ground moves")."""
    g0, g1 = s * y[Y_THETA], s * y_end[Y_THETA]
    d0, d1 = s * y[Y_THETA_DOT], s * y_end[Y_THETA_DOT]
    if g0 > 0.0 and g1 > 0.0 and d0 < 0.0 < d1:
        _, g_min = hermite_min(g0, d0, g1, d1, h)
        return min(graze, g_min / prm[PAR_ALPHA_REF])
    return graze


@njit(cache=True, inline="always")
def _unsplit(tau, one_step, h, unsplit):
    """OUT_UNSPLIT so far, updated at an event that ended a phase of length tau [s]: where
    the phase ended inside the first step after its start (one_step), tau / h (h [s]: the
    step then in effect, dt_on while the ground moves, dt after) if above ``unsplit``. Such
    a phase is one RK4 step of length tau at every step longer than it, so two runs at such
    steps agree on it whatever its error. The loop keeps the value at t_close too: a safe
    run reports the phases up to its last approach to the saddle, an overturn all those
    before its fall."""
    return max(unsplit, tau / h) if one_step else unsplit


@njit(cache=True, **INLINE)
def _theta_max(y, y_end, h_end, s, theta_max):
    """theta_max updated over a rocking step (t, y) -> (t + h_end, y_end), including a
    turning point inside it."""
    a_end = abs(y_end[Y_THETA])
    if a_end > theta_max:
        theta_max = a_end
    if s * y[Y_THETA_DOT] > 0.0 and s * y_end[Y_THETA_DOT] < 0.0:
        # turning point inside the step: Hermite maximum of s*theta = -min(-s*theta)
        _, gm = hermite_min(-s * y[Y_THETA], -s * y[Y_THETA_DOT], -s * y_end[Y_THETA],
                            -s * y_end[Y_THETA_DOT], h_end)
        if -gm > theta_max:
            theta_max = -gm
    return theta_max


@njit(cache=True, **INTERNAL)
def _uplift(t, y, on, prm, out, FLEX, DAMPED, GROUND):
    """Check uplift from full contact at (t, y) and count it. Returns the new phase."""
    s = uplift_side(t, y, on, prm, FLEX, DAMPED, GROUND)
    if s != 0:
        out[OUT_UPLIFTS] += 1.0
    return s


@njit(cache=True, **INTERNAL)
def _apply_impact(t, y, s, on, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    """Impact at (t, y) ending rocking on corner s: the impact map and its counters; back
    in full contact, uplift is checked again at once. Returns (y, new phase)."""
    out[OUT_IMPACTS] += 1.0
    if out[OUT_IMPACTS] == 1.0:
        out[OUT_T_FIRST_IMPACT] = t
    impact_depths(y, on, prm, out)
    y, s_new, e, e_d, loss = impact_map(y, s, prm, FLEX, ENERGY)
    if e > out[OUT_E_MAX]:
        out[OUT_E_MAX] = e
    if e > 1.0:
        _flag(out, STATUS_E_ABOVE_1)
    if s_new == 0:
        out[OUT_CONTACTS] += 1.0
        if e > 0.0:
            _flag(out, STATUS_SETTLED)
    if ENERGY:
        out[OUT_E_IMPACT] += e_d
        if loss < 0.0:
            out[OUT_E_GAINED] -= loss
            out[OUT_N_GAINING] += 1.0
            _flag(out, STATUS_ENERGY_GAIN)
    if s_new == 0:
        s_new = _uplift(t, y, on, prm, out, FLEX, DAMPED, GROUND)
    return y, s_new


@njit(cache=True, **INTERNAL)
def _decided(t, y, s, theta_max, margin, t_close, prm, FLEX, ENERGY, REACTIONS):
    """After the pulse, at the first loop top after it and after each impact: is the
    outcome decided (safe)? Returns (decided, theta_max, margin, t_close).

    A rigid body's E is constant to its next impact: its OUT_MARGIN is taken here, and
    ``rigid_bounded`` gives the peak still to come. A flexible body's T + V only falls
    (``flexible_bounded``, whose energy margin a decided run's OUT_MARGIN takes, as a
    rigid body's), tested where only the outcome is asked for: a run that accounts energy
    or the ground's reactions goes on, its story to rest was asked for.
    """
    literally(FLEX)
    if FLEX:
        q = -1.0 if ENERGY or REACTIONS else _flexible_bounded(FLEX, y, s, theta_max, prm)
        if q >= 0.0:  # decided: its energy margin is the closest it comes from here on
            margin = min(margin, q)
            if q < prm[PAR_CLOSE]:
                t_close = t
        return q >= 0.0, theta_max, margin, t_close
    margin = _rigid_margin(FLEX, y, s, prm, margin)
    if margin < prm[PAR_CLOSE]:
        t_close = t
    peak = _rigid_bounded(FLEX, y, s, prm, FLEX)
    return peak >= 0.0, max(theta_max, peak), margin, t_close


@njit(cache=True, **INTERNAL)
def _energy_margin(y, s, prm, margin):
    """A rigid body's OUT_MARGIN once the ground is still, rocking on corner s: its energy
    is then constant to the next impact, and sqrt(|E - E_ref|/E_ref) (E_ref = M g (R -
    h_cg), the barrier) is the vertex distance ``_saddle`` measures near the saddle; taken
    here too because a run may end at once (STATUS_BOUNDED) or overturn without a step
    near the saddle."""
    hcg = prm[PAR_HCG]
    e_ref = prm[PAR_MTOT] * prm[PAR_G] * (math.hypot(prm[PAR_B], hcg) - hcg)
    e = mechanical_energy(y[Y_THETA], y[Y_THETA_DOT], 0.0, 0.0, s, prm, False)
    q = math.sqrt(abs(e - e_ref) / e_ref)
    return q if q < margin else margin


# a flexible variant compiles neither this nor the rigid mechanical_energy it calls (as
# _rigid_bounded)
_rigid_margin = skipped_when(True, _energy_margin, np.inf)


@njit(cache=True, inline="always")
def _saddle_bounds(prm):
    """``_near_saddle``'s constants of a run: (v_cap [rad/s], saddle0 [rad], r0 [rad],
    r_u [rad/m]); saddle0 = NaN where the row has no body (h_cg or M not > 0)."""
    sl = SADDLE_SLACK
    half = 0.5 * prm[PAR_ALPHA_REF] * (1.0 + sl)
    if not (prm[PAR_HCG] > 0.0 and prm[PAR_MTOT] > 0.0):
        return half, np.nan, 0.0, 0.0
    saddle0 = math.atan(prm[PAR_B] / prm[PAR_HCG])
    r_u = prm[PAR_M] / (prm[PAR_MTOT] * prm[PAR_HCG]) * (1.0 + sl)
    return half, saddle0, half * (1.0 + sl) + sl, r_u


@njit(cache=True, inline="always")
def _near_saddle(y, s, near):
    """False where ``_saddle`` would leave the margin as it is, for sure: a cheap test on
    the path of every free rocking step (``_saddle`` takes an atan and four divisions and
    is a call; inlined it slows every step).

    near = ``_saddle_bounds``: (v_cap, saddle0, r0, r_u). |theta'| > v_cap = alpha_ref/2
    (1 + SADDLE_SLACK) gives |v| > 1/2. atan is 1-Lipschitz, so |s theta_s - saddle0| <=
    m |u| / (M h_cg) (saddle0 = atan(b/h_cg), the saddle at u = 0), and |s theta - saddle0|
    > alpha_ref/2 + m |u| / (M h_cg) gives |x| > 1/2; r0 + r_u |u| is that bound widened by
    SADDLE_SLACK (relative and absolute), far above the round-off of either side, so the
    margin is the same to the bit as if ``_saddle`` ran at every step. saddle0 = NaN:
    always True (every comparison with NaN fails). The two tests are or-ed without a
    branch between them (one well-predicted branch, measured faster than two).
    """
    v_cap, saddle0, r0, r_u = near
    far = ((abs(y[Y_THETA_DOT]) > v_cap)
           | (abs(s * y[Y_THETA] - saddle0) > r0 + r_u * abs(y[Y_U])))
    return not far


@njit(cache=True, **INTERNAL)
def _saddle(y, s, prm):
    """The distance of the free rocking motion from the overturning saddle, in units of
    alpha_ref (its smallest over the run is OUT_MARGIN; ``rocksweep.compute.certify``);
    inf outside the window |x|, |v| < 1/2.

    Rocking on corner s, the body's centre of gravity is above the corner at
    theta_s = s atan((b - s m u / M) / h_cg) (the spring's u shifts it). With x = (s theta -
    s theta_s)/alpha_ref and v = theta'/(p alpha_ref) (p = 1), the motion near the saddle is
    x'' = x: hyperbolae on which v^2 - x^2 (~ (E - E_barrier)/E_ref) stays constant, whose
    vertex, sqrt(|v^2 - x^2|) from the saddle, is the closest the motion comes. It is
    taken from every step end within half an alpha_ref of the saddle (any point of the
    hyperbola gives its vertex, so steps of any length see it): a small value means the
    run decided between overturning and not by a small margin of energy. Called only
    where ``_near_saddle`` says the step end may be that close (~10% of Figure 3(a)'s
    free rocking steps): a call, not inlined.
    """
    a_ref = prm[PAR_ALPHA_REF]
    th_s = math.atan((prm[PAR_B] - s * prm[PAR_M] * y[Y_U] / prm[PAR_MTOT]) / prm[PAR_HCG])
    x = (s * y[Y_THETA] - th_s) / a_ref
    v = y[Y_THETA_DOT] / a_ref
    if abs(x) < 0.5 and abs(v) < 0.5:
        return math.sqrt(abs(v * v - x * x))
    return np.inf


@njit(cache=True, **INTERNAL)
def _overturned(t, out):
    out[OUT_OUTCOME] = OUTCOME_MODE1 if out[OUT_IMPACTS] > 0.0 else OUTCOME_MODE2
    out[OUT_T_OVERTURN] = t
    _flag(out, STATUS_OVERTURNED)


@njit(cache=True, inline="always")
def _record(hist, t, y, s, on, prm, out, FLEX, GROUND):
    """Append a history row at (t, y) in phase s, or flag STATUS_HIST_FULL; nothing (not
    even compiled) without a history."""
    if hist is not None:
        if _write_row(hist, int(out[OUT_HIST_ROWS]), t, y, s, on, prm,
                      out[OUT_E_IMPACT], FLEX, GROUND):
            out[OUT_HIST_ROWS] += 1.0
        else:
            _flag(out, STATUS_HIST_FULL)


@njit(cache=True, **INTERNAL)
def _write_row(hist, row, t, y, s, on, prm, e_imp, FLEX, GROUND):
    literally(FLEX)
    if row >= hist.shape[0]:
        return False
    hist[row, HIST_T] = t
    hist[row, HIST_THETA] = y[Y_THETA]
    hist[row, HIST_THETA_DOT] = y[Y_THETA_DOT]
    hist[row, HIST_U] = y[Y_U]
    hist[row, HIST_U_DOT] = y[Y_U_DOT]
    hist[row, HIST_PHASE] = s
    hist[row, HIST_E] = mechanical_energy(y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT], s,
                                          prm, FLEX)
    hist[row, HIST_W_IN] = y[Y_W_IN]
    hist[row, HIST_D_DAMP] = y[Y_D_DAMP]
    hist[row, HIST_E_IMPACT] = e_imp
    hist[row, HIST_XG] = ground_acc(GROUND, t, on, prm)
    # the sliding base's columns, as a base that cannot slide has them: x = 0, rest or
    # rock (``vocab.phases``' codes), no friction loss
    hist[row, HIST_X] = 0.0
    hist[row, HIST_CONTACT] = PHASE_ROCK if s != 0 else PHASE_REST
    hist[row, HIST_D_FRIC] = 0.0
    return True


@njit(cache=True, **INLINE)
def _finish(t, y, s, steps, event_steps, theta_max, prm, out, FLEX, ENERGY):
    """The result row's last entries: end time, step counts, theta_max and the energy
    accounting (NaN without)."""
    out[OUT_T_END] = t
    out[OUT_STEPS] = steps
    out[OUT_EVENT_STEPS] = event_steps
    out[OUT_THETA_MAX] = theta_max
    if ENERGY:
        out[OUT_W_IN] = y[Y_W_IN]
        out[OUT_D_DAMP] = y[Y_D_DAMP]
        out[OUT_E_END] = _energy(ENERGY, y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT], s,
                                 prm, FLEX)
    else:
        out[OUT_W_IN] = np.nan
        out[OUT_D_DAMP] = np.nan
        out[OUT_E_IMPACT] = np.nan
        out[OUT_E_GAINED] = np.nan
        out[OUT_N_GAINING] = np.nan
        out[OUT_E_END] = np.nan
