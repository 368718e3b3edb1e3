"""Fixed-step RK4 with event location: the loop that runs one point (jitted).

Design (scipy's ``_ivp`` split): ``rk4_step`` knows nothing of events; ``_crossing``
decides whether an event function crossed zero inside a step (including a dip through zero
and back that leaves both ends on the same side, found from the step's cubic Hermite
interpolant); ``_locate`` brackets and shrinks the root by re-integrating from the step's
start; ``simulate_point`` owns the phases and the actions.

Compile-time specialisation: the functions take the flags FLEX, DAMPED and ENERGY and call
``numba.literally`` on them, so numba compiles one specialisation per flag value (a
``Literal[bool]`` type) and the branches a variant does not need are removed at compile
time (by LLVM: numba still types and lowers them, its own dead-branch pruning does not
read literal arguments, so they cost compile time but no run time). The time history is
the exception: ``simulate_point`` gets ``hist=None`` when there is none, and numba prunes
the ``if hist is not None`` branches before typing. One small jitted entry point per
variant (bottom of this module) fixes the flags; every variant is assembled from the same
functions.

Speed: the right-hand sides (``derivatives`` and the equations), the event functions and
``rk4_step`` itself are inlined where they are called (numba ``inline="always"``), so an
RK4 step makes no function call: a call costs about as much as a right-hand side, most of
it the reference count of ``prm`` taken and dropped on every call (scripts/bench_kernel.py,
roofline; inlining ``rk4_step`` made the sweeps 10-20% faster, bit for bit the same, for
~8% more compile time).

Event functions g (the event fires when g crosses from > 0 to <= 0):
  impact     g = s theta              (rocking on corner s)
  overturn   g = pi/2 - s theta
  uplift     g = M g b - s Q          (full contact, each corner s; Q from ``uplift_moment``)
The pulse end is not searched for: the step is shortened to land on it exactly.
"""

import math

import numpy as np
from numba import literally, njit

from rocksweep.kernel.equations import (
    contact_rhs,
    ground_acc,
    ground_jerk,
    impact_loss,
    mechanical_energy,
    restitution,
    rigid_rhs,
    rocking_rhs,
    uplift_moment,
    uplift_moment_rate,
)
from rocksweep.kernel.layout import (
    HIST_D_DAMP,
    HIST_E,
    HIST_E_IMPACT,
    HIST_PHASE,
    HIST_T,
    HIST_THETA,
    HIST_THETA_DOT,
    HIST_U,
    HIST_U_DOT,
    HIST_W_IN,
    HIST_XG,
    OUT_CONTACTS,
    OUT_D_DAMP,
    OUT_E_END,
    OUT_E_GAINED,
    OUT_E_IMPACT,
    OUT_E_MAX,
    OUT_EVENT_STEPS,
    OUT_HIST_ROWS,
    OUT_IMPACTS,
    OUT_N_GAINING,
    OUT_OUTCOME,
    OUT_STATUS,
    OUT_STEPS,
    OUT_T_END,
    OUT_T_FIRST_IMPACT,
    OUT_T_OVERTURN,
    OUT_THETA_MAX,
    OUT_UPLIFTS,
    OUT_W_IN,
    OUTCOME_MODE1,
    OUTCOME_MODE2,
    OUTCOME_SAFE,
    PAR_B,
    PAR_C,
    PAR_DT,
    PAR_G,
    PAR_H,
    PAR_HCG,
    PAR_K,
    PAR_M,
    PAR_MAXEVENTS,
    PAR_MAXSTEPS,
    PAR_MTOT,
    PAR_RESTRATE,
    PAR_ROOT,
    PAR_TEND,
    PAR_THETA0,
    PAR_THETA_DOT0,
    PAR_THETA_OVER,
    PAR_TOL,
    PAR_TPULSE,
    ROOT_HERMITE,
    ROOT_ILLINOIS,
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
)

# Functions only ever called from jitted code: no Python or C entry point to build.
_INTERNAL = {"no_cpython_wrapper": True, "no_cfunc_wrapper": True}

EV_NONE = 0
EV_IMPACT = 1
EV_OVERTURN = 2
EV_UPLIFT_POS = 3
EV_UPLIFT_NEG = 4


