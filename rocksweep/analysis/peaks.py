"""The excursions (half cycles) of a rocking history and the cost of aligning two
sequences of them: the misfit of a calibration (``rocksweep.analysis.calibrate``, whose
module docstring gives the method, steps 1-3). numpy only."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

PEAK_TOP = 0.5  # a peak's parabola goes through the samples above this share of it ...
PEAK_RAMP = 0.2  # ... weighted from 0 there to 1 at PEAK_TOP + PEAK_RAMP
ONSET_SAMPLES = 5  # a measurement's first value: the median of its first samples


@dataclass(frozen=True)
class Peaks:
    """Excursions of a history: signed peak (theta/alpha) float64[n], peak time float64[n]."""

    value: np.ndarray
    time: np.ndarray
    area: np.ndarray | None = None  # integral of |theta| over each excursion [theta/alpha p t]


def excursions(t: np.ndarray, theta: np.ndarray, h: float) -> Peaks:
    """The excursions of a sampled history beyond the threshold h (see the module
    docstring, step 1). t: float64[n] increasing; theta: float64[n]."""
    big = np.flatnonzero(np.abs(theta) > h)
    if big.size == 0:
        return Peaks(np.zeros(0), np.zeros(0), np.zeros(0))
    sign = np.sign(theta[big])
    new = np.ones(big.size, bool)
    new[1:] = sign[1:] != sign[:-1]
    starts = np.flatnonzero(new)
    # the largest sample of each group of samples beyond h
    signed = sign * theta[big]
    ends = np.append(starts[1:], big.size)
    arg = np.array([s + int(np.argmax(signed[s:e])) for s, e in zip(starts, ends,
                                                                       strict=True)])
    k = big[arg]
    sg = sign[starts]
    value, when = theta[k].copy(), t[k].copy()
    # a parabola through the top of each excursion (the samples within PEAK_TOP of its
    # largest): the largest sample alone is biased up by the noise (the largest of several
    # noisy samples), a least-squares fit through many is not
    first = big[starts]
    last = big[ends - 1]
    n = t.size
    area = np.empty(k.size)
    for j in range(k.size):
        a, b = int(first[j]), int(last[j]) + 1
        seg = sg[j] * theta[a:b]
        # the area beyond the threshold, int max(|theta| - h, 0) dt from the sample before
        # to the sample after: many samples average the noise, and a sample near the
        # threshold (or after a gap) weighs ~0, so the area is continuous in the parameters
        a0, b0 = max(a - 1, 0), min(b + 1, n)
        over = np.maximum(sg[j] * theta[a0:b0] - h, 0.0)
        area[j] = float(np.sum(0.5 * (over[1:] + over[:-1]) * np.diff(t[a0:b0])))
        # weights rise from 0 at PEAK_TOP of the largest to 1 at PEAK_TOP + PEAK_RAMP:
        # a sample entering the top as the parameters change enters with weight 0, so the
        # peak is continuous in the parameters
        wgt = np.clip((seg / seg.max() - PEAK_TOP) / PEAK_RAMP, 0.0, 1.0)
        top = np.flatnonzero(wgt > 0) + a
        if top.size < 4:
            continue
        tt = t[top] - t[k[j]]
        c2, c1, c0 = np.polyfit(tt, theta[top], 2, w=np.sqrt(wgt[top - a]))
        tv = -c1 / (2 * c2) if sg[j] * c2 < 0 else (tt[0] if sg[j] * c1 < 0 else tt[-1])
        tv = min(max(tv, tt[0]), tt[-1])  # the top at an end (a release from a tilt)
        value[j] = c0 + c1 * tv + c2 * tv * tv
        when[j] = t[k[j]] + tv
    return Peaks(value, when, area)


def alignment_cost(a: np.ndarray, b: np.ndarray, h: float, band: int = 12,
                   area_a: np.ndarray | None = None, area_b: np.ndarray | None = None,
                   t_scale: float = 1.0) -> tuple[float, list[tuple[int, int]]]:
    """Least cost of aligning two signed peak sequences (module docstring, step 2) and the
    pairs (i, j) of that alignment. ``band``: pairs with |i - j| beyond it are not tried
    (the cost of the rest is exact within the band)."""
    fa = np.maximum(np.abs(a) - h, 0.0)
    fb = np.maximum(np.abs(b) - h, 0.0)
    if area_a is not None and area_b is not None:  # the areas, as mean levels
        ga, gb = area_a / t_scale, area_b / t_scale
        fa = np.stack([fa, ga], axis=1)
        fb = np.stack([fb, gb], axis=1)
    else:
        fa, fb = fa[:, None], fb[:, None]
    fa2, fb2 = np.sum(fa**2, axis=1), np.sum(fb**2, axis=1)
    n, m = a.size, b.size
    inf = math.inf
    d = np.full((n + 1, m + 1), inf)
    d[0, 0] = 0.0
    sa, sb = np.sign(a), np.sign(b)

    def pair(i: int, j: int) -> float:
        if sa[i] == sb[j]:
            return float(np.sum((fa[i] - fb[j]) ** 2))
        return float(fa2[i] + fb2[j])

    for j in range(1, m + 1):
        d[0, j] = d[0, j - 1] + fb2[j - 1] if j <= band else inf
    for i in range(1, n + 1):
        if i <= band:
            d[i, 0] = d[i - 1, 0] + fa2[i - 1]
        lo, hi = max(1, i - band), min(m, i + band)
        for j in range(lo, hi + 1):
            d[i, j] = min(d[i - 1, j - 1] + pair(i - 1, j - 1), d[i - 1, j] + fa2[i - 1],
                          d[i, j - 1] + fb2[j - 1])
    if not math.isfinite(d[n, m]):  # longer than the band allows: the rest unpaired
        return float(np.sum(fa2) + np.sum(fb2)), []
    pairs = []
    i, j = n, m
    while i > 0 and j > 0:
        if math.isclose(d[i, j], d[i - 1, j - 1] + pair(i - 1, j - 1), rel_tol=1e-12,
                        abs_tol=1e-300):
            if sa[i - 1] == sb[j - 1]:
                pairs.append((i - 1, j - 1))
            i, j = i - 1, j - 1
        elif math.isclose(d[i, j], d[i - 1, j] + fa2[i - 1], rel_tol=1e-12, abs_tol=1e-300):
            i -= 1
        else:
            j -= 1
    return float(d[n, m]), pairs[::-1]


def hermite(t_h: np.ndarray, y: np.ndarray, dy: np.ndarray, t: np.ndarray) -> np.ndarray:
    """A history's y at times t by cubic Hermite interpolation of (y, y') between its rows
    (t_h non-decreasing; at a repeated time, as after an event, the later row is used);
    beyond its ends, its first or last value."""
    i = np.searchsorted(t_h, t, side="right") - 1
    i = np.clip(i, 0, t_h.size - 2)
    t0, t1 = t_h[i], t_h[i + 1]
    h = t1 - t0
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(h > 0, (t - t0) / h, 0.0)
    s = np.clip(s, 0.0, 1.0)
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    out = h00 * y[i] + h10 * h * dy[i] + h01 * y[i + 1] + h11 * h * dy[i + 1]
    out = np.where(t >= t_h[-1], y[-1], out)
    return np.where(t <= t_h[0], y[0], out)


def onset(t: np.ndarray, theta: np.ndarray, level: float, *, noisy: bool = False) -> float:
    """The time a history first departs from its first value by ``level``, interpolated
    between samples. ``noisy`` (a measurement): the first value is the median of the first
    ONSET_SAMPLES samples and the departure must hold at two samples in a row, so one
    noise sample (the first, or one beyond the level) cannot start the motion."""
    ref = float(np.median(theta[:ONSET_SAMPLES])) if noisy else float(theta[0])
    d = np.abs(theta - ref)
    beyond = d > level
    if noisy:
        beyond[:-1] &= beyond[1:]
        beyond[-1] = False
    k = np.flatnonzero(beyond)
    if k.size == 0:
        return math.nan
    i = int(k[0])
    if i == 0:
        return float(t[0])
    f = min(max((level - d[i - 1]) / (d[i] - d[i - 1]), 0.0), 1.0)
    return float(t[i - 1] + f * (t[i] - t[i - 1]))
