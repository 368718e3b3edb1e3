"""The excitation path from the ground to the body: orientation and building floors
(pre-processing on the record path; no numba here, no new kernel variant).

Orientation (``ground.h2``, ``ground.angle``): a planar body whose rocking plane makes
the angle ``angle`` [deg] with the first horizontal component sees

    a(t) = a1(t) cos(angle) + a2(t) sin(angle)                      (``project``)

sample by sample (both components share one DT; the shorter is at rest after its end).

Floors (``floor:``): the body stands on a floor of a linear building driven at its base by
the ground acceleration a_g(t) (cascade: the body does not load the building, its mass
is negligible beside the floor's). With modes i of period T_i [s], damping ratio zeta_i
and participation Gamma_i phi_i (the mode's participation factor times its shape at the
floor), each modal coordinate obeys

    y_i'' + 2 zeta_i w_i y_i' + w_i^2 y_i = -a_g(t),   w_i = 2 pi / T_i,  at rest at t = 0,

and the floor's absolute acceleration is

    a_f(t) = a_g(t) + sum_i Gamma_i phi_i y_i''(t)
           = a_g(t) (1 - sum_i Gamma_i phi_i) - sum_i Gamma_i phi_i (2 zeta_i w_i y_i' + w_i^2 y_i).

For a piecewise-linear ground (a record, ``physics.records``) y_i and y_i' are exact at
every sample: the Nigam-Jennings recurrence of the response spectra
(``intensity.nj_response``, the one implementation). The floor motion is a record like any
other, linear between its samples, at the ground's own samples (a floor record written by
hand from the same building at the same samples, e.g. by ``scipy.signal.lsim``, runs the
same), unless the stiffest mode's period spans fewer than POINTS_PER_PERIOD = 16 of them:
then the ground is refined (exactly: it is linear between samples) to h = DT / m, m =
min(ceil(POINTS_PER_PERIOD DT / T_min), MAX_REFINE), so that linear interpolation misses
a_f's peaks by at most 1 - cos(pi / 16) = 1.9%.

Ring-down: after the record the ground is at rest, but the building keeps vibrating. The
floor motion goes on as the modes' free vibration (closed form, ``intensity.
free_vibration``) sampled at h until its envelope,
sum_i |Gamma_i phi_i| w_i^2 R_i (1 + 2 zeta_i) exp(-zeta_i w_i tau) (R_i the free
vibration's amplitude), has fallen below RINGDOWN_SHARE = 1% of the floor's peak
acceleration: the tail is then too weak to move a body the floor's motion drives (it
changes max|theta| by far less than the 1% to which a run is compared to its reference,
docs/floors.md). An undamped mode would ring for ever: damping must be > 0; a motion
(the refined record and its ring-down) of more than MAX_MOTION_SAMPLES = 2^24 samples
(128 MiB: e.g. a damping of 1e-5 at a period of 2 s) is refused in one line before any of
it is made.

A mode so stiff that w h > RIGID_WH = 1e8 at the finest steps moves with the ground to
float64's precision (its relative acceleration ~ (w h)^-2 of the ground's): it adds
nothing and asks no refinement (a period of 1e-300 s would overflow w^2).

A pulse (``pulse:`` with ``floor:``) is the ground motion; it reaches the building as a
record sampled at PULSE_POINTS = 64 points per 2 pi of its phase w t, the last sample at
its end (``pulse_record``); the linear interpolation of the samples is within
1 - cos(pi / 64) = 0.12% of the pulse.

The building filters the horizontal motion only (``physics.ground_motion``).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np

from rocksweep.errors import FloorError
from rocksweep.physics.intensity import free_vibration, nj_response, refined
from rocksweep.physics.records import GroundRecord

#: fewest samples per period of the stiffest mode (the floor motion's linear
#: interpolation is then within 1 - cos(pi / 16) = 1.9% of its peaks)
POINTS_PER_PERIOD = 16
#: most sub-steps per record sample (a mode much stiffer than DT: 64 per sample)
MAX_REFINE = 64
#: the ring-down stops where the floor's free vibration stays below this share of its peak
RINGDOWN_SHARE = 0.01
#: most samples of one motion the body feels (the ground refined, and the ring-down):
#: 2^24, 128 MiB of float64; a building that needs more is refused in one line
MAX_MOTION_SAMPLES = 1 << 24
#: a mode with w h above this moves with the ground (its relative response ~ (w h)^-2)
RIGID_WH = 1e8
#: samples per 2 pi of a pulse's phase w t when a pulse drives a building
PULSE_POINTS = 64


@dataclass(frozen=True)
class Mode:
    """One mode of the building: period [s] > 0, damping ratio in (0, 1) and
    participation Gamma phi at the floor (!= 0)."""

    period: float
    damping: float
    participation: float


def project(a1: np.ndarray, a2: np.ndarray, angle_deg: float) -> np.ndarray:
    """a1 cos(angle) + a2 sin(angle), float64[max(n1, n2)] (the shorter at rest after its
    end); angle [deg]."""
    n = max(a1.size, a2.size)
    th = math.radians(angle_deg)
    out = np.zeros(n)
    out[:a1.size] += a1 * math.cos(th)
    out[:a2.size] += a2 * math.sin(th)
    return out


def rigid(mode: Mode, h: float) -> bool:
    """Whether ``mode`` moves with the ground at steps h [s] to float64's precision: its
    relative acceleration is ~(w h)^-2 of the ground's (quasi-static), below 1e-16 where
    w h > RIGID_WH (a period of 1e-300 s: w^2 would overflow)."""
    return not (2.0 * math.pi / mode.period * h <= RIGID_WH)


def refinement(dt: float, modes: tuple[Mode, ...]) -> int:
    """Sub-steps per record sample for these modes (module docstring); the modes ``rigid``
    even at the finest refinement need none."""
    flexible = [m for m in modes if not rigid(m, dt / MAX_REFINE)]
    if not flexible:
        return 1
    ratio = POINTS_PER_PERIOD * dt / min(m.period for m in flexible)
    return int(min(max(math.ceil(ratio), 1), MAX_REFINE)) if ratio < MAX_REFINE \
        else MAX_REFINE


def _too_long(samples: float, h: float, why: str) -> FloorError:
    return FloorError(
        f"floor: the motion the body feels would need {samples:.3g} samples at steps of "
        f"{h:.3g} s ({why}), more than {MAX_MOTION_SAMPLES:,} ({MAX_MOTION_SAMPLES * 8 >> 20}"
        " MiB) a motion; give the building more damping or a shorter period, or a shorter "
        "or coarser record")


def floor_motion(acc: np.ndarray, dt: float, modes: tuple[Mode, ...]
                 ) -> tuple[np.ndarray, float]:
    """The floor's absolute acceleration (module docstring) of the piecewise-linear ground
    ``acc`` (float64[n], at t = k dt [s], units kept: g for records), with its ring-down:
    (a_f float64[N], h [s]), a_f[k] at t = k h, h = dt / ``refinement``; N - 1 >= (n - 1)
    dt / h (the record), the samples after it its ring-down. A mode ``rigid`` at h adds
    nothing (the floor moves with the ground). More than MAX_MOTION_SAMPLES samples (the
    refined record and the ring-down, counted before any is made) is a one-line
    FloorError."""
    m = refinement(dt, modes)
    h = dt / m
    n = (np.size(acc) - 1) * m + 1
    if n > MAX_MOTION_SAMPLES:
        raise _too_long(n, h, f"the record refined {m} times for the building's shortest "
                              "period")
    x = refined(np.asarray(acc, np.float64), dt, m)
    flexible = [md for md in modes if not rigid(md, h)]
    gp_sum = sum(md.participation for md in flexible)
    floor = x * (1.0 - gp_sum)
    ends = []
    for md in flexible:
        w = 2.0 * math.pi / md.period
        y, v = nj_response(-x, w, md.damping, h, rate=True)
        floor -= md.participation * (2.0 * md.damping * w * v + w * w * y)
        ends.append((md, w, float(y[-1]), float(v[-1])))
    peak = float(np.max(np.abs(floor)))
    # ring-down: each mode's envelope below RINGDOWN_SHARE * peak / (number of modes)
    stop, slowest = 0.0, None
    for md, w, y0, v0 in ends:
        wd = w * math.sqrt(1.0 - md.damping ** 2)
        amp = math.hypot(y0, (v0 + md.damping * w * y0) / wd)
        env = abs(md.participation) * w * w * amp * (1.0 + 2.0 * md.damping)
        limit = RINGDOWN_SHARE * peak / len(ends)
        if env > limit > 0.0:
            with np.errstate(over="ignore"):  # a damping of 5e-324: an endless ring-down
                t = float(np.float64(math.log(env / limit)) / np.float64(md.damping * w))
            if not t <= stop:
                stop, slowest = t, md
    if n + stop / h > MAX_MOTION_SAMPLES:
        raise _too_long(n + stop / h, h, f"a ring-down of {stop:.3g} s until the mode of "
                        f"period {slowest.period:g} s and damping {slowest.damping:g} "
                        f"falls below {RINGDOWN_SHARE:.0%} of the floor's peak")
    n_tail = int(math.ceil(stop / h))
    if n_tail == 0:
        return floor, h
    tau = np.arange(1, n_tail + 1) * h
    tail = np.zeros(n_tail)
    for md, w, y0, v0 in ends:
        y, v = free_vibration(y0, v0, w, md.damping, tau)
        tail -= md.participation * (2.0 * md.damping * w * v + w * w * y)
    return np.concatenate((floor, tail)), h


def pulse_record(shape, w: float) -> tuple[np.ndarray, float]:
    """A pulse (``excitation.PulseShape``) of angular frequency w [rad/s] as a record of
    peak 1: (samples float64[n] of shape(w t), dt [s]), PULSE_POINTS per 2 pi of phase,
    the last sample at the pulse's end."""
    d = shape.duration
    n = int(math.ceil(d / (2.0 * math.pi) * PULSE_POINTS))
    phi = np.linspace(0.0, d, n + 1)
    return np.asarray(shape.acc(phi), np.float64), d / (n * w)


def derived_record(acc: np.ndarray, dt: float, name: str, parts: tuple) -> GroundRecord:
    """A GroundRecord of computed samples (what the body feels): ``parts`` (the inputs'
    digests and the path's parameters) make its sha256; it has no file."""
    acc = np.ascontiguousarray(acc, dtype=np.float64)
    pga = float(np.max(np.abs(acc)))
    if not pga > 0.0:
        acc = acc.copy()
        acc[0] = 1e-300  # no motion at all (a1 and a2 cancel): a peak to divide by
        pga = 1e-300
    acc.setflags(write=False)
    sha = hashlib.sha256(repr(parts).encode()).hexdigest()
    return GroundRecord(name=name, dt=float(dt), acc=acc, npts=int(acc.size), pga=pga,
                        sha256=sha, source=name, title="")