# ----------------------------------------------------------------------------------------
# The right-hand side on the state (theta, theta', u, u', W_in, D_damp)
# ----------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def derivatives(t, y, s, on, prm, FLEX, DAMPED, ENERGY):
    """dy/dt for phase s (0 full contact, +-1 rocking corner); y is a 6-tuple."""
    theta, theta_dot, u, u_dot = y[0], y[1], y[2], y[3]
    xg = ground_acc(t, on, prm)
    if s == 0:
        if not FLEX:
            return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        u_dd, p_in, p_damp = contact_rhs(u, u_dot, xg, prm, DAMPED)
        if ENERGY:
            return (0.0, 0.0, u_dot, u_dd, p_in, p_damp)
        return (0.0, 0.0, u_dot, u_dd, 0.0, 0.0)
    if not FLEX:
        theta_dd, p_in = rigid_rhs(theta, theta_dot, s, xg, prm)
        if ENERGY:
            return (theta_dot, theta_dd, 0.0, 0.0, p_in, 0.0)
        return (theta_dot, theta_dd, 0.0, 0.0, 0.0, 0.0)
    theta_dd, u_dd, p_in, p_damp = rocking_rhs(theta, theta_dot, u, u_dot, s, xg, prm, DAMPED)
    if ENERGY:
        return (theta_dot, theta_dd, u_dot, u_dd, p_in, p_damp)
    return (theta_dot, theta_dd, u_dot, u_dd, 0.0, 0.0)


@njit(cache=True, inline="always")
def _axpy(y, a, k):
    return (y[0] + a * k[0], y[1] + a * k[1], y[2] + a * k[2],
            y[3] + a * k[3], y[4] + a * k[4], y[5] + a * k[5])


@njit(cache=True, inline="always")
def rk4_step(t, y, h, s, on, prm, FLEX, DAMPED, ENERGY):
    """One classical RK4 step of size h from (t, y). Returns the new 6-tuple."""
    # The four stages share one call site of the inlined right-hand side (numba types and
    # lowers it once, LLVM unrolls the loop): 1/4 of the compile time of four call sites.
    zero = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    k = k1 = k23 = zero
    for stage in range(4):
        c = 0.0 if stage == 0 else (h if stage == 3 else 0.5 * h)
        k = derivatives(t + c, _axpy(y, c, k), s, on, prm, FLEX, DAMPED, ENERGY)
        if stage == 0:
            k1 = k
        elif stage == 1:
            k23 = k
        elif stage == 2:
            k23 = _axpy(k23, 1.0, k)  # k2 + k3
    w = h / 6.0  # k is k4 now
    return (y[0] + w * (k1[0] + 2.0 * k23[0] + k[0]),
            y[1] + w * (k1[1] + 2.0 * k23[1] + k[1]),
            y[2] + w * (k1[2] + 2.0 * k23[2] + k[2]),
            y[3] + w * (k1[3] + 2.0 * k23[3] + k[3]),
            y[4] + w * (k1[4] + 2.0 * k23[4] + k[4]),
            y[5] + w * (k1[5] + 2.0 * k23[5] + k[5]))


# ----------------------------------------------------------------------------------------
# Events
# ----------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def event_value(ev, t, y, s, on, prm, FLEX, DAMPED):
    """Value of event function ``ev`` at (t, y) in phase s."""
    if ev == EV_IMPACT:
        return s * y[0]
    if ev == EV_OVERTURN:
        return prm[PAR_THETA_OVER] - s * y[0]
    q = uplift_moment(y[2], y[3], ground_acc(t, on, prm), prm, FLEX, DAMPED)
    mgb = prm[PAR_MTOT] * prm[PAR_G] * prm[PAR_B]
    return mgb - q if ev == EV_UPLIFT_POS else mgb + q


@njit(cache=True, inline="always")
def event_rate(ev, t, y, s, on, prm, FLEX, DAMPED):
    """d/dt of event function ``ev`` at (t, y) (for the Hermite check)."""
    if ev == EV_IMPACT:
        return s * y[1]
    if ev == EV_OVERTURN:
        return -s * y[1]
    dq = uplift_moment_rate(y[2], y[3], ground_acc(t, on, prm), ground_jerk(t, on, prm), prm,
                            FLEX, DAMPED)
    return -dq if ev == EV_UPLIFT_POS else dq


