"""The loop of the base that may slide: one point on a ground with Coulomb friction (jitted).

The contact model ``layout.CONTACT_SLIDE`` (``variants.CONTACTS``), run where a scene
gives ``body.mu`` (docs/sliding.md). ``simulate_sliding`` takes ``loop.simulate_point``'s
arguments and owns the phase (s, sigma): s the corner (0 flat), sigma the slip direction
(0 stuck), and the 9-slot state y = (theta, theta', u, u', W_in, D_damp, x, x', D_fric)
(``layout.Y_*``). Fixed RK4 steps of ``sliding.sliding_derivatives`` (the loop's own step
lengths, ``loop._step_length``, and rotation limit; the step and its events in
``slide_events``), and every change of phase a located event of a continuous function, on
its far side, handled at the event's state:

| phase      | events (slot: 0, 1, 2, 3)                                                |
|------------|--------------------------------------------------------------------------|
| rest       | uplift on +b, on -b (s Q = M g b), stick break (mu_s N - abs(H) < 0)     |
| slide      | uplift while sliding on +b, on -b (``slide_uplift_moment``), slip stop   |
| rock       | impact (theta = 0), overturning, stick break (N <= 0 included)           |
| slide-rock | impact, overturning, slip stop (x' = 0), Painleve (den = JAM_DEN M: jam) |

A stick break, an uplift and a slip stop go to ``sliding.choose_phase`` (x' = 0 exactly
at a stop); an impact to ``sliding.friction_impact`` (the scene's law where the corner
sticks); Painleve to ``sliding.jam_impulse``. An event function fires only when it goes
from > 0 to <= 0 inside a step (a stick break: < 0, the static cone holds on its edge), so
a phase entered on its own surface, or held where no phase is consistent (``choose_phase``'s
JAM and LIFT_OFF: the corner held as in the no-slip model, flagged ``lifts_off``), does not
switch again at the same instant; every switch counts against the run's event cap.

Results beside the loop's: OUT_SLIDE_MAX, OUT_SLIDE_FINAL (|x| [m]), OUT_REGIME (bit
1 << phase code of every phase entered), OUT_D_FRIC (friction's loss, energy variants:
W_in = E_end + D_damp + E_impact + D_fric; an impact's loss split by
``friction_impact``'s W_f), STATUS_SLID where the base slipped. The no-slip model's
friction demand (REACTIONS, outputs.contact) has no meaning here: NaN. A rigid body
rocking on a stuck corner once the ground is still is decided safe where its energy is
below the barrier (``rigid_bounded``: friction and impacts only take energy away;
STATUS_BOUNDED, its margin), as in the no-slip loop, but the run goes on to rest: the
slips still to come count.
"""

import math

import numpy as np
from numba import literally, njit

