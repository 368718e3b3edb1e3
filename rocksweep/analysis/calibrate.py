"""Calibration: the scene numbers (lam, e, e_factor, zeta...) that reproduce a measured
rocking history, with a confidence interval.

The misfit: peak amplitudes per half cycle, aligned
-----------------------------------------------------
A rocking history is a sequence of excursions (half cycles) between impacts. What the
impact law sets is how much of an excursion's amplitude survives the impact that ends it;
when an impact happens is a consequence of the amplitudes. Least squares on theta(t) is
dominated by phase: after a few impacts a tiny error in e shifts the simulated impacts by
half a cycle, and theta(t) then differs by twice the amplitude for any parameter value,
so its misfit flattens out and grows local minima. The peaks do not drift: the misfit here
is on the sequence of excursion peaks.

1. The excursions of a history (measured, or simulated and sampled at the measured times
   by Hermite interpolation of theta and theta'): the samples between two changes of
   sign, a sign counting once |theta| exceeds a threshold h (noise near zero, or the
   base resting in full contact between two uplifts on one corner, starts none). Each
   has two features: its signed peak, the vertex of a least-squares parabola through the
   samples above PEAK_TOP of its largest (the largest noisy sample alone is biased up;
   the same rule on both sides, so the parabola's own shape error cancels), and its area
   beyond the threshold, int max(|theta| - h, 0) dt, divided by the median duration of
   the measured excursions (a level: many samples average the noise, and a sample near
   the threshold or next to a gap weighs ~0, so the area is continuous in the
   parameters). h = max(H_NOISE x sigma, H_REL x max |theta|), sigma the measured noise
   (``measured.noise_level``): the small rebounds of a chattering body, near the noise,
   do not count. An excursion whose peak reaches pi/2 within H_NOISE sigma is a fall
   (the body lies on its side): its area is set to 0, so it is compared by its peak
   alone (the plateau's area measures how long the record goes on after the fall).
2. The two sequences are aligned by a sequence alignment (dynamic programming, as an edit
   distance): a pair of excursions of one sign costs the squared differences of their
   features, (f(a) - f(b))^2 + (g_a - g_b)^2 with f(a) = max(|a| - h, 0) and g the area
   level; an excursion left unpaired costs f^2 + g^2. An excursion just above the
   threshold in one history and just below it in the other then costs ~0 and cannot shift
   the pairing of the later, larger ones (which order matching would do).
3. The misfit is the least cost over alignments, S (units (theta/alpha)^2); ``misfit`` in
   the result is sqrt(S / N), N the number of measured excursions.

The starts are aligned: the measured history may begin with a quiet part of any length
(before a release, or before the pulse lifts the body); the simulated history is shifted
so that both depart from their first value by the threshold at the same time, refined by
least squares on theta over the first half cycles (before any phase drift).

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

Verdicts
--------
``reason``: "ok", or the words below joined by "," (with a ``CalibrationWarning`` giving
the numbers): "misfit" when the peaks' RMS error over the degrees of freedom, sqrt(S_min /
(N - k)), exceeds MISFIT_RATIO times the noise (``noise``: the measurement's, estimated
from the history or given, and at least NOISE_FLOOR of the largest |theta/alpha|, the
agreement a right model reaches on a noise-free measurement): the model cannot reproduce
the measurement at any value inside the bounds, and the interval is not an uncertainty of
a right model; "unidentifiable" when a key's interval spans its bounds (the profile is
flat: the history does not say the key, or the key does not change it); "at_bound" when
an estimate sits on a search bound (within AT_BOUND of the span: the minimum may lie
beyond; not at the key's own limit, as lam = 0, where nothing lies beyond).
"not_converged" when a minimisation stopped without meeting its test (Nelder-Mead at its
evaluation cap on the full history; a profile's inner minimisation at its cap, or with its
minimum still at the edge of its widened bracket: the profile misfit is then too high and
the interval may be too narrow), or when any run of the fit or the profiles found a
misfit below the estimate's by more than LOWER_SHARE of the interval's rise (the estimate
is not the least misfit). Golden-section searches stop only at their tolerance.
A fitted key that cannot change the scene's runs (lam under law constant) is refused
before any run.

Speed: each misfit evaluation is one run of the single-run history kernel (no plot, no
Dataset): the scene's point is made once and each candidate rewrites its own row.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from rocksweep.analysis.peaks import Peaks, alignment_cost, excursions, hermite, onset
from rocksweep.compute.dispatch import run_variant
from rocksweep.errors import BodyError, CalibrationError, set_key
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel import warm_up
from rocksweep.numerics import Numerics, step_budget
from rocksweep.physics.bodies import u_cr
from rocksweep.physics.measured import Measured, noise_level, read_measured
from rocksweep.physics.points import kernel_kind, point_row
from rocksweep.schema import KEYS, fmt
from rocksweep.vocab.axes import INITIAL, axis_name
from rocksweep.vocab.kinds import CALIBRATION, KIND_ATTR
from rocksweep.vocab.laws import CONSTANT, LAWS

ACCURACY = "fine"  # the least accuracy of a calibration's runs (``calibration_numerics``)
H_NOISE = 4.0  # threshold of an excursion, in noise standard deviations ...
H_REL = 0.02  # ... and at least this share of the largest |theta|
GRID = 21  # first look of a one-parameter fit: GRID values across the bounds
GRID_2D = 9  # ... and GRID_2D^2 for two parameters
STAGES = (3, 6, 12, 24, 48, 96, 192)  # half cycles compared at each stage of ``_fit``
PROFILE_POINTS = 15  # values of the profile misfit a parabola is fitted to (``_smooth_profile``)
# practical default bounds of a fitted key (inside the key's admissible range)
DEFAULT_BOUNDS = {"impact.lam": (0.0, 2.0), "impact.e": (0.02, 1.0),
                  "impact.e_factor": (0.2, 2.0), "body.zeta": (0.0, 0.5)}
# keys of a scene's point a fit may set although the scene does not give them
OPTIONAL_NAMES = ("e_factor", *INITIAL)
# Longest measured history fitted [p t]: a free-rocking block comes to rest within ~100.
MAX_SPAN = 1e4
# Largest |theta| [rad] of a measurement: pi/2 (the body on its side) and 5% for noise.
THETA_LIMIT = 1.05 * math.pi / 2
#: "misfit": the peaks' RMS error over the degrees of freedom above this many noises. Good
#: fits of independent histories (scipy's block at 0-1% noise, a flexible body at 0.2-1%)
#: give 0.14-1.04; a block under the vertical law fitted to e = 0.6 (no lam gives it) 210
MISFIT_RATIO = 3.0
#: the least noise a misfit is compared with, as a share of the largest |theta/alpha|
NOISE_FLOOR = 0.002
#: "at_bound": an estimate within this share of its bounds' span from one of them
AT_BOUND = 1e-3
#: "not_converged": a run whose misfit is below the estimate's by more than this share of
#: the interval's rise chi2_1(ci) s^2 (less is the misfit's roughness at the scale of the
#: search's tolerance, and moves no interval end)
LOWER_SHARE = 0.01
VERDICTS = ("ok", "misfit", "unidentifiable", "at_bound", "not_converged")


class CalibrationWarning(UserWarning):
    """A fit that should not be trusted as it is (its ``reason`` is not "ok"); ``str()``
    is one line with the numbers."""


def calibration_numerics(n: Numerics) -> Numerics:
    """The numerics of a calibration's runs: the scene's, but at least ACCURACY's steps and
    event tolerance (a fitted value must not carry the step's error: at `default`, 5 steps
    per period, a freely rocking block's e came out 0.004 high, outside its interval);
    the scene's horizon, rest rate and event cap are kept."""
    fine = Numerics.preset(ACCURACY)
    if n.steps_per_period >= fine.steps_per_period and n.event_tol <= fine.event_tol:
        return n
    return replace(fine, horizon=n.horizon, rest_rate=n.rest_rate, max_events=n.max_events)


class _Result:
    """What a one-dimensional minimisation found (``x``, ``fun``), as scipy's result."""

    def __init__(self, x: float, fun: float) -> None:
        self.x, self.fun = x, fun


def _golden(f: Any, bounds: tuple[float, float], xatol: float) -> _Result:
    """Minimum of f on [lo, hi] by golden-section search to xatol (a unimodal bracket;
    scipy.optimize's import costs ~0.2-1 s of every command, this a few lines)."""
    lo, hi = bounds
    r = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = lo + (1 - r) * (hi - lo), lo + r * (hi - lo)
    fa, fb = f(a), f(b)
    while hi - lo > xatol:
        if fa <= fb:
            hi, b, fb = b, a, fa
            a = lo + (1 - r) * (hi - lo)
            fa = f(a)
        else:
            lo, a, fa = a, b, fb
            b = lo + r * (hi - lo)
            fb = f(b)
    return _Result(a, fa) if fa <= fb else _Result(b, fb)


def _fallen(peaks: Peaks, top: float) -> Peaks:
    """The excursions with the area of those whose |peak| reaches ``top`` (pi/2 within the
    noise, theta/alpha_ref: the body overturned) set to 0: after the fall the body lies on
    its side, and that plateau's area measures how long the record goes on after it, not
    the rocking; the fall is compared by its peak."""
    fell = np.abs(peaks.value) >= top
    if not fell.any() or peaks.area is None:
        return peaks
    return Peaks(peaks.value, peaks.time, np.where(fell, 0.0, peaks.area))


class Problem:
    """A scene's one point, a measured history and the keys to fit: the misfit of any
    candidate values (``misfit``) and the histories behind it (``evaluate``)."""

    def __init__(self, scene: Any, measured: Measured, fit: Sequence[str],
                 bounds: Mapping[str, Sequence[float]] | None = None,
                 noise: float | None = None) -> None:
        self.scene = scene
        self.m = measured
        self.keys = tuple(fit)
        self.names = [check_fit_key(scene, k) for k in self.keys]
        self.bounds = np.array([check_bounds(k, (bounds or {}).get(k)) for k in self.keys])
        self.values = _single_values(scene, self.names)
        self.numerics = calibration_numerics(scene.single_numerics)
        base = scene.point(self.values)
        self.alpha = base.body.alpha_ref
        # the measurement's noise [theta/alpha_ref]: given, or estimated from the history
        self.noise_given = noise is not None
        self.sigma = float(noise) if noise is not None else noise_level(measured.t,
                                                                          measured.theta)
        amp = float(np.max(np.abs(measured.theta)))
        self.h = max(H_NOISE * self.sigma, H_REL * amp)
        self.t_onset = onset(measured.t, measured.theta, self.h)
        if not math.isfinite(self.t_onset):
            raise CalibrationError(f"{measured.source}: theta_over_alpha never departs from "
                                   f"its first value by more than {self.h:.3g} (4 x the "
                                   "noise): no motion to fit")
        self.quiet = self.t_onset - float(measured.t[0])
        # a peak at pi/2 within the noise: the body lies on its side (``_fallen``)
        self.top = math.pi / 2 / self.alpha - H_NOISE * self.sigma
        self.peaks = _fallen(excursions(measured.t, measured.theta, self.h), self.top)
        if self.peaks.value.size < 2:
            raise CalibrationError(
                f"{measured.source}: {self.peaks.value.size} half cycle(s) beyond the noise "
                f"(|theta_over_alpha| > {self.h:.3g}); a fit of the impact law needs the "
                "measurement to go on past at least one impact")
        # the time scale that makes an excursion's area a level: the median duration of the
        # measured excursions (area / duration ~ its mean |theta|)
        with np.errstate(invalid="ignore", divide="ignore"):
            dur = self.peaks.area / np.maximum(np.abs(self.peaks.value) - self.h, 1e-300)
        self.t_scale = float(np.median(dur[dur > 0])) if np.any(dur > 0) else 1.0
        # the start window of the shift (``_shift``): from the first sample to the second
        # half-cycle peak; the shift is searched within a tenth of that window
        t_end = self.peaks.time[1] if self.peaks.time.size > 1 else measured.t[-1]
        self.window = np.flatnonzero(measured.t <= t_end)
        self.dt_shift = 0.1 * max(float(t_end - self.t_onset), 1e-3)
        self.runs = 0
        self.n_use: int | None = None  # compare the first n_use half cycles (None: all)
        # the least misfit of every candidate on all half cycles, and where (``_verdict``:
        # a profile that finds less than the estimate's says the fit did not converge)
        self.least: tuple[float, np.ndarray | None] = (math.inf, None)
        #: minimisations that stopped without meeting their test: {where: how many}
        self.unconverged: dict[str, int] = {}
        self._cache: dict[tuple, tuple | None] = {}

    def point(self, x: np.ndarray) -> Any:
        values = dict(self.values)
        for name, v in zip(self.names, x, strict=True):
            values[name] = float(v)
        return self.scene.point(values)

    def run_candidate(self, x: np.ndarray) -> tuple[np.ndarray, dict] | None:
        """(result row, raw history columns) of a candidate; None if the candidate's body
        is not physical."""
        try:
            point = self.point(x)
        except (BodyError, ValueError):
            return None
        row = point_row(point, self.numerics)
        row[L.PAR_TO_REST] = 1.0  # the whole measured span, past a rigid body's bound
        need = float(self.m.t[-1] - self.t_onset) + row[L.PAR_TPULSE] + 10.0
        if row[L.PAR_TEND] < need:
            row[L.PAR_TEND] = need
            row[L.PAR_MAXSTEPS] = step_budget(row[L.PAR_TPULSE], need, row[L.PAR_DT],
                                              row[L.PAR_DT_ON], self.numerics)
        # the one dispatch of every run: close calls certified as ``rocksweep.simulate``'s
        # (the finest run's history kept)
        hists: list = [None]
        out = run_variant(row[None, :], kernel_kind(point.body), L.LEVEL_OUTCOME,
                          point.ground, self.numerics.refine, histories=hists)[0]
        hist = hists[0]
        self.runs += 1
        n = int(out[L.OUT_HIST_ROWS])
        a = point.body.alpha_ref
        return out, {"t": hist[:n, L.HIST_T], "theta": hist[:n, L.HIST_THETA] / a,
                     "theta_dot": hist[:n, L.HIST_THETA_DOT] / a,
                     "phase": hist[:n, L.HIST_PHASE]}

    def evaluate(self, x: np.ndarray) -> dict | None:
        """Everything about a candidate: misfit S, the simulated theta at the measured
        times, the time shift, its peaks and impact times (measured time)."""
        key = tuple(float(v) for v in x)
        if key in self._cache:  # one run per candidate, whatever half cycles are compared
            got = self._cache[key]
        else:
            got = self._run(x)
            if len(self._cache) < 5000:
                self._cache[key] = got
        if got is None:
            return None
        theta, shift, peaks, impacts, out = got
        mine, sim = self.peaks, peaks
        n = self.n_use
        if n is not None and n < mine.value.size:  # the first n half cycles (``fit``)
            cut = 0.5 * (mine.time[n - 1] + mine.time[n])
            keep = sim.time <= cut
            mine = Peaks(mine.value[:n], mine.time[:n], mine.area[:n])
            sim = Peaks(sim.value[keep], sim.time[keep], sim.area[keep])
        cost, pairs = alignment_cost(mine.value, sim.value, self.h, area_a=mine.area,
                                     area_b=sim.area, t_scale=self.t_scale)
        return {"S": cost, "theta": theta, "shift": shift, "peaks": peaks, "pairs": pairs,
                "impacts": impacts, "out": out}

    def _run(self, x: np.ndarray) -> tuple | None:
        """A candidate's simulated history at the measured times, its shift, excursions,
        impacts (measured time) and result row; None for a body that is not physical."""
        got = self.run_candidate(x)
        if got is None:
            return None
        out, h = got
        shift = self._shift(h)
        theta = hermite(h["t"], h["theta"], h["theta_dot"], self.m.t - shift)
        peaks = _fallen(excursions(self.m.t, theta, self.h), self.top)
        t, ph = h["t"], h["phase"]
        ev = np.flatnonzero((t[1:] == t[:-1]) & (ph[:-1] != 0) & (ph[1:] != ph[:-1]))
        impacts = t[ev] + shift
        return theta, shift, peaks, impacts[impacts <= self.m.t[-1]], out

    def _shift(self, h: dict) -> float:
        """The time shift that aligns a simulated history's start with the measured one:
        first the shift that makes both depart from their first value by the threshold at
        the same time (the simulation sampled as the measurement), then the least-squares
        shift of theta over the measured start window (up to the second half-cycle peak,
        before any phase drift; a slow start, as a release from a tilt, departs too
        gently for the threshold alone)."""
        t_rel = self.m.t - self.m.t[0]
        th = hermite(h["t"], h["theta"], h["theta_dot"], t_rel)
        t_sim = onset(t_rel, th, self.h)
        if not math.isfinite(t_sim):
            return self.t_onset
        shift0 = self.t_onset - t_sim
        w = self.window
        tt, yy = self.m.t[w], self.m.theta[w]

        def ss(sh: float) -> float:
            return float(np.sum((hermite(h["t"], h["theta"], h["theta_dot"], tt - sh) - yy)
                                ** 2))
        r = _golden(ss, (shift0 - self.dt_shift, shift0 + self.dt_shift), 1e-6)
        return float(r.x) if r.fun <= ss(shift0) else shift0

    def misfit(self, x: np.ndarray) -> float:
        x = np.asarray(x, float)
        if np.any(x < self.bounds[:, 0]) or np.any(x > self.bounds[:, 1]):
            return math.inf
        got = self.evaluate(x)
        s = math.inf if got is None or not math.isfinite(got["S"]) else got["S"]
        if self.n_use is None and s < self.least[0]:
            self.least = (s, x.copy())
        return s

    def stopped(self, where: str) -> None:
        """Count a minimisation that stopped without meeting its test."""
        self.unconverged[where] = self.unconverged.get(where, 0) + 1


# ---------------------------------------------------------------------------------------
# Checks
# ---------------------------------------------------------------------------------------

def fittable(scene: Any) -> list[str]:
    """The keys of a scene that a fit may set: its numeric axes (body, impact, pulse,
    ground, initial) and the optional impact.e_factor and initial state."""
    out = [a.key for a in scene.axes if KEYS.get(a.key) is not None
           and KEYS[a.key].kind == "axis" and a.key != "body.mu"]
    out += [f"impact.{n}" if n == "e_factor" else f"initial.{n}" for n in OPTIONAL_NAMES]
    values = {a.name: a.values[0] for a in scene.axes}
    try:
        rigid = scene.make_body(**{a.name: values[a.name] for a in scene.body_axes()}).rigid
    except (BodyError, ValueError):
        rigid = False
    return list(dict.fromkeys(
        k for k in out if not (scene.free and k.startswith("pulse."))
        # a rigid body has no top mass: its displacement and rate mean nothing
        and not (rigid and k in ("initial.u_over_ucr", "initial.udot_over_pucr"))))


def check_fit_key(scene: Any, key: Any) -> str:
    """The axis name a fit key sets, or a one-line CalibrationError."""
    if not isinstance(key, str):
        raise CalibrationError(f"fit key {key!r}: must be a dotted scene key such as "
                               "impact.lam")
    if key == "impact.e" and "e" not in {a.name for a in scene.axes}:
        raise CalibrationError("fit impact.e: only law constant uses e; give impact: "
                               "{law: constant, e: ...} in the scene (or fit impact.e_factor)")
    laws = {str(v) for a in scene.axes if a.name == "law" for v in a.values}
    if key == "impact.lam" and laws and laws <= {CONSTANT}:
        others = " or ".join(law for law in LAWS if law != CONSTANT)
        raise CalibrationError(f"fit impact.lam: law {CONSTANT} does not use lam (its e is "
                               "impact.e), so no lam changes a run; fit impact.e or "
                               f"impact.e_factor, or use law {others}")
    allowed = fittable(scene)
    if key not in allowed:
        raise CalibrationError(f"fit {key}: not a number of this scene (fit one of "
                               f"{', '.join(allowed)})")
    return axis_name(key)


def check_bounds(key: str, given: Any) -> tuple[float, float]:
    """(lo, hi) of a fit key: given, or DEFAULT_BOUNDS / the key's admissible range;
    a one-line CalibrationError outside the admissible range."""
    spec = KEYS[key]
    lo_ok = spec.lo + (0.0 if spec.lo_in else 1e-9 * max(1.0, abs(spec.lo)))
    hi_ok = spec.hi - (0.0 if spec.hi_in else 1e-9 * max(1.0, abs(spec.hi)))
    if given is None:
        lo, hi = DEFAULT_BOUNDS.get(key, (max(lo_ok, -10.0), min(hi_ok, 10.0)))
        return float(lo), float(hi)
    try:
        lo, hi = (float(v) for v in given)
    except (TypeError, ValueError):
        raise CalibrationError(f"bounds {key} = {fmt(given)}: give two numbers (lo, hi)"
                               ) from None
    allowed = spec.allowed.removeprefix("must be ")
    for v in (lo, hi):
        if not math.isfinite(v) or (v < spec.lo or (v == spec.lo and not spec.lo_in)
                                    or v > spec.hi or (v == spec.hi and not spec.hi_in)):
            raise CalibrationError(f"bounds {key} = ({fmt(lo)}, {fmt(hi)}): {fmt(v)} is "
                                   f"outside the key's admissible range ({allowed})")
    if not lo < hi:
        raise CalibrationError(f"bounds {key} = ({fmt(lo)}, {fmt(hi)}): lo must be below hi")
    return lo, hi


def _single_values(scene: Any, fitted: Sequence[str]) -> dict[str, Any]:
    """The scene's one value of every axis; a swept axis that is not fitted is refused."""
    for a in scene.axes:
        if len(a.values) != 1 and a.name not in fitted:
            raise CalibrationError(f"{a.key} has {len(a.values)} values: a calibration "
                                   "fits one point; pick one with {fix}",
                                   fix=set_key(a.key, "set_fix"))
    return {a.name: a.values[0] for a in scene.axes}


# ---------------------------------------------------------------------------------------
# The fit
# ---------------------------------------------------------------------------------------

def _minimise(problem: Problem, free: list[int], fixed: dict[int, float],
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
        r = _golden(lambda v: problem.misfit(full(np.array([v]))), (lo, hi),
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
    from scipy.optimize import minimize

    r = minimize(lambda z: problem.misfit(full(z)), z0, method="Nelder-Mead",
                 options={"initial_simplex": simplex, "xatol": 1e-5 * span.min(),
                          "fatol": 1e-12, "maxfev": 400})
    if not r.success and problem.n_use is None:
        problem.stopped("fit")
    return full(r.x), float(r.fun)


def _fit(problem: Problem) -> tuple[np.ndarray, float]:
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
    x, s = _minimise(problem, list(range(k)), {}, b.mean(axis=1))
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
                r = _golden(lambda v: problem.misfit(np.array([v])), (lo, hi), 1e-5 * span[0])
                if r.fun <= s:
                    x, s = np.array([float(r.x)]), float(r.fun)
        else:
            simplex = np.vstack([x, *(np.clip(x + np.diag(step)[i], b[:, 0], b[:, 1])
                                      for i in range(k))])
            from scipy.optimize import minimize

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
    x2, s2 = _minimise(problem, list(range(k)), {}, b.mean(axis=1))
    return (x2, s2) if s2 < s else (x, s)


def _profile_end(problem: Problem, i: int, x_hat: np.ndarray, s_min: float, limit: float,
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
        _, s = _minimise_local(problem, others, {i: v}, x_hat)
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


def _smooth_profile(problem: Problem, i: int, x_hat: np.ndarray, lo: float, hi: float,
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
            ss.append(_minimise_local(problem, others, {i: v}, x_hat)[1])
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


def _minimise_local(problem: Problem, free: list[int], fixed: dict[int, float],
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
            r = _golden(f, (lo, hi), 1e-5 * span[0])
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
    from scipy.optimize import minimize

    r = minimize(g, x[free], method="Nelder-Mead",
                 options={"xatol": 1e-4 * span.min(), "fatol": 1e-12, "maxfev": 200})
    if not r.success:
        problem.stopped("profile")
    y = x.copy()
    y[free] = r.x
    return y, float(r.fun)


def calibrate_problem(problem: Problem, ci: float = 0.95) -> Any:
    """Fit a ``Problem``: the Dataset of ``rocksweep.calibrate`` (see ``calibrate``)."""
    from statistics import NormalDist

    import xarray as xr

    t0 = time.perf_counter()
    k = len(problem.keys)
    kind = kernel_kind(problem.point(problem.bounds.mean(axis=1)).body)
    warm_up(kind, None, problem.scene.ground)
    x_hat, s_min = _fit(problem)
    if not math.isfinite(s_min):
        raise CalibrationError("no candidate inside the bounds gives a physical body; "
                               "check the bounds")
    best = problem.evaluate(x_hat)
    n = problem.peaks.value.size
    s2 = max(s_min / max(n - k, 1), problem.sigma**2)
    # chi2 quantile of 1 degree of freedom: the square of the normal's two-sided quantile
    # (statistics, not scipy.stats: its import costs ~0.5 s of every command)
    limit = NormalDist().inv_cdf(0.5 + 0.5 * ci) ** 2 * s2
    lo, hi, lo_b, hi_b = (np.empty(k), np.empty(k), np.zeros(k, bool), np.zeros(k, bool))
    for i in range(k):
        lo[i], lo_b[i] = _profile_end(problem, i, x_hat, s_min, limit, -1)
        hi[i], hi_b[i] = _profile_end(problem, i, x_hat, s_min, limit, +1)
        lo[i], hi[i], lo_b[i], hi_b[i] = _smooth_profile(problem, i, x_hat, lo[i], hi[i],
                                                         limit, lo_b[i], hi_b[i])
    reason, why, noise, dof = _verdict(problem, x_hat, s_min, lo, hi, lo_b, hi_b, limit)
    wall = time.perf_counter() - t0
    m = problem.m
    pairs = best["pairs"]
    fitted_peak = np.full(n, np.nan)
    for i, j in pairs:
        fitted_peak[i] = best["peaks"].value[j]
    notes = list(m.notes)
    if best["shift"] > 2 * float(np.median(np.diff(m.t))):
        notes.append(f"a leading quiet part: the motion starts {best['shift']:.4g} p*t later "
                     "than in the simulation (aligned by shifting the simulation)")
    ds = xr.Dataset(
        {"estimate": ("parameter", x_hat), "lo": ("parameter", lo), "hi": ("parameter", hi),
         "lo_at_bound": ("parameter", lo_b), "hi_at_bound": ("parameter", hi_b),
         "bound_lo": ("parameter", problem.bounds[:, 0]),
         "bound_hi": ("parameter", problem.bounds[:, 1]),
         "misfit": ((), math.sqrt(s_min / n)),
         "noise": ((), noise, {"long_name": "the measurement's noise the misfit is compared "
                                            "with (estimated from the history, or given; at "
                                            "least NOISE_FLOOR x max |theta/alpha|)",
                               "units": "theta/alpha_ref"}),
         "dof": ((), np.int64(dof), {"long_name": "degrees of freedom: measured half "
                                                  "cycles less fitted keys"}),
         "reason": ((), reason, {"long_name": "verdict: ok, or the reasons joined by ',' ("
                                              + ", ".join(VERDICTS[1:]) + ")"}),
         "measured_theta": ("p_t", m.theta,
                            {"long_name": "measured theta / alpha_ref"}),
         "fitted_theta": ("p_t", best["theta"],
                          {"long_name": "simulated theta / alpha_ref at the estimate"}),
         "impact_time": ("impact", best["impacts"],
                         {"long_name": "impacts of the fitted simulation [p*t, measured "
                                       "time]"}),
         "peak_time": ("peak", problem.peaks.time),
         "measured_peak": ("peak", problem.peaks.value),
         "fitted_peak": ("peak", fitted_peak)},
        coords={"parameter": ("parameter", list(problem.keys)), "p_t": ("p_t", m.t)})
    ds["misfit"].attrs = {"long_name": "RMS error of the half-cycle peaks at the estimate",
                          "units": "theta/alpha_ref"}
    ds.attrs = {
        KIND_ATTR: CALIBRATION,
        "title": f"calibration of {', '.join(problem.keys)}",
        "ci": ci,
        "interval": "profile likelihood: misfit <= min + chi2_1(ci) s^2, s^2 = max(S_min/"
                    "(N - k), sigma^2)",
        "misfit_definition": "sqrt(S/N): S the least cost of aligning the measured and "
                             "simulated half-cycle peaks (rocksweep.analysis.calibrate)",
        "noise_sigma": problem.sigma, "threshold": problem.h, "n_peaks": n,
        "time_shift": best["shift"], "runs": problem.runs, "wall_time_s": wall,
        "measured": m.source, "notes": "; ".join(notes) if notes else "",
        "scene": problem.scene.text, "accuracy": problem.numerics.describe(),
        "outcome": int(best["out"][L.OUT_OUTCOME]),
        "noise_given": int(problem.noise_given),
    }
    if reason != "ok":
        import warnings

        warnings.warn(CalibrationWarning(
            f"calibration of {', '.join(problem.keys)}: " + "; ".join(
                f"{w} ({why[w]})" for w in reason.split(","))), stacklevel=2)
    return ds


def _verdict(problem: Problem, x_hat: np.ndarray, s_min: float, lo: np.ndarray,
             hi: np.ndarray, lo_b: np.ndarray, hi_b: np.ndarray, limit: float
             ) -> tuple[str, dict[str, str], float, int]:
    """(reason, {word: the numbers}, noise, dof) of a fit (module docstring, Verdicts);
    limit: the interval's rise of the misfit."""
    n, k = problem.peaks.value.size, len(problem.keys)
    dof = n - k
    amp = float(np.max(np.abs(problem.m.theta)))
    noise = max(problem.sigma, NOISE_FLOOR * amp)
    why: dict[str, str] = {}
    rms = math.sqrt(s_min / max(dof, 1))
    if rms > MISFIT_RATIO * noise:
        whose = "given" if problem.noise_given else "estimated"
        why["misfit"] = (f"the peaks' RMS error {rms:.3g} on {dof} dof is {rms / noise:.3g} "
                         f"times the {whose} noise {noise:.3g}: the model does not reproduce "
                         "the measurement inside the bounds")
    span = problem.bounds[:, 1] - problem.bounds[:, 0]
    flat, edge = [], []
    for i, key in enumerate(problem.keys):
        if lo_b[i] and hi_b[i]:
            ends = [problem.misfit(np.where(np.arange(k) == i, b, x_hat))
                    for b in problem.bounds[i]]
            same = all(math.isclose(e, s_min, rel_tol=1e-9, abs_tol=1e-300) for e in ends)
            flat.append(f"{key} in [{lo[i]:.4g}, {hi[i]:.4g}] spans its bounds" +
                        (": it does not change the simulated history" if same else ""))
        x = float(x_hat[i])
        b_lo, b_hi = problem.bounds[i]
        near = b_lo if x - b_lo < b_hi - x else b_hi
        # a bound that is the key's own limit (lam = 0, e = 1) has nothing beyond it
        limit = near in (KEYS[key].lo, KEYS[key].hi)
        if min(x - b_lo, b_hi - x) <= AT_BOUND * span[i] and not limit:
            edge.append(f"{key} = {x:.4g} on the bound {near:g}; the least misfit may lie "
                        "beyond")
    if flat:
        why["unidentifiable"] = "; ".join(flat)
    if edge:
        why["at_bound"] = "; ".join(edge)
    stops = []
    least, where = problem.least
    if where is not None and least < s_min - LOWER_SHARE * limit:
        at = ", ".join(f"{k} = {v:.4g}" for k, v in zip(problem.keys, where, strict=True))
        stops.append(f"a run at {at} has misfit S {least:.4g} below the estimate's "
                     f"{s_min:.4g}: the fit missed the least misfit")
    for place, count in problem.unconverged.items():
        cap = "its evaluation cap" if place == "fit" else "a cap or its bracket's edge"
        stops.append(f"{count} {place} minimisation{'s' * (count > 1)} stopped at {cap}")
    if stops:
        why["not_converged"] = "; ".join(stops)
    return (",".join(why) or "ok"), why, noise, dof



def calibrate_scene(scene: Any, measured: Any, fit: str | Sequence[str],
                    bounds: Mapping[str, Sequence[float]] | None = None, ci: float = 0.95,
                    p: float | None = None, overrides: Any = (),
                    noise: float | None = None) -> Any:
    """``rocksweep.calibrate`` (its arguments documented there): ``fit`` (a key or a
    non-empty list of distinct keys) and ``ci`` (in [0.5, 1)) checked first, then the scene
    loaded (``scene.inputs.load``: a Scene, a path, YAML text or a dict, with
    ``overrides``), the measured history read (``physics.measured.read_measured``, in the
    scene's body's alpha_ref and u_cr; p [rad/s] given, else the scene's ``_body_p``) and
    the keys fitted (``calibrate_problem``)."""
    from rocksweep.scene.inputs import load

    keys = [fit] if isinstance(fit, str) else list(fit)
    if not keys:
        raise CalibrationError("fit = []: give at least one key, e.g. impact.lam")
    if len(set(keys)) < len(keys):
        raise CalibrationError(f"fit = {keys}: a key is given twice")
    if isinstance(ci, bool) or not (isinstance(ci, float | int) and 0.5 <= ci < 1):
        raise CalibrationError(f"ci = {ci!r}: must be in [0.5, 1)")
    ci = float(ci)
    if bounds is not None:
        if not isinstance(bounds, Mapping):
            raise TypeError(f"bounds = {bounds!r}: must be a mapping {{key: (lo, hi)}}, e.g. "
                            "{'impact.lam': (0, 1)}")
        for k in bounds:
            if k not in keys:
                raise CalibrationError(f"bounds {k!r}: not a fitted key (fitted: "
                                       f"{', '.join(map(str, keys))}); give bounds of the "
                                       "fitted keys only")
    if p is not None:
        if isinstance(p, bool) or not isinstance(p, int | float | np.integer | np.floating):
            raise TypeError(f"p = {p!r}: must be a number (the body's p [rad/s]) or None")
        if not (math.isfinite(p) and p > 0):
            raise CalibrationError(f"p = {p!r}: must be a finite number > 0 [rad/s]")
    if noise is not None:
        if isinstance(noise, bool) or not isinstance(noise, int | float | np.integer
                                                     | np.floating):
            raise TypeError(f"noise = {noise!r}: must be a number (theta/alpha_ref) or None")
        if not (math.isfinite(noise) and noise >= 0):
            raise CalibrationError(f"noise = {noise!r}: must be a finite number >= 0 (the "
                                   "measurement noise's standard deviation, theta/alpha_ref)")
    scene, _ = load(scene, overrides)
    p_body = _body_p(scene) if p is None else float(p)
    values = {a.name: a.values[0] for a in scene.axes}
    body = scene.point(values).body
    m = read_measured(measured, p=p_body, alpha_ref=body.alpha_ref, u_cr=u_cr(body) or None)
    if p is not None and not m.physical:
        raise CalibrationError(f"p = {p!r}: {m.source} has the dimensionless columns p_t, "
                               "theta_over_alpha; p reads physical columns t [s], theta "
                               "[rad] only (leave it out)")
    _check_measured_span(m, body.alpha_ref)
    return calibrate_problem(Problem(scene, m, keys, bounds, noise), ci)


def _check_measured_span(m: Measured, alpha_ref: float) -> None:
    """Refuse a measured history no rocking body of this scene can have (one line): |theta|
    reaching pi/2 (the body would lie on its side: the wrong column, unit or body), or a
    span longer than MAX_SPAN (each candidate is simulated over all of it)."""
    amax = float(np.max(np.abs(m.theta)))
    if amax * alpha_ref > THETA_LIMIT:
        raise CalibrationError(f"{m.source}: |theta_over_alpha| reaches {amax:.4g}, |theta| "
                               f"= {amax * alpha_ref:.4g} rad for this body (alpha "
                               f"{alpha_ref:.4g} rad); a rocking body's |theta| stays below "
                               "pi/2, where it lies on its side (is it the wrong column, unit "
                               "or body?)")
    span = m.duration
    if span > MAX_SPAN:
        raise CalibrationError(f"{m.source}: the history spans {span:.4g} p*t; at most "
                               f"{MAX_SPAN:g} (each candidate is simulated over all of it: "
                               "cut the history to the rocking)")


def _body_p(scene: Any) -> float | None:
    """The body's p [rad/s] a scene knows (a physical body's, a record scene's ground.p),
    else None."""
    if scene.physical is not None:
        return scene.physical["p"]
    names = {a.name: a for a in scene.axes}
    if "p" in names and len(names["p"].values) == 1:
        return float(names["p"].values[0])
    return None

def calibrated_overrides(fit: Any, which: str = "all") -> dict[str, Any]:
    """Overrides that sweep a scene at a calibration's values: ``which`` "estimate", "lo"
    or "hi" gives one value per key; "all" the list [lo, estimate, hi] (distinct values,
    ascending), so that ``rocksweep.run(scene, overrides=calibrated_overrides(fit))`` draws
    the diagram at the estimate and at both ends of the interval (a swept dimension per
    key)."""
    if which not in ("all", "estimate", "lo", "hi"):
        raise CalibrationError(f"which = {which!r}: must be all, estimate, lo or hi")
    out: dict[str, Any] = {}
    for key in fit["parameter"].values.tolist():
        sel = fit.sel(parameter=key)
        if which != "all":
            out[key] = float(sel[which])
            continue
        vals = sorted({float(sel["lo"]), float(sel["estimate"]), float(sel["hi"])})
        out[key] = vals if len(vals) > 1 else vals[0]
    return out
