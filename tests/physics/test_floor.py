"""The floor motion and the orientation, against independent derivations.

- the floor's absolute acceleration of a building of one or two modes under a recorded
  ground equals scipy.signal.lsim of the building's state-space model (linear
  interpolation of the input: exact for the piecewise-linear ground), ring-down included;
- the ring-down stops where lsim's continued free vibration stays below the stated share
  of the floor's peak;
- a stiff building (period -> 0) carries the ground motion (a_f -> a_g (1 - 0) + Gamma phi
  a_g... its floor moves with the ground), a flexible undamped-like one isolates it;
- the projection of two components is the rotation of the horizontal plane.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

from rocksweep.errors import FloorError
from rocksweep.physics.excitation import PulseShape
from rocksweep.physics.floor import (
    MAX_MOTION_SAMPLES,
    RINGDOWN_SHARE,
    Mode,
    floor_motion,
    project,
    pulse_record,
)
from rocksweep.physics.records import read_record

ROOT = Path(__file__).resolve().parents[2]
NEARFAULT = ROOT / "records" / "synthetic_nearfault.AT2"


def ten_seconds():
    """The near-fault record's first 10 s, ending at 0 (after its last sample the ground is
    at rest: a record that ends at 0 has no jump there, which lsim's ramps would smear)."""
    rec = read_record(NEARFAULT)
    acc = rec.acc[:2000].copy()
    acc[-1] = 0.0
    return acc, rec.dt


def lsim_floor(acc, dt, modes, t):
    """The floor's absolute acceleration at times t by lsim: states (y_i, y_i') of every
    mode driven by -a_g; output a_g (1 - sum gp) - sum gp (2 zeta w y' + w^2 y)."""
    n = len(modes)
    A = np.zeros((2 * n, 2 * n))
    B = np.zeros((2 * n, 1))
    C = np.zeros((1, 2 * n))
    for i, (T, z, gp) in enumerate(modes):
        w = 2 * math.pi / T
        A[2 * i, 2 * i + 1] = 1.0
        A[2 * i + 1, 2 * i] = -w * w
        A[2 * i + 1, 2 * i + 1] = -2 * z * w
        B[2 * i + 1, 0] = -1.0
        C[0, 2 * i] = -gp * w * w
        C[0, 2 * i + 1] = -gp * 2 * z * w
    D = np.array([[1.0 - sum(m[2] for m in modes)]])
    u = np.interp(t, np.arange(acc.size) * dt, acc, right=0.0)
    return signal.lsim((A, B, C, D), u, t)[1]


@pytest.mark.parametrize("modes", [((0.6, 0.05, 1.3),),
                                   ((1.2, 0.03, 1.4), (0.25, 0.05, -0.5))])
def test_floor_motion_is_lsim_of_the_building(modes):
    acc, dt = ten_seconds()
    af, h = floor_motion(acc, dt, tuple(Mode(*m) for m in modes))
    t = np.arange(af.size) * h
    ref = lsim_floor(acc, dt, modes, t)
    assert af.size > (acc.size - 1) * dt / h + 10  # a ring-down follows the record
    assert np.max(np.abs(af - ref)) < 1e-8 * np.max(np.abs(ref))


def test_ringdown_stops_below_its_share_of_the_peak():
    acc, dt = ten_seconds()
    modes = ((0.8, 0.02, 1.3),)
    af, h = floor_motion(acc, dt, (Mode(*modes[0]),))
    t_long = np.arange(af.size * 3) * h
    ref = lsim_floor(acc, dt, modes, t_long)
    peak = np.max(np.abs(ref))
    assert np.max(np.abs(ref[af.size:])) < RINGDOWN_SHARE * peak
    # and not much sooner: one period before the stop it was still above a tenth of it
    before = af.size - int(0.8 / h)
    assert np.max(np.abs(ref[before:af.size])) > 0.1 * RINGDOWN_SHARE * peak


