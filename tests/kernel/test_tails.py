"""The tails of the accuracy: the worst cases of a wide-space sample
(scripts/wide_space.py), each against the scipy reference or a closed form, at the preset
that should get them right.

- a huge cosine pulse (A_ratio = -19.6, w/p = 0.33) on an undamped body: without a limit on
  the rotation per step it was decided in 2-6 RK4 steps;
- a rigid body falling from the top: its fall time and energy balance against the
  quadrature of the energy integral;
- e > 1 (lam = 1.3): energy-gaining impacts with fast excursions between them, overturning
  after 19 impacts at the reference;
- zeta = 0 chattering cut short by the rest-rate rule: never reported as "rest".
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from bodies import table3
from scipy.integrate import quad

from rocksweep.compute.single import run_point
from rocksweep.kernel import chunk_kernel
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import FlexibleBody
from rocksweep.physics.points import Point, point_row
from rocksweep.physics.reference import reference_run

# The huge slow cosine pulse of the wide-space sample on undamped bodies (wn/p = 1.56, zeta = 0): an
# overturning without impact (mode 2) and one after an impact (mode 1).
HUGE_COSINE = {
    "mode2": Point(FlexibleBody(1.56, 0.0, 0.45, 0.54, 0.05, 0.56), 0.4, "cosine", 0.33, -19.6),
    "mode1": Point(FlexibleBody(1.56, 0.0, 0.45, 1.3, 1.0, 0.56), 0.4, "cosine", 0.33, -19.6),
}


@pytest.mark.parametrize("case", sorted(HUGE_COSINE))
def test_huge_slow_pulse_is_not_crossed_in_a_handful_of_steps(case):
    """Overturning time within 0.05 p*t of the reference at `accurate` (0.02 for the mode 1
    run: 0.024 off at 8 steps per period without the rotation limit, 0.012 with it, 0.004
    at the preset's 10), and at `default` at least
    the steps the rule implies for the last fall alone, pi/2 / (0.25 alpha_cg) = 14 (the
    mode 2 run took 4 without the limit)."""
    p = HUGE_COSINE[case]
    ref = reference_run(p, Numerics())
    assert ref["outcome"] == (L.OUTCOME_MODE2 if case == "mode2" else L.OUTCOME_MODE1)
    acc = run_point(p, Numerics.preset("accurate"), history=False)
    assert acc.outcome == case
    assert abs(acc.t_overturn - ref["t_overturn"]) <= (0.05 if case == "mode2" else 0.02)
    # the body turns through pi/2 = 3.5 alpha_cg: at most 0.25 alpha_cg per step
    d = run_point(p, Numerics.preset("default"), history=False)
    assert d.get("steps") >= math.pi / 2 / (0.25 * p.body.alpha_ref) - 1
    assert abs(d.t_overturn - ref["t_overturn"]) <= 0.15


def _rigid_fall(alpha_cg: float, numerics: Numerics) -> tuple[np.ndarray, FlexibleBody, float]:
    """A rigid body started at theta = 0 with theta' 10% above what carries it over the top
    (no pulse: A_ratio = 0). Returns (energy kernel's result row, body, theta'_0)."""
    body = FlexibleBody(**table3(wn_over_p=math.inf, alpha_cg=alpha_cg,
                                 alpha_A=min(1.3, 2 * alpha_cg)))
    w0 = 1.1 * math.sqrt(2 * (1 - math.cos(body.alpha_ref)))  # p = 1
    row = point_row(Point(body, 0.0, "sine", 12.0, 0.0), numerics)
    row[L.PAR_THETA_DOT0] = w0
    out = np.empty((1, L.N_OUT))
    chunk_kernel(L.KIND_RIGID, L.LEVEL_ENERGY)(row[None, :], out)
    return out[0], body, w0


@pytest.mark.parametrize("alpha_cg", [0.05, 0.15, 0.4])
def test_rigid_fall_time_and_energy_balance(alpha_cg):
    """Guards against a fall to overturning crossed in 7-10 RK4 steps (the rigid step has no
    spring limit): with I_O theta'' = M g R_cg sin(theta - alpha), p = 1,
    theta'^2 = theta'_0^2 + 2 (cos alpha - cos(theta - alpha)) from theta = 0, so the fall
    time is the integral of 1/theta' up to pi/2 and the energy at the end is the start's,
    1/2 I_O theta'_0^2 (nothing acts on the body)."""
    # `default` steps the free fall at 2 pi/5 p*t or 0.25 alpha_cg of turning, whichever is
    # shorter (its zero-amplitude pulse, 0.52 p*t long, no longer sets the step after it
    # ends): 5.1e-4 p*t and 1.2e-4 E_ref off; `accurate` 1.8e-5 and 1.4e-6
    for preset, t_tol, e_tol in (("default", 1e-3, 2.5e-4), ("accurate", 1e-4, 2e-5)):
        out, body, w0 = _rigid_fall(alpha_cg, Numerics.preset(preset))
        a = body.alpha_ref
        t_exact, _ = quad(
            lambda th, w0=w0, a=a: 1.0 / math.sqrt(w0**2 + 2 * (math.cos(a) - math.cos(th - a))),
            0.0, math.pi / 2, epsabs=1e-12, epsrel=1e-12, limit=200)
        assert out[L.OUT_OUTCOME] == L.OUTCOME_MODE2
        assert abs(out[L.OUT_T_OVERTURN] - t_exact) < t_tol
        e0 = 0.5 * body.I_O * w0**2
        assert abs(out[L.OUT_E_END] - e0) / body.E_ref < e_tol
        assert out[L.OUT_W_IN] == 0.0


def test_energy_gaining_impacts_resolved_at_accurate():
    """e > 1 (lam = 1.3, undamped, stiff spring): each impact multiplies theta' by up to
    2.9, the excursions between impacts get short and fast; the overturning after 19
    impacts at the reference (t = 3.59) is found within 0.05 p*t at `accurate` (0.009 off;
    0.025 at 8 steps per period; at 8 without the rotation limit the run overturned at 1.51
    after 11 impacts)."""
    body = FlexibleBody(10.3, 0.0, 0.126, 1.11, 3.43, 0.628)
    p = Point(body, 1.3, "sine", 8.14, -2.894)
    ref = reference_run(p, Numerics())
    assert ref["status"] & L.STATUS_E_ABOVE_1 and ref["outcome"] == L.OUTCOME_MODE1
    r = run_point(p, Numerics.preset("accurate"), history=False)
    assert "e_above_1" in r.status and r.outcome == "mode1"
    assert r.impacts == ref["impacts"]
    assert abs(r.t_overturn - ref["t_overturn"]) <= 0.05


def test_chattering_cut_short_by_the_rest_rate_is_not_rest():
    """zeta = 0, stiff spring: the rest-rate rule ends chattering sequences ("settled"),
    and the run is never called "rest" (a proof) on the rule-made state. The reference, with
    the same rule, is still chattering at the horizon on its own trajectory (hundreds more
    impacts), and so is every preset: `default` (and `draft`) ended "settled" at p*t ~ 56
    (43) while RK4 damped this undamped spring (omega_rock/p = 117) at ~2 p, before the
    spring's steps bounded that damping (``numerics.spring_decay``). The runs account
    energy (a history's kernel), which goes on past the energy's bound (the outcome-only
    kernel ends these runs there, 'bounded': ``flexible_bounded``)."""
    body = FlexibleBody(22.5, 0.0, 0.195, 0.644, 0.359, 0.582)
    p = Point(body, 0.334, "cosine", 4.78, 15.9)
    for name in ("draft", "default", "accurate", "fine"):
        r = run_point(p, Numerics.preset(name))
        assert r.status == ["horizon", "settled"] and r.outcome == "safe", (name, r.status)
        assert r.impacts > 1000, name  # chattering on to the horizon, as the reference does


def test_rest_still_proven_without_the_rule():
    """The other side: a flexible body whose pulse never lifts it (A below the uplift
    threshold) ends "rest" at the pulse's end, with no "settled"."""
    body = FlexibleBody(22.5, 0.0, 0.195, 0.644, 0.359, 0.582)
    r = run_point(Point(body, 0.334, "sine", 4.78, 0.3), Numerics.preset("default"),
                  history=False)
    assert r.status == ["rest"] and r.get("uplifts") == 0
