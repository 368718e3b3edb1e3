"""One step of the base that may slide and the events in it (jitted).

The RK4 step of ``sliding.sliding_derivatives`` in phase (s, sigma), on the 9-slot state y
(``slide_loop``'s), and the phase's four event functions (``slide_loop``'s table), each
firing when it goes from > 0 to <= 0: where one may have fired inside a step, ``_search``
locates the first (the no-slip model's ``stepping`` and ``events``, for the sliding base).
"""

import numpy as np
from numba import literally, njit

from rocksweep.kernel._cache import INLINE, INTERNAL
from rocksweep.kernel.equations import tip_moment, uplift_moment, uplift_moment_rate, uplift_rates
from rocksweep.kernel.events import HERMITE_PAST, NEWTON_XTOL, hermite_min, hermite_root
from rocksweep.kernel.ground import ground_acc, ground_gravity, ground_jerk
from rocksweep.kernel.layout import (
    PAR_THETA_OVER,
    PAR_TOL,
    Y_THETA,
    Y_THETA_DOT,
    Y_U,
    Y_U_DOT,
    Y_X_DOT,
)
from rocksweep.kernel.sliding import (
    TIP_ROUNDOFF,
    jam_clearance,
    slide_uplift_moment,
    sliding_derivatives,
    slip_state,
    stick_margin,
)

# The event slots of a phase (``_event_values``): 0 and 1 the impact and overturning
# (rocking) or the uplifts on +b and -b (flat), 2 the stick break (stuck) or the slip stop
# (slipping), 3 Painleve (slide-rock, ``sliding.jam_clearance``; else never)
SLOT_FIRST = 0
SLOT_SECOND = 1
SLOT_CONTACT = 2
SLOT_JAM = 3
N_SLOTS = 4
# the least positive float64: a stuck contact exactly on its cone's edge still holds
# (``choose_phase``), so its margin 0 counts as not crossed
EDGE = 5e-324


@njit(cache=True, **INLINE)
def _rates(t, y, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND):
    return sliding_derivatives(t, y, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND)


@njit(cache=True, **INLINE)
def _axpy(y, a, k):
    """y + a k, slot by slot (9 slots)."""
    return (y[0] + a * k[0], y[1] + a * k[1], y[2] + a * k[2], y[3] + a * k[3],
            y[4] + a * k[4], y[5] + a * k[5], y[6] + a * k[6], y[7] + a * k[7],
            y[8] + a * k[8])


@njit(cache=True, **INLINE)
def _rk4(t, y, h, k1, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND):
    """One classical RK4 step of size h from (t, y) in phase (s, sigma) whose first stage
    k1 is known (as ``stepping.rk4_from``: one call site of the right-hand side)."""
    k = k1
    k23 = k1
    for stage in range(1, 4):
        c = h if stage == 3 else 0.5 * h
        k = _rates(t + c, _axpy(y, c, k), s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY,
                   GROUND)
        if stage == 1:
            k23 = k
        elif stage == 2:
            k23 = _axpy(k23, 1.0, k)
    w = h / 6.0
    return _axpy(_axpy(y, w, k1), w, _axpy(_axpy(k23, 1.0, k23), 1.0, k))



# ----------------------------------------------------------------------------------------
# Events
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE)
def _event_values(t, y, s, sigma, on, mu, mu_s, prm, FLEX, DAMPED, GROUND):
    """The four event functions of phase (s, sigma) at (t, y) (module docstring; inf: none
    in this phase), each fires when it goes from > 0 to <= 0; and N [N] while the base
    slide-rocks (1 in the other phases: no lift-off to flag)."""
    theta, theta_dot, u, u_dot = y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT]
    xg = ground_acc(GROUND, t, on, prm)
    g = ground_gravity(GROUND, t, on, prm)
    e3 = np.inf
    n = 1.0
    if s != 0:
        e0 = s * theta
        e1 = prm[PAR_THETA_OVER] - s * theta
        if sigma != 0:
            _, n, den = slip_state(theta, theta_dot, u, u_dot, s, sigma, xg, g, mu, prm,
                                   FLEX, DAMPED)
            e3 = jam_clearance(den, prm)
    else:
        mgb = tip_moment(g, prm)
        if sigma == 0:
            q = uplift_moment(u, u_dot, xg, g, prm, FLEX, DAMPED)
        else:
            # a rigid body sliding at mu = tan(alpha_cg) has Q = M g b for good: it slides
            q = slide_uplift_moment(u, u_dot, sigma, xg, g, mu, prm, FLEX, DAMPED)
            mgb *= 1.0 + TIP_ROUNDOFF
        e0 = mgb - q
        e1 = mgb + q
    if sigma == 0:
        e2 = stick_margin(theta, theta_dot, u, u_dot, s, xg, g, mu_s, prm, FLEX, DAMPED)
        if e2 == 0.0:
            e2 = EDGE
    else:
        e2 = sigma * y[Y_X_DOT]
    return e0, e1, e2, e3, n


