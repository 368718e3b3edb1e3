"""Event detection and location inside one RK4 step (jitted).

Event functions g (the event fires when g crosses from > 0 to <= 0):

  impact     g = s theta              (rocking on corner s)
  overturn   g = pi/2 - s theta
  uplift     g = M g b - s Q          (full contact, each corner s; Q from ``uplift_moment``;
                                       with a vertical, g + a_v in both)

The pulse end is not searched for: the loop shortens the step to land on it exactly.

``_first_event`` asks ``_crossing`` about a phase's two event functions. ``_crossing``
decides whether g crossed zero inside the step: a sign change at the ends, or a dip through
zero and back that leaves both ends on the same side, screened with the step's cubic
Hermite interpolant (``hermite_min``) and searched by ``_dip``. ``_locate`` shrinks the
bracket of a crossing to the event tolerance by re-integrating from the step's start, with
one of three root finders (bisection, Illinois, Hermite: ``hermite_root``).
"""

import math

from numba import literally, njit

from rocksweep.kernel._cache import INLINE, INTERNAL
from rocksweep.kernel.equations import (
    tip_moment,
    uplift_moment,
    uplift_moment_rate,
    uplift_rates,
)
from rocksweep.kernel.ground import ground_acc, ground_gravity, ground_jerk
from rocksweep.kernel.layout import (
    PAR_ROOT,
    PAR_THETA_OVER,
    PAR_TOL,
    ROOT_HERMITE,
    ROOT_ILLINOIS,
    Y_THETA,
    Y_THETA_DOT,
    Y_U,
    Y_U_DOT,
)
from rocksweep.kernel.stepping import rk4_from

EV_NONE = 0
EV_IMPACT = 1
EV_OVERTURN = 2
EV_UPLIFT_POS = 3
EV_UPLIFT_NEG = 4

# hermite_min: below this |3 c3| the interpolant is a quadratic (c3 = 0 to round-off) and
# its minimum is the root of a linear c'; dividing by it instead would overflow.
CUBIC_TINY = 1e-300
# hermite_root: Newton converges in 3-5 iterations from the secant start; 16 bound the loop
# even if every step fell back to bisection (2^-16 of the bracket).
NEWTON_MAX_ITER = 16
# hermite_root stops when a Newton step is below this fraction of the event tolerance:
# _locate puts the trial at least tol/2 inside the bracket anyway, so finer buys nothing.
NEWTON_XTOL = 0.05
# _locate (Hermite): a trial after the first goes this fraction of the tolerance past the
# cubic's root, away from the end the last trial moved. The root estimates converge fast
# but approach from one side (the cubic's error keeps its sign), so the trials at the
# estimates themselves kept landing on the same side; a trial just past the root brackets
# it from the other side, and the next one, past it the other way, closes the bracket at
# 2 x 0.45 < 1 tolerance. Figure 3(a): 4.24 -> 3.78 trials per event (its impacts come in
# chattering runs); no sweep point of the shipped scenes changes outcome.
HERMITE_PAST = 0.45
# _dip: Illinois on g' converges superlinearly (a few trials); this bounds a pathological g.
DIP_MAX_TRIALS = 50


# ----------------------------------------------------------------------------------------
# Event functions and their rates
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE)
def event_value(ev, t, y, s, on, prm, FLEX, DAMPED, GROUND):
    """Value of event function ``ev`` at (t, y) in phase s."""
    if ev == EV_IMPACT:
        return s * y[Y_THETA]
    if ev == EV_OVERTURN:
        return prm[PAR_THETA_OVER] - s * y[Y_THETA]
    g = ground_gravity(GROUND, t, on, prm)
    q = uplift_moment(y[Y_U], y[Y_U_DOT], ground_acc(GROUND, t, on, prm), g, prm, FLEX, DAMPED)
    mgb = tip_moment(g, prm)
    return mgb - q if ev == EV_UPLIFT_POS else mgb + q


