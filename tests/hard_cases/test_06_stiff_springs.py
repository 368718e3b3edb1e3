"""Hard case 6: stiff springs (wn/p = 50, 200) integrate stably and approach the welded body."""

import math

import numpy as np
import pytest
from hardkit import BASE, assert_sane, kernel_events, reference_events, run
from hardkit import table3_body as body
from scipy.integrate import solve_ivp

from rocksweep.kernel.layout import PAR_DT
from rocksweep.numerics import spring_steps
from rocksweep.physics.bodies import G
from rocksweep.physics.points import Point, body_omega_rock, point_row

pytestmark = pytest.mark.hard

STIFF = (50.0, 200.0)
PULSES = [("sine", 3.0, 2.0), ("cosine", 4.0, 2.0)]
FREE_PULSES = [("cosine", 4.0, 2.0), ("sine", 4.0, 1.5)]  # safe: long free rocking after


@pytest.fixture(scope="module")
def runs():
    """{(pulse, wn/p): run} for the Table 3 geometry with stiff springs and welded (inf)."""
    out = {}
    for pulse in {*PULSES, *FREE_PULSES}:
        for wn in (*STIFF, math.inf):
            out[pulse, wn] = run(Point(body(wn_over_p=wn), 0.2, *pulse))
    return out


def _welded_flight(b, apex: float) -> float:
    """Flight time [p*t] of the welded body's free rocking that peaks at |theta| = apex.

    Independent of the kernel: I_O theta'' = -M g R_cg sin(alpha_cg - theta) on the +b
    corner (the potential M g R_cg (cos(alpha_cg - theta) - cos alpha_cg)), integrated by
    DOP853 from the apex down to theta = 0; the flight is twice that (time reversal).
    """
    def f(t, y):
        return (y[1], -b.M * G * b.R_cg * math.sin(b.alpha_cg - y[0]) / b.I_O)

    def land(t, y):
        return y[0]

    land.terminal = True
    sol = solve_ivp(f, (0.0, 50.0), (apex, 0.0), method="DOP853", events=land, rtol=1e-12,
                    atol=1e-14)
    return 2.0 * float(sol.t_events[0][0])


@pytest.mark.parametrize("wn", STIFF)
@pytest.mark.parametrize("pulse", PULSES)
def test_stiff_spring_integrates_stably(runs, pulse, wn):
    """Guards against a step that ignores the spring (RK4 blows up or loses the energy balance)."""
    r = runs[pulse, wn]
    b = r.point.body
    # the step follows the spring while the base rocks (omega_rock ~ 2.7 omega_n, a bit
    # more with the top mass above the corner): at least 20 steps per its period (more for
    # a stiffer spring: ``numerics.spring_steps`` bounds RK4's damping of it), well inside
    # RK4's stability limit (|i w dt| < 2.83)
    dt = point_row(r.point, BASE)[PAR_DT]
    fastest = body_omega_rock(b)
    assert fastest >= b.omega_rock > 2.5 * b.omega_n
    zeta_rock = b.zeta * fastest / b.omega_n  # zeta sqrt(Gamma) (underdamped: < 1)
    n = float(spring_steps(fastest, BASE.steps_per_period, zeta_rock))
    assert n >= BASE.steps_per_period
    assert dt == pytest.approx(2 * math.pi / (fastest * n))
    assert dt * fastest < 2.0
    assert_sane(r)
    # no energy appears from nowhere in the stiff spring: it holds at most what the pulse
    # put in plus what gravity can release (the cg falling by at most R_cg)
    h = r.history
    assert (0.5 * b.k * h["u"] ** 2).max() <= h["W_in"].max() + b.M * G * b.R_cg


