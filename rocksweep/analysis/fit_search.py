"""The least misfit of a calibration (``rocksweep.analysis.calibrate``; the misfit:
``analysis.misfit``) and its interval: ``fit`` (a continuation over the half cycles, and
the plain fit on all of them), ``profile_end`` and ``smooth_profile`` (the profile
likelihood's interval), ``minimise`` and ``minimise_local`` (a grid, then Brent's
method or Nelder-Mead).

The interval
------------
Profile likelihood: a parameter's 95% interval holds the values whose misfit, minimised
over the other fitted parameters, exceeds the least misfit by at most chi2_1(0.95) s^2,
with s^2 = max(S_min / (N - k), sigma^2) the variance of one peak's error (the residual
scatter, never below the measured noise). The misfit of a run with many impacts is rough
on small scales, so the interval is widened to where a parabola fitted to the profile
across it rises by the same amount plus twice the profile's scatter about the parabola
(the union of both is kept). Less noise gives a smaller s^2 and a narrower
interval; an interval that reaches a bound is stated (``lo_at_bound``/``hi_at_bound``).
"""

from __future__ import annotations

import math

import numpy as np

from rocksweep.analysis.misfit import Problem, golden

GRID = 21  # first look of a one-parameter fit: GRID values across the bounds
GRID_2D = 9  # ... and GRID_2D^2 for two parameters
STAGES = (3, 6, 12, 24, 48, 96, 192)  # half cycles compared at each stage of ``fit``
PROFILE_POINTS = 15  # values of the profile misfit a parabola is fitted to (``smooth_profile``)


def minimise(problem: Problem, free: list[int], fixed: dict[int, float],
              start: np.ndarray) -> tuple[np.ndarray, float]:
    """Least misfit over the parameters ``free`` with the others at ``fixed``: a grid
    (GRID values for one, GRID_2D^2 for two) then Brent's method / Nelder-Mead from its
    best point."""
    def full(z: np.ndarray) -> np.ndarray:
        x = start.copy()
        for i, v in fixed.items():
            x[i] = v
        x[free] = z
        return x

    b = problem.bounds[free]
    if len(free) == 0:
        x = full(np.zeros(0))
        return x, problem.misfit(x)
    if len(free) == 1:
        g = np.linspace(b[0, 0], b[0, 1], GRID)
        s = np.array([problem.misfit(full(np.array([v]))) for v in g])
        k = int(np.argmin(s))
        lo, hi = g[max(k - 1, 0)], g[min(k + 1, GRID - 1)]
        r = golden(lambda v: problem.misfit(full(np.array([v]))), (lo, hi),
                    1e-5 * (b[0, 1] - b[0, 0]))
        best = (r.x, r.fun) if r.fun <= s[k] else (g[k], s[k])
        return full(np.array([best[0]])), float(best[1])
    if len(free) == 2:
        g0 = np.linspace(b[0, 0], b[0, 1], GRID_2D)
        g1 = np.linspace(b[1, 0], b[1, 1], GRID_2D)
        s = np.array([[problem.misfit(full(np.array([u, v]))) for v in g1] for u in g0])
        i, j = np.unravel_index(int(np.argmin(s)), s.shape)
        z0 = np.array([g0[i], g1[j]])
    else:
        z0 = start[free]
    span = b[:, 1] - b[:, 0]
    simplex = np.vstack([z0, *(z0 + np.diag(0.1 * span)[k] * (1 if z0[k] + 0.1 * span[k]
                                                                <= b[k, 1] else -1)
                               for k in range(len(free)))])
    from scipy.optimize import minimize  # lazy: scipy (+0.3 s)

    r = minimize(lambda z: problem.misfit(full(z)), z0, method="Nelder-Mead",
                 options={"initial_simplex": simplex, "xatol": 1e-5 * span.min(),
                          "fatol": 1e-12, "maxfev": 400})
    if not r.success and problem.n_use is None:
        problem.stopped("fit")
    return full(r.x), float(r.fun)


