"""The coded physics against independent sympy derivations (section 2 of the paper).

The Lagrangian is written here from the positions of the two masses in the ground's
inertial frame (rotation matrix, ground displacement x_g(t)); nothing is taken from
rocksweep's code but the parameter values.
"""

import numpy as np
import pytest
import sympy as sp

from rocksweep.kernel import eq1
from rocksweep.kernel import equations as eq
from rocksweep.kernel.layout import PAR_LAM, PAR_LAW
from rocksweep.numerics import Numerics
from rocksweep.physics import impact
from rocksweep.physics.bodies import BlockBody, impact_energy_loss, restitution, restitution_rigid
from rocksweep.physics.points import Point, point_row
from rocksweep.vocab.laws import EQ1, LAW_CODE, LOCKED

t = sp.symbols("t")
m, mA, IA, h, hA, b, g, k, c, lam = sp.symbols("m m_A I_A h h_A b g k c lambda", positive=True)
s = sp.symbols("s")  # +1 / -1: corner x = s b


def _positions(theta, u, xg, corner):
    """Top mass P and base mass A in the ground frame, rocking clockwise by theta about
    the base corner at x = corner (body frame), which stays on the ground."""
    rot = sp.Matrix([[sp.cos(theta), sp.sin(theta)], [-sp.sin(theta), sp.cos(theta)]])
    pivot = sp.Matrix([xg + corner, 0])
    P = pivot + rot * sp.Matrix([u - corner, h])
    A = pivot + rot * sp.Matrix([-corner, hA])
    return P, A


@pytest.fixture(scope="module")
def lagrange_solution():
    theta = sp.Function("theta")(t)
    u = sp.Function("u")(t)
    xg = sp.Function("x_g")(t)
    P, A = _positions(theta, u, xg, s * b)
    vP, vA = P.diff(t), A.diff(t)
    T = (m * vP.dot(vP) + mA * vA.dot(vA) + IA * theta.diff(t) ** 2) / 2
    V = m * g * P[1] + mA * g * A[1] + k * u**2 / 2
    L = T - V
    D = c * u.diff(t) ** 2 / 2  # Rayleigh dissipation: the damper's generalised force
    eqs = [sp.diff(L.diff(q.diff(t)), t) - L.diff(q) + D.diff(q.diff(t)) for q in (theta, u)]
    th, w, uu, v, thdd, udd, xgdd = sp.symbols("th w uu v thdd udd xgdd")
    subs = [(theta.diff(t, 2), thdd), (u.diff(t, 2), udd), (xg.diff(t, 2), xgdd),
            (theta.diff(t), w), (u.diff(t), v), (xg.diff(t), sp.Symbol("xgd")),
            (theta, th), (u, uu)]
    eqs = [sp.expand(e.subs(subs)) for e in eqs]
    # linear in the accelerations: mass matrix and forces, solved numerically per state
    mass, force = sp.linear_eq_to_matrix(eqs, [thdd, udd])
    args = (th, w, uu, v, s, xgdd, m, mA, IA, h, hA, b, g, k, c)
    f_mass, f_force = sp.lambdify(args, mass, "numpy"), sp.lambdify(args, force, "numpy")

    def accelerations(*a):
        return np.linalg.solve(np.array(f_mass(*a), float), np.array(f_force(*a), float)[:, 0])

    return accelerations, [e.has(sp.Symbol("xgd")) for e in eqs]


def test_rocking_equations_equal_lagrange_derivation(body_fig3, lagrange_solution):
    """rocking_rhs = Lagrange's equations with d'Alembert ground loads, both corners."""
    accelerations, has_xg_velocity = lagrange_solution
    assert not any(has_xg_velocity)  # only the ground *acceleration* loads the body
    bd = body_fig3
    row = point_row(Point(bd, 0.2, "sine", 2.0, 3.0), Numerics())
    rng = np.random.default_rng(1)
    for _ in range(40):
        th, w = rng.uniform(-1.2, 1.2), rng.uniform(-2, 2)
        uu, v, xg = rng.uniform(-0.5, 0.5), rng.uniform(-2, 2), rng.uniform(-20, 20)
        for corner in (1, -1):
            got = eq.rocking_rhs(th, w, uu, v, corner, xg, 9.81, row, True)
            args = (th, w, uu, v, corner, xg, bd.m, bd.m_A, bd.I_A, bd.h, bd.h_A, bd.b, 9.81,
                    bd.k, bd.c)
            want = accelerations(*args)
            assert got[0] == pytest.approx(want[0], rel=1e-9, abs=1e-10)
            assert got[1] == pytest.approx(want[1], rel=1e-9, abs=1e-10)


