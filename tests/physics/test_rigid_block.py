"""The rigid kernel against the classic rocking block (Housner 1963 and after).

The block is checked against results derived here, independently of the kernel's code:

- Housner's restitution for a uniform block, e = 1 - 1.5 sin^2(alpha) (angular momentum
  about the future corner, I_O = 4/3 M R^2), and its lam generalisation;
- free rocking from theta_0: the exact (nonlinear) quarter period from energy conservation
  by quadrature, and its small-alpha limit (1/p) arccosh(1/(1 - theta_0/alpha));
- uplift where |xg''| first reaches g tan(alpha);
- the forced block against scipy's DOP853 on the classic equation of motion
  theta'' = -p^2 [sin(s alpha - theta) + (xg''/g) cos(s alpha - theta)] with Housner's
  impact map, written here from the literature, not from ``rocksweep.kernel.equations``.

Times are p*t (p = 1 rad/s for every body rocksweep builds).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from bodies import table3
from scipy.integrate import quad, solve_ivp

from rocksweep.kernel import chunk_kernel, point_kernel
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, FlexibleBody, G, restitution_rigid
from rocksweep.physics.points import Point, kernel_kind, point_row

ALPHA = 0.2618  # the classic slender block (15 degrees)
# Fine steps so that the integration error is far below the differences checked.
PRECISE = Numerics.preset("fine", steps_per_period=400, event_tol=1e-12)


def _row(point: Point, numerics: Numerics, theta0: float = 0.0) -> np.ndarray:
    row = point_row(point, numerics)
    row[L.PAR_THETA0] = theta0
    return row


def run_outcome(point: Point, numerics: Numerics, theta0: float = 0.0) -> np.ndarray:
    """Result row float64[N_OUT] of the outcome-only kernel."""
    out = np.empty((1, L.N_OUT))
    chunk_kernel(kernel_kind(point.body), L.LEVEL_OUTCOME)(_row(point, numerics, theta0)[None],
                                                          out)
    return out[0]


def run_history(point: Point, numerics: Numerics, theta0: float = 0.0):
    """(result row, history float64[n, N_HIST]) of the single-run kernel."""
    row = _row(point, numerics, theta0)
    out = np.empty(L.N_OUT)
    hist = np.empty((200_000, L.N_HIST))
    point_kernel(kernel_kind(point.body))(row, out, hist)
    return out, hist[: int(out[L.OUT_HIST_ROWS])]


def impact_rows(hist: np.ndarray) -> list[tuple[int, int]]:
    """(before, after) row pairs of the impacts in a history (same t, theta 0 after)."""
    t, th, ph = hist[:, L.HIST_T], hist[:, L.HIST_THETA], hist[:, L.HIST_PHASE]
    return [(k - 1, k) for k in range(1, len(t))
            if t[k] == t[k - 1] and ph[k - 1] != 0 and ph[k] != ph[k - 1] and th[k] == 0.0
            and th[k - 1] != 0.0]


# ---------------------------------------------------------------------------------------
# Restitution
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("alpha", [0.1, ALPHA, 0.5])
def test_housner_restitution_of_the_block(alpha):
    """e = 1 - 1.5 sin^2(alpha): model, and the kernel's impact (theta'+ / theta'-)."""
    housner = 1 - 1.5 * math.sin(alpha) ** 2
    body = BlockBody(alpha=alpha)
    assert float(restitution_rigid(body, 0.0)) == pytest.approx(housner, rel=1e-14)
    # free rocking from theta_0 = alpha/2: the first impact multiplies theta' by e
    out, hist = run_history(Point(body, 0.0, "sine", 1.0, 0.0), PRECISE, theta0=0.5 * alpha)
    (before, after), *_ = impact_rows(hist)
    e_kernel = hist[after, L.HIST_THETA_DOT] / hist[before, L.HIST_THETA_DOT]
    assert e_kernel == pytest.approx(housner, rel=1e-13)
    assert hist[after, L.HIST_PHASE] == -hist[before, L.HIST_PHASE]


@pytest.mark.parametrize("lam", [0.0, 0.5, 1.0])
def test_block_restitution_with_lam(lam):
    """Impulse at lam*b from the future corner (Chatzis et al.): for a uniform block
    e = (4/3 - (2 - lam) sin^2 a) / (4/3 - lam sin^2 a); e = 1 at lam = 1."""
    s2 = math.sin(ALPHA) ** 2
    expected = (4 / 3 - (2 - lam) * s2) / (4 / 3 - lam * s2)
    body = BlockBody(alpha=ALPHA)
    out, hist = run_history(Point(body, lam, "sine", 1.0, 0.0), PRECISE, theta0=0.3 * ALPHA)
    (before, after), *_ = impact_rows(hist)
    e_kernel = hist[after, L.HIST_THETA_DOT] / hist[before, L.HIST_THETA_DOT]
    assert e_kernel == pytest.approx(expected, rel=1e-13)
    assert out[L.OUT_E_MAX] == pytest.approx(expected, rel=1e-13)


