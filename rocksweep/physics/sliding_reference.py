"""The reference path of the sliding base: scipy's DOP853 phase by phase (the yardstick of
``rocksweep.kernel.sliding``; docs/sliding.md).

``sliding_reference(point, mu_static=None)`` runs one point (a rigid body or the paper's
flexible body, a pulse or a record) on a ground with Coulomb friction ``point.mu``
(kinetic) and ``mu_static`` (default the point's ``mu_static``, else mu); ``result_row``
gives its result as a kernel result row (``rocksweep accuracy``). It is written apart from
the kernel's module:

- equations: Newton-Euler for the masses in the generalised coordinates q = (theta, u, x)
  (x the sliding displacement, the pivot at x + s b): M(q) q'' = f(q, q', t) + e_x F
  with M = sum m_i J_i^T J_i + I e_theta e_theta^T from each mass's Jacobian J_i, the
  normal force N = sum m_i (Y_i'' + g) and F = sum m_i (X_i'' + xg''), solved as linear
  systems (stuck: x'' = 0; slipping: F = -mu sigma N); flat phases hold theta = 0 and read
  the moment the ground must supply about each corner from the theta row;
- events: located by solve_ivp (stick break mu_s N - |H|, slip stop x' = 0, uplift, impact,
  overturning, the Painleve denominator), each landed on its far side;
- the phase a non-slipping base enters: each candidate solved and checked (rest, rock,
  slide, slide-rock, in that order);
- impacts: the free body at theta = 0 (base velocity (v_x, v_y), rotation w, and the top
  mass's rate u' unless ``locked``), a vertical impulse at the locus x_Q the law's e
  implies (found from three stuck impacts: e is a Moebius function of x_Q) or, landing
  flat, at both corners (the old corner's normal velocity kept 0), a horizontal one at the
  ground; Routh's process on the free body's own velocity responses.

It shares with the kernel the ground motion (eq. 2, ``ground.any_ground_acc``), the law's e
and the settling rule (``equations.restitution``), the no-slip rest proof
(``equations.rest_margin``) and the parameter row (``points.point_row``). Times are p*t.
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.integrate import solve_ivp

from rocksweep.errors import BudgetExceededError
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel.equations import rest_margin, restitution
from rocksweep.kernel.ground import any_ground_acc
from rocksweep.numerics import Numerics
from rocksweep.physics.points import Point, point_row
from rocksweep.physics.reference import result_row as no_slip_row
from rocksweep.vocab.outcomes import STATUS_BIT
from rocksweep.vocab.phases import PHASE_CODE, PHASES

RTOL = 1e-10
ATOL = 1e-12
_TH, _U, _X = 0, 1, 2  # coordinates
# state y: theta, theta', u, u', x, x', W_in, D_damp, D_fric
_N_Y = 9
# Most right-hand-side evaluations of one run (~130 us each: ~20 s): past them the run
# stops with status step_cap, its outcome undecided. A body whose normal force falls
# through zero on a slipping corner (lifts_off) can drive DOP853's step to nothing near
# the Painleve point (a flexible body at mu 0.64 under a sine at w/p 11.8 ran for more than
# an hour; the kernel decides it, mode 2, in milliseconds). The slowest of 550 random
# points that finished (``scripts/slide_check.py``) took ~6 s, ~45 000 evaluations.
MAX_EVALUATIONS = 150_000


class _Body:
    """The body's masses, from the parameter row: flexible (base m_A at h_A with I_A, top
    mass m at (u, h)) or rigid (M at h_cg with I_G)."""

    def __init__(self, prm: np.ndarray, flex: bool, damped: bool) -> None:
        self.flex, self.damped = flex, damped
        self.b, self.g, self.M = float(prm[L.PAR_B]), float(prm[L.PAR_G]), float(prm[L.PAR_MTOT])
        self.k, self.c = float(prm[L.PAR_K]), float(prm[L.PAR_C]) if damped else 0.0
        self.locked = flex and prm[L.PAR_LAW] == L.LAW_LOCKED
        if flex:
            m, m_a = float(prm[L.PAR_M]), float(prm[L.PAR_MA])
            h, h_a = float(prm[L.PAR_H]), float(prm[L.PAR_HA])
            i_a = float(prm[L.PAR_IA0]) - m_a * (self.b**2 + h_a**2)
            # (mass, height, moves with u, rotational inertia)
            self.masses = [(m, h, True, 0.0), (m_a, h_a, False, i_a)]
        else:
            h_cg = float(prm[L.PAR_HCG])
            self.masses = [(self.M, h_cg, False,
                            float(prm[L.PAR_IO]) - self.M * (self.b**2 + h_cg**2))]
        self.coords = [_TH, _U, _X] if flex else [_TH, _X]

    def kinematics(self, th, w, u, ud, s):
        """Per mass: (m, position (2), J (2x3), gamma (2), I) with acc = J q'' + gamma."""
        c, sn, sb = math.cos(th), math.sin(th), s * self.b
        out = []
        for m, eta, moves, inertia in self.masses:
            xi = (u if moves else 0.0) - sb
            pos = np.array([sb + c * xi + sn * eta, -sn * xi + c * eta])
            jac = np.zeros((2, 3))
            jac[:, _TH] = (-sn * xi + c * eta, -c * xi - sn * eta)
            if moves:
                jac[:, _U] = (c, -sn)
            jac[:, _X] = (1.0, 0.0)
            gam = w * w * np.array([-c * xi - sn * eta, sn * xi - c * eta])
            if moves:
                gam += 2 * w * ud * np.array([-sn, -c])
            out.append((m, pos, jac, gam, inertia))
        return out

    def system(self, t, th, w, u, ud, s, xg, g):
        """(M (3x3), f (3), n (3), n0, hx (3), h0): M q'' = f + e_x F; N = n q'' + n0;
        the ground's horizontal force H = hx q'' + h0."""
        mass, f = np.zeros((3, 3)), np.zeros(3)
        n, hx = np.zeros(3), np.zeros(3)
        n0, h0 = 0.0, 0.0
        for m, _, jac, gam, inertia in self.kinematics(th, w, u, ud, s):
            mass += m * jac.T @ jac
            mass[_TH, _TH] += inertia
            f += jac.T @ (m * np.array([-xg, -g]) - m * gam)
            n += m * jac[1]
            n0 += m * (gam[1] + g)
            hx += m * jac[0]
            h0 += m * (gam[0] + xg)
        if self.flex:
            f[_U] -= self.k * u + self.c * ud
        return mass, f, n, n0, hx, h0


