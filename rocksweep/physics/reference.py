"""The reference path: scipy's DOP853 with its own event handling (the yardstick).

``reference_run(point, numerics)`` runs one point with ``scipy.integrate.solve_ivp``
(DOP853, rtol 1e-10, atol 1e-12) and returns the same summary quantities as the kernel's
result row. It shares the equations with the RK4 kernel, one copy of each, from
``rocksweep.kernel.equations`` (called from Python): the ground motion (eq. 2) and its
rate, the right-hand sides, the uplift moment Q, its rate and the tipping moment M g b,
the restitution of eq. (1), the energy, the rest bound (``rest_margin``), the rigid bound
(``rigid_peak``), the ridge of the potential energy (``ridge_energy``) and the spring's
rate while rocking (its step limit). Their independent check is the sympy derivation
(tests/test_derivations.py). The integrator, the loop, the
event location, the impact map, the settling rule and the horizon are written again here,
from the rules documented in ``rocksweep.kernel.loop`` and ``rocksweep.kernel.transitions``
and the paper:

- full contact: m u'' + c u' + k u = -m xg''; the body uplifts on corner s when s Q >= M g b;
- rocking on corner s: the two-degree-of-freedom equations; impact when theta = 0,
  overturning when |theta| = pi/2;
- impact (eq. 1, or the point's impact law, ``rocksweep.physics.impact``): theta'^+ =
  e theta'^- and rocking goes on on the other corner if e > 0 and |e theta'^-| >= rest
  rate, else full contact; the top mass keeps its horizontal momentum m (u' + h theta')
  (laws vertical and constant) or its rate u' (law locked); full contact is checked for
  uplift at once;
- after the pulse, in full contact, rest is proven when the largest Q on the oscillator's
  energy ellipse is below M g b (the energy never grows: c >= 0);
- a rigid body after the pulse whose energy cannot carry it over the barrier stops early
  (safe, STATUS_BOUNDED), as in the kernel; so does a flexible body inside its ridge's
  peak whose energy, after an impact, is below the ridge at its theta_max
  (``ridge_energy``, where the row's PAR_RIDGE says its impacts lose energy), in a run
  without events or contact logged (the kernel's outcome-only variants);
- the run stops at the horizon t_pulse + horizon (flagged), or after max_events events.

Each phase is one ``solve_ivp`` call from the transition to the next one or to the next
scheduled time (the pulse's end, the horizon), so no step ever straddles a jump of the
right-hand side. Events are located by ``solve_ivp`` (Brent's method on the DOP853 dense
output, to a few ulps of t). A crossing hidden inside one step (the event function dips
through zero and back) is caught from the extrema of the event function, tracked as
non-terminal events: a minimum of s*theta at or below 0, or a maximum of s*Q at or above
M g b, means a crossing was stepped over; it is then located on the dense output between
the previous extremum and that one. theta_max is the largest |theta| over the maxima of
s*theta (located, not sampled) and the phase ends.

A vertical ground acceleration a_v (the point's ``Excitation``: ``vertical``, the
component as read, or ``harmonic``) is evaluated here from the point itself, not from the
kernel's reader of its row (``_vertical``): the equations above are called with gravity
g + a_v(t) in place of g, the uplift events compare Q with M (g + a_v) b, and the run
stops, ``airborne``, at the first time g + a_v <= 0, located by its own root search (``_air_time``).

Times are p*t (p = 1 rad/s), angles in rad, SI units with m = 1 kg (``rocksweep.physics.bodies``).
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel.contact import ground_reactions, impact_impulses, impulse_ratio
from rocksweep.kernel.equations import (
    BOUND_ENERGY_MARGIN,
    contact_rhs,
    mechanical_energy,
    rest_margin,
    restitution,
    ridge_energy,
    rigid_peak,
    rigid_rhs,
    rocking_rhs,
    rocking_spring_omega,
    tip_moment,
    uplift_moment,
    uplift_moment_rate,
)
from rocksweep.kernel.ground import any_ground_acc, any_ground_jerk
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import G
from rocksweep.physics.points import Point, point_row

RTOL = 1e-10
ATOL = 1e-12

_NONE, _IMPACT, _OVERTURN, _UPLIFT, _REST = 0, 1, 2, 3, 4


class _Problem:
    """One point's parameters and the phase right-hand sides and event functions."""

    def __init__(self, prm: np.ndarray, flex: bool, damped: bool, rtol: float, atol: float,
                 vertical: tuple | None = None):
        self.prm = prm
        self.flex = flex
        self.damped = damped
        self.rtol = rtol
        self.atol = atol
        self.omega = float(prm[L.PAR_OMEGA])
        self.t_pulse = float(prm[L.PAR_TPULSE])
        self.g = float(prm[L.PAR_G])
        self.mgb = float(tip_moment(self.g, prm))
        # (a_v(t), d a_v/dt(t), t_air) while the ground moves (``_vertical``), or None
        self.vertical = vertical
        self.t_air = math.inf if vertical is None else vertical[2]
        self.theta_over = float(prm[L.PAR_THETA_OVER])
        self.rest_rate = float(prm[L.PAR_RESTRATE])
        self.h = float(prm[L.PAR_H])
        self.law = float(prm[L.PAR_LAW])  # the impact law (e itself: ``restitution``)
        # largest step: a tenth of the shortest period (spring while rocking, pulse, 2 pi/p)
        periods = [2 * math.pi] + ([2 * math.pi / self.omega] if self.omega > 0 else [])
        # a record: its sample interval in kernel time (0: none); phases end on every
        # sample time while it acts, so no DOP853 step straddles a kink of the input
        self.rec_dt = float(prm[L.PAR_REC_DT]) if prm.shape[0] > L.N_PAR else 0.0
        if flex:  # the spring with the top mass at u = 0 (lever arm b); damping left to
            # DOP853's error control
            w_rock = rocking_spring_omega(math.sqrt(prm[L.PAR_K] / prm[L.PAR_M]), 0.0,
                                          prm[L.PAR_M], prm[L.PAR_H], prm[L.PAR_IA0],
                                          prm[L.PAR_B])
            periods.append(2 * math.pi / w_rock)
        self.max_step = min(periods) / 10.0
        self.nfev = 0
        self.steps = 0
        self.last_sol = None  # the latest phase's solution (dense output), for contact

    # --- eq. (2) -----------------------------------------------------------------------
    def xg(self, t: float, on: bool) -> float:
        return any_ground_acc(t, on, self.prm)

    def jerk(self, t: float, on: bool) -> float:
        return any_ground_jerk(t, on, self.prm)

    def gravity(self, t: float, on: bool) -> float:
        """g + a_v(t) [m/s^2] (g without a vertical, or when the ground is still)."""
        return self.g + self.vertical[0](t) if on and self.vertical is not None else self.g

    def gravity_rate(self, t: float, on: bool) -> float:
        return self.vertical[1](t) if on and self.vertical is not None else 0.0

    # --- full contact ------------------------------------------------------------------
    def q(self, t: float, y, on: bool) -> float:
        """Uplift moment Q [N m] in full contact, y = (u, u')."""
        return uplift_moment(y[0], y[1], self.xg(t, on), self.gravity(t, on), self.prm,
                             self.flex, self.damped)

    def weight(self, t: float, on: bool) -> float:
        """M (g + a_v) b [N m]: what resists uplift at t."""
        return self.mgb if self.vertical is None else tip_moment(self.gravity(t, on), self.prm)

    def ratio_rate(self, t: float, y, on: bool) -> float:
        """d/dt (Q / (M (g + a_v) b)) times (M (g + a_v) b)^2, y = (u, u'): its zeros are
        the extrema of Q against the weight's moment (of Q itself without a vertical)."""
        g = self.gravity(t, on)
        dq = uplift_moment_rate(y[0], y[1], self.xg(t, on), self.jerk(t, on), g, self.prm,
                                self.flex, self.damped)
        if self.vertical is None:
            return dq * self.mgb
        dg = self.gravity_rate(t, on)
        if self.flex:
            dq += self.prm[L.PAR_M] * dg * y[0]  # Q's m (g + a_v) u
        w = self.weight(t, on)
        return dq * w - self.q(t, y, on) * self.prm[L.PAR_MTOT] * dg * self.prm[L.PAR_B]

    def uplift_corner(self, t: float, y, on: bool) -> int:
        """Corner the body uplifts on from full contact at (t, y): s with s Q >= M g b, or 0."""
        q, w = self.q(t, y, on), self.weight(t, on)
        if q >= w:
            return 1
        if q <= -w:
            return -1
        return 0

    def rest_margin(self, y) -> float:
        """Largest Q^2 over the energy ellipse of (u, u') minus (M g b)^2 (< 0: rest)."""
        if not self.flex:
            return -1.0
        return rest_margin(y[0], y[1], self.prm)

    def contact_fun(self, on: bool):
        prm, damped = self.prm, self.damped

        if not self.flex:
            def fun(t, y):
                self.nfev += 1
                return (0.0, 0.0)
            return fun

        def fun(t, y):
            self.nfev += 1
            u_dd = contact_rhs(y[0], y[1], self.xg(t, on), prm, damped)[0]
            return (y[1], u_dd)
        return fun

    # --- rocking -----------------------------------------------------------------------
    def rocking_fun(self, s: int, on: bool):
        prm, damped = self.prm, self.damped

        if not self.flex:
            def fun(t, y):
                self.nfev += 1
                return (y[1], rigid_rhs(y[0], y[1], s, self.xg(t, on), self.gravity(t, on),
                                        prm)[0])
            return fun

        def fun(t, y):
            self.nfev += 1
            th_dd, u_dd, _, _ = rocking_rhs(y[0], y[1], y[2], y[3], s, self.xg(t, on),
                                            self.gravity(t, on), prm, damped)
            return (y[1], th_dd, y[3], u_dd)
        return fun

    def solve(self, fun, t0: float, t1: float, y0, events):
        sol = solve_ivp(fun, (t0, t1), y0, method="DOP853", rtol=self.rtol, atol=self.atol,
                        max_step=self.max_step, events=events, dense_output=True)
        self.steps += len(sol.t) - 1
        self.last_sol = sol
        return sol


