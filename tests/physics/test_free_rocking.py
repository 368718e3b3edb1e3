"""Initial states and free rocking against results derived here.

- the classic block released from rest at theta_0: the exact quarter period by quadrature of
  energy conservation (theta'' = -p^2 sin(alpha - theta), p = 1), its linearised closed form
  p t = arctanh(sqrt(1 - (1 - theta_0/alpha)^2)) (Housner 1963; = arccosh(alpha/(alpha -
  theta_0))), Housner's restitution e = 1 - 1.5 sin^2 alpha per impact and the peak
  recursion cos(alpha - theta_n+1) - cos alpha = e^2 (cos(alpha - theta_n) - cos alpha);
- a tilt beyond alpha at rest falls without an impact (mode 2), one below it does not;
- the top mass of a flexible body released with u_0 in full contact is a damped
  oscillator m u'' + c u' + k u = 0 (the base stays on the ground below uplift);
- inadmissible initial states are one-line errors.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from bodies import table3
from scipy.integrate import quad

import rocksweep
from rocksweep.errors import RocksweepError
from rocksweep.physics.bodies import FlexibleBody, G

ALPHA = 0.25


def block_scene(theta_over_alpha, alpha=ALPHA, lam=0.0, **numerics):
    scene = {"name": "free block", "body": {"kind": "block", "alpha": alpha},
             "impact": {"lam": lam}, "initial": {"theta_over_alpha": theta_over_alpha}}
    if numerics:
        scene["numerics"] = numerics
    return scene


def quarter_period(alpha: float, theta0: float) -> float:
    """p t from theta_0 at rest to theta = 0: t = int dtheta / sqrt(2 (cos(alpha - theta_0)
    - cos(alpha - theta))), with theta = theta_0 (1 - v^2) to remove the end singularity."""
    def f(v: float) -> float:
        th = theta0 * (1 - v * v)
        d = 2 * (math.cos(alpha - theta0) - math.cos(alpha - th))
        return 2 * theta0 * v / math.sqrt(d) if v > 0 else 2 * theta0 / math.sqrt(
            2 * theta0 * math.sin(alpha - theta0))
    return quad(f, 0.0, 1.0, epsabs=0.0, epsrel=1e-12, limit=200)[0]


def excursions(h) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(peak theta/alpha of each rocking excursion of a rigid block, from the energy of a
    state inside it: cos(alpha - theta_p) = cos(alpha - |theta|) + theta'^2 / 2 (p = 1);
    theta' just before and just after each impact) from a history Dataset; impacts are
    the pairs of rows at one time."""
    t = h.p_t.values
    th = h.theta_over_alpha.values * ALPHA
    thd = h.theta_dot_over_alpha.values * ALPHA
    ph = h.phase.values
    imp = np.flatnonzero((t[1:] == t[:-1]) & (ph[:-1] != 0) & (ph[1:] != ph[:-1]))
    bounds = [0, *(imp + 1).tolist(), len(t)]
    peaks = []
    for a, b in zip(bounds, bounds[1:], strict=False):
        if b - a < 3:
            break
        k = (a + b) // 2
        c = math.cos(ALPHA - abs(th[k])) + 0.5 * thd[k] ** 2
        peaks.append((ALPHA - math.acos(min(c, 1.0))) / ALPHA)
    return np.array(peaks), thd[imp] / ALPHA, thd[imp + 1] / ALPHA


def test_quarter_period_and_housner_restitution_of_a_released_block():
    theta0 = 0.6 * ALPHA
    sim = rocksweep.simulate(block_scene(0.6, accuracy="fine", steps_per_period=200,
                                         event_tol=1e-11))
    assert sim.summary["t_first_impact"] == pytest.approx(quarter_period(ALPHA, theta0),
                                                          rel=1e-8)
    housner = 1 - 1.5 * math.sin(ALPHA) ** 2
    peaks, before, after = excursions(sim.history)
    assert len(before) > 20  # rocks to rest through many impacts
    assert after[:10] / before[:10] == pytest.approx(np.full(10, housner), rel=1e-9)
    # the peaks follow the energy recursion of e^2 per impact
    a = ALPHA
    theta = theta0
    for k in range(1, 6):
        v = housner**2 * (math.cos(a - theta) - math.cos(a))
        theta = a - math.acos(v + math.cos(a))
        assert peaks[k] * a == pytest.approx(theta, rel=1e-7)
    assert sim.summary["outcome"] == "safe"