class _Phase:
    """One phase's accelerations and forces: s the corner (0 flat), sigma the slip."""

    def __init__(self, body: _Body, s: int, sigma: int, mu: float) -> None:
        self.body, self.s, self.sigma, self.mu = body, s, sigma, mu

    def solve(self, t, y, xg, g, corner=None):
        """(q'' (3), F, N, den, moment): the phase's accelerations; den the Painleve
        denominator of a slip (1 if stuck); moment: flat phases, the moment about
        ``corner`` (+-1) the ground's normal force must supply to hold theta'' = 0
        (the body tips onto the corner when corner * moment <= 0)."""
        bd, s, sigma = self.body, self.s, self.sigma
        th, w = (0.0, 0.0) if s == 0 else (y[0], y[1])
        u, ud = (y[2], y[3]) if bd.flex else (0.0, 0.0)
        mass, f, n, n0, hx, h0 = bd.system(t, th, w, u, ud, corner or s or 1, xg, g)
        free = [i for i in bd.coords if not (s == 0 and i == _TH)
                and not (sigma == 0 and i == _X)]
        a = mass[np.ix_(free, free)].copy()
        rhs = f[free].copy()
        den = 1.0
        if sigma != 0:  # F = -mu sigma N enters the x row
            ix = free.index(_X)
            a[ix] += self.mu * sigma * n[free]
            rhs[ix] -= self.mu * sigma * n0
            with np.errstate(invalid="ignore"):  # a rejected stage's NaN state
                den = float(np.linalg.det(a) / np.linalg.det(mass[np.ix_(free, free)]))
        qdd = np.zeros(3)
        if free:
            try:
                qdd[free] = np.linalg.solve(a, rhs)
            except np.linalg.LinAlgError:  # den = 0 exactly (a Painleve point): no finite
                qdd[free] = np.nan  # accelerations; DOP853 rejects the step and shortens it
        big_n = float(n @ qdd + n0)
        force = float(hx @ qdd + h0)
        moment = float(mass[_TH] @ qdd - f[_TH]) if s == 0 else 0.0
        return qdd, force, big_n, den, moment

    def rhs(self, xg_of, g):
        bd = self.body

        def fun(t, y):
            xg = xg_of(t)
            qdd, force, _, _, _ = self.solve(t, y, xg, g)
            w = 0.0 if self.s == 0 else y[1]
            ud = y[3] if bd.flex else 0.0
            xd = y[5] if self.sigma != 0 else 0.0
            # the ground's power: -xg'' times the horizontal momentum
            th = 0.0 if self.s == 0 else y[0]
            mom = sum(m * (jac[0] @ np.array([w, ud, xd])) for m, _, jac, _, _ in
                      bd.kinematics(th, w, y[2], ud, self.s or 1))
            return [w, qdd[_TH], ud, qdd[_U], xd, qdd[_X], -xg * mom,
                    bd.c * ud * ud, -(force if self.sigma != 0 else 0.0) * xd]
        return fun