def test_full_contact_equation(body_fig3):
    """Full contact: m u'' + c u' + k u = -m xg''."""
    bd = body_fig3
    row = point_row(Point(bd, 0.2, "sine", 2.0, 3.0), Numerics())
    for uu, v, xg in [(0.1, -0.3, 4.0), (-0.2, 0.5, -7.0)]:
        u_dd = eq.contact_rhs(uu, v, xg, row, True)[0]
        assert bd.m * u_dd + bd.c * v + bd.k * uu == pytest.approx(-bd.m * xg, rel=1e-12)


def test_rigid_equation_is_welded_flexible_one(body_fig3):
    """rigid_rhs = Lagrange for the welded body: I_O theta'' = -dV/dtheta - M xg'' dX_G/dtheta."""
    bd = body_fig3
    row = point_row(Point(bd, 0.2, "sine", 2.0, 3.0), Numerics())
    th, xg_ = sp.symbols("th xg")
    for corner in (1, -1):
        rot = sp.Matrix([[sp.cos(th), sp.sin(th)], [-sp.sin(th), sp.cos(th)]])
        G = rot * sp.Matrix([-corner * bd.b, bd.h_cg])  # centre of gravity from the corner
        rhs = sp.lambdify((th, xg_), (-sp.diff(bd.M * 9.81 * G[1], th)
                                      - xg_ * bd.M * sp.diff(G[0], th)) / bd.I_O)
        for theta, xg in [(0.05, 3.0), (0.4, -2.0), (-0.3, 1.0)]:
            assert eq.rigid_rhs(theta, 0.7, corner, xg, 9.81, row)[0] == pytest.approx(
                rhs(theta, xg), rel=1e-12)


# ------------------------------------------------------------------------------------
# Impact: eq. (1), (5), (6) from the impulse-momentum balance
# ------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def impact_solution():
    """theta'^+ and u'^+ from (i) angular momentum of the whole body about the impulse
    point and (ii) the top mass's horizontal momentum, at theta = 0, for an impact that
    ends rocking on corner s_old (future corner -s_old)."""
    uu, v_m, w_m, w_p, v_p = sp.symbols("uu v_m w_m w_p v_p")
    s_old = sp.Symbol("s_old")
    x_q = -s_old * b * (1 - lam)  # lam*b from the future corner -s_old b

    def velocities(w, v, corner):
        # rigid rotation (clockwise w) about (corner, 0), plus the top mass's slide v
        def vel(x, y):
            return sp.Matrix([w * y, -w * (x - corner)])
        return vel(uu, h) + sp.Matrix([v, 0]), vel(0, hA)

    def h_about_q(w, v, corner):
        vP, vA = velocities(w, v, corner)
        def cross(r, vv):
            return r[0] * vv[1] - r[1] * vv[0]

        return (m * cross((uu - x_q, h), vP) + mA * cross((0 - x_q, hA), vA) - IA * w)

    eqs = [h_about_q(w_p, v_p, -s_old * b) - h_about_q(w_m, v_m, s_old * b),
           m * (velocities(w_p, v_p, -s_old * b)[0][0] - velocities(w_m, v_m, s_old * b)[0][0])]
    sol = sp.solve(eqs, [w_p, v_p], dict=True)[0]
    e = sp.simplify(sol[w_p] / w_m)

    def kinetic(w, v, corner):
        vP, vA = velocities(w, v, corner)
        return (m * vP.dot(vP) + mA * vA.dot(vA) + IA * w**2) / 2

    e_d = sp.simplify(kinetic(w_m, v_m, s_old * b) - kinetic(sol[w_p], sol[v_p], -s_old * b))
    return {"e": e, "E_d": e_d, "syms": (uu, v_m, w_m, s_old)}


def _paper_eq1(IA_, mA_, hA_, m_, u_, b_, lam_, upper):
    pm = 1 if upper else -1  # the paper's +/- (upper) and -/+ (lower)
    num = IA_ + mA_ * hA_**2 + m_ * u_ * (-pm * b_ + u_) + b_ * (1 - lam_) * (
        -mA_ * b_ - m_ * b_ + pm * m_ * u_)
    den = IA_ + mA_ * hA_**2 + m_ * u_ * (pm * b_ + u_) + b_ * (1 - lam_) * (
        mA_ * b_ + m_ * b_ + pm * m_ * u_)
    return num / den


def test_eq1_is_the_impulse_momentum_balance(impact_solution):
    """Eq. (1) as printed equals the balance; the paper's upper sign is s_old = +1."""
    uu, v_m, w_m, s_old = impact_solution["syms"]
    e = impact_solution["e"]
    for upper, s_val in ((True, 1), (False, -1)):
        paper = _paper_eq1(IA, mA, hA, m, uu, b, lam, upper)
        assert sp.simplify(e.subs(s_old, s_val) - paper) == 0