@njit(cache=True, inline="always")
def _hermite_cubic(g0, d0, g1, d1, h):
    """(c2, c3) of the cubic Hermite interpolant c(x) = g0 + d0 h x + c2 x^2 + c3 x^3 of g
    on a step of length h (x in [0, 1]) from g and its rate at both ends."""
    return 3.0 * (g1 - g0) - h * (2.0 * d0 + d1), 2.0 * (g0 - g1) + h * (d0 + d1)


@njit(cache=True, inline="always")
def hermite_min(g0, d0, g1, d1, h):
    """Minimum of the cubic Hermite interpolant of g on [0, h] when g dips inside the step.

    Called when g0 > 0, g1 > 0, d0 < 0 < d1 (g falls, then rises). Returns
    (tau, g_min) at the interior minimum of the cubic.
    """
    c2, c3 = _hermite_cubic(g0, d0, g1, d1, h)
    # c'(x) = h d0 + 2 c2 x + 3 c3 x^2 = 0, root with c'' > 0
    qa, qb, qc = 3.0 * c3, 2.0 * c2, h * d0
    if abs(qa) < 1e-300:
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


@njit(cache=True, inline="always")
def hermite_root(g0, d0, g1, d1, h, xtol):
    """Root in [0, h] of the cubic Hermite interpolant of g when g0 >= 0 >= g1.

    Safeguarded Newton on c(x) = g0 + d0 h x + c2 x^2 + c3 x^3, x in [0, 1], keeping a
    bracket (c > 0 on its left end; g0 = 0 with the curve rising counts as > 0, so the root
    found is the crossing after it, not x = 0); a Newton step that leaves the bracket is
    replaced by a bisection. Stops when a step is below xtol (in units of h). Returns tau.
    """
    c2, c3 = _hermite_cubic(g0, d0, g1, d1, h)
    a, b = 0.0, 1.0
    x = g0 / (g0 - g1) if g0 > 0.0 else 0.5
    for _ in range(16):
        c = g0 + x * (h * d0 + x * (c2 + x * c3))
        if c > 0.0:
            a = x
        else:
            b = x
        dc = h * d0 + x * (2.0 * c2 + 3.0 * x * c3)
        x_new = x - c / dc if dc != 0.0 else 0.5 * (a + b)
        if not (a < x_new < b):
            x_new = 0.5 * (a + b)
        done = abs(x_new - x) < xtol
        x = x_new
        if done:
            break
    return x * h


@njit(cache=True, **_INTERNAL)
def _locate(ev, t0, y0, lo, g_lo, hi, g_hi, y_hi, s, on, prm, FLEX, DAMPED, ENERGY):
    """Shrink a bracket [lo, hi] (g(lo) >= 0 >= g(hi); lo = 0, y(lo) = y0) of event ``ev``
    to PAR_TOL.

    Every trial point is a fresh RK4 step of that length from (t0, y0), so the located
    state is the integrator's own solution, not an interpolant. Root finder (PAR_ROOT):

    - bisection: the design's guaranteed method, log2(h/tol) trials (18-25 at the presets);
    - Illinois regula falsi: keeps the bracket, converges superlinearly;
    - Hermite: each trial is the root of the cubic Hermite interpolant of g over the
      bracket (g and its rate at both ends: the rate comes with the state, theta' or
      dQ/dt), put at least tol/2 inside the bracket, so that a trial next to the root
      closes it; two trials running that fail to halve the bracket are followed by a
      bisection step, which bounds the worst case. 2-4 trials per event.

    Returns (tau, y(tau), re-integrations), with tau on the far side of the root (the event
    has happened at tau).
    """
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    tol = prm[PAR_TOL]
    illinois = prm[PAR_ROOT] == ROOT_ILLINOIS
    hermite = prm[PAR_ROOT] == ROOT_HERMITE
    n = 0
    side = 0
    slow = 0  # trials running that did not halve the bracket (Hermite)
    d_lo = d_hi = 0.0
    if hermite:
        d_lo = event_rate(ev, t0 + lo, y0, s, on, prm, FLEX, DAMPED)
        d_hi = event_rate(ev, t0 + hi, y_hi, s, on, prm, FLEX, DAMPED)
    while hi - lo > tol:
        width = hi - lo
        if hermite:
            mid = 0.5 * (lo + hi)
            if slow < 2:
                mid = lo + hermite_root(g_lo, d_lo, g_hi, d_hi, width, 0.05 * tol / width)
                if not (mid == mid):
                    mid = 0.5 * (lo + hi)
                mid = min(max(mid, lo + 0.5 * tol), hi - 0.5 * tol)
        elif illinois:
            mid = hi - g_hi * (hi - lo) / (g_hi - g_lo)
            # stay strictly inside and shrink by at least tol/2 from either end
            if mid <= lo + 0.5 * tol or mid >= hi - 0.5 * tol or not (mid == mid):
                mid = 0.5 * (lo + hi)
        else:
            mid = 0.5 * (lo + hi)
        y_mid = rk4_step(t0, y0, mid, s, on, prm, FLEX, DAMPED, ENERGY)
        g_mid = event_value(ev, t0 + mid, y_mid, s, on, prm, FLEX, DAMPED)
        d_mid = event_rate(ev, t0 + mid, y_mid, s, on, prm, FLEX, DAMPED) if hermite else 0.0
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
        slow = slow + 1 if hi - lo > 0.5 * width else 0
    return hi, y_hi, n


