"""The misfit of a calibration (``rocksweep.analysis.calibrate``): a scene's one point, a
measured history and the keys to fit (``Problem``), and the misfit of any candidate values.

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
so that both depart from their first value by the threshold at the same time (the
measurement's first value the median of its first samples, its departure held at two
samples in a row: one noise sample cannot start it), refined by least squares on theta
over the first half cycles (before any phase drift): a grid across half that window either
side, then a golden section in its best cell. A slow start (a release from a tilt) departs
by the threshold at a time the noise moves by a good part of a half cycle, so the
onsets alone are no bracket.

Speed: each misfit evaluation is one run of the single-run history kernel (no plot, no
Dataset): the scene's point is made once and each candidate rewrites its own row.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from rocksweep.analysis.fit_keys import check_bounds, check_fit_key, single_values
from rocksweep.analysis.peaks import Peaks, alignment_cost, excursions, hermite, onset
from rocksweep.compute.dispatch import run_variant
from rocksweep.errors import BodyError, CalibrationError
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics, step_budget
from rocksweep.physics.measured import Measured, noise_level
from rocksweep.physics.points import kernel_kind, point_row

ACCURACY = "fine"  # the least accuracy of a calibration's runs (``calibration_numerics``)
H_NOISE = 4.0  # threshold of an excursion, in noise standard deviations ...
H_REL = 0.02  # ... and at least this share of the largest |theta|
SHIFT_GRID = 41  # the start's shift: a grid across its bracket first (``Problem._shift``)


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


def golden(f: Any, bounds: tuple[float, float], xatol: float) -> _Result:
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


def fallen(peaks: Peaks, top: float) -> Peaks:
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
        self.values = single_values(scene, self.names)
        self.numerics = calibration_numerics(scene.single_numerics)
        base = scene.point(self.values)
        self.alpha = base.body.alpha_ref
        # the measurement's noise [theta/alpha_ref]: given, or estimated from the history
        self.noise_given = noise is not None
        self.sigma = float(noise) if noise is not None else noise_level(measured.t,
                                                                          measured.theta)
        amp = float(np.max(np.abs(measured.theta)))
        self.h = max(H_NOISE * self.sigma, H_REL * amp)
        self.t_onset = onset(measured.t, measured.theta, self.h, noisy=True)
        if not math.isfinite(self.t_onset):
            raise CalibrationError(f"{measured.source}: theta_over_alpha never departs from "
                                   f"its first value by more than {self.h:.3g} (4 x the "
                                   "noise): no motion to fit")
        self.quiet = self.t_onset - float(measured.t[0])
        # a peak at pi/2 within the noise: the body lies on its side (``fallen``)
        self.top = math.pi / 2 / self.alpha - H_NOISE * self.sigma
        self.peaks = fallen(excursions(measured.t, measured.theta, self.h), self.top)
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
        # half-cycle peak; the shift is searched within half that window of the onsets'
        # (a slow start, as a release from a tilt, departs by the threshold at a time the
        # noise moves by a good part of the window: 0.43 p*t of 3 for 1% noise)
        t_end = self.peaks.time[1] if self.peaks.time.size > 1 else measured.t[-1]
        self.window = np.flatnonzero(measured.t <= t_end)
        self.dt_shift = 0.5 * max(float(t_end - self.t_onset), 1e-3)
        self.runs = 0
        self.n_use: int | None = None  # compare the first n_use half cycles (None: all)
        # the least misfit of every candidate on all half cycles, and where (the verdict,
        # ``calibrate``: a profile that finds less than the estimate's says the fit did
        # not converge)
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
        peaks = fallen(excursions(self.m.t, theta, self.h), self.top)
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
        # a grid across the bracket, then a golden section in the best cell: the squares
        # are unimodal near the right shift only
        grid = np.linspace(shift0 - self.dt_shift, shift0 + self.dt_shift, SHIFT_GRID)
        sims = hermite(h["t"], h["theta"], h["theta_dot"], (tt[None, :] - grid[:, None])
                       .ravel()).reshape(grid.size, tt.size)  # every shift in one call
        k = int(np.argmin(np.sum((sims - yy[None, :]) ** 2, axis=1)))
        r = golden(ss, (grid[max(k - 1, 0)], grid[min(k + 1, SHIFT_GRID - 1)]), 1e-6)
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
