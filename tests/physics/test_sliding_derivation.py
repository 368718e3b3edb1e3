"""The sliding base's equations (``rocksweep.kernel.sliding``) against an independent sympy
derivation: Lagrange's equations with the sliding displacement x as a third coordinate
and Coulomb's friction F as its generalised force, the reactions H and N from Newton's
law for the masses (docs/sliding.md).

The positions are ``test_derivations._positions`` with the pivot at x_g + x + s b; nothing
is taken from rocksweep's code but the parameter values. Rocking with the corner stuck the
derivation reproduces today's equations (``equations.rocking_rhs``, ``rigid_rhs``) and
reactions (``contact.ground_reactions``).
"""

import math

import numpy as np
import pytest
import sympy as sp
from bodies import BODY2, BODY3, table3
from test_derivations import _positions

from rocksweep.kernel import contact, sliding
from rocksweep.kernel import equations as eq
from rocksweep.numerics import Numerics
from rocksweep.physics import friction
from rocksweep.physics.bodies import BlockBody, FlexibleBody
from rocksweep.physics.points import Point, point_row

t = sp.symbols("t")
m, mA, IA, h, hA, b, g, k, c = sp.symbols("m m_A I_A h h_A b g k c", positive=True)
S, F = sp.symbols("s F")
TH, W, UU, V, XD, THDD, UDD, XDD, XGDD = sp.symbols("th w uu v xd thdd udd xdd xgdd")
ACC = [THDD, UDD, XDD]
G_ = 9.81


def _lagrange(masses, coords, extra_T=0, V_extra=0, damper=0):
    """Lagrange's equations with the ground's horizontal displacement inside the positions
    (inertial frame) and the friction F as the generalised force on x; H = sum m X'',
    N = sum m (Y'' + g). masses: (mass, position) pairs. Returns (mass matrix, forces,
    H, N) in the symbols above (H, N with the accelerations ACC)."""
    vel = [(mi, p.diff(t)) for mi, p in masses]
    T = sum(mi * v.dot(v) for mi, v in vel) / 2 + extra_T
    Vp = sum(mi * g * p[1] for mi, p in masses) + V_extra
    L = T - Vp
    x = coords[-1]
    eqs = [sp.diff(L.diff(q.diff(t)), t) - L.diff(q) + sp.diff(damper, q.diff(t))
           - (F if q is x else 0) for q in coords]
    H = sum(mi * p.diff(t, 2)[0] for mi, p in masses)
    N = sum(mi * (p.diff(t, 2)[1] + g) for mi, p in masses)
    return eqs, H, N


def _subs(exprs, theta, u, x, xg):
    pairs = [(theta.diff(t, 2), THDD), (u.diff(t, 2), UDD), (x.diff(t, 2), XDD),
             (xg.diff(t, 2), XGDD), (theta.diff(t), W), (u.diff(t), V), (x.diff(t), XD),
             (xg.diff(t), sp.Symbol("xgd")), (theta, TH), (u, UU), (x, sp.Symbol("xx"))]
    return [sp.expand(e.subs(pairs)) for e in exprs]


@pytest.fixture(scope="module")
def rocking_model():
    """Flexible body rocking on corner S, sliding by x: (eqs, H, N)."""
    theta, u, x, xg = (sp.Function(n)(t) for n in ("theta", "u", "x", "x_g"))
    P, A = _positions(theta, u, xg + x, S * b)
    eqs, H, N = _lagrange([(m, P), (mA, A)], [theta, u, x],
                          extra_T=IA * theta.diff(t) ** 2 / 2, V_extra=k * u**2 / 2,
                          damper=c * u.diff(t) ** 2 / 2)
    H, N = _subs([H, N], theta, u, x, xg)
    return _subs(eqs, theta, u, x, xg), H, N


