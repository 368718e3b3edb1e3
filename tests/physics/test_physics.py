"""Uplift, RK4 order, energy balance, mirror symmetry and the paper's own claims."""

import math

import numpy as np
import pytest
from bodies import table3
from numba import njit
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from rocksweep.compute.single import run_point
from rocksweep.kernel import equations as eq
from rocksweep.kernel import stepping as ki
from rocksweep.kernel.layout import GROUND_PULSE
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import FlexibleBody, G, restitution, restitution_rigid
from rocksweep.physics.points import Point, point_row

# Physics checks run at a pinned accuracy, independent of how the presets are tuned.
NUM = Numerics.preset("default", steps_per_period=20, event_tol=1e-8)


# ------------------------------------------------------------------------------------
# Uplift
# ------------------------------------------------------------------------------------


def test_uplift_moment_matches_rocking_equation_at_rest(body_fig3):
    """At theta = theta' = 0, the rocking equation's theta'' changes sign exactly where the
    uplift criterion s Q = M g b says (two separately coded formulas agree)."""
    bd = body_fig3
    row = point_row(Point(bd, 0.2, "sine", 2.0, 3.0), NUM)
    mgb = bd.M * G * bd.b
    rng = np.random.default_rng(3)
    for _ in range(50):
        u, v, xg = rng.uniform(-0.3, 0.3), rng.uniform(-1, 1), rng.uniform(-10, 10)
        q = eq.uplift_moment(u, v, xg, G, row, True, True)
        for s in (1, -1):
            th_dd = eq.rocking_rhs(0.0, 0.0, u, v, s, xg, G, row, True)[0]
            # theta'' (I_A0 + m a^2) = Q - s M g b: rocking on s starts iff s Q > M g b
            assert s * th_dd > 0 if s * q > mgb else s * th_dd <= 0


@pytest.mark.parametrize("factor, lifts_at_zero", [(0.999, False), (1.001, True)])
def test_cosine_pulse_uplift_at_t0_brackets_static_threshold(body_fig3, factor, lifts_at_zero):
    """A cosine pulse lifts the body at t = 0 iff m_A h_A A >= M g b (statics of the base
    mass's inertia load about a corner, u = 0 at rest)."""
    bd = body_fig3
    a_crit = bd.M * G * bd.b / (bd.m_A * bd.h_A)
    a_ratio = factor * a_crit / (G * math.tan(bd.alpha_cg))
    run = run_point(Point(bd, 0.2, "cosine", 3.0, -a_ratio), NUM)
    h = run.history
    first = np.flatnonzero(h["phase"] != 0)
    assert bool(h["t"][first[0]] == 0.0) is lifts_at_zero
    assert run.uplifts >= 1


def test_rigid_uplift_at_g_tan_alpha():
    """Rigid body, sine pulse: uplift when A sin(w t) first reaches g tan(alpha_cg)."""
    bd = FlexibleBody(**table3(wn_over_p=math.inf, zeta=0.0))
    for a_ratio in (1.3, 3.0):
        run = run_point(Point(bd, 0.0, "sine", 2.0, a_ratio), NUM)
        h = run.history
        t_up = h["t"][np.flatnonzero(h["phase"] != 0)[0]]
        assert t_up == pytest.approx(math.asin(1 / a_ratio) / 2.0, abs=1e-7)
    assert run_point(Point(bd, 0.0, "sine", 2.0, 0.999), NUM).uplifts == 0


def test_flexible_uplift_time_matches_independent_integration(body_fig3):
    """Flexible body, sine pulse: the first uplift is where Q(t) of the full-contact
    response (integrated here by scipy's DOP853, not the kernel) first reaches M g b."""
    bd = body_fig3
    w, a_ratio = 1.5, 1.2
    A = a_ratio * G * math.tan(bd.alpha_cg)

    def contact(t, y):  # m u'' + c u' + k u = -m A sin(w t)
        return [y[1], -(bd.k * y[0] + bd.c * y[1]) / bd.m - A * math.sin(w * t)]

    sol = solve_ivp(contact, (0, 2 * math.pi / w), [0.0, 0.0], method="DOP853", rtol=1e-12,
                    atol=1e-14, dense_output=True)

    def excess(t):  # |Q| - M g b, Q derived by statics of the base in full contact
        u, v = sol.sol(t)
        q = bd.h * (bd.k * u + bd.c * v) + bd.m * G * u - bd.m_A * bd.h_A * A * math.sin(w * t)
        return abs(q) - bd.M * G * bd.b

    ts = np.linspace(1e-6, 2 * math.pi / w, 4001)
    vals = np.array([excess(x) for x in ts])
    i = int(np.argmax(vals >= 0))
    assert vals[i] >= 0 > vals[i - 1]
    t_star = brentq(excess, ts[i - 1], ts[i], xtol=1e-13)
    run = run_point(Point(bd, 0.2, "sine", w, a_ratio), NUM)
    h = run.history
    t_up = h["t"][np.flatnonzero(h["phase"] != 0)[0]]
    assert t_up == pytest.approx(t_star, abs=1e-6)


# ------------------------------------------------------------------------------------
# RK4 order and energy
# ------------------------------------------------------------------------------------


@njit
def _rk4_loop(row, y0, t_total, n, s):
    # jitted: a `literally`-specialised kernel function called from Python re-enters the
    # dispatcher on every call; from jitted code the flags are literals at compile time
    y, t, h = y0, 0.0, t_total / n
    for _ in range(n):
        y = ki.rk4_step(t, y, h, s, True, row, True, True, True, GROUND_PULSE)
        t += h
    return y