from rocksweep.kernel._cache import INLINE, INTERNAL
from rocksweep.kernel.equations import rest_margin, tip_moment
from rocksweep.kernel.ground import ground_acc, ground_flags, ground_gravity
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
    OUT_IMPULSE_MAX,
    OUT_LIFT_ANGLE,
    OUT_LIFT_GRAZE,
    OUT_MARGIN,
    OUT_MODE_GRAZE,
    OUT_MU_REQ,
    OUT_N_GAINING,
    OUT_N_MIN,
    OUT_REGIME,
    OUT_SLIDE_FINAL,
    OUT_SLIDE_MAX,
    OUT_STATUS,
    OUT_STEPS,
    OUT_T_CLOSE,
    OUT_T_END,
    OUT_T_FIRST_IMPACT,
    OUT_THETA_MAX,
    OUT_UPLIFTS,
    OUT_W_IN,
    PAR_ALPHA_REF,
    PAR_C,
    PAR_CLOSE,
    PAR_DT,
    PAR_DT_ON,
    PAR_G,
    PAR_K,
    PAR_M,
    PAR_MAXEVENTS,
    PAR_MAXSTEPS,
    PAR_MTOT,
    PAR_MU,
    PAR_MU_STATIC,
    PAR_REC_H,
    PAR_ROT_STEP,
    PAR_T_AIR,
    PAR_TEND,
    PAR_THETA0,
    PAR_THETA_DOT0,
    PAR_THETA_OVER,
    PAR_TPULSE,
    PAR_U0,
    PAR_U_DOT0,
    STATUS_AIRBORNE,
    STATUS_BOUNDED,
    STATUS_E_ABOVE_1,
    STATUS_EVENT_CAP,
    STATUS_HIST_FULL,
    STATUS_HORIZON,
    STATUS_LIFTS_OFF,
    STATUS_NONFINITE,
    STATUS_REST,
    STATUS_SETTLED,
    STATUS_SLID,
    STATUS_STEP_CAP,
    Y_D_DAMP,
    Y_D_FRIC,
    Y_THETA,
    Y_THETA_DOT,
    Y_U,
    Y_U_DOT,
    Y_W_IN,
    Y_X,
    Y_X_DOT,
)
from rocksweep.kernel.loop import (
    _flag,
    _graze,
    _near_saddle,
    _overturned,
    _reset,
    _rigid_bounded,
    _rigid_margin,
    _rotation_step,
    _saddle,
    _saddle_bounds,
    _step_length,
    _theta_max,
    impact_depths,
)
from rocksweep.kernel.slide_events import (
    SLOT_CONTACT,
    SLOT_FIRST,
    SLOT_JAM,
    SLOT_SECOND,
    _event_values,
    _first_event,
    _rates,
    _rk4,
)
from rocksweep.kernel.sliding import (
    LIFT_OFF,
    TIP_ROUNDOFF,
    choose_phase,
    friction_impact,
    jam_clearance,
    jam_impulse,
    phase_code,
    slide_uplift_moment,
    sliding_energy,
    slip_state,
)

# A slide-rock step whose normal force N moved by more than N_JUMP x max(M g, |N| at its
# start) is taken again a quarter as long, up to N_RETRIES times (``_painleve_step``,
# ``_shorter``): near a Painleve point (den -> 0) the slip's accelerations grow as 1/den,
# and one fixed step through it (threshold seed 5 at mu 0.62, 5 steps a period: den
# 0.0135 -> 0.0050, N 0.85 -> -710 M g, theta' -0.48 -> 3.7 rad/s) flung the body over in
# mode 2 where finer steps rock to rest or fall in mode 1 (docs/sliding.md, "Near
# thresholds"). A smooth step moves N by ~0.1 M g at 5 steps a period.
N_JUMP = 0.5
N_RETRIES = 8
# While the base slips its step is at most SLIP_STEP of the step then in effect (dt_on
# while the ground moves, dt after): threshold seed 9's block at mu 0.264 ~ tan alpha
# slide-rocks for 2.4 p t near its tipping point under a slow pulse, and at 5 steps a
# period took the wrong class with margins 0.39-0.92 alpha_ref (finer runs: 0.25, mode 2);
# at half the step it is right, margin 0.2535 (docs/sliding.md, "Near thresholds").
SLIP_STEP = 0.5
# A slide-rock step that ends with the rocking corner's N at or below LIFT_NEAR x M g is a
# lift-off a finer step may make (OUT_LIFT_ANGLE, ``_lifted``; not flagged ``lifts_off``):
# sliding threshold seed 55's coarse run came within 0.0087 M g of it and fell in mode 1,
# where 10 steps a period and finer lift off and fall in mode 2, as the reference. On
# Figure 3(a)'s sliding grid at mu 0.3 and 0.5 no run comes that near (below 0.02 M g)
# without lifting off; 5.7% and 13% come below 0.05 M g.
LIFT_NEAR = 0.02