def _locked_momentum(w, corner, x_q, uu, v):
    """Angular momentum about (x_q, 0) of the body rotating clockwise at w about
    (corner, 0), the top mass at (uu, h) sliding at v relative to the base."""
    vp = sp.Matrix([w * h + v, -w * (uu - corner)])
    va = sp.Matrix([w * hA, w * corner])
    return (m * ((uu - x_q) * vp[1] - h * vp[0]) + mA * ((0 - x_q) * va[1] - hA * va[0])
            - IA * w)


def test_the_one_eq1_is_the_impulse_momentum_balance(impact_solution):
    """``kernel.eq1.restitution`` (the one definition: the kernel compiles it, the physics
    evaluates it on arrays) on sympy symbols equals the balance, for both corners; with
    m h^2 added (law locked) it is the balance whose top mass keeps u' instead."""
    uu, v_m, w_m, s_old = impact_solution["syms"]
    for s_val in (1, -1):
        coded = eq1.restitution(s_val, uu, lam, m, mA, b, IA + mA * hA**2, 0)
        assert sp.simplify(coded - impact_solution["e"].subs(s_old, s_val)) == 0
        # locked: the top mass moves with the base (u' kept): the angular momentum about
        # the impulse point alone balances, one unknown
        w_p = sp.Symbol("w_p")
        x_q = -s_val * b * (1 - lam)
        before = _locked_momentum(w_m, s_val * b, x_q, uu, v_m)
        locked = sp.solve(_locked_momentum(w_p, -s_val * b, x_q, uu, v_m) - before, w_p)[0] / w_m
        coded = eq1.restitution(s_val, uu, lam, m, mA, b, IA + mA * hA**2, m * h**2)
        assert sp.simplify(coded - locked) == 0


def test_every_eq1_caller_gives_the_kernels_bits(body_fig2):
    """Eq. (1) in one place: the physics (``bodies.restitution``, ``impact.restitution``
    under each law) and the kernel (``equations.restitution`` on the row) give the same
    float64, bit for bit, and the rigid body's e likewise."""
    bd = body_fig2
    row = point_row(Point(bd, 0.0, "sine", 2.0, 3.0), Numerics())
    for law in (EQ1, LOCKED):
        row[PAR_LAW] = LAW_CODE[law]
        for lam_v in (0.0, 0.3, 1.0, 1.7):
            row[PAR_LAM] = lam_v
            u_ = np.linspace(-2.0, 2.0, 9) * bd.u_cr
            for upper in (True, False):
                kernel = [eq.restitution(1 if upper else -1, x, row, True) for x in u_]
                assert impact.restitution(bd, lam_v, u_, upper, law).tolist() == kernel
                if law == EQ1:
                    assert restitution(bd, lam_v, u_, upper).tolist() == kernel
    block = BlockBody(alpha=0.3)
    row = point_row(Point(block, 0.0, "sine", 2.0, 3.0), Numerics())
    for lam_v in (0.0, 0.5, 1.0):
        row[PAR_LAM] = lam_v
        assert float(restitution_rigid(block, lam_v)) == eq.restitution(1, 0.0, row, False)


def test_eq5_is_the_derivative_of_eq1(impact_solution):
    uu, _, _, s_old = impact_solution["syms"]
    for upper, s_val in ((True, 1), (False, -1)):
        pm = 1 if upper else -1
        d = sp.diff(impact_solution["e"].subs(s_old, s_val), lam)
        den = (IA + mA * hA**2 + m * uu * (pm * b + uu)
               + b * (1 - lam) * (mA * b + m * b + pm * m * uu))
        paper5 = (2 * (m + mA) * b**2 * (IA + mA * hA**2) + 2 * m * mA * b**2 * uu**2) / den**2
        assert sp.simplify(d - paper5) == 0


def test_eq6_is_the_kinetic_energy_jump(impact_solution):
    uu, v_m, w_m, s_old = impact_solution["syms"]
    for upper, s_val in ((True, 1), (False, -1)):
        pm = 1 if upper else -1
        e = impact_solution["e"].subs(s_old, s_val)
        IA0 = IA + mA * (b**2 + hA**2)
        paper6 = (-sp.Rational(1, 2) * (IA0 + m * b**2 + m * uu**2) * (e**2 - 1) * w_m**2
                  - pm * m * b * uu * (e**2 + 1) * w_m**2)
        assert sp.simplify(impact_solution["E_d"].subs(s_old, s_val) - paper6) == 0