@pytest.fixture(scope="module")
def rigid_model():
    """A rigid body (mass m at the centre of gravity, height h, inertia IA about it)."""
    theta, x, xg = (sp.Function(n)(t) for n in ("theta", "x", "x_g"))
    pivot = sp.Matrix([xg + x + S * b, 0])
    rot = sp.Matrix([[sp.cos(theta), sp.sin(theta)], [-sp.sin(theta), sp.cos(theta)]])
    G = pivot + rot * sp.Matrix([-S * b, h])
    eqs, H, N = _lagrange([(m, G)], [theta, x], extra_T=IA * theta.diff(t) ** 2 / 2)
    u = sp.Function("u")(t)
    H, N = _subs([H, N], theta, u, x, xg)
    return _subs(eqs, theta, u, x, xg), H, N


def _flex_row(body):
    return point_row(Point(body, 0.2, "sine", 2.0, 3.0), Numerics())


def _flex_values(bd):
    return {m: bd.m, mA: bd.m_A, IA: bd.I_A, h: bd.h, hA: bd.h_A, b: bd.b, g: G_, k: bd.k,
            c: bd.c}


def test_x_acceleration_enters_as_the_ground_acceleration(rocking_model, rigid_model):
    """Every equation, H and N depend on x'' and xg'' only through their sum (the base's
    absolute acceleration), and not on x or x': what lets the kernel use today's
    equations under a = xg'' + x''. The x equation is H = F (Newton for the whole body)."""
    z = sp.Symbol("z")
    for eqs, H, N in (rocking_model, rigid_model):
        for e in (*eqs, H, N):
            shifted = sp.expand(e.subs(XDD, z - XGDD))
            assert not shifted.has(XGDD)
            assert not e.has(sp.Symbol("xx")) and not e.has(XD)
        assert sp.simplify(eqs[-1] - (H - F)) == 0


_ARGS = (TH, W, UU, V, XD, XGDD, S, F, m, mA, IA, h, hA, b, g, k, c)


def _numeric(eqs, H, N):
    """(mass, rest, h_row, h0, n_row, n0) as numpy functions of _ARGS: eqs = mass acc -
    rest, H = h_row acc + h0, N = n_row acc + n0 (all linear in the accelerations)."""
    mass, rest = sp.linear_eq_to_matrix(eqs, ACC)
    h_row, h0 = sp.linear_eq_to_matrix([H], ACC)  # H = h_row acc - h0
    n_row, n0 = sp.linear_eq_to_matrix([N], ACC)
    h0, n0 = -h0, -n0
    return [sp.lambdify(_ARGS, e, "numpy") for e in (mass, rest, h_row, h0, n_row, n0)]


def _solve(model, values, state, sigma, mu, coords):
    """Numerical accelerations (theta'', u'', x''), F and N in a phase: stuck (sigma 0:
    x'' = 0, F = H) or slipping (F = -mu sigma N)."""
    args = [state.get(a, values.get(a, 0.0)) for a in _ARGS]
    mass, rest, h_row, h0, n_row, n0 = (np.array(f(*args), float) for f in model)
    # the F in ``rest`` is evaluated at F = 0: add it back as an unknown
    idx = [ACC.index(a) for a in coords]
    a_mat, r_vec = mass[:, idx], rest[:, 0]  # one equation per coordinate
    ix = len(idx) - 1  # the x equation: mass acc - rest = F
    if sigma == 0:
        sol = np.zeros(len(idx))
        sol[:ix] = np.linalg.solve(a_mat[:ix, :ix], r_vec[:ix])
    else:  # F = -mu sigma (n_row acc + n0)
        a_mat = a_mat.copy()
        a_mat[ix] += mu * sigma * n_row[0, idx]
        r_vec = r_vec.copy()
        r_vec[ix] -= mu * sigma * n0[0, 0]
        sol = np.linalg.solve(a_mat, r_vec)
    acc = np.zeros(3)
    acc[idx] = sol
    return list(acc), float(h_row[0] @ acc + h0[0, 0]), float(n_row[0] @ acc + n0[0, 0])