@njit(cache=True, **INLINE)
def _pick(ev, slot):
    if slot == SLOT_FIRST:
        return ev[0]
    if slot == SLOT_SECOND:
        return ev[1]
    if slot == SLOT_CONTACT:
        return ev[2]
    return ev[3]


@njit(cache=True, **INTERNAL)
def _locate(slot, t0, y0, k1, g_lo, hi, g_hi, y_hi, s, sigma, on, mu, mu_s, prm, FLEX,
            DAMPED, ENERGY, GROUND):
    """Shrink the bracket [0, hi] (g(0) = g_lo >= 0 >= g(hi) = g_hi) of the event in
    ``slot`` to PAR_TOL, each trial a fresh RK4 step from (t0, y0) (as ``events._locate``):
    an impact (g = s theta, its rate s theta' in the state) by the roots of g's cubic
    Hermite interpolant (``events.hermite_root``, each trial after the first HERMITE_PAST
    tolerances past it, a bisection after two that did not halve the bracket: the no-slip
    loop's rule), the others by Illinois regula falsi. Returns (tau, y(tau), trials), tau
    on the far side."""
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    lo = 0.0
    tol = prm[PAR_TOL]
    n = 0
    side = 0
    hermite = s != 0 and slot == SLOT_FIRST
    d_lo, d_hi = s * y0[Y_THETA_DOT], s * y_hi[Y_THETA_DOT]
    slow = 0
    while hi - lo > tol:
        width = hi - lo
        if hermite and slow < 2:
            mid = lo + hermite_root(g_lo, d_lo, g_hi, d_hi, width, NEWTON_XTOL * tol / width)
            if not (mid == mid):
                mid = 0.5 * (lo + hi)
            mid += HERMITE_PAST * tol * side  # (side: +1 after lo moved, -1 after hi)
            mid = min(max(mid, lo + 0.5 * tol), hi - 0.5 * tol)
        elif hermite:
            mid = 0.5 * (lo + hi)
        else:
            mid = hi - g_hi * (hi - lo) / (g_hi - g_lo)
            if mid <= lo + 0.5 * tol or mid >= hi - 0.5 * tol or not (mid == mid):
                mid = 0.5 * (lo + hi)
        y_mid = _rk4(t0, y0, mid, k1, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND)
        g_mid = _pick(_event_values(t0 + mid, y_mid, s, sigma, on, mu, mu_s, prm, FLEX,
                                    DAMPED, GROUND), slot)
        d_mid = s * y_mid[Y_THETA_DOT]
        n += 1
        if g_mid <= 0.0:
            hi, g_hi, d_hi, y_hi = mid, g_mid, d_mid, y_mid
            if side == -1 and not hermite:
                g_lo *= 0.5
            side = -1
        else:
            lo, g_lo, d_lo = mid, g_mid, d_mid
            if side == 1 and not hermite:
                g_hi *= 0.5
            side = 1
        if slow >= 2:
            slow = 0
        else:
            slow = slow + 1 if hi - lo > 0.5 * width else 0
    return hi, y_hi, n