@njit(cache=True, **INTERNAL)
def simulate_sliding(prm, out, hist, FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    """Run one point of the sliding base from rest (or the row's initial state) to a
    decided outcome, a cap, rest or the horizon (module docstring). Arguments as
    ``loop.simulate_point``'s; REACTIONS is not read (the friction demand is NaN)."""
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    t, dt, t_pulse, t_end = 0.0, prm[PAR_DT], prm[PAR_TPULSE], prm[PAR_TEND]
    dt_on = prm[PAR_DT_ON]
    max_steps, max_events = prm[PAR_MAXSTEPS], prm[PAR_MAXEVENTS]
    records, vertical = ground_flags(GROUND)
    h_rec = prm[PAR_REC_H] if records else 0.0
    t_air = prm[PAR_T_AIR] if vertical else math.inf
    mu, mu_s = prm[PAR_MU], prm[PAR_MU_STATIC]
    jump = N_JUMP * prm[PAR_MTOT] * prm[PAR_G]  # ``_painleve_step``'s least [N]
    on = 0.0 < t_pulse
    _reset(out)
    y = (prm[PAR_THETA0], prm[PAR_THETA_DOT0], prm[PAR_U0], prm[PAR_U_DOT0], 0.0, 0.0, 0.0,
         0.0, 0.0)
    s = 0
    if y[Y_THETA] != 0.0 or y[Y_THETA_DOT] != 0.0:
        s = 1 if y[Y_THETA] > 0.0 or (y[Y_THETA] == 0.0 and y[Y_THETA_DOT] > 0.0) else -1
    s, sigma = _enter(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, GROUND)
    _record(hist, t, y, s, sigma, on, prm, out, FLEX, GROUND)
    steps, event_steps, switches = 0, 0, 0
    theta_max, slide_max = abs(y[Y_THETA]), 0.0
    rot, acc = prm[PAR_ROT_STEP], 0.0
    margin = graze = dip = lift = np.inf  # OUT_MARGIN, the grazes (the no-slip loop's)
    t_close = np.nan
    near = _saddle_bounds(prm)
    ev0 = _event_values(t, y, s, sigma, on, mu, mu_s, prm, FLEX, DAMPED, GROUND)
    free_check = True  # a rigid body's bound, as the no-slip loop's (once per free flight)

    while True:
        on = t < t_pulse
        if s == 0 and sigma == 0 and not on and _rest_for_good(y, mu_s, prm, FLEX):
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
        if not FLEX and s != 0 and sigma == 0 and not on and free_check:
            # rocking on a stuck corner, the ground still: its energy can only fall
            # (impacts with e <= 1 and friction dissipate; a slip's kinetic energy is
            # part of it), so below the barrier it cannot overturn (``rigid_bounded``):
            # its class is decided (STATUS_BOUNDED), but the run goes on to rest, for
            # the slips still to come (slide_max, slide_final)
            free_check = False
            margin = _rigid_margin(FLEX, y, s, prm, margin)
            if margin < prm[PAR_CLOSE]:
                t_close = t
            peak = _rigid_bounded(FLEX, y, s, prm, FLEX)
            if peak >= 0.0:
                if peak > theta_max:
                    theta_max = peak
                _flag(out, STATUS_BOUNDED)
        if steps + event_steps >= max_steps:
            _flag(out, STATUS_STEP_CAP)
            break
        if out[OUT_IMPACTS] + out[OUT_UPLIFTS] + switches >= max_events:
            _flag(out, STATUS_EVENT_CAP)
            break
        h, lands = _step_length(t, on, dt, dt_on, t_pulse, t_end, h_rec)
        h, lands = _slip_step(h, lands, sigma, on, dt, dt_on)
        air = vertical and t + h >= t_air
        if air:
            h, lands = t_air - t, False
        if s != 0 and rot > 0.0:
            h_rot = _rotation_step(y[Y_THETA_DOT], acc, rot)
            if h_rot < h:
                h, lands, air = h_rot, False, False
        k1 = _rates(t, y, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND)
        y1 = _rk4(t, y, h, k1, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND)
        steps += 1
        if s != 0 and rot > 0.0:
            turn = abs(y1[Y_THETA] - y[Y_THETA])
            while turn > 2.0 * rot:
                h, lands, air = h * max(0.25, 0.9 * math.sqrt(rot / turn)), False, False
                y1 = _rk4(t, y, h, k1, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND)
                steps += 1
                turn = abs(y1[Y_THETA] - y[Y_THETA])
            acc = abs(y1[Y_THETA_DOT] - y[Y_THETA_DOT]) / h
        ev1 = _event_values(t + h, y1, s, sigma, on, mu, mu_s, prm, FLEX, DAMPED, GROUND)
        if s != 0 and sigma != 0 and _painleve_step(ev0, ev1, jump):
            h, y1, ev1, more = _shorter(t, y, h, k1, ev0, jump, s, sigma, on, mu, mu_s, prm,
                                        FLEX, DAMPED, ENERGY, GROUND)
            steps, lands, air = steps + more, False, False
        if not _finite(y1):
            _flag(out, STATUS_NONFINITE)
            break
        slot, tau, y_ev, n, low = _first_event(t, y, k1, y1, h, ev0, ev1, s, sigma, on, mu,
                                               mu_s, prm, FLEX, DAMPED, ENERGY, GROUND)
        event_steps += n
        if s != 0:
            theta_max = _theta_max(y, y_ev, tau, s, theta_max)
            if slot < 0 and sigma != 0:  # slide-rock's N at the step's end
                _lifted(out, y1, on, ev1[4], prm)  # N <= 0: the ground pulls
        if abs(y_ev[Y_X]) > slide_max:
            slide_max = abs(y_ev[Y_X])

        if slot < 0:
            if s != 0 and (on or out[OUT_IMPACTS] == 0.0):  # (no impact yet: mode 2)
                g = _graze(y, y1, h, s, prm, np.inf)
                graze = min(graze, g) if on else graze
                dip = min(dip, g) if out[OUT_IMPACTS] == 0.0 else dip
            elif s == 0 and out[OUT_IMPACTS] == 0.0:  # (before the first uplift)
                lift = min(lift, low)
            t, y, ev0 = (t_pulse if lands else (t_air if air else t + h)), y1, ev1
            if s != 0 and sigma == 0 and not on and _near_saddle(y, s, near):
                q = _saddle(y, s, prm)
                if q < prm[PAR_CLOSE]:
                    t_close = t
                margin = min(margin, q)
            _record(hist, t, y, s, sigma, t < t_pulse, prm, out, FLEX, GROUND)
            if lands and sigma == 0:
                # the pulse's end: xg'' jumps (a cosine's peak), the stuck force with it
                off = t < t
                s_new, sigma = _choose(t, y, s, off, mu, mu_s, prm, out, FLEX, DAMPED,
                                       GROUND)
                if s_new != s:
                    out[OUT_UPLIFTS] += 1.0
                s = s_new
                ev0 = _event_values(t, y, s, sigma, off, mu, mu_s, prm, FLEX, DAMPED, GROUND)
                _record(hist, t, y, s, sigma, off, prm, out, FLEX, GROUND)
            continue

        t, y = t + tau, y_ev
        _record(hist, t, y, s, sigma, on, prm, out, FLEX, GROUND)
        if s != 0 and slot == SLOT_SECOND:
            _overturned(t, out)
            theta_max = max(theta_max, prm[PAR_THETA_OVER])
            break
        if s != 0 and slot == SLOT_FIRST:
            y, s, sigma = _impact(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, ENERGY,
                                  GROUND)
            free_check = True
        else:
            switches += 1
            y, s, sigma = _switch(slot, t, y, s, sigma, on, mu, mu_s, prm, out, FLEX, DAMPED,
                                  ENERGY, GROUND)
        ev0 = _event_values(t, y, s, sigma, on, mu, mu_s, prm, FLEX, DAMPED, GROUND)
        _record(hist, t, y, s, sigma, on, prm, out, FLEX, GROUND)
    _finish(t, y, s, steps, event_steps, theta_max, slide_max,
            (margin, t_close, graze, dip, lift), prm, out, FLEX, ENERGY)


@njit(cache=True, **INLINE)
def _finish(t, y, s, steps, event_steps, theta_max, slide_max, nearness, prm, out, FLEX,
            ENERGY):
    """The result row's last entries: end time, step counts, theta_max, the slide, how
    near the run came to the other class (nearness: OUT_MARGIN, OUT_T_CLOSE, OUT_GRAZE, the
    dip before an impact and the uplift function's least value before the first uplift
    [N m], as the no-slip loop's), the energy accounting (NaN without) and the no-slip
    demand's slots (NaN)."""
    margin, t_close, graze, dip, lift = nearness
    out[OUT_MARGIN], out[OUT_T_CLOSE], out[OUT_GRAZE] = margin, t_close, graze
    out[OUT_MODE_GRAZE] = dip if out[OUT_IMPACTS] == 0.0 else out[OUT_MODE_GRAZE]
    out[OUT_LIFT_GRAZE] = lift / tip_moment(prm[PAR_G], prm)
    out[OUT_T_END] = t
    out[OUT_STEPS] = steps
    out[OUT_EVENT_STEPS] = event_steps
    out[OUT_THETA_MAX] = theta_max
    out[OUT_SLIDE_MAX] = slide_max
    out[OUT_SLIDE_FINAL] = abs(y[Y_X])
    out[OUT_MU_REQ] = np.nan
    out[OUT_N_MIN] = np.nan
    out[OUT_IMPULSE_MAX] = np.nan
    if ENERGY:
        out[OUT_W_IN] = y[Y_W_IN]
        out[OUT_D_DAMP] = y[Y_D_DAMP]
        out[OUT_D_FRIC] = y[Y_D_FRIC]
        out[OUT_E_END] = _energy(y, s, prm, FLEX)
    else:
        out[OUT_W_IN] = np.nan
        out[OUT_D_DAMP] = np.nan
        out[OUT_D_FRIC] = np.nan
        out[OUT_E_IMPACT] = np.nan
        out[OUT_E_GAINED] = np.nan
        out[OUT_N_GAINING] = np.nan
        out[OUT_E_END] = np.nan


def chunk_entry(FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    """The chunk entry point's body of a row (``variants.ContactModel``): the loop a
    global name of this module, as ``variants``' no-slip entries."""
    def chunk(prms, outs):
        for i in range(prms.shape[0]):
            simulate_sliding(prms[i], outs[i], None, FLEX, DAMPED, ENERGY, REACTIONS, GROUND)
    return chunk


def point_entry(FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    """The point entry point's body of a row (``chunk_entry``'s)."""
    def point(prm, out, hist):
        simulate_sliding(prm, out, hist, FLEX, DAMPED, ENERGY, REACTIONS, GROUND)
    return point


# ----------------------------------------------------------------------------------------
# Steps
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE)
def _slip_step(h, lands, sigma, on, dt, dt_on):
    """(h [s], lands): the step, at most SLIP_STEP of the step then in effect (dt_on while
    the ground moves, dt after) while the base slips (sigma != 0); a shortened step no
    longer lands on the pulse's end (the next one does)."""
    cap = SLIP_STEP * (dt_on if on else dt)
    if sigma != 0 and h > cap:
        return cap, False
    return h, lands


@njit(cache=True, **INLINE)
def _painleve_step(ev0, ev1, jump):
    """A slide-rock step whose normal force N (slot 4) moved by more than ``jump`` [N] or
    N_JUMP of its own size at the step's start, whichever is larger."""
    return abs(ev1[4] - ev0[4]) > max(jump, N_JUMP * abs(ev0[4]))


@njit(cache=True, **INTERNAL)
def _shorter(t, y, h, k1, ev0, jump, s, sigma, on, mu, mu_s, prm, FLEX, DAMPED, ENERGY,
             GROUND):
    """A slide-rock step of h [s] from (t, y) (first stage k1, event values ev0 at its
    start) that ``_painleve_step`` refused, taken again a quarter as long until it
    passes, at most N_RETRIES times (or the state is not finite).
    Returns (h, y1, its event values, the RK4 evaluations taken)."""
    more = 0
    while True:
        h *= 0.25
        y1 = _rk4(t, y, h, k1, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND)
        ev1 = _event_values(t + h, y1, s, sigma, on, mu, mu_s, prm, FLEX, DAMPED, GROUND)
        more += 1
        if not _painleve_step(ev0, ev1, jump) or more >= N_RETRIES or not _finite(y1):
            return h, y1, ev1, more



@njit(cache=True, **INLINE)
def _finite(y):
    return (math.isfinite(y[Y_THETA]) and math.isfinite(y[Y_THETA_DOT])
            and math.isfinite(y[Y_U]) and math.isfinite(y[Y_U_DOT])
            and math.isfinite(y[Y_X]) and math.isfinite(y[Y_X_DOT]))


@njit(cache=True, **INLINE)
def _energy(y, s, prm, FLEX):
    return sliding_energy(y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT], y[Y_X_DOT], s, prm,
                          FLEX)


@njit(cache=True, **INLINE)
def _rest_for_good(y, mu_s, prm, FLEX):
    """Flat, stuck, the ground still: the body never uplifts (``equations.rest_margin``)
    nor slips again (the spring's largest force on its energy ellipse within mu_s M g);
    a rigid body at once."""
    if not FLEX:
        return True
    u, ud = y[Y_U], y[Y_U_DOT]
    m, k, c = prm[PAR_M], prm[PAR_K], prm[PAR_C]
    e2 = m * ud * ud + k * u * u
    f_max = math.sqrt(e2 * (k + c * c / m))
    return rest_margin(u, ud, prm) < 0.0 and f_max <= mu_s * prm[PAR_MTOT] * prm[PAR_G]


# ----------------------------------------------------------------------------------------
# Actions
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE)
def _regime(out, s, sigma):
    """Mark phase (s, sigma) as visited (OUT_REGIME's bit, STATUS_SLID)."""
    bit = 1 << phase_code(s, sigma)
    out[OUT_REGIME] = int(out[OUT_REGIME]) | bit
    if sigma != 0:
        _flag(out, STATUS_SLID)