@pytest.mark.parametrize("body", [BODY3, BODY2], ids=["fig3", "fig2"])
def test_rocking_stuck_and_slipping_equal_lagrange(rocking_model, body):
    """Rocking on a stuck corner: today's rocking_rhs and ground_reactions; on a slipping
    corner: the kernel's slide-rock accelerations, F = -mu sigma N and N."""
    model = _numeric(*rocking_model)
    row = _flex_row(body)
    rng = np.random.default_rng(44)
    for _ in range(20):
        th, w = rng.uniform(-0.3, 0.3), rng.uniform(-1, 1)
        uu, v, xd, xg = rng.uniform(-0.3, 0.3), rng.uniform(-1, 1), rng.uniform(-1, 1), \
            rng.uniform(-15, 15)
        s = 1 if th > 0 else -1
        state = {TH: th, W: w, UU: uu, V: v, XD: xd, XGDD: xg, S: s}
        acc, f_val, n_val = _solve(model, _flex_values(body), state, 0, 0.0, ACC)
        thdd, udd, _, _ = eq.rocking_rhs(th, w, uu, v, s, xg, G_, row, True)
        assert thdd == pytest.approx(acc[0], rel=1e-10, abs=1e-12)
        assert udd == pytest.approx(acc[1], rel=1e-10, abs=1e-12)
        h_k, n_k = contact.ground_reactions(th, w, uu, v, s, xg, G_, row, True, True)
        scale = body.M * (G_ + abs(xg))
        assert h_k == pytest.approx(f_val, abs=1e-11 * scale)
        assert n_k == pytest.approx(n_val, abs=1e-11 * scale)
        for sigma in (1, -1):
            mu = rng.uniform(0.1, 1.0)
            acc, f_val, n_val = _solve(model, _flex_values(body), state, sigma, mu, ACC)
            got = sliding.accelerations(th, w, uu, v, s, sigma, xg, G_, mu, row, True, True)
            for a_k, a_s in zip(got[:3], acc, strict=True):
                assert a_k == pytest.approx(a_s, rel=1e-9, abs=1e-10)
            assert got[3] == pytest.approx(f_val, abs=1e-10 * scale)
            assert got[3] == pytest.approx(-mu * sigma * n_val, abs=1e-10 * scale)
            _, n_k, den = sliding.slip_state(th, w, uu, v, s, sigma, xg, G_, mu, row, True,
                                             True)
            assert n_k == pytest.approx(n_val, abs=1e-10 * scale)
            assert den > 0


@pytest.mark.parametrize("body", [BlockBody(alpha=0.2), FlexibleBody(**table3(
    wn_over_p=math.inf, zeta=0.0))], ids=["block", "welded"])
def test_rigid_stuck_and_slipping_equal_lagrange(rigid_model, body):
    model = _numeric(*rigid_model)
    row = _flex_row(body)
    i_g = body.I_O - body.M * (body.b**2 + body.h_cg**2)
    values = {m: body.M, IA: i_g, h: body.h_cg, b: body.b, g: G_}
    rng = np.random.default_rng(7)
    for _ in range(6):
        th, w, xd, xg = rng.uniform(-0.5, 0.5), rng.uniform(-1, 1), rng.uniform(-1, 1), \
            rng.uniform(-10, 10)
        s = 1 if th > 0 else -1
        state = {TH: th, W: w, XD: xd, XGDD: xg, S: s}
        acc, f_val, n_val = _solve(model, values, state, 0, 0.0, [THDD, XDD])
        assert eq.rigid_rhs(th, w, s, xg, G_, row)[0] == pytest.approx(acc[0], rel=1e-10)
        h_k, n_k = contact.ground_reactions(th, w, 0.0, 0.0, s, xg, G_, row, False, False)
        assert (h_k, n_k) == pytest.approx((f_val, n_val), rel=1e-10, abs=1e-10)
        for sigma in (1, -1):
            acc, f_val, n_val = _solve(model, values, state, sigma, 0.4, [THDD, XDD])
            got = sliding.accelerations(th, w, 0.0, 0.0, s, sigma, xg, G_, 0.4, row, False,
                                        False)
            assert got[0] == pytest.approx(acc[0], rel=1e-9, abs=1e-10)
            assert got[2] == pytest.approx(acc[2], rel=1e-9, abs=1e-10)
            assert got[3] == pytest.approx(-0.4 * sigma * n_val, rel=1e-9, abs=1e-10)