def energy(body: _Body, y, s: int) -> float:
    """T + V - V_rest [J] in the ground's frame (x' included)."""
    th, w = (0.0, 0.0) if s == 0 else (y[0], y[1])
    u, ud = (y[2], y[3]) if body.flex else (0.0, 0.0)
    qd = np.array([w, ud, y[5]])
    e = 0.5 * body.k * u * u if body.flex else 0.0
    for m, pos, jac, _, inertia in body.kinematics(th, w, u, ud, s or 1):
        v = jac @ qd
        e += 0.5 * m * (v @ v) + 0.5 * inertia * w * w + m * body.g * pos[1]
    for m, eta, _, _ in body.masses:
        e -= m * body.g * eta
    return e


# ----------------------------------------------------------------------------------------
# the phase a non-slipping base enters
# ----------------------------------------------------------------------------------------


def choose(body: _Body, t, y, s: int, xg: float, g: float, mu: float, mu_s: float):
    """(s, sigma, jam) consistent with the forces where x' = 0 (module docstring)."""
    if s != 0:
        _, force, big_n, _, _ = _Phase(body, s, 0, mu).solve(t, y, xg, g)
        if abs(force) <= mu_s * big_n or big_n <= 0:  # (N <= 0: held, as no-slip)
            return s, 0, False
        # the slip against the force friction cannot hold: with den > 0 its x'' has the
        # sign sg exactly (the phase's F = -mu sg N against |force| > mu N), so its sign
        # is not tested (round-off on the far side of a stick break)
        sg = -1 if force > 0 else 1
        _, _, big_n, den, _ = _Phase(body, s, sg, mu).solve(t, y, xg, g)
        if den > 0 and big_n > 0:
            return s, sg, False
        return s, 0, True
    rest = _Phase(body, 0, 0, mu)
    _, force, big_n, _, m_p = rest.solve(t, y, xg, g, corner=1)
    m_m = rest.solve(t, y, xg, g, corner=-1)[4]
    tips = [c for c, mom in ((1, m_p), (-1, m_m)) if c * mom <= 0]
    if not tips and abs(force) <= mu_s * big_n:
        return 0, 0, False
    for c in tips:
        _, force, big_n, _, _ = _Phase(body, c, 0, mu).solve(t, y, xg, g)
        if big_n > 0 and abs(force) <= mu_s * big_n:
            return c, 0, False
    for sg in (1, -1):
        ph = _Phase(body, 0, sg, mu)
        qdd, _, _, _, mp = ph.solve(t, y, xg, g, corner=1)
        mm = ph.solve(t, y, xg, g, corner=-1)[4]
        tol = 1e-12 * body.M * g * body.b  # (mu = tan alpha: slides, theta'' = 0)
        if sg * qdd[_X] > 0 and mp > -tol and -mm > -tol:
            return 0, sg, False
    for c in (1, -1):
        for sg in (1, -1):
            qdd, _, big_n, den, _ = _Phase(body, c, sg, mu).solve(t, y, xg, g)
            if den > 0 and big_n > 0 and sg * qdd[_X] > 0 and c * qdd[_TH] >= 0:
                return c, sg, False
    return (tips[0] if tips else 0), 0, True


# ----------------------------------------------------------------------------------------
# the impact with friction: the free body at theta = 0
# ----------------------------------------------------------------------------------------


class _FreeBody:
    """The body at theta = 0 as a free body: z = (v_x, v_y, w[, u']) (the base's point on
    the ground line under its centre, the rotation, the top mass's rate unless locked)."""

    def __init__(self, body: _Body, u: float) -> None:
        self.body, self.u = body, u
        n = 4 if body.flex and not body.locked else 3
        mass = np.zeros((n, n))
        for m, eta, moves, inertia in body.masses:
            x0 = u if moves else 0.0
            # velocity of the mass (v_x + w eta [+ u'], v_y - w x0)
            jx = np.zeros(n)
            jx[0], jx[2] = 1.0, eta
            if moves and n == 4:
                jx[3] = 1.0
            jy = np.zeros(n)
            jy[1], jy[2] = 1.0, -x0
            mass += m * (np.outer(jx, jx) + np.outer(jy, jy))
            mass[2, 2] += inertia
        self.inv = np.linalg.inv(mass)
        self.n = n

    def vertical(self, x_pt: float) -> np.ndarray:
        """The generalised impulse of a unit upward impulse at (x_pt, 0)."""
        v = np.zeros(self.n)
        v[1], v[2] = 1.0, -x_pt
        return v

    def horizontal(self) -> np.ndarray:
        v = np.zeros(self.n)
        v[0] = 1.0
        return v

    def state(self, w, ud, xd, pivot) -> np.ndarray:
        """z of the body rocking at rate w about the pivot at x = pivot, slipping at xd."""
        z = np.array([xd, w * pivot, w, ud][: self.n])
        return z

    def corner_vn(self, x_pt: float) -> np.ndarray:
        """Row giving the vertical velocity of the base point at (x_pt, 0)."""
        return self.vertical(x_pt)