@njit(cache=True, inline="always")
def _crossing(ev, t0, y0, y1, h, s, on, prm, FLEX, DAMPED, ENERGY):
    """Did event ``ev`` fire in the step (t0, y0) -> (t0 + h, y1)?

    Returns (tau, y_event, re-integrations); tau < 0 if it did not. A sign change at the
    ends is bracketed at once. Same sign at both ends but falling then rising (a dip
    through zero and back, e.g. a grazing impact inside a coarse step) is checked with the
    step's cubic Hermite interpolant; when its minimum is nearer zero than the dip is deep,
    ``_dip`` searches the integrator's own solution. This screening runs for every event
    function at every step and is inlined into the loop; the searches are calls.
    """
    g0 = event_value(ev, t0, y0, s, on, prm, FLEX, DAMPED)
    g1 = event_value(ev, t0 + h, y1, s, on, prm, FLEX, DAMPED)
    if g1 <= 0.0:
        # g0 = 0 happens right after an action put the state on g = 0 (uplift leaves
        # theta = 0): if the motion turns straight back, that is an event just after t0.
        return _locate(ev, t0, y0, 0.0, g0, h, g1, y1, s, on, prm, FLEX, DAMPED, ENERGY)
    if g0 <= 0.0:
        return -1.0, y1, 0  # leaving g = 0 after an action: not an event
    d0 = event_rate(ev, t0, y0, s, on, prm, FLEX, DAMPED)
    if d0 >= 0.0:
        return -1.0, y1, 0
    d1 = event_rate(ev, t0 + h, y1, s, on, prm, FLEX, DAMPED)
    if d1 <= 0.0:
        return -1.0, y1, 0
    tau, g_min = hermite_min(g0, d0, g1, d1, h)
    if g_min > min(g0, g1) - g_min:
        return -1.0, y1, 0  # far from zero compared with the dip: the cubic is good enough
    return _dip(ev, t0, y0, y1, h, g0, d0, d1, tau, s, on, prm, FLEX, DAMPED, ENERGY)


@njit(cache=True, **_INTERNAL)
def _dip(ev, t0, y0, y1, h, g0, d0, d1, tau, s, on, prm, FLEX, DAMPED, ENERGY):
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
        y_m = rk4_step(t0, y0, tau, s, on, prm, FLEX, DAMPED, ENERGY)
        g_m = event_value(ev, t0 + tau, y_m, s, on, prm, FLEX, DAMPED)
        n += 1
        if g_m <= 0.0:
            tau, y_e, k = _locate(ev, t0, y0, 0.0, g0, tau, g_m, y_m, s, on, prm, FLEX,
                                  DAMPED, ENERGY)
            return tau, y_e, n + k
        d_m = event_rate(ev, t0 + tau, y_m, s, on, prm, FLEX, DAMPED)
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
        if g_m > max(-r_lo, r_hi) * (hi - lo) or hi - lo <= prm[PAR_TOL] or n >= 50:
            return -1.0, y1, n
        tau = lo - f_lo * (hi - lo) / (f_hi - f_lo)
        if not (lo < tau < hi):
            tau = 0.5 * (lo + hi)