@njit(cache=True, **INLINE)
def event_rate(ev, t, y, s, on, prm, FLEX, DAMPED, GROUND):
    """d/dt of event function ``ev`` at (t, y) (for the Hermite interpolant)."""
    if ev == EV_IMPACT:
        return s * y[Y_THETA_DOT]
    if ev == EV_OVERTURN:
        return -s * y[Y_THETA_DOT]
    dq = uplift_moment_rate(y[Y_U], y[Y_U_DOT], ground_acc(GROUND, t, on, prm),
                            ground_jerk(GROUND, t, on, prm), ground_gravity(GROUND, t, on, prm),
                            prm, FLEX, DAMPED)
    rate_pos, rate_neg = uplift_rates(GROUND, dq, t, y[Y_U], on, prm, FLEX)
    return rate_pos if ev == EV_UPLIFT_POS else rate_neg


# ----------------------------------------------------------------------------------------
# The cubic Hermite interpolant of g over a step (pure arithmetic; jitted callers only: the
# tests reach these through @njit wrappers)
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE)
def hermite_cubic(g0, d0, g1, d1, h):
    """(c2, c3) of the cubic Hermite interpolant c(x) = g0 + d0 h x + c2 x^2 + c3 x^3 of g
    on a step of length h (x in [0, 1]) from g and its rate at both ends."""
    return 3.0 * (g1 - g0) - h * (2.0 * d0 + d1), 2.0 * (g0 - g1) + h * (d0 + d1)


@njit(cache=True, **INLINE)
def hermite_min(g0, d0, g1, d1, h):
    """Minimum of the cubic Hermite interpolant of g on [0, h] when g dips inside the step.

    Called when g0 > 0, g1 > 0, d0 < 0 < d1 (g falls, then rises). Returns
    (tau, g_min) at the interior minimum of the cubic.
    """
    c2, c3 = hermite_cubic(g0, d0, g1, d1, h)
    # c'(x) = h d0 + 2 c2 x + 3 c3 x^2 = 0, root with c'' > 0
    qa, qb, qc = 3.0 * c3, 2.0 * c2, h * d0
    if abs(qa) < CUBIC_TINY:
        x = -qc / qb
    else:
        disc = qb * qb - 4.0 * qa * qc
        if disc < 0.0:
            disc = 0.0
        sq = math.sqrt(disc)
        # the minimum has c''(x) = 2 c2 + 6 c3 x > 0  <=>  x = (-qb + sq) / (2 qa)
        x = (-qb + sq) / (2.0 * qa)
    if x < 0.0:
        x = 0.0
    elif x > 1.0:
        x = 1.0
    return x * h, g0 + x * (h * d0 + x * (c2 + x * c3))


@njit(cache=True, **INLINE)
def hermite_root(g0, d0, g1, d1, h, xtol):
    """Root in [0, h] of the cubic Hermite interpolant of g when g0 >= 0 >= g1.

    Safeguarded Newton on c(x) = g0 + d0 h x + c2 x^2 + c3 x^3, x in [0, 1], keeping a
    bracket (c > 0 on its left end; g0 = 0 with the curve rising counts as > 0, so the root
    found is the crossing after it, not x = 0); a Newton step that leaves the bracket is
    replaced by a bisection. Stops when a step is, or the next is predicted to be, below
    xtol (in units of h). Returns tau. (Only the trials' placement depends on it: the
    bracket of an event is kept on g itself, ``_locate``.)
    """
    return hermite_newton(g0, d0, g1, d1, h, xtol)[0] * h