def _flat_model():
    """The flat body (theta = 0 held): Lagrange in (u, x); and the moment its ground's
    normal force must supply about corner S, read from the rocking model's theta
    equation at theta = theta' = theta'' = 0."""
    u, x, xg = (sp.Function(n)(t) for n in ("u", "x", "x_g"))
    P = sp.Matrix([xg + x + u, h])
    A = sp.Matrix([xg + x, hA])
    eqs, H, N = _lagrange([(m, P), (mA, A)], [u, x], V_extra=k * u**2 / 2,
                          damper=c * u.diff(t) ** 2 / 2)
    theta = sp.Function("theta")(t)
    H, N = _subs([H, N], theta, u, x, xg)
    return _subs(eqs, theta, u, x, xg), H, N


def test_flat_phases_and_uplift_while_sliding(rocking_model):
    """Flat: N = M g; sliding, x'' and u'' of the kernel; the uplift moment of a sliding
    body (``slide_uplift_moment``) from the theta equation: the normal force's moment
    about corner s it needs is m_s, and Q = s M g b - m_s is the same for both corners."""
    eqs_f, H_f, N_f = _flat_model()
    eqs_r, _, _ = rocking_model
    for body in (BODY3, BODY2):
        row, vals = _flex_row(body), _flex_values(body)
        assert float(N_f.subs(vals)) == pytest.approx(body.M * G_, rel=1e-14)
        for uu, v, xg, mu in [(0.1, -0.3, 4.0, 0.3), (-0.2, 0.5, -7.0, 0.6)]:
            for sigma in (1, -1):
                sub = {**vals, UU: uu, V: v, XGDD: xg}
                e_num = [sp.expand(e.subs(sub).subs(F, -mu * sigma * body.M * G_))
                         for e in eqs_f]
                sol = sp.solve(e_num, [UDD, XDD], dict=True)[0]
                got = sliding.accelerations(0.0, 0.0, uu, v, 0, sigma, xg, G_, mu, row,
                                            True, True)
                assert got[1] == pytest.approx(float(sol[UDD]), rel=1e-11)
                assert got[2] == pytest.approx(float(sol[XDD]), rel=1e-11)
                qs = []
                for s in (1, -1):
                    m_s = float(eqs_r[0].subs({**sub, S: s, TH: 0, W: 0, THDD: 0,
                                               UDD: sol[UDD], XDD: sol[XDD]}))
                    qs.append(s * body.M * G_ * body.b - m_s)
                assert qs[0] == pytest.approx(qs[1], rel=1e-10)
                q_k = sliding.slide_uplift_moment(uu, v, sigma, xg, G_, mu, row, True, True)
                assert q_k == pytest.approx(qs[0], rel=1e-10, abs=1e-12)
            # stuck: today's uplift moment from the same reading
            m_s = float(eqs_r[0].subs({**vals, UU: uu, V: v, XGDD: xg, S: 1, TH: 0, W: 0,
                                       THDD: 0, XDD: 0, UDD: eq.contact_rhs(
                                           uu, v, xg, row, True)[0]}))
            assert body.M * G_ * body.b - m_s == pytest.approx(
                eq.uplift_moment(uu, v, xg, G_, row, True, True), rel=1e-10)


def test_rigid_slide_rock_from_rest_accelerates_the_base_by_A_r():
    """A rigid body slide-rocking from rest: the base's absolute acceleration is A_r(mu),
    the closed form (``physics.friction.rock_threshold``), whatever A."""
    blk = BlockBody(alpha=0.25)
    row = _flex_row(blk)
    for mu in (0.4, 0.8):
        a_r, den = friction.rock_threshold(blk, mu)
        assert den > 0
        for A in (0.9 * G_, 2.0 * G_):
            x_dd, n, _ = sliding.slip_state(0.0, 0.0, 0.0, 0.0, -1, -1, A, G_, mu, row,
                                            False, False)
            assert A + x_dd == pytest.approx(a_r, rel=1e-12)