@njit(cache=True, **_INTERNAL)
def uplift_side(t, y, on, prm, FLEX, DAMPED):
    """Corner (+1 / -1) the body uplifts on from full contact at (t, y), or 0."""
    q = uplift_moment(y[2], y[3], ground_acc(t, on, prm), prm, FLEX, DAMPED)
    mgb = prm[PAR_MTOT] * prm[PAR_G] * prm[PAR_B]
    if q >= mgb:
        return 1
    if q <= -mgb:
        return -1
    return 0


@njit(cache=True, **_INTERNAL)
def rest_proven(y, prm, FLEX):
    """After the pulse, in full contact: can the oscillator ever uplift the body again?

    Q = (h k + m g) u + h c u' is linear in (u, u'); over the energy ellipse
    1/2 m u'^2 + 1/2 k u^2 <= E (which c >= 0 never lets grow) its largest value is
    sqrt(2 E (L_u^2/k + L_v^2/m)). Below M g b the body stays in contact for good.
    """
    if not FLEX:
        return True
    m, k, h = prm[PAR_M], prm[PAR_K], prm[PAR_H]
    l_u = h * k + m * prm[PAR_G]
    l_v = h * prm[PAR_C]
    e2 = m * y[3] * y[3] + k * y[2] * y[2]  # 2 E
    q_max2 = e2 * (l_u * l_u / k + l_v * l_v / m)
    mgb = prm[PAR_MTOT] * prm[PAR_G] * prm[PAR_B]
    return q_max2 < mgb * mgb


@njit(cache=True, **_INTERNAL)
def rigid_bounded(y, s, prm):
    """After the pulse, a rigid body rocking on corner s: is its outcome decided (safe)?

    With no ground motion its energy E is constant while it rocks and is multiplied by
    e^2 <= 1 at every impact when |e| <= 1 (lam <= 1; e is the same at every impact).
    The potential V = M g (R cos(a - s theta) - h_cg), a = atan(b/h_cg), peaks at
    s theta = a; a body inside the barrier (s theta < a) with E below that peak (with a
    1e-6 relative margin for the integrator's energy error) never overturns. Returns the
    largest |theta| still to come (V = E if moving away from theta = 0, else V = e^2 E
    after the next impact), or -1 when not proven.
    """
    e = restitution(s, 0.0, prm, False)
    if abs(e) > 1.0:
        return -1.0
    mg, b, hcg = prm[PAR_MTOT] * prm[PAR_G], prm[PAR_B], prm[PAR_HCG]
    r = math.hypot(b, hcg)
    a = math.atan2(b, hcg)
    e_now = mechanical_energy(y[0], y[1], 0.0, 0.0, s, prm, False)
    if not (s * y[0] < a and e_now < (1.0 - 1e-6) * mg * (r - hcg)):
        return -1.0
    if s * y[1] < 0.0:
        e_now *= e * e
    return a - math.acos(min((e_now / mg + hcg) / r, 1.0))


# ----------------------------------------------------------------------------------------
# The loop
# ----------------------------------------------------------------------------------------


@njit(cache=True, **_INTERNAL)
def _record(hist, row, t, y, s, on, prm, e_imp, FLEX):
    literally(FLEX)
    if row >= hist.shape[0]:
        return False
    hist[row, HIST_T] = t
    hist[row, HIST_THETA] = y[0]
    hist[row, HIST_THETA_DOT] = y[1]
    hist[row, HIST_U] = y[2]
    hist[row, HIST_U_DOT] = y[3]
    hist[row, HIST_PHASE] = s
    hist[row, HIST_E] = mechanical_energy(y[0], y[1], y[2], y[3], s, prm, FLEX)
    hist[row, HIST_W_IN] = y[4]
    hist[row, HIST_D_DAMP] = y[5]
    hist[row, HIST_E_IMPACT] = e_imp
    hist[row, HIST_XG] = ground_acc(t, on, prm)
    return True