def _responses(fb: _FreeBody, loci, keep_zero):
    """Velocity responses to (J_x, J_y): returns a function J -> dz (linear), where J_y
    is shared by the vertical impulses at ``loci`` so as to keep the normal velocities at
    ``keep_zero`` unchanged (flat landing: the old corner), else J_y acts at loci[0]."""
    gx = fb.inv @ fb.horizontal()
    if keep_zero is None:
        gy = fb.inv @ fb.vertical(loci[0])
        return gx, gy
    # J_new at loci[0], J_old at keep_zero; J_new + J_old = J_y, d v_n(old) = 0
    row = fb.corner_vn(keep_zero)
    r_new, r_old = row @ (fb.inv @ fb.vertical(loci[0])), row @ (fb.inv @ fb.vertical(keep_zero))
    r_x = row @ gx
    # per unit J_y (J_x = 0): J_new = r_old / (r_old - r_new)
    jn = r_old / (r_old - r_new)
    gy = fb.inv @ (jn * fb.vertical(loci[0]) + (1 - jn) * fb.vertical(keep_zero))
    # per unit J_x: the old corner's vertical impulse cancels its velocity change
    jo = -r_x / (r_old - r_new)
    gx = gx + fb.inv @ (jo * fb.vertical(keep_zero) - jo * fb.vertical(loci[0]))
    return gx, gy


def _routh(z0, gx, gy, row_t, row_n, mu, mu_s, v_rest):
    """Routh's process on the free body: (J_x, J_y, W_f, jam, v_t at the end: exactly 0
    where the contact ends stuck)."""
    vt, vn = row_t @ z0, row_n @ z0
    tx, ty, nx, ny = row_t @ gx, row_t @ gy, row_n @ gx, row_n @ gy
    jx = jy = w_f = 0.0
    jam = False
    r_stick = -ty / tx  # dJ_x/dJ_y that keeps v_t
    for _ in range(8):
        if vn >= 0:
            break
        if vt == 0.0:
            if abs(r_stick) <= mu_s:
                d = -vn / (nx * r_stick + ny)
                jx, jy, vn = jx + r_stick * d, jy + d, 0.0
                break
            sg = -1.0 if r_stick > 0 else 1.0
        else:
            sg = 1.0 if vt > 0 else -1.0
        dvn, dvt = ny - mu * sg * nx, ty - mu * sg * tx
        if dvn <= 0:  # the slip cannot end the impact: stuck by a tangential impulse
            djx, djy = _stop_slip(vt, tx, ty, nx, ny)
            w_f += 0.5 * vt * djx
            jx, jy, vt, jam = jx + djx, jy + djy, 0.0, True
            d = -vn / (nx * r_stick + ny)
            jx, jy, vn = jx + r_stick * d, jy + d, 0.0
            break
        d_end = -vn / dvn
        d_stop = -vt / dvt if (vt != 0 and sg * dvt < 0) else math.inf
        d = min(d_end, d_stop)
        vt_new = vt + dvt * d if d < d_stop else 0.0
        w_f += -mu * sg * d * 0.5 * (vt + vt_new)
        jx, jy = jx - mu * sg * d, jy + d
        vt, vn = vt_new, (0.0 if d == d_end else vn + dvn * d)
    if vt != 0.0 and abs(vt) < v_rest:  # the settling rule of the slip
        djx, djy = _stop_slip(vt, tx, ty, nx, ny)
        w_f += 0.5 * vt * djx
        jx, jy, vt = jx + djx, jy + djy, 0.0
    return jx, jy, w_f, jam, vt


def _stop_slip(vt, tx, ty, nx, ny):
    """(dJ_x, dJ_y) that stop the slip vt and leave the normal velocity as it is."""
    return np.linalg.solve(np.array([[tx, ty], [nx, ny]]), [-vt, 0.0])