@njit(cache=True, **INLINE)
def hermite_newton(g0, d0, g1, d1, h, xtol):
    """``hermite_root``'s Newton iteration: (x = tau / h, iterations taken)."""
    c2, c3 = hermite_cubic(g0, d0, g1, d1, h)
    a, b = 0.0, 1.0
    # The start: a Newton step from the end nearer the root (by that step), or, from g = 0
    # (an excursion bracketed from the surface, e.g. a chattering impact), the root of the
    # parabola g0 + d0 h x + c2 x^2; else the secant (the midpoint from g = 0). Newton from
    # the midpoint took 5 iterations on average, up to the cap, on Figure 3(a)'s impacts
    # (the cubic's other root at x = 0 pulled it into bisections); from here ~1.4.
    if g0 > 0.0:
        step_lo = -g0 / (h * d0) if d0 < 0.0 else 2.0
        step_hi = g1 / (h * d1) if d1 < 0.0 else 2.0
        if 0.0 < step_lo < 1.0 and step_lo <= step_hi:
            x = step_lo
        elif 0.0 < step_hi < 1.0:
            x = 1.0 - step_hi
        else:
            x = g0 / (g0 - g1)
    else:
        x = -h * d0 / c2 if 0.0 < h * d0 < -c2 else 0.5
    iterations = 0
    for _ in range(NEWTON_MAX_ITER):
        iterations += 1
        c = g0 + x * (h * d0 + x * (c2 + x * c3))
        if c > 0.0:
            a = x
        else:
            b = x
        dc = h * d0 + x * (2.0 * c2 + 3.0 * x * c3)
        x_new = x - c / dc if dc != 0.0 else 0.5 * (a + b)
        # (landing on an end is a Newton step too: c = 0 there, the root itself)
        newton = dc != 0.0 and a <= x_new <= b
        if not newton:
            x_new = 0.5 * (a + b)
        dx = abs(x_new - x)
        # done when this step is below xtol, or, after a Newton step, when the next one is
        # predicted to be (Newton's error squares: |c''/(2 c')| dx^2): it would only
        # confirm the estimate
        done = dx < xtol or (newton and abs(c2 + 3.0 * c3 * x_new) * dx * dx < xtol * abs(dc))
        x = x_new
        if done:
            break
    return x, iterations


# ----------------------------------------------------------------------------------------
# Locating a crossing on the integrator's own solution
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INTERNAL)
def _locate(ev, t0, y0, k1, g_lo, hi, g_hi, y_hi, s, on, prm, FLEX, DAMPED, ENERGY, GROUND):
    """Shrink a bracket [0, hi] (g(0) = g_lo >= 0 >= g(hi) = g_hi, y(0) = y0, y(hi) = y_hi)
    of event ``ev`` to PAR_TOL.

    Every trial point is a fresh RK4 step of that length from (t0, y0), so the located
    state is the integrator's own solution, not an interpolant; all of them share the
    step's first stage k1 = dy/dt at (t0, y0) (``stepping.rk4_from``).

    Root finder (PAR_ROOT):

    - bisection: the design's guaranteed method, log2(h/tol) trials (18-25 at the presets);
    - Illinois regula falsi: keeps the bracket, converges superlinearly;
    - Hermite: each trial is the root of the cubic Hermite interpolant of g over the
      bracket (g and its rate at both ends: the rate comes with the state, theta' or
      dQ/dt), after the first moved HERMITE_PAST x tol past it (away from the end the
      last trial moved) and put at least tol/2 inside the bracket, so that two trials
      next to the root close it; two trials running that fail to halve the bracket are
      followed by one bisection step, which bounds the worst case. 2-5 trials per event
      (3.8 on average on Figure 3(a)).

    Returns (tau, y(tau), re-integrations), with tau on the far side of the root (the event
    has happened at tau).
    """
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    lo = 0.0
    tol = prm[PAR_TOL]
    illinois = prm[PAR_ROOT] == ROOT_ILLINOIS
    hermite = prm[PAR_ROOT] == ROOT_HERMITE
    n = 0
    side = 0
    slow = 0  # trials running that did not halve the bracket (Hermite)
    d_lo = d_hi = 0.0
    if hermite:
        d_lo = event_rate(ev, t0 + lo, y0, s, on, prm, FLEX, DAMPED, GROUND)
        d_hi = event_rate(ev, t0 + hi, y_hi, s, on, prm, FLEX, DAMPED, GROUND)
    while hi - lo > tol:
        width = hi - lo
        if hermite:
            mid = 0.5 * (lo + hi)
            if slow < 2:
                mid = lo + hermite_root(g_lo, d_lo, g_hi, d_hi, width, NEWTON_XTOL * tol / width)
                if not (mid == mid):
                    mid = 0.5 * (lo + hi)
                if side == 1:
                    mid += HERMITE_PAST * tol
                elif side == -1:
                    mid -= HERMITE_PAST * tol
                mid = min(max(mid, lo + 0.5 * tol), hi - 0.5 * tol)
        elif illinois:
            mid = hi - g_hi * (hi - lo) / (g_hi - g_lo)
            # stay strictly inside and shrink by at least tol/2 from either end
            if mid <= lo + 0.5 * tol or mid >= hi - 0.5 * tol or not (mid == mid):
                mid = 0.5 * (lo + hi)
        else:
            mid = 0.5 * (lo + hi)
        y_mid = rk4_from(t0, y0, mid, k1, s, on, prm, FLEX, DAMPED, ENERGY, GROUND)
        g_mid = event_value(ev, t0 + mid, y_mid, s, on, prm, FLEX, DAMPED, GROUND)
        d_mid = (event_rate(ev, t0 + mid, y_mid, s, on, prm, FLEX, DAMPED, GROUND) if hermite
                 else 0.0)
        n += 1
        if g_mid <= 0.0:
            hi, g_hi, d_hi, y_hi = mid, g_mid, d_mid, y_mid
            if side == -1 and illinois:
                g_lo *= 0.5
            side = -1
        else:
            lo, g_lo, d_lo = mid, g_mid, d_mid
            if side == 1 and illinois:
                g_hi *= 0.5
            side = 1
        if slow >= 2:
            slow = 0  # that was the bisection step: the next trial is Hermite's again
        else:
            slow = slow + 1 if hi - lo > 0.5 * width else 0
    return hi, y_hi, n