@njit(cache=True, **INLINE)
def _first_event(t, y, k1, y1, h, ev0, ev1, s, sigma, on, mu, mu_s, prm, FLEX, DAMPED,
                 ENERGY, GROUND):
    """The first event of the step (t, y) -> (t + h, y1), as ``_search``: a screen on the
    path of every step (inlined), the search a call where a slot may have fired."""
    maybe = False
    for slot in range(N_SLOTS):
        g0, g1 = _pick(ev0, slot), _pick(ev1, slot)
        if g1 <= 0.0 and (g0 > 0.0 or (s != 0 and slot == SLOT_FIRST and g0 == 0.0)):
            maybe = True
        if _slip_turned(slot, sigma, g0, g1):
            maybe = True
    if s != 0 and ev0[0] > 0.0 and s * y[Y_THETA_DOT] < 0.0 < s * y1[Y_THETA_DOT]:
        maybe = True  # theta turned back toward 0 inside the step: a dip to screen
    dip = (-1, h, np.inf)  # (slot, tau, g_min): ``_lift_dip``'s, at rest
    if s == 0 and sigma == 0:
        dip = _lift_dip(t, y, y1, h, ev0, ev1, on, prm, FLEX, DAMPED, GROUND)
        lift, low = dip[0], dip[2]
        if lift >= 0 and not low > min(ev0[lift], ev1[lift]) - low:
            maybe = True  # an uplift moment that peaked inside the step near M g b
    if not maybe:
        return -1, h, y1, 0, dip[2]
    slot, tau, y_ev, n = _search(t, y, k1, y1, h, ev0, ev1, dip, s, sigma, on, mu, mu_s,
                                 prm, FLEX, DAMPED, ENERGY, GROUND)
    return slot, tau, y_ev, n, max(dip[2], 0.0)


@njit(cache=True, **INLINE)
def _lift_rates(t, y, on, prm, FLEX, DAMPED, GROUND):
    """d/dt of rest's uplift functions M g b - Q and M g b + Q (slots 0, 1) at (t, y), as
    ``events.event_rate``'s (the stuck base's full contact is the no-slip model's)."""
    dq = uplift_moment_rate(y[Y_U], y[Y_U_DOT], ground_acc(GROUND, t, on, prm),
                            ground_jerk(GROUND, t, on, prm), ground_gravity(GROUND, t, on, prm),
                            prm, FLEX, DAMPED)
    return uplift_rates(GROUND, dq, t, y[Y_U], on, prm, FLEX)


@njit(cache=True, **INLINE)
def _lift_dip(t, y, y1, h, ev0, ev1, on, prm, FLEX, DAMPED, GROUND):
    """At rest (s = 0, sigma = 0), the uplift function that fell and rose again inside the
    step (t, y) -> (t + h, y1), above 0 at both ends: (slot, tau, g_min) at the minimum of
    its cubic Hermite interpolant, as ``events._crossing``'s dip (an uplift moment that
    peaked inside a coarse step: threshold seeds 28, 29 and 31 with body.mu, where finer
    runs uplift by a hair there and impact, and fall in mode 1, not 2); (-1, h, inf) if
    none. The slide's uplift function has no rate here: it is not screened."""
    if not (ev0[0] > 0.0 and ev1[0] > 0.0 and ev0[1] > 0.0 and ev1[1] > 0.0):
        return -1, h, np.inf
    d0 = _lift_rates(t, y, on, prm, FLEX, DAMPED, GROUND)
    if not (d0[0] < 0.0 or d0[1] < 0.0):
        return -1, h, np.inf
    d1 = _lift_rates(t + h, y1, on, prm, FLEX, DAMPED, GROUND)
    for slot in (SLOT_FIRST, SLOT_SECOND):
        if d0[slot] < 0.0 < d1[slot]:
            tau, g_min = hermite_min(ev0[slot], d0[slot], ev1[slot], d1[slot], h)
            return slot, tau, g_min
    return -1, h, np.inf


@njit(cache=True, **INLINE)
def _slip_turned(slot, sigma, g0, g1):
    """A slip that starts at x' = 0 (g0 = sigma x' = 0: a phase entered by ``_choose``)
    and ends its first step moving against sigma: it stopped and turned inside the step.
    Without this the slot, which fires only from > 0, never fires, and friction pushes
    the base along its slip (energy from nowhere: a block at alpha 0.15, mu 0.5, sine
    w/p 12, A_ratio 12 slid 11 b and overturned at `default`, safe at `fine` and in the
    reference)."""
    return slot == SLOT_CONTACT and sigma != 0 and g0 == 0.0 and g1 < 0.0