def fit(problem: Problem) -> tuple[np.ndarray, float]:
    """The least misfit over every fitted key, by continuation over the half cycles.

    An error in e grows with every impact, so the misfit of a long history has a narrow
    basin (e within ~1% after 30 impacts) on a plateau (a history that died out early
    costs the same whatever its e): a grid can miss it. The fit therefore starts on the
    first STAGES[0] half cycles (a wide basin: a grid over the bounds, then Brent or
    Nelder-Mead), and doubles them stage by stage up to all, each stage refining the last
    estimate on a local grid of half the previous spacing. The plain fit on all half cycles
    (a grid over the bounds, then Brent or Nelder-Mead) is done too; the lower misfit
    wins."""
    n_all = problem.peaks.value.size
    stages = [n for n in STAGES if n < n_all] + [n_all]
    k = len(problem.keys)
    b = problem.bounds
    span = b[:, 1] - b[:, 0]
    problem.n_use = stages[0]
    x, s = minimise(problem, list(range(k)), {}, b.mean(axis=1))
    step = span / ((GRID if k == 1 else GRID_2D) - 1)
    for n in stages[1:]:
        problem.n_use = n
        if k == 1:
            g = np.unique(np.clip(x[0] + np.linspace(-2, 2, 9) * step[0], b[0, 0], b[0, 1]))
            ss = np.array([problem.misfit(np.array([v])) for v in g])
            j = int(np.argmin(ss))
            lo, hi = g[max(j - 1, 0)], g[min(j + 1, g.size - 1)]
            x, s = np.array([g[j]]), float(ss[j])
            if hi > lo:
                r = golden(lambda v: problem.misfit(np.array([v])), (lo, hi), 1e-5 * span[0])
                if r.fun <= s:
                    x, s = np.array([float(r.x)]), float(r.fun)
        else:
            simplex = np.vstack([x, *(np.clip(x + np.diag(step)[i], b[:, 0], b[:, 1])
                                      for i in range(k))])
            from scipy.optimize import minimize  # lazy: scipy (+0.3 s)

            r = minimize(problem.misfit, x, method="Nelder-Mead",
                         options={"initial_simplex": simplex, "xatol": 1e-5 * span.min(),
                                  "fatol": 1e-12, "maxfev": 200})
            if r.fun <= problem.misfit(x):
                x = np.asarray(r.x, float)
            s = problem.misfit(x)
        step = step / 2
    problem.n_use = None
    s = problem.misfit(x)
    # the first half cycles may say little about the keys (a pulse's first excursions
    # before any impact): the plain grid on every half cycle is tried too, the better kept
    x2, s2 = minimise(problem, list(range(k)), {}, b.mean(axis=1))
    return (x2, s2) if s2 < s else (x, s)


def profile_end(problem: Problem, i: int, x_hat: np.ndarray, s_min: float, limit: float,
                 side: int) -> tuple[float, bool]:
    """Where the profile misfit of parameter i reaches s_min + limit on one side (side -1
    below the estimate, +1 above): (value, at_bound)."""
    others = [k for k in range(len(x_hat)) if k != i]
    lo, hi = problem.bounds[i]
    edge = lo if side < 0 else hi

    def prof(v: float) -> float:
        if not others:
            x = x_hat.copy()
            x[i] = v
            return problem.misfit(x)
        _, s = minimise_local(problem, others, {i: v}, x_hat)
        return s

    span = hi - lo
    step = 0.005 * span
    inside = float(x_hat[i])
    while True:
        v = inside + side * step
        if (side < 0 and v <= edge) or (side > 0 and v >= edge):
            if prof(edge) - s_min <= limit:
                return float(edge), True
            v = edge
            out = v
            break
        if prof(v) - s_min > limit:
            out = v
            break
        inside, step = v, step * 1.6
    for _ in range(12 if not others else 7):  # bisection: inside (within), out (beyond)
        mid = 0.5 * (inside + out)
        if prof(mid) - s_min > limit:
            out = mid
        else:
            inside = mid
    return float(0.5 * (inside + out)), False


