"""Intensity measures (rocksweep.physics.intensity) against closed forms and scipy's lsim."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import lsim

from rocksweep.physics import intensity as im
from rocksweep.physics.bodies import G


def sine(a: float, period: float, cycles: int, steps_per_cycle: int):
    """a sin(w t) over whole cycles, sampled so that the zeros and peaks fall on samples."""
    dt = period / steps_per_cycle
    t = np.arange(cycles * steps_per_cycle + 1) * dt
    return a * np.sin(2.0 * math.pi * t / period), dt


def lsim_sa(acc: np.ndarray, dt: float, period: float, zeta: float, tail: float) -> float:
    """Sa from scipy's lsim (exact for linearly interpolated input) on the record followed by
    `tail` seconds of rest, sampled every dt / 8."""
    w = 2.0 * math.pi / period
    n = acc.size
    fine = 8
    t_rec = np.arange(n) * dt
    t = np.arange(int(((n - 1) * dt + tail) / (dt / fine)) + 1) * (dt / fine)
    x = np.where(t <= t_rec[-1], np.interp(t, t_rec, acc), 0.0)
    _, y, _ = lsim(([1.0], [1.0, 2.0 * zeta * w, w * w]), -x, t)
    return w * w * float(np.max(np.abs(y)))


def test_pga_and_pgv_of_a_sine():
    a, period = 0.35, 0.8
    acc, dt = sine(a, period, cycles=3, steps_per_cycle=4000)
    w = 2.0 * math.pi / period
    assert im.pga(acc) == pytest.approx(a, rel=1e-12)
    # v(t) = (a g / w)(1 - cos w t): peak 2 a g / w at each half cycle
    assert im.pgv(acc, dt) == pytest.approx(2.0 * a * G / w, rel=1e-6)
    # in m/s^2: the same number with g = 1
    assert im.pgv(acc * G, dt, g=1.0) == pytest.approx(2.0 * a * G / w, rel=1e-6)
    assert im.duration(acc, dt) == pytest.approx(3 * period, rel=1e-12)


def test_pgv_extremum_between_samples():
    # acc = [1, -1] over one step: v(t) = g (t - t^2/dt) peaks at t = dt/2 with g dt / 4,
    # while at the samples v = 0 and v(dt) = 0
    dt = 0.02
    assert im.pgv(np.array([1.0, -1.0]), dt) == pytest.approx(G * dt / 4.0, rel=1e-12)
    assert np.allclose(im.velocity(np.array([1.0, -1.0]), dt), 0.0)


def test_pgv_has_no_baseline_correction():
    # a constant acceleration keeps accelerating: v = g a t
    acc = np.full(101, 0.1)
    assert im.pgv(acc, 0.01) == pytest.approx(G * 0.1 * 1.0, rel=1e-12)


def test_sa_undamped_resonance_growth_is_exact():
    # u'' + w^2 u = -a sin(w t) from rest: u = (a / (2 w^2)) (w t cos w t - sin w t); over N
    # whole cycles |u| peaks at the end with pi N a / w^2, and the free vibration after it
    # (u' = 0 there) keeps that amplitude: Sa = pi N a
    a, period, cycles = 0.2, 0.5, 3
    acc, dt = sine(a, period, cycles, steps_per_cycle=1000)
    s = im.sa(acc, dt, [period], zeta=0.0)
    assert s.shape == (1,)
    # the linearly interpolated sine's fundamental is sinc^2(w dt / 2) ~ 1 - (w dt)^2 / 12
    # of the sine's (3.3e-6 here): the recurrence itself adds nothing visible
    wdt = 2.0 * math.pi / 1000
    assert s[0] == pytest.approx(math.pi * cycles * a * (1 - wdt**2 / 12), rel=2e-7)


def test_sa_damped_steady_state_limit():
    # many cycles at resonance with damping: the amplitude tends to a / (2 zeta) (Sa = a /
    # (2 zeta)); after 60 cycles at zeta = 0.05 the transient exp(-zeta w t) is e^-18.8
    a, period, zeta, cycles = 0.1, 0.4, 0.05, 60
    acc, dt = sine(a, period, cycles, steps_per_cycle=400)
    assert im.sa(acc, dt, [period], zeta=zeta)[0] == pytest.approx(a / (2 * zeta), rel=1e-4)


@pytest.mark.parametrize("period", [0.03, 0.1, 0.5, 1.3, 4.0])
def test_sa_matches_lsim_on_a_random_record(period):
    rng = np.random.default_rng(7)
    acc = np.convolve(rng.standard_normal(600), np.ones(5) / 5, mode="same") * 0.2
    dt = 0.01
    # the tail lets the free vibration after the record peak (long periods)
    ref = lsim_sa(acc, dt, period, 0.05, tail=1.5 * period)
    assert im.sa(acc, dt, [period])[0] == pytest.approx(ref, rel=5e-3)


def test_sa_free_vibration_after_the_record_counts():
    # a half sine much shorter than the period: the peak comes after the record ends
    acc, dt = sine(0.5, 0.2, 1, 200)
    acc = acc[:101]  # the first half cycle: acc >= 0
    period = 3.0
    assert im.sa(acc, dt, [period], zeta=0.0)[0] == pytest.approx(
        lsim_sa(acc, dt, period, 0.0, tail=period), rel=2e-3)
    # the peak of the forced part alone (samples of the record) is far smaller
    w = 2.0 * math.pi / period
    t = np.arange(acc.size) * dt
    _, y, _ = lsim(([1.0], [1.0, 0.0, w * w]), -acc, t)
    assert w * w * np.max(np.abs(y)) < 0.5 * im.sa(acc, dt, [period], zeta=0.0)[0]


def test_sa_short_period_tends_to_pga():
    acc, dt = sine(0.4, 1.0, 2, 1000)
    s = im.sa(acc, dt, [0.0, 1e-3, 1e-2], zeta=0.05)
    assert s[0] == im.pga(acc)
    assert s[1] == pytest.approx(0.4, rel=1e-4)
    assert s[2] == pytest.approx(0.4, rel=2e-3)


def test_sa_is_vectorised_and_linear():
    rng = np.random.default_rng(3)
    acc = rng.standard_normal(300) * 0.1
    periods = np.array([0.1, 0.5, 2.0])
    s = im.sa(acc, 0.01, periods)
    assert s.shape == (3,) and s.dtype == np.float64
    assert np.array_equal(s, np.array([im.sa(acc, 0.01, [p])[0] for p in periods]))
    assert np.allclose(im.sa(3.0 * acc, 0.01, periods), 3.0 * s, rtol=1e-12)


def test_sa_starts_at_rest_when_the_first_sample_is_not_zero():
    # a constant acceleration c from t = 0 (a step): u = -(c / w^2)(1 - cos w t), Sa = 2 c
    acc = np.full(2001, 0.3)
    assert im.sa(acc, 0.001, [0.5], zeta=0.0)[0] == pytest.approx(0.6, rel=1e-6)


@pytest.mark.parametrize("bad", [dict(acc=[1.0]), dict(acc=[0.0, np.nan]),
                                 dict(dt=0.0), dict(periods=[-1.0]), dict(zeta=1.0)])
def test_bad_input_is_a_value_error(bad):
    args = dict(acc=[0.0, 1.0, 0.0], dt=0.01, periods=[0.5], zeta=0.05) | bad
    with pytest.raises(ValueError):
        im.sa(args["acc"], args["dt"], args["periods"], args["zeta"])


def test_a_records_digest_is_the_sha256_of_its_bytes():
    from rocksweep.physics.records import digest

    # FIPS 180-2's test vector for "abc"
    assert digest(b"abc") == ("ba7816bf8f01cfea414140de5dae2223"
                              "b00361a396177a9cb410ff61f20015ad")