# ---------------------------------------------------------------------------------------
# Free rocking from theta_0
# ---------------------------------------------------------------------------------------


def quarter_period_exact(alpha: float, theta0: float) -> float:
    """Time p*t from theta_0 (at rest) to theta = 0 of the nonlinear free block.

    theta'' = -p^2 sin(alpha - theta) gives 1/2 theta'^2 = cos(alpha - theta_0) -
    cos(alpha - theta) (p = 1); with theta = theta_0 (1 - v^2) the integrand is regular:
    T = int_0^1 2 theta_0 v dv / sqrt(4 sin(alpha - theta_0 + x) sin(x)), x = theta_0 v^2/2.
    """
    def f(v: float) -> float:
        x = 0.5 * theta0 * v * v
        sin_x_over_v = math.sin(x) / (v * v) if v > 0 else 0.5 * theta0
        return 2 * theta0 / math.sqrt(4 * math.sin(alpha - theta0 + x) * sin_x_over_v)

    return quad(f, 0.0, 1.0, epsabs=0.0, epsrel=1e-13, limit=200)[0]


def test_free_rocking_quarter_period():
    """Exact nonlinear quarter period to 1e-8; the arccosh closed form of the linearised
    block is approached as alpha -> 0 at the rate alpha^2 (theta_0/alpha fixed)."""
    ratio = 0.5  # theta_0 / alpha
    linear = math.acosh(1 / (1 - ratio))  # p = 1
    gaps = []
    for alpha in (0.2, 0.05, 0.0125):
        body = BlockBody(alpha=alpha)
        out = run_outcome(Point(body, 0.0, "sine", 1.0, 0.0), PRECISE, theta0=ratio * alpha)
        t_quarter = out[L.OUT_T_FIRST_IMPACT]
        assert t_quarter == pytest.approx(quarter_period_exact(alpha, ratio * alpha), rel=1e-8)
        gaps.append(abs(t_quarter / linear - 1))
    assert gaps[0] > 5e-4  # at alpha = 0.2 the linearisation is visibly off ...
    assert gaps[2] < 1e-5  # ... and at alpha = 0.0125 it is the limit
    for big, small in zip(gaps, gaps[1:], strict=False):
        assert 10 < big / small < 25  # quartering alpha divides the gap by ~16: O(alpha^2)


def test_free_rocking_with_other_inertia():
    """A body with I_O = 2 M R^2 still rocks at p = sqrt(M g R / I_O) = 1 rad/s: the
    quarter period in p*t does not depend on the inertia (only on alpha and theta_0)."""
    alpha, theta0 = 0.3, 0.2
    t = [run_outcome(Point(BlockBody(alpha=alpha, inertia=i), 0.0, "sine", 1.0, 0.0), PRECISE,
                     theta0=theta0)[L.OUT_T_FIRST_IMPACT] for i in (4 / 3, 2.0)]
    expected = quarter_period_exact(alpha, theta0)
    assert t == pytest.approx([expected, expected], rel=1e-8)


# ---------------------------------------------------------------------------------------
# Uplift
# ---------------------------------------------------------------------------------------


def test_no_uplift_below_g_tan_alpha():
    body = BlockBody(alpha=ALPHA)
    for shape, a_ratio in (("sine", 0.98), ("cosine", 0.99), ("sine", -0.99)):
        out = run_outcome(Point(body, 0.0, shape, 2.0, a_ratio), PRECISE)
        assert out[L.OUT_UPLIFTS] == 0
        assert out[L.OUT_THETA_MAX] == 0.0
        assert out[L.OUT_OUTCOME] == L.OUTCOME_SAFE
        assert int(out[L.OUT_STATUS]) & L.STATUS_REST


@pytest.mark.parametrize("a_ratio, corner", [(1.02, -1), (3.0, -1), (-1.5, 1)])
def test_uplift_where_ground_acceleration_reaches_g_tan_alpha(a_ratio, corner):
    """Sine pulse A sin(omega t): uplift at omega t = arcsin(g tan(alpha) / |A|), on the
    corner behind the ground's acceleration (A > 0 pushes the body onto its -b corner)."""
    w = 2.0
    body = BlockBody(alpha=ALPHA)
    out, hist = run_history(Point(body, 0.0, "sine", w, a_ratio), PRECISE)
    first = np.nonzero(hist[:, L.HIST_PHASE] != 0)[0][0]
    assert hist[first, L.HIST_T] == pytest.approx(math.asin(1 / abs(a_ratio)) / w, abs=1e-9)
    assert hist[first, L.HIST_PHASE] == corner
    assert abs(hist[first, L.HIST_XG]) == pytest.approx(G * math.tan(ALPHA), rel=1e-8)