def test_linearised_quarter_period_for_a_slender_block():
    """alpha -> 0: p t -> arctanh(sqrt(1 - (1 - theta_0/alpha)^2)) (Housner's linear
    solution theta = alpha - (alpha - theta_0) cosh(p t))."""
    r = 0.7
    closed = math.atanh(math.sqrt(1 - (1 - r) ** 2))
    sim = rocksweep.simulate(block_scene(r, alpha=0.005, accuracy="fine",
                                         steps_per_period=200, event_tol=1e-11))
    assert sim.summary["t_first_impact"] == pytest.approx(closed, rel=1e-5)


def test_tilt_beyond_alpha_falls_without_impact_as_a_sweep_axis():
    ds = rocksweep.run(block_scene([0.5, 0.95, 1.05, 1.5]))
    assert ds.outcome.dims == ("theta_over_alpha",)
    assert ds.outcome.values.tolist() == [0, 0, 2, 2]


def test_initial_rate_from_contact_rocks_on_the_rate_s_corner():
    """theta = 0 with theta' = w0 > 0: energy w0^2 / 2 reaches the peak theta_1 with
    cos(alpha - theta_1) = cos(alpha) + w0^2 / 2 on the positive side."""
    w0 = 0.4  # x p alpha
    scene = {"body": {"kind": "block", "alpha": ALPHA},
             "initial": {"thetadot_over_palpha": w0},
             "numerics": {"accuracy": "fine", "steps_per_period": 400}}
    h = rocksweep.simulate(scene).history
    assert h.phase.values[0] == 1 and h.theta_over_alpha.values[1] > 0
    peak = ALPHA - math.acos(math.cos(ALPHA) + (w0 * ALPHA) ** 2 / 2)
    assert excursions(h)[0][0] * ALPHA == pytest.approx(peak, rel=1e-7)
    mirrored = rocksweep.simulate({**scene, "initial": {"thetadot_over_palpha": -w0}})
    assert mirrored.history.phase.values[0] == -1
    assert mirrored.history.theta_over_alpha.values[1] < 0


@pytest.mark.parametrize("factor, side", [(0.98, 0), (1.02, 1), (-1.02, -1)])
def test_top_mass_released_in_full_contact_uplifts_beyond_its_threshold(factor, side):
    """Released at rest in full contact with u_0 (no ground motion): about a corner the
    spring's force k u at height h and the top mass's weight offset by u (P-delta) turn the
    body against the weight's M g b, so it uplifts at t = 0 exactly when |u_0| > u* =
    M g b / (k h + m g) = u_cr / (1 + g/(omega_n^2 h)), on the corner u_0 points to; below,
    the undamped oscillator never exceeds |u_0| and the base never lifts."""
    body = table3(zeta=0.0)
    fb = FlexibleBody(**body)
    u_star = 1 / (1 + G / (fb.omega_n**2 * fb.h))  # x u_cr
    scene = {"body": body, "impact": {"lam": 0.0},
             "initial": {"u_over_ucr": factor * u_star}}
    sim = rocksweep.simulate(scene)
    if side:
        assert sim.summary["uplifts"] >= 1
        assert sim.history.phase.values[1] == side
        assert sim.summary["theta_max_over_alpha"] > 0
    else:
        assert sim.summary["uplifts"] == 0
        assert sim.summary["theta_max_over_alpha"] == 0.0


@pytest.mark.parametrize("initial, words", [
    ({"theta_over_alpha": 7.0}, "initial.theta_over_alpha = 7.0: |theta|"),
    ({"theta_over_alpha": -6.3}, "must be < pi/2"),
    ({"u_over_ucr": 0.5}, "initial.u_over_ucr = 0.5: a rigid body"),
    ({"thetadot_over_palpha": float("inf")}, "initial.thetadot_over_palpha = inf"),
])
def test_inadmissible_initial_states_are_one_line(initial, words):
    scene = {"body": {"kind": "block", "alpha": ALPHA}, "initial": initial}
    with pytest.raises(RocksweepError) as err:
        rocksweep.simulate(scene)
    assert words in str(err.value)
    assert "\n" not in str(err.value)
