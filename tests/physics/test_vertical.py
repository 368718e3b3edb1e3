"""The vertical ground acceleration a_v (docs/vertical.md).

- the equations of motion with a moving base (x_g(t), y_g(t)) derived by Lagrange in the
  inertial frame (sympy, from the geometry alone) equal the kernel's right-hand sides
  with gravity g + y_g'' (flexible and rigid bodies), and the kernel's power of the
  vertical loads is -y_g'' d/dt(sum m_i Y_i);
- a rigid block uplifts where |xg''| = (g + a_v) tan(alpha) (statics);
- a body under a constant vertical acceleration c g is the same body under gravity
  g (1 + c): omega_n/p and w/p divided by sqrt(1 + c), A_ratio by 1 + c, time p t times
  sqrt(1 + c), u/u_cr divided by 1 + c (the rescaling derived in docs/vertical.md);
- the kernel's outcomes equal the independent reference's on rigid-block points near
  their thresholds, horizontal pulse and vertical harmonic given as two-column records;
- g + a_v <= 0 during a run: status airborne at the first such time (a harmonic's closed
  form, a record's linear segment), the same in the reference; the energy balance with a
  vertical; a zero vertical changes nothing.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from bodies import FIG4

from rocksweep.compute.single import run_point
from rocksweep.kernel import equations as eq
from rocksweep.kernel import layout as L
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, FlexibleBody
from rocksweep.physics.ground_motion import (
    Harmonic,
    air_time_harmonic,
    air_time_record,
    pulse,
    recorded,
)
from rocksweep.physics.points import Point, point_row
from rocksweep.physics.records import parse_record
from rocksweep.physics.reference import reference_run

G = 9.81


# ------------------------------------------------------------------------------------
# Derivation: Lagrange in the inertial frame, the base moving by (x_g(t), y_g(t))
# ------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def moving_base():
    """(accelerations(th, w, u, v, s, xg, yg, m, m_A, I_A, h, h_A, b, g, k, c) -> (th'',
    u''), dY/dt(th, w, u, v, s, m, m_A, h, h_A, b)) of the flexible body rocking on corner
    s, from T and V of the two masses in the inertial frame (clockwise theta about the
    corner (s b, 0) of the base; the top mass at (u, h), the base at (0, h_A) in the
    body's frame), the damper as the generalised force -c u'."""
    t = sp.Symbol("t")
    th, u = sp.Function("th")(t), sp.Function("u")(t)
    xg, yg = sp.Function("xg")(t), sp.Function("yg")(t)
    s, m, m_A, I_A, h, h_A, b, g, k, c = sp.symbols("s m m_A I_A h h_A b g k c")

    def place(x, y):  # a body point (x, y) after the rotation about the corner
        xr = x - s * b
        return (xg + s * b + xr * sp.cos(th) + y * sp.sin(th),
                yg - xr * sp.sin(th) + y * sp.cos(th))

    P, A = place(u, h), place(0, h_A)
    vel = [sp.diff(q, t) for q in (*P, *A)]
    T = (m * (vel[0] ** 2 + vel[1] ** 2) + m_A * (vel[2] ** 2 + vel[3] ** 2)
         + I_A * sp.diff(th, t) ** 2) / 2
    V = g * (m * P[1] + m_A * A[1]) + k * u ** 2 / 2
    L_ = T - V
    eqs = [sp.diff(sp.diff(L_, sp.diff(q, t)), t) - sp.diff(L_, q) - f
           for q, f in ((th, 0), (u, -c * sp.diff(u, t)))]
    W, Uv, THD, UDD, XGA, YGA = sp.symbols("W Uv THD UDD XGA YGA")
    TH, U = sp.symbols("TH U")
    subs = [(sp.diff(th, t, 2), THD), (sp.diff(u, t, 2), UDD), (sp.diff(xg, t, 2), XGA),
            (sp.diff(yg, t, 2), YGA), (sp.diff(th, t), W), (sp.diff(u, t), Uv), (th, TH),
            (u, U)]
    eqs = [sp.expand(e.subs(subs)) for e in eqs]
    # only the base's accelerations load the body, never its position or velocity
    assert not any(e.has(xg) or e.has(yg) or e.has(sp.Derivative) for e in eqs)
    mass, force = sp.linear_eq_to_matrix(eqs, [THD, UDD])
    args = (TH, W, U, Uv, s, XGA, YGA, m, m_A, I_A, h, h_A, b, g, k, c)
    f_mass, f_force = sp.lambdify(args, mass), sp.lambdify(args, force)
    # the masses' heights above the base, and their rate
    heights = (m * (P[1] - yg) + m_A * (A[1] - yg)).subs([(sp.diff(th, t), W), (th, TH),
                                                          (sp.diff(u, t), Uv), (u, U)])
    rate = sp.diff(m * (P[1] - yg) + m_A * (A[1] - yg), t).subs(
        [(sp.diff(th, t), W), (sp.diff(u, t), Uv), (th, TH), (u, U)])
    f_rate = sp.lambdify((TH, W, U, Uv, s, m, m_A, h, h_A, b), rate)
    assert heights is not None

    def accelerations(*a):
        return np.linalg.solve(np.array(f_mass(*a), float), np.array(f_force(*a), float)[:, 0])

    return accelerations, f_rate


def test_rocking_with_vertical_equals_the_moving_base_lagrangian(body_fig3, moving_base):
    """rocking_rhs with gravity g + a_v = Lagrange's equations with the base accelerating
    by (xg'', a_v), both corners, random states; the kernel's power of the vertical loads
    is -a_v times the rate of sum m_i Y_i."""
    accelerations, f_rate = moving_base
    bd = body_fig3
    row = point_row(Point(bd, 0.2, "sine", 2.0, 3.0), Numerics())
    rng = np.random.default_rng(5)
    for _ in range(30):
        th, w = rng.uniform(-1.2, 1.2), rng.uniform(-2, 2)
        uu, v = rng.uniform(-0.5, 0.5), rng.uniform(-2, 2)
        xg, av = rng.uniform(-20, 20), rng.uniform(-8, 8)
        for s in (1, -1):
            got = eq.rocking_rhs(th, w, uu, v, s, xg, G + av, row, True)
            want = accelerations(th, w, uu, v, s, xg, av, bd.m, bd.m_A, bd.I_A, bd.h,
                                 bd.h_A, bd.b, G, bd.k, bd.c)
            assert got[0] == pytest.approx(want[0], rel=1e-9, abs=1e-10)
            assert got[1] == pytest.approx(want[1], rel=1e-9, abs=1e-10)
            p_v = eq.vertical_power(0.0, th, w, uu, v, s, G + av, row, True)
            rate = f_rate(th, w, uu, v, s, bd.m, bd.m_A, bd.h, bd.h_A, bd.b)
            assert p_v == pytest.approx(-av * rate, rel=1e-10, abs=1e-12)


def test_rigid_with_vertical_equals_the_moving_base_lagrangian():
    """A block: one mass M at its centre of gravity, I_O about the corner; the Lagrangian
    with the base accelerating by (xg'', a_v) against rigid_rhs under g + a_v."""
    blk = BlockBody(alpha=0.25)
    row = point_row(Point(blk, 1.0, "sine", 2.0, 3.0), Numerics())
    t = sp.Symbol("t")
    th, xg, yg = (sp.Function(n)(t) for n in ("th", "xg", "yg"))
    for s in (1, -1):
        X = xg + s * blk.b * (1 - sp.cos(th)) + blk.h_cg * sp.sin(th)
        Y = yg + s * blk.b * sp.sin(th) + blk.h_cg * sp.cos(th)
        i_g = blk.I_O - blk.M * (blk.b ** 2 + blk.h_cg ** 2)
        T = (blk.M * (sp.diff(X, t) ** 2 + sp.diff(Y, t) ** 2)
             + i_g * sp.diff(th, t) ** 2) / 2
        L_ = T - G * blk.M * Y
        e = sp.diff(sp.diff(L_, sp.diff(th, t)), t) - sp.diff(L_, th)
        THD, W, TH, XGA, YGA = sp.symbols("THD W TH XGA YGA")
        e = e.subs([(sp.diff(th, t, 2), THD), (sp.diff(xg, t, 2), XGA),
                    (sp.diff(yg, t, 2), YGA), (sp.diff(th, t), W), (th, TH)])
        f = sp.lambdify((TH, W, XGA, YGA), sp.solve(e, THD)[0])
        for theta, w, x, av in [(0.05, 0.3, 3.0, 2.0), (-0.2, -1.0, -2.0, -4.0),
                                (0.3, 0.7, 1.0, 6.0)]:
            got = eq.rigid_rhs(theta, w, s, x, G + av, row)[0]
            assert got == pytest.approx(f(theta, w, x, av), rel=1e-10)


@pytest.mark.parametrize("a_v_g", [-0.5, 0.0, 0.6])
def test_block_uplifts_where_xg_is_g_plus_av_tan_alpha(a_v_g):
    """Statics of a block at rest: the uplift moment reaches M (g + a_v) b exactly at
    |xg''| = (g + a_v) tan(alpha)."""
    blk = BlockBody(alpha=0.3)
    row = point_row(Point(blk, 1.0, "sine", 2.0, 1.0), Numerics())
    g = G * (1.0 + a_v_g)
    for factor, lifts in ((0.999, False), (1.001, True)):
        xg = -factor * g * math.tan(0.3)
        q = eq.uplift_moment(0.0, 0.0, xg, g, row, False, False)
        assert (q >= eq.tip_moment(g, row)) is lifts


# ------------------------------------------------------------------------------------
# A constant vertical acceleration is a change of gravity
# ------------------------------------------------------------------------------------


def _constant(c: float) -> Harmonic:
    """a_v = c g exactly: sin(0 t + pi/2) = 1 (``pulse.vertical.w_over_p: 0``)."""
    return Harmonic(c, 0.0, 90.0)


@pytest.mark.parametrize("c, lam, A_ratio", [(0.5, 0.2, 4.0), (-0.3, 0.6, 2.5)])
def test_constant_vertical_is_gravity_times_one_plus_c(c, lam, A_ratio):
    """A flexible body under a_v = c g during a 3-cycle sine pulse, against the same body
    under g' = g (1 + c) in the kernel's own units (p' = p sqrt(1 + c)): omega_n/p and
    w/p divided by sqrt(1 + c), A_ratio by 1 + c. The histories agree at equal physical
    times (p' t = sqrt(1 + c) p t) while the pulse acts: theta/alpha_cg equal, u/u_cr
    times 1 + c (u_cr holds g); the outcome agrees if decided before the pulse ends."""
    q = 1.0 + c
    w_over_p = 2.0
    num = Numerics.preset("fine")
    body = FlexibleBody(**FIG4)
    scaled = FlexibleBody(**{**FIG4, "wn_over_p": FIG4["wn_over_p"] / math.sqrt(q)})
    a = run_point(Point(body, lam, pulse("sine", cycles=3, harmonic=_constant(c)), w_over_p,
                        A_ratio), num)
    b = run_point(Point(scaled, lam, pulse("sine", cycles=3), w_over_p / math.sqrt(q),
                        A_ratio / q), num)
    ha, hb = a.history_columns(), b.history_columns()
    t_pulse = 3 * 2 * math.pi / w_over_p
    ta = np.linspace(0.0, min(t_pulse, ha["p_t"][-1], hb["p_t"][-1] / math.sqrt(q)), 200)
    th_a = np.interp(ta, ha["p_t"], ha["theta_over_alpha"])
    th_b = np.interp(ta * math.sqrt(q), hb["p_t"], hb["theta_over_alpha"])
    assert np.max(np.abs(th_a)) > 0.2  # it rocks
    np.testing.assert_allclose(th_a, th_b, atol=2e-3 * np.max(np.abs(th_a)))
    u_a = np.interp(ta, ha["p_t"], ha["u_over_ucr"])
    u_b = np.interp(ta * math.sqrt(q), hb["p_t"], hb["u_over_ucr"])
    np.testing.assert_allclose(u_a, q * u_b, atol=2e-3 * np.max(np.abs(u_a)))
    if a.t_overturn is not None and a.t_overturn < t_pulse:
        assert b.outcome == a.outcome
        assert b.t_overturn == pytest.approx(math.sqrt(q) * a.t_overturn, rel=1e-4)


# ------------------------------------------------------------------------------------
# Kernel against the independent reference
# ------------------------------------------------------------------------------------


def _two_column(t: np.ndarray, a: np.ndarray, name: str):
    text = "\n".join(f"{ti:.8f} {ai:.10e}" for ti, ai in zip(t, a, strict=True))
    return parse_record(text.encode(), f"{name}.txt")


@pytest.mark.parametrize("a_v, w_v, A_ratio", [
    (0.2, 6.0, 1.1), (0.5, 9.0, 1.4), (0.8, 4.0, 1.25), (0.8, 12.0, 2.0)])
def test_kernel_outcome_equals_reference_with_vertical_records(a_v, w_v, A_ratio):
    """A block (alpha 0.2) under a one-cycle sine (period 1 s) and a vertical harmonic
    a_v g sin(w_v t), both as two-column records at DT = 5 ms, at the default preset:
    the kernel's outcome, impacts and max theta equal the reference's."""
    dt, p = 0.005, 2 * math.pi / 1.5
    t = np.arange(0.0, 2.0 + dt / 2, dt)
    h = _two_column(t, np.where(t <= 1.0, np.sin(2 * math.pi * t), 0.0), "h")
    v = _two_column(t, a_v * np.sin(w_v * t), "v")
    point = Point(BlockBody(alpha=0.2), 1.0, recorded(h, v), math.nan, A_ratio, p=p)
    num = Numerics()
    k = run_point(point, num, history=False)
    r = reference_run(point, num)
    assert k.outcome == {0: "safe", 1: "mode1", 2: "mode2"}[r["outcome"]]
    assert k.impacts == r["impacts"] or k.outcome != "safe"
    if k.outcome == "safe":
        assert k.out[L.OUT_THETA_MAX] == pytest.approx(r["theta_max"], rel=2e-2, abs=1e-4)


def test_zero_vertical_changes_nothing(body_fig3):
    """The vertical variant with a_v = 0 gives the horizontal variant's run (a check that
    the vertical code adds nothing but g + a_v)."""
    plain = run_point(Point(body_fig3, 0.4, "sine", 5.3, 5.0), Numerics(), history=False)
    zero = run_point(Point(body_fig3, 0.4, pulse("sine", harmonic=Harmonic(0.0, 3.0, 0.0)),
                           5.3, 5.0), Numerics(), history=False)
    assert zero.outcome == plain.outcome == "mode1"
    assert zero.out[L.OUT_IMPACTS] == plain.out[L.OUT_IMPACTS]
    assert zero.out[L.OUT_T_OVERTURN] == pytest.approx(plain.out[L.OUT_T_OVERTURN], rel=1e-12)


def test_energy_balance_with_a_vertical(body_fig3):
    """E_end - E_0 = W_in - D_damp - E_impact with the vertical's work in W_in (E with the
    constant g), over a run with impacts, to the integrator's error (converged steps);
    the vertical's share of W_in is not small."""
    num = Numerics.preset("fine", steps_per_period=80, event_tol=1e-10)
    run = run_point(Point(body_fig3, 0.2, pulse("sine", harmonic=Harmonic(0.6, 5.0, 20.0)),
                          2.0, 1.5), num)
    o = run.out
    assert o[L.OUT_IMPACTS] >= 1
    balance = o[L.OUT_W_IN] - o[L.OUT_D_DAMP] - o[L.OUT_E_IMPACT]
    assert o[L.OUT_E_END] == pytest.approx(balance, abs=1e-6 * o[L.OUT_W_IN])
    plain = run_point(Point(body_fig3, 0.2, "sine", 2.0, 1.5), num)
    assert abs(o[L.OUT_W_IN] - plain.out[L.OUT_W_IN]) > 0.05 * plain.out[L.OUT_W_IN]


# ------------------------------------------------------------------------------------
# airborne: g + a_v <= 0
# ------------------------------------------------------------------------------------


def test_air_time_closed_forms():
    """The first t with 1 + a sin(w t + phase) <= 0: (pi + asin(1/a) - phase)/w; 0 when
    the phase is already past it; inf below |a| = 1 or after the pulse; a record's first
    crossing of -1/scale inside its segment."""
    t = air_time_harmonic([2.0, 2.0, 0.9, 2.0, -2.0], 3.0, [0.0, 225.0, 0.0, 0.0, 0.0],
                          [9.0, 9.0, 9.0, 0.1, 9.0])
    want = (math.pi + math.asin(0.5)) / 3.0
    assert t[0] == pytest.approx(want, rel=1e-14)
    assert t[1] == 0.0 and math.isinf(t[2]) and math.isinf(t[3])
    assert t[4] == pytest.approx(math.asin(0.5) / 3.0, rel=1e-14)  # -2 sin = 2 sin(+pi)
    shape = np.array([0.0, -0.4, -0.8, -0.2])
    got = air_time_record(shape, 0.5, np.array([2.0, 1.0, 10.0]))
    # scale 2: shape <= -0.5 between samples 1 (-0.4) and 2 (-0.8): 1.25 samples
    assert got[0] == pytest.approx(1.25 * 0.5) and math.isinf(got[1])
    assert got[2] == pytest.approx((0.1 / 0.4) * 0.5)


def test_airborne_stops_the_run_where_g_plus_av_reaches_zero():
    """A block under a 1.5 g harmonic: the run stops at the closed-form time, status
    airborne (a flagged run), in the kernel and the reference alike."""
    pv = Harmonic(1.5, 6.0, 10.0)
    point = Point(BlockBody(alpha=0.2), 1.0, pulse("sine", harmonic=pv), 2.0, 1.5)
    k = run_point(point, Numerics(), history=False)
    r = reference_run(point, Numerics())
    t_air = (math.pi + math.asin(1 / 1.5) - math.radians(10.0)) / 6.0
    assert "airborne" in k.summary()["status"]
    assert int(k.out[L.OUT_STATUS]) & L.STATUS_FLAGGED
    assert k.out[L.OUT_T_END] == pytest.approx(t_air, rel=1e-12)
    assert r["status"] & L.STATUS_AIRBORNE and r["t_end"] == pytest.approx(t_air, rel=1e-9)