def impact(body: _Body, prm, y, s: int, mu: float, mu_s: float):
    """The impact at theta = 0 ending rocking on s: (y after, s_new, sigma_new, e, W_f,
    jam)."""
    u = y[2] if body.flex else 0.0
    w_m, ud_m, xd_m = y[1], (y[3] if body.flex else 0.0), y[5]
    e = float(restitution(s, u, prm, body.flex))
    b = body.b
    if e > 0 and abs(e * w_m) >= prm[L.PAR_RESTRATE]:
        s_new = -s
    else:
        s_new = 0
    v_rest = float(prm[L.PAR_RESTRATE] * prm[L.PAR_HCG])  # the slip's settling rule
    fb = _FreeBody(body, u)
    z0 = fb.state(w_m, ud_m, xd_m, s * b)
    row_t, row_n = fb.horizontal(), fb.corner_vn(-s * b)
    if s_new != 0:
        z, jx, jy, w_f, jam, vt = _rock_to_rock(fb, z0, row_t, row_n, e, w_m, b, mu, mu_s,
                                                v_rest)
        if not (z[2] / w_m > 0 and abs(z[2]) >= prm[L.PAR_RESTRATE]):
            s_new = 0  # friction turned the rotation back: the base lands flat
    if s_new == 0:
        gx, gy = _responses(fb, [-s * b], s * b)
        jx, jy, w_f, jam, vt = _routh(z0, gx, gy, row_t, row_n, mu, mu_s, v_rest)
        z = z0 + gx * jx + gy * jy
    y_new = np.array(y, dtype=float)
    y_new[0], y_new[1] = 0.0, (z[2] if s_new != 0 else 0.0)
    if body.flex:
        y_new[3] = z[3] if fb.n == 4 else ud_m
    y_new[5] = vt
    sigma = 0 if vt == 0.0 else (1 if vt > 0 else -1)
    return y_new, s_new, sigma, e, w_f, jam


def _rock_to_rock(fb: _FreeBody, z0, row_t, row_n, e, w_m, b, mu, mu_s, v_rest):
    """The rocking-to-rocking impact: the vertical impulse at the locus whose stuck impact
    (x' kept) gives e (e is Moebius in x_Q: fitted through three loci and inverted)."""
    def ratio(xq):
        gx_, gy_ = _responses(fb, [xq], None)
        a = np.array([[row_t @ gx_, row_t @ gy_], [row_n @ gx_, row_n @ gy_]])
        jx_, jy_ = np.linalg.solve(a, [0.0, -(row_n @ z0)])
        return (z0 + gx_ * jx_ + gy_ * jy_)[2] / w_m

    xs = np.array([-b, 0.0, b]) * 0.7
    fs = np.array([ratio(x) for x in xs])
    # f (1 + d x) = a + c x  ->  [1, x, -f x] (a, c, d) = f
    a_, c_, d_ = np.linalg.solve(np.column_stack([np.ones(3), xs, -fs * xs]), fs)
    x_q = (a_ - e) / (e * d_ - c_)
    gx, gy = _responses(fb, [x_q], None)
    jx, jy, w_f, jam, vt = _routh(z0, gx, gy, row_t, row_n, mu, mu_s, v_rest)
    return z0 + gx * jx + gy * jy, jx, jy, w_f, jam, vt


def jam_impulse(body: _Body, y, s: int, xg: float, g: float):
    """Painleve's jam on corner s: the horizontal impulse at the pivot that stops the slip
    (the normal impulse there does no work: the pivot stays on the ground). Returns
    (y after, work of the impulse [J])."""
    th, w = y[0], y[1]
    u, ud = (y[2], y[3]) if body.flex else (0.0, 0.0)
    mass, _, n, _, _, _ = body.system(0.0, th, w, u, ud, s, xg, g)
    free = body.coords
    inv = np.linalg.inv(mass[np.ix_(free, free)])
    col = inv[:, free.index(_X)]
    j_x = -y[5] / col[free.index(_X)]
    dq = np.zeros(3)
    dq[free] = col * j_x
    y_new = np.array(y, dtype=float)
    y_new[1] += dq[_TH]
    if body.flex:
        y_new[3] += dq[_U]
    y_new[5] = 0.0
    return y_new, 0.5 * j_x * y[5]


def _word(s: int, sigma: int) -> str:
    return PHASES[(2 if s else 0) + (1 if sigma else 0)]


def _armed(fn, t0: float, direction: float, terminal: bool):
    """An event function armed once it leaves zero (a phase often starts on its surface)."""
    def ev(t, y):
        v = fn(t, y)
        return 1.0 if (v == 0.0 and t == t0) else v

    ev.direction, ev.terminal = direction, terminal
    return ev