@njit(cache=True, **INTERNAL)
def _search(t, y, k1, y1, h, ev0, ev1, dip, s, sigma, on, mu, mu_s, prm, FLEX, DAMPED,
            ENERGY, GROUND):
    """The first event of the step (t, y) -> (t + h, y1): (slot, tau, y(tau), trials);
    slot -1, h, y1 if none. ev0, ev1: the event values at both ends; dip: ``_lift_dip``'s
    (slot, tau, g_min) at rest (slot -1 elsewhere). Every slot that
    changed sign is located, the earliest kept; an impact right after theta = 0 (the
    motion turning straight back) too. One that dips through theta = 0 and back inside
    the step (a grazing one), and at rest an uplift moment that peaks past M g b inside
    it (``_lift_dip``), are screened with the function's cubic Hermite interpolant and
    checked on a fresh step to its minimum."""
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    best, tau_best, y_best, n = -1, h, y1, 0
    for slot in range(N_SLOTS):
        g0, g1 = _pick(ev0, slot), _pick(ev1, slot)
        # theta = 0 after an impact or an uplift: a motion that turns straight back is an
        # impact just after t (as ``events._crossing``); the other functions fire only
        # from > 0 (a phase held on the wrong side of its cone waits to come back)
        if not (g0 > 0.0 or (s != 0 and slot == SLOT_FIRST and g0 == 0.0 and g1 <= 0.0)
                or _slip_turned(slot, sigma, g0, g1)):
            continue
        hi, g_hi, y_hi = h, g1, y1
        if g1 > 0.0:
            # a dip inside the step: theta's toward 0 (rocking), or an uplift moment's
            # toward M g b (at rest, ``_lift_dip``), checked on a fresh step to its minimum
            if s != 0 and slot == SLOT_FIRST:
                d0, d1 = s * y[Y_THETA_DOT], s * y1[Y_THETA_DOT]
                if not (d0 < 0.0 < d1):
                    continue
                tm, g_min = hermite_min(g0, d0, g1, d1, h)
            elif dip[0] == slot:
                tm, g_min = dip[1], dip[2]
            else:
                continue
            if g_min > min(g0, g1) - g_min or not 0.0 < tm < h:
                continue
            y_m = _rk4(t, y, tm, k1, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND)
            n += 1
            g_m = _pick(_event_values(t + tm, y_m, s, sigma, on, mu, mu_s, prm, FLEX, DAMPED,
                                      GROUND), slot)
            if g_m > 0.0:
                continue
            hi, g_hi, y_hi = tm, g_m, y_m
        if best >= 0 and hi > tau_best:
            # a bracket past the earliest event so far: its root may still come first.
            # Shrink it to that event's time (its state a fresh step, as _locate's
            # trials); skip it only where it has not fired by then. (Skipped whole, a
            # block's stick break from rest lost to its later uplift in the same step:
            # the slip started at the uplift, slide_max 1.5% short at `draft`.)
            g_b = _pick(_event_values(t + tau_best, y_best, s, sigma, on, mu, mu_s, prm,
                                      FLEX, DAMPED, GROUND), slot)
            if g_b > 0.0:
                continue
            hi, g_hi, y_hi = tau_best, g_b, y_best
        tau, y_ev, k = _locate(slot, t, y, k1, g0, hi, g_hi, y_hi, s, sigma, on, mu, mu_s,
                               prm, FLEX, DAMPED, ENERGY, GROUND)
        n += k
        if best < 0 or tau < tau_best:
            best, tau_best, y_best = slot, tau, y_ev
    if best >= 0:
        # A slot that fired and came back inside the step (above zero again at its end, so
        # not bracketed above) may have fired before the event taken: where it is below
        # zero there, it came first, and is located before it. (Kept, a slip stop after
        # such an impact left a flexible body at mu 0.73 rocking on the wrong side of its
        # corner, through the ground: 3.5 b of slip, |theta| to 18 alpha.)
        ev_b = _event_values(t + tau_best, y_best, s, sigma, on, mu, mu_s, prm, FLEX,
                             DAMPED, GROUND)
        for slot in range(N_SLOTS):
            g0, g_b = _pick(ev0, slot), _pick(ev_b, slot)
            if slot == best or not g_b < 0.0 or not (
                    g0 > 0.0 or (s != 0 and slot == SLOT_FIRST and g0 == 0.0)
                    or _slip_turned(slot, sigma, g0, g_b)):
                continue
            tau, y_ev, k = _locate(slot, t, y, k1, g0, tau_best, g_b, y_best, s, sigma, on,
                                   mu, mu_s, prm, FLEX, DAMPED, ENERGY, GROUND)
            n += k
            if tau < tau_best:
                best, tau_best, y_best = slot, tau, y_ev
    return best, tau_best, y_best, n