@njit(cache=True, **INLINE)
def _lifted(out, y, on, n, prm):
    """At state y with the rocking corner's normal force n [N]: flag a lift-off
    (STATUS_LIFTS_OFF, n <= 0: the corner held) and, where n <= LIFT_NEAR M g (a lift-off,
    or one a finer step may make), keep OUT_LIFT_ANGLE: the least |theta| / alpha_ref
    after the ground stopped, 0 while it moves (``on``)."""
    if not n > 0.0:
        _flag(out, STATUS_LIFTS_OFF)
    if not n > LIFT_NEAR * prm[PAR_MTOT] * prm[PAR_G]:
        angle = 0.0 if on else abs(y[Y_THETA]) / prm[PAR_ALPHA_REF]
        out[OUT_LIFT_ANGLE] = min(out[OUT_LIFT_ANGLE], angle)


@njit(cache=True, **INTERNAL)
def _choose(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, GROUND):
    """``choose_phase`` at (t, y) of a base that does not slip (x' = 0): the new (s,
    sigma), entered; JAM and LIFT_OFF hold the corner (LIFT_OFF flagged ``lifts_off``)."""
    g = ground_gravity(GROUND, t, on, prm)
    s_new, sigma, flag = choose_phase(y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT], s,
                                      ground_acc(GROUND, t, on, prm), g, mu, mu_s, prm, FLEX,
                                      DAMPED)
    if flag & LIFT_OFF:
        _lifted(out, y, on, 0.0, prm)
    _regime(out, s_new, sigma)
    return s_new, sigma