def test_coded_restitution_matches_paper_eq1(body_fig2):
    """model.restitution, the kernel's restitution and eq. (1) typed from the paper agree."""
    bd = body_fig2
    row = point_row(Point(bd, 0.0, "sine", 2.0, 3.0), Numerics())
    for lam_v in (0.0, 0.3, 1.0, 1.7):
        row[PAR_LAM] = lam_v
        for u_over in (-2.0, -0.5, 0.0, 1.3):
            u_ = u_over * bd.u_cr
            for upper in (True, False):
                paper = _paper_eq1(bd.I_A, bd.m_A, bd.h_A, bd.m, u_, bd.b, lam_v, upper)
                assert float(restitution(bd, lam_v, u_, upper)) == pytest.approx(paper, rel=1e-12)
                assert eq.restitution(1 if upper else -1, u_, row, True) == pytest.approx(
                    paper, rel=1e-12)


def test_eq6_function_matches_energy_jump(body_fig2):
    """model.impact_energy_loss (eq. 6) equals T^- - T^+ computed from the kernel's energy."""
    bd = body_fig2
    row = point_row(Point(bd, 0.5, "sine", 2.0, 3.0), Numerics())
    for u_, v, w in [(0.02, 0.1, -0.3), (-0.05, -0.2, 0.4)]:
        s_old = 1 if w < 0 else -1  # returning to theta = 0 from side s_old
        e = float(restitution(bd, 0.5, u_, upper=(s_old == 1)))
        w_p = e * w
        v_p = v + bd.h * (w - w_p)
        jump = (eq.mechanical_energy(0.0, w, u_, v, s_old, row, True)
                - eq.mechanical_energy(0.0, w_p, u_, v_p, -s_old, row, True))
        assert float(impact_energy_loss(bd, e, u_, w, upper=(s_old == 1))) == pytest.approx(
            jump, rel=1e-10)


@pytest.mark.parametrize("pi", [dict(wn_over_p=2.43), dict(wn_over_p=9.82),
                                dict(wn_over_p=1.2, alpha_cg=0.4, mA_over_m=2.0)])
def test_ridge_is_the_least_potential_over_u_and_peaks_at_the_saddle(pi):
    """The kernel's energy bound (``kernel.ridge``): W(theta) = min over u of V(theta, u)
    - V_rest, with V written here from the masses' heights, and its peak theta_r, where
    (theta_r, u(theta_r)) is a stationary point of V: the overturning saddle."""
    from rocksweep.kernel.ridge import ridge_energy, ridge_theta
    from rocksweep.physics.bodies import FlexibleBody, G

    body = FlexibleBody(**{"zeta": 0.05, "alpha_cg": 0.15, "alpha_A": 0.28, "mA_over_m": 0.47,
                           "IA_ratio": 0.56, **pi})
    th, uu = sp.symbols("th uu", real=True)
    P, A = _positions(th, uu, 0, b)  # corner s = +1
    vals = {m: body.m, mA: body.m_A, h: body.h, hA: body.h_A, b: body.b, g: G, k: body.k}
    V = (m * g * P[1] + mA * g * A[1] + k * uu**2 / 2).subs(vals)
    V = V - V.subs({th: 0, uu: 0})
    u_min = sp.solve(sp.diff(V, uu), uu)[0]  # V is quadratic in u, k > 0: its minimum
    W = sp.simplify(V.subs(uu, u_min))
    args = (body.m, body.m_A, body.h, body.h_A, body.b, body.k, G)
    for x in np.linspace(0.0, 1.5, 13):
        assert ridge_energy(x, *args) == pytest.approx(float(W.subs(th, x)), rel=1e-12,
                                                       abs=1e-12)
        assert ridge_energy(-x, *args) == ridge_energy(x, *args)  # the other corner
    theta_r = float(ridge_theta(*args))
    # the peak: dW/dtheta = 0 there (sympy's root), and V's gradient vanishes at the saddle
    root = float(sp.nsolve(sp.diff(W, th), th, theta_r))
    # (golden sections compare values: W is flat at its peak, so theta_r is found to ~1e-8
    # rad, where W is within round-off of its peak)
    assert theta_r == pytest.approx(root, abs=1e-7)
    u_r = float(u_min.subs(th, root))
    grad = [float(sp.diff(V, q).subs({th: root, uu: u_r})) for q in (th, uu)]
    assert np.allclose(grad, 0.0, atol=1e-9 * float(V.subs({th: root, uu: u_r})))
    assert 0.0 < root < np.pi / 2 and float(W.subs(th, root)) > 0.0