@pytest.mark.parametrize("pulse", PULSES)
def test_rocking_before_the_first_impact_approaches_the_welded_body(runs, pulse):
    """Guards against a stiff body whose rocking does not tend to the welded (rigid) body's."""
    welded = runs[pulse, math.inf]
    t_imp = next(e.t for e in kernel_events(welded) if e.kind == "impact")
    h0 = welded.history
    m = h0["t"] < t_imp
    err = {}
    for wn in STIFF:
        h = runs[pulse, wn].history
        err[wn] = np.abs(np.interp(h0["t"][m], h["t"], h["theta"]) - h0["theta"][m]).max()
        t_imp_wn = next(e.t for e in kernel_events(runs[pulse, wn]) if e.kind == "impact")
        assert t_imp_wn == pytest.approx(t_imp, abs=0.02 * 50 / wn)
    alpha = welded.point.body.alpha_cg
    assert err[200.0] < 5e-3 * alpha
    assert err[200.0] < err[50.0] / 3  # converging (~1/wn^2 for the sine, ~1/wn for the
    #                                    cosine, whose spring needs ~1/wn to lift the body)


@pytest.mark.parametrize("pulse", FREE_PULSES)
def test_free_rocking_between_impacts_approaches_the_welded_body(runs, pulse):
    """Guards against stiff-spring flights between impacts that do not tend to rigid rocking."""
    worst = {}
    for wn in STIFF:
        r = runs[pulse, wn]
        h = r.history
        ev = kernel_events(r)
        errs = []
        for e0, e1 in zip(ev[:-1], ev[1:], strict=True):
            if not (e0.kind == e1.kind == "impact" and e0.t > r.point.t_pulse and e0.s_after):
                continue
            m = (h["t"] > e0.t) & (h["t"] < e1.t)
            apex = np.abs(h["theta"][m]).max()
            if apex < 0.05 * r.point.body.alpha_cg:
                break  # the chattering tail: flights too small to time against the apex
            errs.append(abs((e1.t - e0.t) / _welded_flight(r.point.body, apex) - 1))
        assert len(errs) >= 4
        worst[wn] = max(errs)
    # the impact throws the top mass into a fast vibration (it keeps its velocity); the
    # mean rocking between impacts is the welded body's, to O(1/wn^2)
    assert worst[50.0] < 5e-3
    assert worst[200.0] < 4e-4
    assert worst[200.0] < worst[50.0] / 8


def test_step_follows_the_overdamped_fast_mode_of_a_tall_body_on_a_light_base():
    """Guards against an RK4 blow-up on the fast real root of the rocking phase (a bug, fixed)."""
    # The base's rotation multiplies the spring AND the damper seen by the top mass by
    # Gamma = 1 + m h^2 / (I_A + m_A R_A^2 + m a^2): here ~700, so zeta = 0.19 becomes ~5,
    # an overdamped mode with a root near -2 zeta' omega' ~ -250. A step set by the
    # frequency omega' alone (20 per period: dt = 0.016) puts it at lambda dt ~ -4, outside
    # RK4's stability interval (-2.79, 0): u' jumped to -6 within 0.05 p*t of the uplift and
    # the body "overturned after an impact" that never happens (found by test_12).
    b = body(wn_over_p=1.0, zeta=0.1875, alpha_cg=0.0625, alpha_A=1.0, mA_over_m=1.0,
             IA_ratio=0.0)
    gamma = 1 + b.m * b.h**2 / (b.I_A + b.m_A * b.R_A**2)
    zeta_r = b.zeta * math.sqrt(gamma)
    assert zeta_r > 4
    root = b.omega_n * math.sqrt(gamma) * (zeta_r + math.sqrt(zeta_r**2 - 1))
    dt = point_row(Point(b, 0.0, "sine", 1.0, 1.0), BASE)[PAR_DT]
    assert root * dt < 2.785 / 4  # well inside the stability interval
    p = Point(b, 0.0, "sine", 1.0, 1.0)
    r = run(p)
    assert_sane(r)
    res = reference_events(p)[0]
    assert r.outcome == "mode2" == {0: "safe", 1: "mode1", 2: "mode2"}[res["outcome"]]
    assert r.t_overturn == pytest.approx(res["t_overturn"], rel=1e-6)