@njit(cache=True, **INTERNAL)
def _enter(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, GROUND):
    """The phase at the run's start (``_choose``; a tip from rest counts as an uplift)."""
    out[OUT_REGIME] = 0.0
    s_new, sigma = _choose(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, GROUND)
    if s_new != s:
        out[OUT_UPLIFTS] += 1.0
    return s_new, sigma


@njit(cache=True, **INTERNAL)
def _switch(slot, t, y, s, sigma, on, mu, mu_s, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    """A stick break, a slip stop, an uplift or Painleve's jam at (t, y). Returns (y, s,
    sigma)."""
    if slot == SLOT_JAM:
        return _jam(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, ENERGY, GROUND)
    if slot == SLOT_CONTACT and sigma != 0:  # the slip stops: x' = 0 exactly
        e_before = _energy(y, s, prm, FLEX) if ENERGY else 0.0
        y = (y[0], y[1], y[2], y[3], y[4], y[5], y[6], 0.0, y[8])
        if ENERGY:  # the stop's round-off of x' (within the event tolerance): friction's
            y = (y[0], y[1], y[2], y[3], y[4], y[5], y[6], 0.0,
                 y[8] + e_before - _energy(y, s, prm, FLEX))
        s_new, sigma = _choose(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, GROUND)
        if s_new != s:
            out[OUT_UPLIFTS] += 1.0
        return y, s_new, sigma
    if s == 0 and slot != SLOT_CONTACT:  # uplift (flat)
        if sigma != 0:  # tips while sliding: slide-rock on that corner, or the jam
            s_new = 1 if slot == SLOT_FIRST else -1
            out[OUT_UPLIFTS] += 1.0
            return _slipping(t, y, s_new, sigma, on, mu, mu_s, prm, out, FLEX, DAMPED,
                             ENERGY, GROUND)
    s_new, sigma = _choose(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, GROUND)
    if s_new != s:
        out[OUT_UPLIFTS] += 1.0
    if s_new == 0:
        y = (0.0, 0.0, y[2], y[3], y[4], y[5], y[6], y[7], y[8])
    return y, s_new, sigma


@njit(cache=True, **INTERNAL)
def _jam(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    """Painleve: the tangential impulse that sticks the slipping corner
    (``sliding.jam_impulse``; its work friction's, the rest of the energy change the
    impacts'), then the phase chosen at x' = 0."""
    g = ground_gravity(GROUND, t, on, prm)
    e_before = _energy(y, s, prm, FLEX) if ENERGY else 0.0
    w, ud, _, _, w_j = jam_impulse(y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT],
                                   y[Y_X_DOT], s, g, prm, FLEX, DAMPED)
    y = (y[0], w, y[2], ud if FLEX else y[3], y[4], y[5], y[6], 0.0, y[8] - w_j)
    if ENERGY:
        out[OUT_E_IMPACT] += e_before - _energy(y, s, prm, FLEX) + w_j
    s_new, sigma = _choose(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, GROUND)
    return y, s_new, sigma


@njit(cache=True, **INTERNAL)
def _slipping(t, y, s, sigma, on, mu, mu_s, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    """The phase a slip (x' != 0, direction sigma) goes on in on corner s (0 flat): flat,
    it tips at once onto a corner where it would uplift while sliding; rocking, it
    slide-rocks where a slip is consistent (den > ``sliding.JAM_DEN`` M), else the jam
    sticks it."""
    g = ground_gravity(GROUND, t, on, prm)
    xg = ground_acc(GROUND, t, on, prm)
    if s == 0:
        q = slide_uplift_moment(y[Y_U], y[Y_U_DOT], sigma, xg, g, mu, prm, FLEX, DAMPED)
        mgb = tip_moment(g, prm) * (1.0 + TIP_ROUNDOFF)
        if q >= mgb or q <= -mgb:
            s = 1 if q > 0.0 else -1
            out[OUT_UPLIFTS] += 1.0
    if s != 0:
        den = slip_state(y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT], s, sigma, xg, g, mu,
                         prm, FLEX, DAMPED)[2]
        if not jam_clearance(den, prm) > 0.0:
            return _jam(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, ENERGY, GROUND)
    _regime(out, s, sigma)
    return y, s, sigma


@njit(cache=True, **INTERNAL)
def _impact(t, y, s, on, mu, mu_s, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    """The impact at (t, y) ending rocking on corner s, with friction
    (``sliding.friction_impact``: the scene's law where the corner sticks): counters, the
    energy split between impacts and friction (W_f), then the phase after it."""
    out[OUT_IMPACTS] += 1.0
    if out[OUT_IMPACTS] == 1.0:
        out[OUT_T_FIRST_IMPACT] = t
    impact_depths(y, on, prm, out)  # the deepest, the shallowest while the ground moves
    e_before = _energy(y, s, prm, FLEX) if ENERGY else 0.0
    s_new, w, ud, xd, e, _, _, w_f, _ = friction_impact(
        y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT], y[Y_X_DOT], s, mu, mu_s, prm, FLEX)
    if e > out[OUT_E_MAX]:
        out[OUT_E_MAX] = e
    if e > 1.0:
        _flag(out, STATUS_E_ABOVE_1)
    if s_new == 0:
        out[OUT_CONTACTS] += 1.0
        if e > 0.0:
            _flag(out, STATUS_SETTLED)
    y = (0.0, w, y[2], ud if FLEX else y[3], y[4], y[5], y[6], xd, y[8] - w_f)
    if ENERGY:
        e_d = e_before - _energy(y, s_new, prm, FLEX) + w_f
        out[OUT_E_IMPACT] += e_d
    if xd == 0.0:
        s2, sigma = _choose(t, y, s_new, on, mu, mu_s, prm, out, FLEX, DAMPED, GROUND)
        if s_new == 0 and s2 != 0:
            out[OUT_UPLIFTS] += 1.0
        return y, s2, sigma
    return _slipping(t, y, s_new, 1 if xd > 0.0 else -1, on, mu, mu_s, prm, out, FLEX,
                     DAMPED, ENERGY, GROUND)


# ----------------------------------------------------------------------------------------
# History
# ----------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _record(hist, t, y, s, sigma, on, prm, out, FLEX, GROUND):
    """Append a history row (nothing, not even compiled, without a history)."""
    if hist is not None:
        if _write_row(hist, int(out[OUT_HIST_ROWS]), t, y, s, sigma, on, prm,
                      out[OUT_E_IMPACT], FLEX, GROUND):
            out[OUT_HIST_ROWS] += 1.0
        else:
            _flag(out, STATUS_HIST_FULL)


@njit(cache=True, **INTERNAL)
def _write_row(hist, row, t, y, s, sigma, on, prm, e_imp, FLEX, GROUND):
    literally(FLEX)
    if row >= hist.shape[0]:
        return False
    hist[row, HIST_T] = t
    hist[row, HIST_THETA] = y[Y_THETA]
    hist[row, HIST_THETA_DOT] = y[Y_THETA_DOT]
    hist[row, HIST_U] = y[Y_U]
    hist[row, HIST_U_DOT] = y[Y_U_DOT]
    hist[row, HIST_PHASE] = s
    hist[row, HIST_E] = _energy(y, s, prm, FLEX)
    hist[row, HIST_W_IN] = y[Y_W_IN]
    hist[row, HIST_D_DAMP] = y[Y_D_DAMP]
    hist[row, HIST_E_IMPACT] = e_imp
    hist[row, HIST_XG] = ground_acc(GROUND, t, on, prm)
    hist[row, HIST_X] = y[Y_X]
    hist[row, HIST_CONTACT] = phase_code(s, sigma)
    hist[row, HIST_D_FRIC] = y[Y_D_FRIC]
    return True
