"""The vertical ground acceleration a_v (positive up) as the kernel reads it (no numba here).

Two forms (docs/vertical.md):

- a record's vertical component (``ground.vertical``), on the horizontal's samples
  (``records.vertical_samples``), scaled by the horizontal's factor: a_v = |A| acc_v /
  PGA_h (A = A_ratio g tan(alpha_cg), the peak of the horizontal; a negative A_ratio turns
  the horizontal round, not the vertical);
- a harmonic acting while the pulse acts (``pulse.vertical``): a_v = a g sin(w_v t +
  phase) for t < t_pulse (a [g], w_v/p, phase [deg]; kernel time p t).

While it acts gravity is g + a_v(t); where g + a_v <= 0 the ground falls faster than the
body would and the model no longer holds: ``air_time_*`` give the first such time, the
kernel's PAR_T_AIR (the run stops there, status ``airborne``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rocksweep.physics.bodies import G


@dataclass(frozen=True)
class VerticalHarmonic:
    """``pulse.vertical``: a_v = amplitude g sin(w_over_p p t + phase) while the pulse acts.

    amplitude [g] (finite; negative: the opposite sign), w_over_p = w_v/p (> 0), phase
    [deg] (finite)."""

    amplitude: float
    w_over_p: float
    phase: float = 0.0


def air_time_harmonic(amplitude, w_over_p, phase_deg, t_pulse) -> np.ndarray:
    """First kernel time t in [0, t_pulse) with 1 + a sin(w t + phase) <= 0 (float64[n],
    inf: none; arguments broadcast, w = w_over_p with p = 1).

    With |a| >= 1 (a < 0 is |a| with phase + pi), sin x <= -1/|a| on the arcs
    [pi + asin(1/|a|), 2 pi - asin(1/|a|)] + 2 pi k: 0 if the phase is on one, else the
    time to the start of the next."""
    a = np.asarray(amplitude, float)
    w = np.asarray(w_over_p, float)
    x0 = np.radians(np.asarray(phase_deg, float)) + np.where(a < 0.0, math.pi, 0.0)
    x0 = np.mod(x0, 2 * math.pi)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.arcsin(np.minimum(1.0, 1.0 / np.abs(a)))  # nan-free where |a| >= 1
        lo, hi = math.pi + c, 2 * math.pi - c
        inside = (x0 >= lo) & (x0 <= hi)
        start = np.where(x0 <= lo, lo, lo + 2 * math.pi)
        t = np.where(inside, 0.0, (start - x0) / w)
        t = np.where((np.abs(a) >= 1.0) & (t < np.asarray(t_pulse, float)), t, np.inf)
    return np.asarray(t, float)


def air_time_record(shape_v: np.ndarray, dt_k, scale_g) -> np.ndarray:
    """First kernel time at which 1 + scale_g shape_v(t) <= 0 for the piecewise-linear
    vertical ``shape_v`` (float64[npts], on samples every dt_k [p t]), per point
    (scale_g: float64[n] >= 0, a_v/g per unit of shape_v; dt_k: float64[n] or a scalar).
    float64[n], inf: never; 0: at t = 0. O(n log npts): the first sample at or below
    -1/scale_g is found in the running minimum, the crossing inside the segment before it
    by linear interpolation."""
    shape_v = np.asarray(shape_v, float)
    scale = np.atleast_1d(np.asarray(scale_g, float))
    run_min = np.minimum.accumulate(shape_v)
    with np.errstate(divide="ignore"):
        level = np.where(scale > 0.0, -1.0 / scale, -np.inf)  # g + a_v <= 0 at shape <= level
    i = np.searchsorted(-run_min, -level, side="left")  # first i with run_min[i] <= level
    out = np.full(scale.shape, np.inf)
    hit = i < shape_v.size
    dt_k = np.broadcast_to(np.asarray(dt_k, float), scale.shape)
    at0 = hit & (i == 0)
    out[at0] = 0.0
    inner = hit & (i > 0)
    k = i[inner]
    a0, a1 = shape_v[k - 1], shape_v[k]
    frac = (level[inner] - a0) / (a1 - a0)  # a0 > level >= a1
    out[inner] = (k - 1 + frac) * dt_k[inner]
    return out


def min_gravity_at_start(a_v0_g: float) -> float:
    """g + a_v(0) [m/s^2] for a_v(0) given in g."""
    return G * (1.0 + a_v0_g)