def _event(fn, t0: float, direction: float, terminal: bool):
    """An event function for solve_ivp that is armed only once it leaves zero.

    A phase often starts on its own event surface (theta = 0 after an impact or uplift,
    theta' = 0 after an uplift). There g(t0) = 0 would make Brent's method return t0 for
    any crossing inside the first step, so an exact zero at t0 reads as "not yet" (+1).
    """
    def g(t, y):
        v = fn(t, y)
        return 1.0 if (v == 0.0 and t == t0) else v

    g.direction = direction
    g.terminal = terminal
    return g


def _far_side(g, t: float) -> float:
    """Nudge t forward by a few ulps until g(t) <= 0 (the event has happened at t)."""
    step = 4 * np.finfo(float).eps * max(1.0, abs(t))
    for _ in range(60):
        if g(t) <= 0.0:
            break
        t += step
        step *= 2.0
    return t


def _root(g, lo: float, hi: float) -> float:
    """The root of g on [lo, hi] (g(lo) > 0 >= g(hi)), on its far side."""
    t = brentq(g, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
    return _far_side(g, t)


def _first_hidden(sol, t0: float, t_end: float, extrema, minima, g) -> float | None:
    """Earliest crossing of g that the solver stepped over (g dipped to <= 0 and back
    inside one step), before t_end.

    extrema: times of every located extremum of g; minima: those that can lie beyond zero
    (a minimum of s theta; an extremum of Q). A minimum with g <= 0 means a crossing since
    the latest extremum with g > 0 (or t0); g is monotone between the two, so the crossing
    is the one root there, located on the dense output.
    """
    for te in sorted(minima):
        if te >= t_end:
            break
        if te <= t0 or g(te) > 0.0:
            continue
        lo = t0
        for tx in sorted(extrema):
            if t0 < tx < te and g(tx) > 0.0:
                lo = tx
        return _root(lambda t: 1.0 if t == t0 else g(t), lo, te)
    return None


def _contact(pb: _Problem, t0: float, y0, t1: float, on: bool):
    """Full contact from t0 to t1 at most. Returns (event, t, y) with y = (u, u')."""
    def mgb(t):
        return pb.weight(t, on)

    events = [
        _event(lambda t, y: mgb(t) - pb.q(t, y, on), t0, -1.0, True),
        _event(lambda t, y: mgb(t) + pb.q(t, y, on), t0, -1.0, True),
        _event(lambda t, y: pb.ratio_rate(t, y, on), t0, 0.0, False),
    ]
    rest = not on and pb.flex
    if rest:
        events.append(_event(lambda t, y: pb.rest_margin(y), t0, -1.0, True))
    sol = pb.solve(pb.contact_fun(on), t0, t1, list(y0), events)
    if sol.status < 0:
        return -1, t0, y0
    t_stop, kind = sol.t[-1], _NONE
    if sol.status == 1:
        for i, k in ((0, _UPLIFT), (1, _UPLIFT), (3, _REST)):
            if i < len(sol.t_events) and len(sol.t_events[i]) and sol.t_events[i][0] <= t_stop:
                t_stop, kind = sol.t_events[i][0], k
    # an uplift stepped over inside one step: an extremum of Q beyond M g b
    t_hid = _first_hidden(sol, t0, t_stop, sol.t_events[2], sol.t_events[2],
                          lambda t: mgb(t) - abs(pb.q(t, sol.sol(t), on)))
    if t_hid is not None:
        t_stop, kind = t_hid, _UPLIFT
    if kind == _UPLIFT:  # land on the far side: s Q >= M g b at the uplift state
        t_stop = _far_side(lambda t: mgb(t) - abs(pb.q(t, sol.sol(t), on)), t_stop)
    y = tuple(sol.sol(t_stop)) if t_stop != sol.t[-1] else tuple(sol.y[:, -1])
    return kind, t_stop, y


def _rocking(pb: _Problem, t0: float, y0, s: int, t1: float, on: bool):
    """Rocking on corner s from t0 to t1 at most.

    Returns (event, t, y, largest |theta| seen) with y = (theta, theta', u, u').
    """
    flex = pb.flex
    events = [
        _event(lambda t, y: s * y[0], t0, -1.0, True),
        _event(lambda t, y: pb.theta_over - s * y[0], t0, -1.0, True),
        _event(lambda t, y: s * y[1], t0, -1.0, False),  # maxima of s theta
        _event(lambda t, y: s * y[1], t0, 1.0, False),  # minima of s theta
    ]
    y_start = list(y0) if flex else [y0[0], y0[1]]
    sol = pb.solve(pb.rocking_fun(s, on), t0, t1, y_start, events)
    if sol.status < 0:
        return -1, t0, y0, 0.0
    t_stop, kind = sol.t[-1], _NONE
    if sol.status == 1:
        for i, k in ((0, _IMPACT), (1, _OVERTURN)):
            if len(sol.t_events[i]) and sol.t_events[i][0] <= t_stop:
                t_stop, kind = sol.t_events[i][0], k
    t_hid = _first_hidden(sol, t0, t_stop, [*sol.t_events[2], *sol.t_events[3]],
                          sol.t_events[3], lambda t: s * sol.sol(t)[0])
    if t_hid is not None:
        t_stop, kind = t_hid, _IMPACT
    theta_max = 0.0
    for te, ye in zip(sol.t_events[2], sol.y_events[2], strict=True):
        if te <= t_stop:
            theta_max = max(theta_max, abs(ye[0]))
    y = sol.sol(t_stop) if t_stop != sol.t[-1] else sol.y[:, -1]
    if kind == _IMPACT:
        y = np.array(y)
        y[0] = 0.0
    elif kind == _OVERTURN:
        y = np.array(y)
        y[0] = s * pb.theta_over
    theta_max = max(theta_max, abs(y[0]))
    if flex:
        return kind, t_stop, (y[0], y[1], y[2], y[3]), theta_max
    return kind, t_stop, (y[0], y[1], 0.0, 0.0), theta_max


# Contact outputs on the reference path: samples per DOP853 step of a phase's dense output
# (its steps are at most a tenth of the shortest period), then the largest sample is
# refined by a bounded Brent search on the dense output between its neighbours.
CONTACT_SAMPLES = 24


class _Contact:
    """Running friction demand max |H|/N, min N/(M g) and max impulse ratio of a reference
    run, from each phase's dense output (``rocksweep.kernel.contact`` for H, N, J)."""

    def __init__(self, pb: _Problem) -> None:
        self.pb = pb
        self.mu = 0.0
        self.n_min = math.inf
        self.impulse = 0.0
        self.mg = float(pb.prm[L.PAR_MTOT] * pb.prm[L.PAR_G])

    def _state(self, sol, t: float, s: int) -> tuple[float, float, float, float]:
        y = sol.sol(t)
        if s == 0:
            return 0.0, 0.0, float(y[0]), float(y[1])
        if self.pb.flex:
            return float(y[0]), float(y[1]), float(y[2]), float(y[3])
        return float(y[0]), float(y[1]), 0.0, 0.0

    def _values(self, sol, t: float, s: int, on: bool) -> tuple[float, float]:
        th, w, u, v = self._state(sol, t, s)
        h_, n_ = ground_reactions(th, w, u, v, s, self.pb.xg(t, on), self.pb.gravity(t, on),
                                  self.pb.prm, self.pb.flex, self.pb.damped)
        return (abs(h_) / n_ if n_ > 0.0 else math.inf), n_ / self.mg

    def phase(self, t0: float, t1: float, s: int, on: bool) -> None:
        """Take the phase just solved (``pb.last_sol``) over [t0, t1]."""
        sol = self.pb.last_sol
        if sol is None:
            return
        knots = np.unique(np.clip(np.concatenate(([t0, t1], sol.t)), t0, t1))
        if len(knots) == 1:
            ts = knots
        else:
            ts = np.unique(np.concatenate([np.linspace(a, b, CONTACT_SAMPLES + 1)
                                           for a, b in zip(knots[:-1], knots[1:],
                                                           strict=True)]))
        vals = np.array([self._values(sol, t, s, on) for t in ts])
        for col, sign in ((0, 1.0), (1, -1.0)):  # max of |H|/N, min of N/(M g)
            f = sign * vals[:, col]
            i = int(np.argmax(f))
            best = f[i]
            if math.isfinite(best) and len(ts) > 2:
                lo, hi = ts[max(i - 1, 0)], ts[min(i + 1, len(ts) - 1)]
                r = minimize_scalar(lambda t, col=col, sign=sign:
                                    -sign * self._values(sol, t, s, on)[col],
                                    bounds=(lo, hi), method="bounded",
                                    options={"xatol": 1e-10 * max(1.0, hi)})
                best = max(best, -float(r.fun))
            if col == 0:
                self.mu = max(self.mu, best)
            else:
                self.n_min = min(self.n_min, -best)

    def impact(self, y, s: int, y_new, s_new: int) -> None:
        j_x, j_y = impact_impulses(s, y[2], y[3], y[1], s_new, y_new[3], y_new[1],
                                   self.pb.prm, self.pb.flex)
        self.impulse = max(self.impulse, impulse_ratio(j_x, j_y))


class _Tally:
    """A reference run's counters, flags and event log (the kernel's result row's)."""

    def __init__(self, pb: _Problem, theta0: float, events: bool) -> None:
        self.pb = pb
        self.status, self.outcome = 0, L.OUTCOME_SAFE
        self.impacts = self.uplifts = self.contacts = self.anomalies = 0
        self.theta_max, self.e_max = abs(theta0), 0.0
        self.t_over = self.t_first = math.nan
        self.log: list[dict] | None = [] if events else None

    def energy(self, y, s: int) -> float:
        return mechanical_energy(y[0], y[1], y[2], y[3], s, self.pb.prm, self.pb.flex)

    def note(self, kind: str, t: float, s0: int, s1: int, y0, y1, e: float = math.nan):
        if self.log is not None:
            self.log.append({"t": t, "kind": kind, "s_before": s0, "s_after": s1,
                             "theta_dot_before": y0[1], "theta_dot_after": y1[1], "u": y0[2],
                             "u_dot_before": y0[3], "u_dot_after": y1[3], "e": e,
                             "energy_before": self.energy(y0, s0),
                             "energy_after": self.energy(y1, s1)})

    def uplift(self, t: float, y, on: bool) -> int:
        """Full contact at (t, y): the corner the body uplifts on (counted), or 0."""
        s = self.pb.uplift_corner(t, (y[2], y[3]), on)
        if s != 0:
            self.uplifts += 1
            self.note("uplift", t, 0, s, y, y)
        return s

    def impact(self, t: float, y, s: int, on: bool, ct) -> tuple[tuple, int]:
        """Impact at theta = 0 ending rocking on corner s (eq. 1, the settling rule, the
        top mass's rule; uplift checked at once back in full contact). Returns (y, s)."""
        pb = self.pb
        self.impacts += 1
        if self.impacts == 1:
            self.t_first = t
        if s * y[1] > 0.0:  # moving away from theta = 0: not a crossing (a bug if seen)
            self.anomalies += 1
        e = float(restitution(s, y[2], pb.prm, pb.flex))
        self.e_max = max(self.e_max, e)
        if e > 1.0:
            self.status |= L.STATUS_E_ABOVE_1
        w_minus = y[1]
        if e > 0.0 and abs(e * w_minus) >= pb.rest_rate:
            s_new, w_plus = -s, e * w_minus
        else:
            s_new, w_plus = 0, 0.0
            self.contacts += 1
            if e > 0.0:
                self.status |= L.STATUS_SETTLED
        if not pb.flex:
            u_dot = 0.0
        elif pb.law == L.LAW_LOCKED:  # the top mass moves with the base: u' is kept
            u_dot = y[3]
        else:  # the spring and damper carry no impulse: m (u' + h theta') is conserved
            u_dot = y[3] + pb.h * (w_minus - w_plus)
        y_new = (0.0, w_plus, y[2], u_dot)
        if ct is not None:
            ct.impact(y, s, y_new, s_new)
        self.note("impact", t, s, s_new, y, y_new, e)
        if s_new == 0:
            s_new = self.uplift(t, y_new, on)
        return y_new, s_new

    def result(self, t: float, wall: float, ct) -> dict:
        res = {
            "outcome": self.outcome, "status": self.status, "impacts": self.impacts,
            "uplifts": self.uplifts, "contacts": self.contacts, "theta_max": self.theta_max,
            "t_overturn": self.t_over, "t_first_impact": self.t_first, "t_end": t,
            "e_max": self.e_max, "steps": self.pb.steps, "nfev": self.pb.nfev,
            "anomalies": self.anomalies, "wall_time": wall,
        }
        if ct is not None:
            finite = math.isfinite(ct.n_min)
            res.update({"mu_required": ct.mu if finite else math.nan,
                        "normal_min_over_Mg": ct.n_min if finite else math.nan,
                        "impulse_ratio_max": ct.impulse})
        if self.log is not None:
            res["events"] = self.log
        return res


def _air_time(a_v, t_pulse: float, period: float) -> float:
    """First t in [0, t_pulse) with g + a_v(t) <= 0 (inf: none): a_v sampled 64 times a
    ``period`` (the vertical's period, or its sample interval), the first sign change
    refined by Brent's method."""
    if not t_pulse > 0.0:
        return math.inf
    n = max(2, int(math.ceil(64 * t_pulse / period)) + 1)
    ts = np.linspace(0.0, t_pulse, n)
    f = np.array([G + a_v(t) for t in ts])
    hit = np.flatnonzero(f <= 0.0)
    if hit.size == 0 or ts[hit[0]] >= t_pulse:
        return math.inf
    i = int(hit[0])
    if i == 0:
        return 0.0
    return _root(lambda t: G + a_v(t), float(ts[i - 1]), float(ts[i]))


def _vertical(point: Point, prm: np.ndarray) -> tuple | None:
    """(a_v(t) [m/s^2], its rate, t_air) of the point's vertical in kernel time, from the
    point (not from the row's PAR_V_*), or None."""
    t_pulse = float(prm[L.PAR_TPULSE])
    pv = point.excitation.harmonic
    if pv is not None:
        amp, w, ph = pv.amplitude * G, float(pv.w_over_p), math.radians(pv.phase)

        def a_v(t):
            return amp * math.sin(w * t + ph)

        def rate(t):
            return amp * w * math.cos(w * t + ph)
        return a_v, rate, _air_time(a_v, t_pulse, 2 * math.pi / w)
    up = point.excitation.vertical
    if up is None:
        return None
    rec = point.record
    # the documented rule: the vertical's linear interpolant at the horizontal's samples
    tk = point.p * rec.times()
    vert = np.interp(rec.times(), up.times(), up.acc, right=0.0)
    av = abs(point.A) / rec.pga * vert  # one factor for both components [m/s^2]
    dtk = point.p * rec.dt

    def a_v(t):
        return float(np.interp(t, tk, av))

    def rate(t):
        k = min(max(int(t / dtk), 0), av.size - 2)
        return float((av[k + 1] - av[k]) / dtk)
    return a_v, rate, _air_time(a_v, t_pulse, dtk)


def reference_run(point: Point, numerics: Numerics | None = None, rtol: float = RTOL,
                  atol: float = ATOL, events: bool = False, early_exit: bool = True,
                  theta0: float | None = None, theta_dot0: float | None = None,
                  contact: bool = False) -> dict:
    """Run one point with the reference integrator.

    numerics supplies horizon, rest_rate and max_events (steps_per_period and event_tol
    are the kernel's and are ignored). The run starts at rest, or rocking from
    (theta0 [rad], theta_dot0 [rad/s]) if either is given and nonzero (default: the
    parameter row's PAR_THETA0, PAR_THETA_DOT0), like the kernel. ``early_exit`` False
    turns off the bounded-energy exits (to follow every impact, e.g. to check free rocking
    against closed forms): a rigid body's, and a flexible body's, which, as in the kernel,
    only a run without ``events`` or ``contact`` takes (the kernel's outcome-only
    variants; the others go on to rest). Returns a dict with the kernel's summary quantities:
    outcome (OUTCOME_* code), status (STATUS_* bits), impacts, uplifts, contacts,
    theta_max [rad], t_overturn, t_first_impact, t_end [p*t] (NaN when not applicable),
    e_max, plus steps (DOP853 steps), nfev (right-hand-side calls), anomalies (impacts
    found with theta' pointing away from theta = 0: impossible, counted as a self-check),
    wall_time [s]; with ``contact`` mu_required, normal_min_over_Mg, impulse_ratio_max
    (the kernel's contact outputs, from each phase's dense output: ``_Contact``); and
    with ``events`` a list of dicts, one per transition (t, kind, s before and after,
    theta', u, u' before and after, e, energy before and after).
    """
    numerics = numerics or Numerics()
    prm = point_row(point, numerics)
    flex = not point.body.rigid
    pb = _Problem(prm, flex, flex and bool(point.body.zeta > 0), rtol, atol,
                  _vertical(point, prm))
    t_end = float(prm[L.PAR_TEND])
    max_events = int(prm[L.PAR_MAXEVENTS])
    t0_wall = time.perf_counter()
    th0 = float(prm[L.PAR_THETA0]) if theta0 is None else float(theta0)
    thd0 = float(prm[L.PAR_THETA_DOT0]) if theta_dot0 is None else float(theta_dot0)
    t = 0.0
    y = (th0, thd0, float(prm[L.PAR_U0]), float(prm[L.PAR_U_DOT0]))  # theta, theta', u, u'
    tally = _Tally(pb, th0, events)
    free_check = True  # test the bounded-energy exit once per excursion (after impacts)
    # a flexible body's bound, as the kernel's outcome-only variants: a run that logs its
    # events or its reactions goes on to rest, as the kernel's that account them do
    outcome_only = not (events or contact)
    ct = _Contact(pb) if contact else None
    if th0 != 0.0 or thd0 != 0.0:  # rocking from the given state, on the corner it points to
        s = 1 if th0 > 0.0 or (th0 == 0.0 and thd0 > 0.0) else -1
    else:
        s = tally.uplift(t, y, pb.t_pulse > 0.0)
    while True:
        on = t < pb.t_pulse
        if s == 0 and not on and pb.rest_margin((y[2], y[3])) < 0.0:
            if not tally.status & L.STATUS_SETTLED:  # "rest" only where no rest-rate rule acted
                tally.status |= L.STATUS_REST
            break
        if t >= t_end:
            tally.status |= L.STATUS_HORIZON
            break
        if t >= pb.t_air:  # g + a_v <= 0: the body leaves the ground
            tally.status |= L.STATUS_AIRBORNE
            break
        if early_exit and not flex and s != 0 and not on and free_check:
            free_check = False
            peak = rigid_peak(y[0], y[1], s, prm)  # the kernel's STATUS_BOUNDED rule
            if peak >= 0.0:
                tally.theta_max = max(tally.theta_max, peak)
                tally.status |= L.STATUS_BOUNDED
                break
        if early_exit and flex and outcome_only and not on and free_check:
            free_check = False  # the kernel's flexible STATUS_BOUNDED rule, after impacts
            # inside the ridge's peak now (PAR_RIDGE NaN: impacts may gain energy)
            theta_r = float(prm[L.PAR_RIDGE])
            if (abs(y[0]) < theta_r and tally.energy(y, s) < (1.0 - BOUND_ENERGY_MARGIN)
                    * ridge_energy(min(tally.theta_max, theta_r), prm)):
                tally.status |= L.STATUS_BOUNDED
                break
        if tally.impacts + tally.uplifts >= max_events:
            tally.status |= L.STATUS_EVENT_CAP
            break
        t_stop = min(pb.t_pulse, pb.t_air) if on else t_end
        if on and pb.rec_dt > 0.0:  # a record: integrate sample interval by interval
            t_stop = min(t_stop, (math.floor(t / pb.rec_dt + 1e-9) + 1.0) * pb.rec_dt)
        if s == 0:
            s = tally.uplift(t, y, on)  # e.g. the cosine pulse's end
            if s != 0:
                continue
            pb.last_sol = None
            kind, t_ev, yc = _contact(pb, t, (y[2], y[3]), t_stop, on)
            y_ev = (0.0, 0.0, yc[0], yc[1])
        else:
            pb.last_sol = None
            kind, t_ev, y_ev, th = _rocking(pb, t, y, s, t_stop, on)
            tally.theta_max = max(tally.theta_max, th)
        if ct is not None and kind >= 0:
            ct.phase(t, t_ev, s, on)
        if kind < 0 or not all(math.isfinite(v) for v in y_ev):
            tally.status |= L.STATUS_NONFINITE
            t = t_ev
            break
        t, y = t_ev, y_ev
        if kind == _NONE:
            if t_stop in (pb.t_pulse, pb.t_air):
                t = t_stop  # exactly, so that the pulse is off (or the run stops) from here on
            continue
        if kind == _REST:
            if not tally.status & L.STATUS_SETTLED:
                tally.status |= L.STATUS_REST
            break
        if kind == _OVERTURN:
            tally.outcome = L.OUTCOME_MODE1 if tally.impacts > 0 else L.OUTCOME_MODE2
            tally.t_over = t
            tally.status |= L.STATUS_OVERTURNED
            break
        if kind == _UPLIFT:
            s_new = pb.uplift_corner(t, (y[2], y[3]), on)
            if s_new == 0:  # the far-side search failed to land past the root
                s_new = 1 if pb.q(t, (y[2], y[3]), on) > 0 else -1
            y_new = (0.0, 0.0, y[2], y[3])
            tally.note("uplift", t, 0, s_new, y, y_new)
            s, y = s_new, y_new
            tally.uplifts += 1
            continue
        free_check = True
        y, s = tally.impact(t, y, s, on, ct)
    return tally.result(t, time.perf_counter() - t0_wall, ct)


def result_row(r: dict) -> np.ndarray:
    """A ``reference_run`` dict as a kernel result row float64[N_OUT]."""
    out = np.full(L.N_OUT, np.nan)
    out[L.OUT_OUTCOME] = r["outcome"]
    out[L.OUT_STATUS] = r["status"]
    out[L.OUT_IMPACTS] = r["impacts"]
    out[L.OUT_UPLIFTS] = r["uplifts"]
    out[L.OUT_THETA_MAX] = r["theta_max"]
    out[L.OUT_T_OVERTURN] = r["t_overturn"]
    out[L.OUT_T_END] = r["t_end"]
    out[L.OUT_STEPS] = r["steps"]
    out[L.OUT_EVENT_STEPS] = 0.0
    out[L.OUT_T_FIRST_IMPACT] = r["t_first_impact"]
    out[L.OUT_E_MAX] = r["e_max"]
    out[L.OUT_CONTACTS] = r["contacts"]
    out[L.OUT_HIST_ROWS] = 0.0
    out[L.OUT_REFINE_EVALS] = 0.0
    out[L.OUT_MU_REQ] = r.get("mu_required", np.nan)
    out[L.OUT_N_MIN] = r.get("normal_min_over_Mg", np.nan)
    out[L.OUT_IMPULSE_MAX] = r.get("impulse_ratio_max", np.nan)
    return out