@njit(cache=True, **INLINE)
def _crossing(ev, t0, y0, k1, y1, h, s, on, prm, FLEX, DAMPED, ENERGY, GROUND):
    """Did event ``ev`` fire in the step (t0, y0) -> (t0 + h, y1)?

    Returns (tau, y_event, re-integrations, g_dip); tau < 0 if it did not. A sign change
    at the ends is bracketed at once. Same sign at both ends but falling then rising (a dip
    through zero and back, e.g. a grazing impact inside a coarse step) is checked with the
    step's cubic Hermite interpolant; when its minimum is nearer zero than the dip is deep,
    ``_dip`` searches the integrator's own solution. g_dip: the cubic's minimum (>= 0) of
    a dip that turned back without an event (inf if none): how near the event came, which
    the loop keeps for the uplift (OUT_LIFT_GRAZE). This screening runs for every event
    function at every step and is inlined into the loop (with ``_first_event``); the
    searches are calls.
    """
    g0 = event_value(ev, t0, y0, s, on, prm, FLEX, DAMPED, GROUND)
    g1 = event_value(ev, t0 + h, y1, s, on, prm, FLEX, DAMPED, GROUND)
    if g1 <= 0.0:
        # g0 = 0 happens right after an action put the state on g = 0 (uplift leaves
        # theta = 0): if the motion turns straight back, that is an event just after t0.
        tau, y_e, n = _locate(ev, t0, y0, k1, g0, h, g1, y1, s, on, prm, FLEX, DAMPED,
                              ENERGY, GROUND)
        return tau, y_e, n, math.inf
    if g0 <= 0.0:
        return -1.0, y1, 0, math.inf  # leaving g = 0 after an action: not an event
    d0 = event_rate(ev, t0, y0, s, on, prm, FLEX, DAMPED, GROUND)
    if d0 >= 0.0:
        return -1.0, y1, 0, math.inf
    d1 = event_rate(ev, t0 + h, y1, s, on, prm, FLEX, DAMPED, GROUND)
    if d1 <= 0.0:
        return -1.0, y1, 0, math.inf
    tau, g_min = hermite_min(g0, d0, g1, d1, h)
    if g_min > min(g0, g1) - g_min:
        # far from zero compared with the dip: the cubic is good enough
        return -1.0, y1, 0, g_min
    tau, y_e, n = _dip(ev, t0, y0, k1, y1, h, g0, d0, d1, tau, s, on, prm, FLEX, DAMPED,
                       ENERGY, GROUND)
    # a dip the search proved to stay above zero: the cubic's minimum (clipped at 0, where
    # the cubic dipped below and the solution did not) says how near it came
    return tau, y_e, n, (max(g_min, 0.0) if tau < 0.0 else math.inf)