def _integrate_rocking(row, y0, t_total, n, s=1):
    return np.array(_rk4_loop(row, y0, t_total, n, s)[:4])


def test_rk4_error_falls_16_fold_per_halving(body_fig3):
    """Fourth order: on a smooth rocking stretch the error drops ~2^4 per halving."""
    row = point_row(Point(body_fig3, 0.2, "sine", 2.0, 2.0), NUM)
    y0 = (0.05, 0.1, 0.01, -0.05, 0.0, 0.0)
    ref = _integrate_rocking(row, y0, 1.0, 16384)
    errs = [np.abs(_integrate_rocking(row, y0, 1.0, n) - ref).max() for n in (64, 128, 256)]
    ratios = [errs[0] / errs[1], errs[1] / errs[2]]
    assert all(14 < r < 19 for r in ratios), ratios  # 17.9, 17.0: approaching 2^4


def _free_flight_drift(steps_per_period):
    """Largest change of E/E_ref over one step between impacts, after the pulse, zeta = 0."""
    bd = FlexibleBody(**table3(zeta=0.0))
    num = Numerics.preset("default", horizon=30.0, steps_per_period=steps_per_period,
                          event_tol=1e-8)
    run = run_point(Point(bd, 0.2, "sine", 6.0, 3.0), num)
    h = run.history
    after = h["t"] > 2 * math.pi / 6.0 + 1e-9
    assert run.impacts > 0 and after.sum() > 50
    assert np.all(h["D_damp"] == 0) and np.all(np.diff(h["W_in"][after]) == 0)
    E = h["E"][after] / bd.E_ref
    smooth = (np.diff(h["E_impact"][after]) == 0) & (np.diff(h["t"][after]) > 0)
    return np.abs(np.diff(E))[smooth].max()


def test_energy_conserved_between_impacts_without_damping_or_ground_motion():
    """zeta = 0, no ground motion: E is constant between impacts up to RK4's O(h^4)."""
    coarse, fine = _free_flight_drift(20), _free_flight_drift(40)
    assert fine < 2e-6
    assert coarse / fine > 8  # the drift is the integrator's, and falls with its order


def test_energy_balance_closes_on_fig5(body_fig3):
    """Work in - damper loss - impact losses = E(t), over the whole Figure 5 run."""
    for lam in (0.0, 0.4):
        h = run_point(Point(body_fig3, lam, "sine", 5.3, 5.0), NUM).history
        bal = h["E"] - (h["W_in"] - h["D_damp"] - h["E_impact"])
        assert np.abs(bal).max() / body_fig3.E_ref < 1e-4


# ------------------------------------------------------------------------------------
# Symmetry
# ------------------------------------------------------------------------------------


@pytest.mark.parametrize("shape, w, a", [("sine", 5.3, 5.0), ("cosine", 2.0, 3.0),
                                         ("sine", 1.0, 1.5)])
def test_mirror_symmetry(body_fig3, shape, w, a):
    """A -> -A mirrors theta and u (exactly: every formula is odd in them) and the outcome."""
    r1 = run_point(Point(body_fig3, 0.2, shape, w, a), NUM)
    r2 = run_point(Point(body_fig3, 0.2, shape, w, -a), NUM)
    assert r1.outcome == r2.outcome and r1.impacts == r2.impacts
    np.testing.assert_allclose(r2.history["theta"], -r1.history["theta"], atol=1e-9)
    np.testing.assert_allclose(r2.history["u"], -r1.history["u"], atol=1e-9)


# ------------------------------------------------------------------------------------
# The paper's claims on its own numbers
# ------------------------------------------------------------------------------------


def test_e_grows_with_lam(body_fig2):
    """Fig. 2(a), eq. (5): e is monotonically increasing in lam, for any u."""
    lam = np.linspace(0, 2, 201)
    for u_over in np.linspace(-2, 2, 17):
        for upper in (True, False):
            e = restitution(body_fig2, lam, u_over * body_fig2.u_cr, upper)
            assert np.all(np.diff(e) > 0)


def test_e_above_one_at_lam1_u_minus2(body_fig2):
    """Section 3.2: e > 1 e.g. at lam = 1, u/u_cr = -2 (Table 2 body, upper sign)."""
    assert float(restitution(body_fig2, 1.0, -2 * body_fig2.u_cr, True)) > 1.0


def test_e_far_below_housner(body_fig2):
    """Section 3.2: e at lam = 0, u = 0 is much smaller than Housner's."""
    e = float(restitution(body_fig2, 0.0, 0.0, True))
    housner = float(restitution_rigid(body_fig2, 0.0))
    assert 0 < e < 0.5 * housner
    assert housner == pytest.approx(1 - 2 * body_fig2.M * body_fig2.b**2 / body_fig2.I_O)


def test_fig5_lam_04_overturns_and_dissipates_less(body_fig3):
    """Figure 5: less energy dissipated for larger lam; lam = 0.4 overturns, 0 and 0.2 not."""
    runs = {lam: run_point(Point(body_fig3, lam, "sine", 5.3, 5.0), NUM) for lam in (0, 0.2, 0.4)}
    assert runs[0.4].outcome == "mode1"
    assert runs[0].outcome == "safe" and runs[0.2].outcome == "safe"

    def dissipated_at(run, t):
        h = run.history
        i = np.searchsorted(h["t"], t)
        return (h["D_damp"][i] + h["E_impact"][i]) / body_fig3.E_ref

    for t in (3.0, 6.0, 9.0):
        d = [dissipated_at(runs[lam], t) for lam in (0, 0.2, 0.4)]
        assert d[0] >= d[1] >= d[2], (t, d)