class _Run:
    """One reference run: the phase loop's state and tallies."""

    def __init__(self, point: Point, mu_s: float, numerics: Numerics, rtol: float,
                 atol: float) -> None:
        self.prm = point_row(point, numerics)
        flex = not point.body.rigid
        self.body = _Body(self.prm, flex, flex and point.body.zeta > 0)
        self.mu, self.mu_s = float(point.mu), mu_s
        self.rtol, self.atol = rtol, atol
        self.t_pulse = float(self.prm[L.PAR_TPULSE])
        self.t_end = float(self.prm[L.PAR_TEND])
        self.rec_dt = float(self.prm[L.PAR_REC_DT])
        periods = [2 * math.pi]
        if self.prm[L.PAR_OMEGA] > 0:
            periods.append(2 * math.pi / float(self.prm[L.PAR_OMEGA]))
        if flex:
            periods.append(2 * math.pi / math.sqrt(self.body.k / float(self.prm[L.PAR_M])) / 3)
        self.max_step = min(periods) / 20
        self.impacts = self.uplifts = self.events = 0
        self.theta_max = self.slide_max = 0.0
        self.e_impact = self.w_fric_impulsive = 0.0
        self.jams = self.lift_offs = 0
        self.steps = self.contacts = 0  # DOP853 steps, impacts that land flat
        self.evaluations = 0  # right-hand-side calls, against MAX_EVALUATIONS
        self.e_max = 0.0  # the largest impact's e
        self.phases: list[str] = []

    def xg(self, t: float, on: bool) -> float:
        return float(any_ground_acc(t, bool(on), self.prm)) if on else 0.0

    def enter(self, s: int, sigma: int) -> tuple[int, int]:
        word = _word(s, sigma)
        if not self.phases or self.phases[-1] != word:
            self.phases.append(word)
        return s, sigma

    def choose(self, t, y, s, on):
        s_new, sigma, jam = choose(self.body, t, y, s, self.xg(t, on), self.body.g, self.mu,
                                   self.mu_s)
        self.jams += int(jam)
        return s_new, sigma

    def slipping(self, t, y, s, sigma, on):
        """The phase a slip (x' != 0) after an impact goes on in: a flat slip that tips at
        once onto a corner slide-rocks; a slide-rock with no consistent slip (Painleve,
        den <= 0) is stuck by a tangential impulse (returns the state after it)."""
        if s == 0:
            ph = _Phase(self.body, 0, sigma, self.mu)
            for c in (1, -1):
                if c * ph.solve(t, y, self.xg(t, on), self.body.g, corner=c)[4] <= 0:
                    self.uplifts += 1
                    s = c
                    break
        if s != 0 and _Phase(self.body, s, sigma, self.mu).solve(
                t, y, self.xg(t, on), self.body.g)[3] <= 0:
            e_before = energy(self.body, y, s)
            y, w_j = jam_impulse(self.body, y, s, self.xg(t, on), self.body.g)
            self.w_fric_impulsive += w_j
            self.e_impact += e_before - energy(self.body, y, s) + w_j
            self.jams += 1
            return y, *self.choose(t, y, s, on)
        return y, s, sigma

    def counted(self, fun):
        """``fun`` counting its calls in ``evaluations``; BudgetExceededError past
        MAX_EVALUATIONS."""
        def counted_fun(t, y):
            self.evaluations += 1
            if self.evaluations > MAX_EVALUATIONS:
                raise BudgetExceededError
            return fun(t, y)
        return counted_fun

    def events_of(self, s, sigma, on, t0):
        """(event functions, their kinds) of phase (s, sigma)."""
        bd, g = self.body, self.body.g
        ph = _Phase(bd, s, sigma, self.mu)

        def solved(t, y, corner=None):
            return ph.solve(t, y, self.xg(t, on), g, corner)

        evs = []
        if sigma == 0:
            evs.append(("stick", lambda t, y: self.mu_s * solved(t, y)[2]
                        - abs(solved(t, y)[1]), True))
        else:
            evs.append(("stop", lambda t, y: sigma * y[5], True))
        if s == 0:
            for c in (1, -1):
                evs.append((f"uplift{c}", lambda t, y, c=c: c * solved(t, y, c)[4], True))
            if sigma == 0 and not on and bd.flex:
                evs.append(("rest", lambda t, y: -1.0 if self.rest_proven(y) else 1.0, True))
        else:
            evs.append(("impact", lambda t, y: s * y[0], True))
            evs.append(("over", lambda t, y: float(self.prm[L.PAR_THETA_OVER]) - s * y[0],
                        True))
            evs.append(("peak", lambda t, y: s * y[1], False))
            evs.append(("liftoff", lambda t, y: solved(t, y)[2], False))
            if sigma != 0:
                evs.append(("jam", lambda t, y: solved(t, y)[3], True))
        fns = [_armed(fn, t0, -1.0, term) for _, fn, term in evs]
        return fns, [k for k, _, _ in evs]

    def rest_proven(self, y) -> bool:
        """After the pulse, flat and stuck: never uplifts (``equations.rest_margin``) nor
        slips again (the spring's largest force on the energy ellipse below mu_s M g)."""
        if not self.body.flex:
            return True
        u, ud = y[2], y[3]
        m = float(self.prm[L.PAR_M])
        e2 = m * ud * ud + self.body.k * u * u
        f_max = math.sqrt(e2 * (self.body.k + self.body.c**2 / m))
        return rest_margin(u, ud, self.prm) < 0.0 and f_max <= self.mu_s * self.body.M * self.body.g

    def far_side(self, sol, fn, t_e, t_hi):
        t = t_e
        step = 4 * np.finfo(float).eps * max(1.0, abs(t))
        for _ in range(60):
            if fn(t, sol.sol(t)) < 0.0 or t >= t_hi:
                break
            t = min(t + step, t_hi)
            step *= 2.0
        return t