@njit(cache=True, **INTERNAL)
def _dip(ev, t0, y0, k1, y1, h, g0, d0, d1, tau, s, on, prm, FLEX, DAMPED, ENERGY, GROUND):
    """A dip of g (g0 > 0, g(h) > 0, d0 < 0 < d1) whose cubic minimum (at tau) is near zero.

    The cubic is only an estimate: the minimum of the integrator's own solution (fresh RK4
    steps from t0, as in ``_locate``) is searched for (Illinois on g' = 0, bracketed by
    d0 < 0 < d1) until g <= 0 is found, which closes the bracket, or the bracket proves
    that the dip stays above zero (g convex there: g_min >= g - max|g'| * width).
    Returns as ``_crossing``.
    """
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    if not (0.0 < tau < h):
        tau = 0.5 * h
    lo, r_lo, f_lo, hi, r_hi, f_hi = 0.0, d0, d0, h, d1, d1
    side = 0
    n = 0
    while True:
        y_m = rk4_from(t0, y0, tau, k1, s, on, prm, FLEX, DAMPED, ENERGY, GROUND)
        g_m = event_value(ev, t0 + tau, y_m, s, on, prm, FLEX, DAMPED, GROUND)
        n += 1
        if g_m <= 0.0:
            tau, y_e, k = _locate(ev, t0, y0, k1, g0, tau, g_m, y_m, s, on, prm, FLEX,
                                  DAMPED, ENERGY, GROUND)
            return tau, y_e, n + k
        d_m = event_rate(ev, t0 + tau, y_m, s, on, prm, FLEX, DAMPED, GROUND)
        if d_m < 0.0:
            lo, r_lo, f_lo = tau, d_m, d_m
            if side == -1:
                f_hi *= 0.5
            side = -1
        else:
            hi, r_hi, f_hi = tau, d_m, d_m
            if side == 1:
                f_lo *= 0.5
            side = 1
        if (g_m > max(-r_lo, r_hi) * (hi - lo) or hi - lo <= prm[PAR_TOL]
                or n >= DIP_MAX_TRIALS):
            return -1.0, y1, n
        tau = lo - f_lo * (hi - lo) / (f_hi - f_lo)
        if not (lo < tau < hi):
            tau = 0.5 * (lo + hi)


@njit(cache=True, **INLINE)
def _first_event(t, y, k1, y1, h, s, on, prm, FLEX, DAMPED, ENERGY, GROUND):
    """The first event in the step (t, y) -> (t + h, y1) of phase s.

    Returns (event code, tau, state at the event, re-integrations, g_dip); EV_NONE and y1
    if none; g_dip: the least of the two event functions' ``_crossing`` dips (inf if none).
    """
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    # The two event codes of a phase go through variables (type int64, not a literal), so
    # that numba compiles _crossing, _locate, event_value and event_rate once, not once per
    # code (a literal argument is a specialisation of its own: 4x the compile time).
    if s != 0:
        ev_a, ev_b = EV_IMPACT, EV_OVERTURN
    else:
        ev_a, ev_b = EV_UPLIFT_POS, EV_UPLIFT_NEG
    tau, y_ev, n, dip = _crossing(ev_a, t, y, k1, y1, h, s, on, prm, FLEX, DAMPED, ENERGY,
                                  GROUND)
    if s != 0 and tau >= 0.0:
        return ev_a, tau, y_ev, n, dip  # the impact ends the phase before any overturning
    tau2, y_ev2, n2, dip2 = _crossing(ev_b, t, y, k1, y1, h, s, on, prm, FLEX, DAMPED, ENERGY,
                                      GROUND)
    dip = min(dip, dip2)
    if tau2 >= 0.0 and (tau < 0.0 or tau2 < tau):
        return ev_b, tau2, y_ev2, n + n2, dip
    if tau >= 0.0:
        return ev_a, tau, y_ev, n + n2, dip
    return EV_NONE, h, y1, n + n2, dip