@njit(cache=True, **_INTERNAL)
def _first_event(t, y, y1, h, s, on, prm, FLEX, DAMPED, ENERGY):
    """The first event in the step (t, y) -> (t + h, y1) of phase s.

    Returns (event code, tau, state at the event, re-integrations); EV_NONE and y1 if none.
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
    tau, y_ev, n = _crossing(ev_a, t, y, y1, h, s, on, prm, FLEX, DAMPED, ENERGY)
    if s != 0 and tau >= 0.0:
        return ev_a, tau, y_ev, n  # the impact ends the phase before any overturning
    tau2, y_ev2, n2 = _crossing(ev_b, t, y, y1, h, s, on, prm, FLEX, DAMPED, ENERGY)
    if tau2 >= 0.0 and (tau < 0.0 or tau2 < tau):
        return ev_b, tau2, y_ev2, n + n2
    if tau >= 0.0:
        return ev_a, tau, y_ev, n + n2
    return EV_NONE, h, y1, n + n2


@njit(cache=True, **_INTERNAL)
def _impact(y, s, prm, FLEX, ENERGY):
    """Impact map at theta = 0 ending rocking on corner s (eq. 1 and the settling rule).

    Returns (state after, new phase, e, energy lost E_d [J], impact loss [J]) (energies 0
    unless ENERGY). E_d = E(before) - E(after) closes the energy balance; it includes the
    potential energy of the located state's overshoot of theta = 0 (within the event
    tolerance). The impact loss (``impact_loss``, eq. 6) is the impact's own share; only it
    decides whether an impact gained energy, so the overshoot cannot flag a spurious gain.
    e > 0 with |e theta'^-| >= PAR_RESTRATE: rocking continues on -s, theta'^+ = e theta'^-.
    Otherwise full contact: e <= 0 is inadmissible as rocking, and a post-impact rate
    below the rest rate ends a chattering (Zeno) sequence after finitely many impacts.
    Either way the top mass keeps its horizontal momentum m (u' + h theta').
    """
    literally(FLEX)
    literally(ENERGY)
    e = restitution(s, y[2], prm, FLEX)
    w_minus = y[1]
    if e > 0.0 and abs(e * w_minus) >= prm[PAR_RESTRATE]:
        s_new = -s
        w_plus = e * w_minus
    else:
        s_new = 0
        w_plus = 0.0
    u_dot_plus = y[3] + prm[PAR_H] * (w_minus - w_plus) if FLEX else 0.0
    y_new = (0.0, w_plus, y[2], u_dot_plus, y[4], y[5])
    e_d = 0.0
    loss = 0.0
    if ENERGY:
        e_d = (mechanical_energy(y[0], y[1], y[2], y[3], s, prm, FLEX)
               - mechanical_energy(0.0, w_plus, y[2], u_dot_plus, s_new, prm, FLEX))
        loss = impact_loss(s, s_new, y[2], w_minus, w_plus, prm, FLEX)
    return y_new, s_new, e, e_d, loss



@njit(cache=True, **_INTERNAL)
def simulate_point(prm, out, hist, FLEX, DAMPED, ENERGY):
    """Run one point from rest to a decided outcome, a cap or the horizon.

    prm: float64[N_PAR] parameter row; out: float64[N_OUT] result row (filled);
    hist: float64[n, N_HIST] history buffer, or None: no history (the recording code is
    then not compiled at all).
    """
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    dt, t_end, t_pulse = prm[PAR_DT], prm[PAR_TEND], prm[PAR_TPULSE]
    max_steps, max_events = prm[PAR_MAXSTEPS], prm[PAR_MAXEVENTS]

    t = 0.0
    theta0, theta_dot0 = prm[PAR_THETA0], prm[PAR_THETA_DOT0]
    y = (theta0, theta_dot0, 0.0, 0.0, 0.0, 0.0)
    s = 0
    status = 0
    outcome = OUTCOME_SAFE
    impacts = 0
    uplifts = 0
    contacts = 0
    steps = 0
    event_steps = 0
    theta_max = abs(theta0)
    t_over = np.nan
    t_first_impact = np.nan
    e_imp = 0.0  # net energy lost in impacts
    e_gained = 0.0
    n_gaining = 0
    e_max = 0.0
    row = 0
    free_check = True  # rigid: test rigid_bounded at the next loop top after the pulse

    on = t_pulse > 0.0
    if theta0 != 0.0 or theta_dot0 != 0.0:
        # a given initial state: rocking on the corner theta (else theta') points to
        s = 1 if theta0 > 0.0 or (theta0 == 0.0 and theta_dot0 > 0.0) else -1
    else:
        # Uplift is possible at t = 0 (a cosine pulse starts at its peak).
        s = uplift_side(t, y, on, prm, FLEX, DAMPED)
        if s != 0:
            uplifts += 1
    if hist is not None:
        if _record(hist, row, t, y, s, on, prm, e_imp, FLEX):
            row += 1

    while True:
        on = t < t_pulse
        if s == 0 and not on and rest_proven(y, prm, FLEX):
            status |= STATUS_REST
            break
        if t >= t_end:
            status |= STATUS_HORIZON
            break
        if not FLEX and s != 0 and not on and free_check:
            # E is constant between impacts after the pulse: test once per excursion
            free_check = False
            peak = rigid_bounded(y, s, prm)
            if peak >= 0.0:
                if peak > theta_max:
                    theta_max = peak
                status |= STATUS_BOUNDED
                break
        if steps + event_steps >= max_steps:
            status |= STATUS_STEP_CAP
            break
        if impacts + uplifts >= max_events:
            status |= STATUS_EVENT_CAP
            break

        h = dt
        lands = False
        if on and t + h >= t_pulse:
            h = t_pulse - t
            lands = True
        elif t + h > t_end:
            h = t_end - t
        y1 = rk4_step(t, y, h, s, on, prm, FLEX, DAMPED, ENERGY)
        steps += 1
        if not (math.isfinite(y1[0]) and math.isfinite(y1[1]) and math.isfinite(y1[2])
                and math.isfinite(y1[3])):
            status |= STATUS_NONFINITE
            break

        ev, tau, y_ev, n = _first_event(t, y, y1, h, s, on, prm, FLEX, DAMPED, ENERGY)
        event_steps += n

        # --- largest |theta|, including a turning point inside the step ---
        y_end = y_ev if ev != EV_NONE else y1
        h_end = tau if ev != EV_NONE else h
        if s != 0:
            a_end = abs(y_end[0])
            if a_end > theta_max:
                theta_max = a_end
            if s * y[1] > 0.0 and s * y_end[1] < 0.0:
                # turning point inside the step: Hermite maximum of s*theta = -min(-s*theta)
                _, gm = hermite_min(-s * y[0], -s * y[1], -s * y_end[0], -s * y_end[1], h_end)
                if -gm > theta_max:
                    theta_max = -gm

        if ev == EV_NONE:
            t = t_pulse if lands else t + h
            y = y1
            if hist is not None:
                if _record(hist, row, t, y, s, t < t_pulse, prm, e_imp, FLEX):
                    row += 1
                else:
                    status |= STATUS_HIST_FULL
            if lands and s == 0:
                # The pulse ends with a jump of xg'' (a cosine pulse ends at its peak), and
                # Q jumps with it by m_A h_A xg'': the state may now be past the uplift
                # threshold, which no crossing inside the next step would show. Checked at
                # once, as at t = 0 and after an impact.
                s = uplift_side(t, y, False, prm, FLEX, DAMPED)
                if s != 0:
                    uplifts += 1
                    if hist is not None:
                        if _record(hist, row, t, y, s, False, prm, e_imp, FLEX):
                            row += 1
                        else:
                            status |= STATUS_HIST_FULL
            continue

        t = t + tau
        y = y_ev
        if hist is not None:
            if _record(hist, row, t, y, s, on, prm, e_imp, FLEX):
                row += 1
            else:
                status |= STATUS_HIST_FULL

        if ev == EV_OVERTURN:
            outcome = OUTCOME_MODE1 if impacts > 0 else OUTCOME_MODE2
            t_over = t
            status |= STATUS_OVERTURNED
            break

        if ev == EV_IMPACT:
            impacts += 1
            free_check = True
            if impacts == 1:
                t_first_impact = t
            y, s_new, e, e_d, loss = _impact(y, s, prm, FLEX, ENERGY)
            s = s_new
            if e > e_max:
                e_max = e
            if e > 1.0:
                status |= STATUS_E_ABOVE_1
            if s == 0:
                contacts += 1
                if e > 0.0:
                    status |= STATUS_SETTLED
            if ENERGY:
                e_imp += e_d
                if loss < 0.0:
                    e_gained -= loss
                    n_gaining += 1
                    status |= STATUS_ENERGY_GAIN
            if s == 0:
                # back in full contact: uplift is checked again at once
                s = uplift_side(t, y, on, prm, FLEX, DAMPED)
                if s != 0:
                    uplifts += 1
        else:
            # uplift: theta = theta' = 0 exactly, now rocking on the located corner
            s = 1 if ev == EV_UPLIFT_POS else -1
            y = (0.0, 0.0, y[2], y[3], y[4], y[5])
            uplifts += 1
        if hist is not None:
            if _record(hist, row, t, y, s, on, prm, e_imp, FLEX):
                row += 1
            else:
                status |= STATUS_HIST_FULL

    out[OUT_OUTCOME] = outcome
    out[OUT_STATUS] = status
    out[OUT_IMPACTS] = impacts
    out[OUT_UPLIFTS] = uplifts
    out[OUT_THETA_MAX] = theta_max
    out[OUT_T_OVERTURN] = t_over
    out[OUT_T_END] = t
    out[OUT_STEPS] = steps
    out[OUT_EVENT_STEPS] = event_steps
    out[OUT_T_FIRST_IMPACT] = t_first_impact
    out[OUT_E_MAX] = e_max
    out[OUT_CONTACTS] = contacts
    out[OUT_HIST_ROWS] = row
    if ENERGY:
        out[OUT_W_IN] = y[4]
        out[OUT_D_DAMP] = y[5]
        out[OUT_E_IMPACT] = e_imp
        out[OUT_E_GAINED] = e_gained
        out[OUT_N_GAINING] = n_gaining
        out[OUT_E_END] = mechanical_energy(y[0], y[1], y[2], y[3], s, prm, FLEX)
    else:
        out[OUT_W_IN] = np.nan
        out[OUT_D_DAMP] = np.nan
        out[OUT_E_IMPACT] = np.nan
        out[OUT_E_GAINED] = np.nan
        out[OUT_N_GAINING] = np.nan
        out[OUT_E_END] = np.nan


@njit(cache=True, **_INTERNAL)
def _chunk(prms, outs, FLEX, DAMPED, ENERGY):
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, FLEX, DAMPED, ENERGY)


# ----------------------------------------------------------------------------------------
# Variants. One entry point per effect set; the flags are literals here.
#   chunk_*: prms float64[n, N_PAR] -> outs float64[n, N_OUT] (filled in place); they
#       release the GIL, so threads of one process run chunks in parallel
#   point_*: one point with energy accounting and a history buffer float64[n, N_HIST]
# ----------------------------------------------------------------------------------------


@njit(cache=True, nogil=True)
def chunk_flexible(prms, outs):
    _chunk(prms, outs, True, True, False)


@njit(cache=True, nogil=True)
def chunk_flexible_undamped(prms, outs):
    _chunk(prms, outs, True, False, False)


@njit(cache=True, nogil=True)
def chunk_rigid(prms, outs):
    _chunk(prms, outs, False, False, False)


@njit(cache=True, nogil=True)
def chunk_flexible_energy(prms, outs):
    _chunk(prms, outs, True, True, True)


@njit(cache=True, nogil=True)
def chunk_flexible_undamped_energy(prms, outs):
    _chunk(prms, outs, True, False, True)


@njit(cache=True, nogil=True)
def chunk_rigid_energy(prms, outs):
    _chunk(prms, outs, False, False, True)


@njit(cache=True)
def point_flexible_history(prm, out, hist):
    simulate_point(prm, out, hist, True, True, True)


@njit(cache=True)
def point_flexible_undamped_history(prm, out, hist):
    simulate_point(prm, out, hist, True, False, True)


@njit(cache=True)
def point_rigid_history(prm, out, hist):
    simulate_point(prm, out, hist, False, False, True)