def test_a_stiff_floor_moves_with_the_ground():
    """T -> 0: y'' -> 0 relative motion, so a_f -> a_g whatever Gamma phi (to O((w_g/w)^2))."""
    acc, dt = ten_seconds()
    af, h = floor_motion(acc, dt, (Mode(0.002, 0.05, 1.5),))
    t = np.arange(af.size) * h
    ground = np.interp(t, np.arange(acc.size) * dt, acc, right=0.0)
    assert np.max(np.abs(af - ground)) < 0.02 * np.max(np.abs(acc))


@pytest.mark.parametrize("damping", [5e-324, 1e-7])
def test_an_endless_ringdown_is_refused_before_it_is_made(damping):
    """The ring-down lasts ln(envelope / 1% of the peak) / (zeta w): 5e-324 overflowed it,
    1e-7 asked 1.3 GiB and more (issue 45). Refused in one line, counted before any
    sample of it is made."""
    import tracemalloc

    acc, dt = ten_seconds()
    tracemalloc.start()
    with pytest.raises(FloorError) as err:
        floor_motion(acc, dt, (Mode(0.5, damping, 1.3),))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    msg = str(err.value)
    assert "\n" not in msg and f"{MAX_MOTION_SAMPLES:,}" in msg and "ring-down" in msg
    assert peak < 8 * MAX_MOTION_SAMPLES / 16  # the record's few samples, not the tail
    # the bound's edge: 1e-4 rings ln(...) / (1e-4 w) ~ 5e3 s = 5e5 samples: made
    af, h = floor_motion(acc, dt, (Mode(0.5, 1e-4, 1.3),))
    assert acc.size < af.size < MAX_MOTION_SAMPLES


def test_a_period_of_1e_300_is_a_rigid_building():
    """w = 2 pi / 1e-300 overflows w^2 (an OverflowError before): a mode with w h > 1e8
    moves with the ground, its relative response (w h)^-2 below float64's precision; the
    recurrence's own answer at 1e-9 s (w h ~ 1e5) is already the ground to 1e-9."""
    acc, dt = ten_seconds()
    af, h = floor_motion(acc, dt, (Mode(1e-300, 0.05, 1.3), Mode(1e-300, 5e-324, -2.0)))
    assert h == dt and np.array_equal(af, acc)
    af9, h9 = floor_motion(acc, dt, (Mode(1e-9, 0.05, 1.3),))
    ground = np.interp(np.arange(af9.size) * h9, np.arange(acc.size) * dt, acc, right=0.0)
    assert np.max(np.abs(af9 - ground)) < 1e-9 * np.max(np.abs(acc))


def test_projection_rotates_the_horizontal_plane():
    rng = np.random.default_rng(3)
    a1, a2 = rng.normal(size=50), rng.normal(size=40)
    a2_full = np.r_[a2, np.zeros(10)]
    assert np.allclose(project(a1, a2, 0.0), a1)
    assert np.allclose(project(a1, a2, 90.0), a2_full)
    assert np.allclose(project(a1, a2, 210.0), -project(a1, a2, 30.0))
    # the plane's energy is the rotation's invariant: p(th)^2 + p(th + 90)^2 = a1^2 + a2^2
    s = project(a1, a2, 37.0) ** 2 + project(a1, a2, 127.0) ** 2
    assert np.allclose(s, a1 ** 2 + a2_full ** 2)


@pytest.mark.parametrize("shape", ["sine", "cosine", "ricker"])
def test_a_pulse_as_samples_is_within_its_interpolation_error(shape):
    pulse = PulseShape(shape)
    acc, dt = pulse_record(pulse, 2.0)
    assert abs(((acc.size - 1) * dt) * 2.0 - pulse.duration) < 1e-12  # ends at D
    phi = np.linspace(0.0, pulse.duration, 20001)
    lin = np.interp(phi / 2.0, np.arange(acc.size) * dt, acc)
    # linear interpolation of a unit-peak smooth pulse at 64 points per 2 pi of phase:
    # within 1 - cos(pi/64) of a sine; the Ricker's curvature is up to ~3x a sine's
    assert np.max(np.abs(lin - pulse.acc(phi))) < 3 * (1 - math.cos(math.pi / 64))