def smooth_profile(problem: Problem, i: int, x_hat: np.ndarray, lo: float, hi: float,
                    limit: float, lo_b: bool, hi_b: bool) -> tuple[float, float, bool, bool]:
    """The interval widened to where a parabola fitted to the profile misfit across it
    (PROFILE_POINTS values over twice its width) rises by ``limit``: the misfit of a run
    with many impacts is rough on small scales (an excursion near the threshold, an event
    more or less in a chattering sequence), and a bump next to the minimum must not cut
    the interval short. The union of both intervals is kept."""
    others = [k for k in range(len(x_hat)) if k != i]
    b_lo, b_hi = problem.bounds[i]
    c = float(x_hat[i])
    a, b = max(b_lo, c - 2 * (c - lo)), min(b_hi, c + 2 * (hi - c))
    if not b > a:
        return lo, hi, lo_b, hi_b
    xs = np.linspace(a, b, PROFILE_POINTS if not others else 9)
    ss = []
    for v in xs:
        if others:
            ss.append(minimise_local(problem, others, {i: v}, x_hat)[1])
        else:
            x = x_hat.copy()
            x[i] = v
            ss.append(problem.misfit(x))
    ss = np.array(ss)
    ok = np.isfinite(ss)
    if ok.sum() < 5:
        return lo, hi, lo_b, hi_b
    c2, c1, c0 = np.polyfit(xs[ok], ss[ok], 2)
    if c2 <= 0:
        return lo, hi, lo_b, hi_b
    x0 = -c1 / (2 * c2)
    # the roughness (the profile's scatter about the parabola) is added to the rise: a
    # difference of two misfits is uncertain by about that much
    rough = float(np.std(ss[ok] - np.polyval([c2, c1, c0], xs[ok])))
    d = math.sqrt((limit + 2 * rough) / c2)
    if x0 - d < lo:
        lo, lo_b = max(b_lo, x0 - d), x0 - d <= b_lo
    if x0 + d > hi:
        hi, hi_b = min(b_hi, x0 + d), x0 + d >= b_hi
    return float(lo), float(hi), bool(lo_b), bool(hi_b)


def minimise_local(problem: Problem, free: list[int], fixed: dict[int, float],
                    start: np.ndarray) -> tuple[np.ndarray, float]:
    """Least misfit over ``free`` near ``start`` (no grid): Brent in a bracket of 10% of
    the bounds for one parameter, Nelder-Mead for more."""
    x = start.copy()
    for k, v in fixed.items():
        x[k] = v
    b = problem.bounds[free]
    span = b[:, 1] - b[:, 0]
    if len(free) == 1:
        k = free[0]

        def f(v: float) -> float:
            y = x.copy()
            y[k] = v
            return problem.misfit(y)
        # a small bracket first (the basin of a long history is narrow), widened while
        # the minimum sits at its edge
        half = 0.01 * span[0]
        best = (float(start[k]), f(float(start[k])))
        for _ in range(5):
            lo, hi = max(b[0, 0], best[0] - half), min(b[0, 1], best[0] + half)
            r = golden(f, (lo, hi), 1e-5 * span[0])
            if r.fun < best[1]:
                best = (float(r.x), float(r.fun))
            at_edge = min(best[0] - lo, hi - best[0]) < 0.05 * half
            if not at_edge or (lo <= b[0, 0] and hi >= b[0, 1]):
                break
            half *= 4
        if at_edge and not (lo <= b[0, 0] and hi >= b[0, 1]):
            problem.stopped("profile")  # the minimum still at its widened bracket's edge
        y = x.copy()
        y[k] = best[0]
        return y, best[1]

    def g(z: np.ndarray) -> float:
        y = x.copy()
        y[free] = z
        return problem.misfit(y)
    from scipy.optimize import minimize  # lazy: scipy (+0.3 s)

    r = minimize(g, x[free], method="Nelder-Mead",
                 options={"xatol": 1e-4 * span.min(), "fatol": 1e-12, "maxfev": 200})
    if not r.success:
        problem.stopped("profile")
    y = x.copy()
    y[free] = r.x
    return y, float(r.fun)