def test_uplift_at_once_under_a_cosine_pulse():
    body = BlockBody(alpha=ALPHA)
    out, hist = run_history(Point(body, 0.0, "cosine", 2.0, 1.02), PRECISE)
    assert hist[0, L.HIST_T] == 0.0 and hist[0, L.HIST_PHASE] == -1
    assert out[L.OUT_UPLIFTS] >= 1


def test_uplift_of_the_welded_flexible_body():
    """wn_over_p = inf: the two-mass body uplifts at |xg''| = g tan(alpha_cg) too."""
    body = FlexibleBody(**table3(wn_over_p=math.inf))
    out, hist = run_history(Point(body, 0.0, "sine", 2.0, 1.5), PRECISE)
    first = np.nonzero(hist[:, L.HIST_PHASE] != 0)[0][0]
    assert hist[first, L.HIST_T] == pytest.approx(math.asin(1 / 1.5) / 2.0, abs=1e-9)


# ---------------------------------------------------------------------------------------
# The forced nonlinear block against scipy
# ---------------------------------------------------------------------------------------


def classic_block(alpha: float, w: float, a_ratio: float, t_end: float,
                  max_impacts: int = 30) -> dict:
    """Sine-pulse response of the uniform block by scipy (DOP853, rtol 1e-12).

    theta'' = -p^2 [sin(s alpha - theta) + (xg''/g) cos(s alpha - theta)], p = 1,
    xg''/g = a_ratio tan(alpha) sin(w t) for t < 2 pi/w; Housner's impact
    theta'+ = (1 - 1.5 sin^2 alpha) theta'-. Uplift at w t = arcsin(1/a_ratio) (a_ratio > 1),
    on s = -1. Stops at t_end, at overturning or after max_impacts impacts (the rocking of
    a block decays through ever faster impacts). Returns impact times, overturning time
    (or None) and max |theta|.
    """
    e = 1 - 1.5 * math.sin(alpha) ** 2
    t_pulse = 2 * math.pi / w
    amp = a_ratio * math.tan(alpha)
    t, y, s = math.asin(1 / a_ratio) / w, [0.0, 0.0], -1
    impacts, t_over, theta_max = [], None, 0.0
    while t < t_end and t_over is None and len(impacts) < max_impacts:
        on = t < t_pulse

        def f(tt, yy, s=s, on=on):
            xg = amp * math.sin(w * tt) if on else 0.0
            return [yy[1], -(math.sin(s * alpha - yy[0]) + xg * math.cos(s * alpha - yy[0]))]

        def impact(tt, yy, s=s):
            return s * yy[0]

        def over(tt, yy, s=s):
            return math.pi / 2 - s * yy[0]

        def turn(tt, yy):
            return yy[1]

        impact.terminal, impact.direction = True, -1
        over.terminal, over.direction = True, -1
        sol = solve_ivp(f, (t, t_pulse if on else t_end), y, method="DOP853", rtol=1e-12,
                        atol=1e-14, events=[impact, over, turn], max_step=0.05)
        for yy in sol.y_events[2]:
            theta_max = max(theta_max, abs(yy[0]))
        if len(sol.t_events[1]):
            t_over = float(sol.t_events[1][0])
        elif len(sol.t_events[0]):
            t = float(sol.t_events[0][0])
            impacts.append(t)
            y, s = [0.0, e * sol.y_events[0][0][1]], -s
        else:
            t, y = float(sol.t[-1]), list(sol.y[:, -1])
    return {"impacts": impacts, "t_over": t_over, "theta_max": theta_max}


@pytest.mark.parametrize("w, a_ratio, outcome", [
    (1.0, 3.0, L.OUTCOME_MODE2),   # overturns without impact
    (3.0, 3.0, L.OUTCOME_MODE1),   # one impact, then overturns
    (4.0, 2.5, L.OUTCOME_MODE1),
    (6.0, 4.0, L.OUTCOME_SAFE),    # rocks on after the pulse, never overturns
])
def test_forced_block_against_scipy(w, a_ratio, outcome):
    body = BlockBody(alpha=ALPHA)
    out = run_outcome(Point(body, 0.0, "sine", w, a_ratio), PRECISE)
    ref = classic_block(ALPHA, w, a_ratio, t_end=40.0)
    assert out[L.OUT_OUTCOME] == outcome
    if ref["t_over"] is None:
        assert outcome == L.OUTCOME_SAFE
        # decided early (below the overturning energy after the pulse); the largest
        # excursion still matches the full scipy run
        assert int(out[L.OUT_STATUS]) & L.STATUS_BOUNDED
        assert out[L.OUT_THETA_MAX] == pytest.approx(ref["theta_max"], rel=1e-7)
    else:
        assert out[L.OUT_T_OVERTURN] == pytest.approx(ref["t_over"], rel=1e-8)
        assert out[L.OUT_IMPACTS] == len(ref["impacts"])
    if ref["impacts"]:
        assert out[L.OUT_T_FIRST_IMPACT] == pytest.approx(ref["impacts"][0], rel=1e-8)