def sliding_reference(point: Point, mu_static: float | None = None,
                      numerics: Numerics | None = None, rtol: float = RTOL,
                      atol: float = ATOL) -> dict:
    """Run one point from rest on a ground with Coulomb friction point.mu (kinetic) and
    mu_static (static; default point.mu_static, NaN: mu) with the reference integrator
    (module docstring).

    numerics: horizon, rest_rate and max_events (the kernel's step settings are not
    used). No vertical ground acceleration (ValueError). Returns outcome (``layout.OUTCOME_*``),
    overturned, impacts, uplifts, phases (the words ``vocab.phases.PHASES`` in the order
    entered), theta_max [rad], slide_max and slide_final [m] (max |x| and |x| at the end),
    t_end, t_first_impact and t_overturn [p*t] (NaN: none), wall_time [s], steps (DOP853's),
    contacts (impacts that land flat), e_max (the largest impact's e), status words
    (horizon, event_cap, step_cap: past MAX_EVALUATIONS, jam: a Painleve jam stuck the contact,
    lifts_off: N < 0 met while rocking), and the energy terms [J]: W_in (the ground's
    work), D_damp, D_fric (friction: sliding and impulses), E_impact (impacts, friction
    excluded), E_end (T + V - V_rest at the end), E_ref (``body.E_ref``) and closure =
    W_in - D_damp - D_fric - E_impact - E_end.
    """
    if point.excitation.harmonic is not None or point.excitation.vertical is not None:
        raise ValueError("sliding_reference: a vertical ground acceleration is not "
                         "modelled (horizontal ground motion only)")
    numerics = numerics or Numerics()
    t0_wall = time.perf_counter()
    if mu_static is None:
        mu_static = point.mu if math.isnan(point.mu_static) else point.mu_static
    run = _Run(point, float(mu_static), numerics, rtol, atol)
    t_first_impact = t_overturn = math.nan
    bd, g, prm = run.body, run.body.g, run.prm
    y = np.zeros(_N_Y)
    t = 0.0
    s, sigma = run.enter(*run.choose(t, y, 0, run.t_pulse > 0))
    outcome, status = L.OUTCOME_SAFE, set()
    max_events = int(prm[L.PAR_MAXEVENTS])
    while True:
        on = t < run.t_pulse
        if s == 0 and sigma == 0 and not on and run.rest_proven(y):
            break
        if t >= run.t_end:
            status.add("horizon")
            break
        if run.events >= max_events:
            status.add("event_cap")
            break
        t_stop = run.t_pulse if on else run.t_end
        if on and run.rec_dt > 0.0:
            t_stop = min(t_stop, (math.floor(t / run.rec_dt + 1e-9) + 1.0) * run.rec_dt)
        ph = _Phase(bd, s, sigma, run.mu)
        fns, kinds = run.events_of(s, sigma, on, t)
        try:
            sol = solve_ivp(run.counted(ph.rhs(lambda tt, on=on: run.xg(tt, on), g)),
                            (t, t_stop), y, method="DOP853", rtol=run.rtol, atol=run.atol,
                            max_step=run.max_step, events=fns, dense_output=True)
        except BudgetExceededError:
            status.add("step_cap")
            break
        run.steps += sol.t.size - 1
        for k, te in zip(kinds, sol.t_events, strict=True):
            if k == "peak":
                run.theta_max = max([run.theta_max] + [abs(sol.sol(v)[0]) for v in te])
            elif k == "liftoff" and len(te):
                run.lift_offs += len(te)
        kind, t_e = None, sol.t[-1]
        for i, k in enumerate(kinds):
            if fns[i].terminal and len(sol.t_events[i]) and sol.t_events[i][0] <= t_e:
                kind, t_e = k, sol.t_events[i][0]
        if kind in ("stick", "uplift1", "uplift-1", "jam", "rest"):
            t_e = run.far_side(sol, fns[kinds.index(kind)], t_e, t_stop)
        y = np.array(sol.sol(t_e)) if t_e != sol.t[-1] else np.array(sol.y[:, -1])
        t = t_e
        if s != 0:
            run.theta_max = max(run.theta_max, abs(y[0]))
        run.slide_max = max(run.slide_max, abs(y[4]))
        if not np.all(np.isfinite(y)):
            status.add("nonfinite")
            break
        if kind is None:
            if not on or t >= run.t_pulse:  # the pulse's end: the stuck force may jump
                t = max(t, run.t_pulse) if on else t
                if sigma == 0:
                    s, sigma = run.enter(*run.choose(t, y, s, False))
            continue
        run.events += 1
        if kind == "rest":
            break
        if kind == "over":
            outcome = L.OUTCOME_MODE1 if run.impacts else L.OUTCOME_MODE2
            run.theta_max = float(prm[L.PAR_THETA_OVER])
            t_overturn = t
            break
        if kind == "stop":
            y[5] = 0.0
            s, sigma = run.enter(*run.choose(t, y, s, on))
        elif kind == "stick":
            s, sigma = run.enter(*run.choose(t, y, s, on))
        elif kind.startswith("uplift"):
            run.uplifts += 1
            if sigma == 0:
                s, sigma = run.enter(*run.choose(t, y, 0, on))
            else:
                s = 1 if kind == "uplift1" else -1
                s, sigma = run.enter(s, sigma)
        elif kind == "jam":
            e_before = energy(bd, y, s)
            y, w_j = jam_impulse(bd, y, s, run.xg(t, on), g)
            run.w_fric_impulsive += w_j
            run.e_impact += e_before - energy(bd, y, s) + w_j
            run.jams += 1
            s, sigma = run.enter(*run.choose(t, y, s, on))
        else:  # impact
            run.impacts += 1
            if run.impacts == 1:
                t_first_impact = t
            y[0] = 0.0
            e_before = energy(bd, y, s)
            y, s_new, sigma_new, e, w_f, jam = impact(bd, prm, y, s, run.mu, run.mu_s)
            run.e_max = max(run.e_max, e)
            run.contacts += int(s_new == 0)
            run.jams += int(jam)
            run.w_fric_impulsive += w_f
            run.e_impact += e_before - energy(bd, y, s_new) + w_f
            if sigma_new == 0:
                s, sigma = run.enter(*run.choose(t, y, s_new, on))
            else:
                y, s, sigma = run.slipping(t, y, s_new, sigma_new, on)
                s, sigma = run.enter(s, sigma)
        if s == 0:
            y[0] = y[1] = 0.0
        if sigma == 0:
            y[5] = 0.0
    status |= {"jam"} if run.jams else set()
    status |= {"lifts_off"} if run.lift_offs else set()
    e_end = energy(bd, y, s)
    d_fric = y[8] - run.w_fric_impulsive
    return {"outcome": outcome, "overturned": outcome != L.OUTCOME_SAFE,
            "impacts": run.impacts, "uplifts": run.uplifts, "phases": run.phases,
            "theta_max": run.theta_max, "slide_max": run.slide_max,
            "slide_final": abs(y[4]), "t_end": t, "t_first_impact": t_first_impact,
            "t_overturn": t_overturn, "wall_time": time.perf_counter() - t0_wall,
            "steps": run.steps, "contacts": run.contacts, "e_max": run.e_max,
            "status": sorted(status),
            "W_in": y[6], "D_damp": y[7], "D_fric": d_fric, "E_impact": run.e_impact,
            "E_end": e_end, "E_ref": point.body.E_ref,
            "closure": y[6] - y[7] - d_fric - run.e_impact - e_end}


def result_row(r: dict) -> np.ndarray:
    """A ``sliding_reference`` dict as a kernel result row float64[N_OUT]: the no-slip
    reference's row (``reference.result_row``: the no-slip contact outputs NaN, steps
    DOP853's) of its status words as ``STATUS_*`` bits (``jam``, which no kernel bit
    names, left out; OVERTURNED and SLID where they hold), and the slide's slots."""
    status = sum(STATUS_BIT[w] for w in r["status"] if w in STATUS_BIT)
    status |= L.STATUS_OVERTURNED if r["overturned"] else 0
    status |= L.STATUS_SLID if r["slide_max"] > 0.0 else 0
    out = no_slip_row({**r, "status": status})
    out[L.OUT_SLIDE_MAX] = r["slide_max"]
    out[L.OUT_SLIDE_FINAL] = r["slide_final"]
    out[L.OUT_REGIME] = sum(1 << PHASE_CODE[w] for w in set(r["phases"]))
    return out
