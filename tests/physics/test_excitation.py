"""The reference pulse shapes (rocksweep.physics.excitation) against closed forms.

- sine/cosine with n cycles: on for 0 <= w t <= 2 pi n (end point included), zero net
  velocity (integral over the pulse = 0);
- Ricker: peak 1 at t0 (w t = 3 pi), zero crossings at tau = +-1/sqrt(2), side lobes
  -2 exp(-3/2) at tau = +-sqrt(3/2), net velocity 0;
- Mavroeidis-Papageorgiou: OpenSees' MPAccSeries::getFactor (written in t, T and AFactor)
  with AFactor from mp_velocity_amplitude, and the MP (2003) velocity in its centred form
  as the integral of the acceleration; peak |shape| = 1, r_max = 2 gamma for nu = 90 deg;
- every rate against central finite differences;
- the rigid block's uplift phase: arcsin(1/|A_ratio|) for the sine, 0 for the cosine, the
  Lambert-W solution of (1 - 2 tau^2) exp(-tau^2) = c for both Ricker lobes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import lambertw

from rocksweep.physics.excitation import (
    PulseShape,
    mp_peak,
    mp_velocity_amplitude,
)

ALL = [PulseShape("sine"), PulseShape("sine", cycles=3), PulseShape("cosine"),
       PulseShape("cosine", cycles=2), PulseShape("ricker"),
       PulseShape("mp", gamma=2.0, nu_deg=90.0), PulseShape("mp", gamma=1.7, nu_deg=30.0),
       PulseShape("mp", gamma=1.0, nu_deg=0.0)]


def _ricker_phi(tau: float) -> float:
    """w t of the Ricker's tau = pi f (t - t0): pi f t = w t / 2, pi f t0 = 1.5 pi."""
    return 2.0 * (tau + 1.5 * math.pi)


@pytest.mark.parametrize("n", [1, 2, 3, 5])
@pytest.mark.parametrize("kind", ["sine", "cosine"])
def test_n_cycles_span_2_pi_n_and_carry_no_net_velocity(kind, n):
    p = PulseShape(kind, cycles=n)
    assert p.duration == pytest.approx(2 * math.pi * n, rel=1e-15)
    trig = math.sin if kind == "sine" else math.cos
    phi = np.linspace(0.0, 2 * math.pi * n, 777)
    np.testing.assert_allclose(p.acc(phi), [trig(x) for x in phi], atol=1e-15)
    end = 2 * math.pi * n
    assert p.acc(end) == pytest.approx(trig(end), abs=1e-12)  # the end point is still on
    assert p.acc(np.nextafter(end, 10 * end)) == 0.0
    assert p.acc(-1e-12) == 0.0
    integral, _ = quad(lambda x: float(p.acc(x)), 0.0, end, limit=50 * n, epsabs=1e-11)
    assert abs(integral) < 1e-10


def test_ricker_peak_crossings_and_side_lobes():
    p = PulseShape("ricker")
    assert p.duration == pytest.approx(6 * math.pi)
    assert p.acc(_ricker_phi(0.0)) == 1.0  # A at t0
    assert p.rate(_ricker_phi(0.0)) == 0.0
    dense = p.acc(np.linspace(0.0, p.duration, 200_001))
    assert dense.max() <= 1.0
    for tau in (-1 / math.sqrt(2), 1 / math.sqrt(2)):
        assert abs(p.acc(_ricker_phi(tau))) < 1e-15
    for tau in (-math.sqrt(1.5), math.sqrt(1.5)):
        assert p.acc(_ricker_phi(tau)) == pytest.approx(-2 * math.exp(-1.5), rel=1e-14)
        assert abs(p.rate(_ricker_phi(tau))) < 1e-15
    assert dense.min() == pytest.approx(-2 * math.exp(-1.5), rel=1e-9)
    # on for 0 <= t <= 2 t0: tau = -+1.5 pi at the ends, off just outside
    assert p.acc(0.0) == pytest.approx((1 - 2 * (1.5 * math.pi) ** 2)
                                       * math.exp(-(1.5 * math.pi) ** 2), rel=1e-13)
    assert p.acc(-1e-9) == 0.0 and p.acc(6 * math.pi + 1e-9) == 0.0
    # zero net velocity: the full wavelet's integral is 0, truncation leaves ~1e-9
    integral, _ = quad(lambda x: float(p.acc(x)), 0.0, p.duration, limit=200)
    assert abs(integral) < 1e-8


@pytest.mark.parametrize("gamma, nu", [(2.0, 90.0), (1.7, 30.0), (1.0, 0.0), (3.0, -45.0)])
def test_mp_is_opensees_mpacc_with_its_velocity_amplitude(gamma, nu):
    """OpenSees MPAccSeries::getFactor(t) with period T, gamma, nu [deg], AFactor, for
    tStart = 0 <= t <= tFinish = gamma T; our A * shape(w t) with w = 2 pi / T."""
    A, T = 3.7, 0.8
    w = 2 * math.pi / T
    af = mp_velocity_amplitude(A, w, gamma, nu)
    p = PulseShape("mp", gamma=gamma, nu_deg=nu)

    def mpacc(t):
        arg = 2 * math.pi * t / T - math.pi * gamma + nu * math.pi / 180
        env = 2 * math.pi * t / (T * gamma)
        return (af * math.pi / (T * gamma)) * (math.sin(env) * math.cos(arg)
                                                - gamma * math.sin(arg) * (1 - math.cos(env)))

    ts = np.linspace(0.0, gamma * T, 301)
    np.testing.assert_allclose(A * p.acc(w * ts), [mpacc(t) for t in ts], atol=1e-12 * A)
    assert p.duration == pytest.approx(2 * math.pi * gamma)


@pytest.mark.parametrize("gamma, nu", [(2.0, 90.0), (2.2, 60.0), (1.3, 0.0)])
def test_mp_acceleration_integrates_to_the_centred_mp_velocity(gamma, nu):
    """v(t) = A_MP/2 [1 + cos(2 pi f_p (t - t0)/gamma)] cos(2 pi f_p (t - t0) + nu) with
    t0 = gamma / (2 f_p) (Mavroeidis & Papageorgiou 2003), the pulse starting at t = 0."""
    A, f_p = 2.0, 1.25
    w = 2 * math.pi * f_p
    a_mp = mp_velocity_amplitude(A, w, gamma, nu)
    t0 = gamma / (2 * f_p)
    p = PulseShape("mp", gamma=gamma, nu_deg=nu)

    def v(t):
        x = 2 * math.pi * f_p * (t - t0)
        return a_mp / 2 * (1 + math.cos(x / gamma)) * math.cos(x + math.radians(nu))

    assert v(0.0) == pytest.approx(0.0, abs=1e-15) and v(2 * t0) == pytest.approx(0.0, abs=1e-15)
    for t in np.linspace(0.0, 2 * t0, 9)[1:]:
        integral, _ = quad(lambda s: A * float(p.acc(w * s)), 0.0, t, limit=200,
                           epsabs=1e-13, epsrel=1e-12)
        assert integral == pytest.approx(v(t) - v(0.0), abs=1e-10 * A)


@pytest.mark.parametrize("gamma", [1.0, 1.5, 2.0, 3.0, 4.5])
def test_mp_peak_is_one_and_2_gamma_for_nu_90(gamma):
    # nu = 90 deg: r(pi gamma) = -gamma (1 - cos pi) sin(90 deg) = -2 gamma, the largest |r|
    assert mp_peak(gamma, 90.0) == pytest.approx(2 * gamma, rel=1e-14)
    for nu in (90.0, 0.0, 37.0, -120.0):
        p = PulseShape("mp", gamma=gamma, nu_deg=nu)
        a = np.abs(p.acc(np.linspace(0.0, p.duration, 100_001)))
        assert a.max() <= 1.0 + 1e-12
        assert a.max() == pytest.approx(1.0, abs=1e-8)
    assert PulseShape("mp", gamma=gamma, nu_deg=90.0).acc(math.pi * gamma) == pytest.approx(-1.0)


@pytest.mark.parametrize("p", ALL, ids=lambda p: p.label)
def test_rate_matches_finite_differences(p):
    rng = np.random.default_rng(7)
    phi = rng.uniform(1e-3, p.duration - 1e-3, 60)
    h = 1e-6
    fd = (p.acc(phi + h) - p.acc(phi - h)) / (2 * h)
    np.testing.assert_allclose(p.rate(phi), fd, atol=2e-8)
    assert p.rate(-1.0) == 0.0 and p.rate(p.duration + 1.0) == 0.0


@pytest.mark.parametrize("a_ratio", [1.0, 1.2, 2.0, 5.0, 50.0])
def test_uplift_under_sine_at_arcsin_one_over_a(a_ratio):
    for n in (1, 2):
        for sign in (1.0, -1.0):  # same time, other corner
            phi = PulseShape("sine", cycles=n).uplift_phase(sign * a_ratio)
            assert phi == pytest.approx(math.asin(1 / a_ratio), rel=1e-12, abs=1e-12)


def test_no_uplift_below_the_threshold_and_cosine_at_once():
    assert PulseShape("sine").uplift_phase(0.99) is None
    assert PulseShape("sine").uplift_phase(0.0) is None
    assert PulseShape("cosine").uplift_phase(0.999) is None
    assert PulseShape("cosine").uplift_phase(1.0) == 0.0
    assert PulseShape("cosine").uplift_phase(-3.0) == 0.0
    assert PulseShape("ricker").uplift_phase(0.999) is None


@pytest.mark.parametrize("a_ratio", [1.0, 1.05, 1.5, 2.0, 2.2, 2.3, 3.0, 10.0])
def test_uplift_under_ricker_by_lambert_w(a_ratio):
    """(1 - 2 u) e^{-u} = c (u = tau^2): with v = 1 - 2u, (v/2) e^{v/2} = c sqrt(e)/2, so
    u = (1 - 2 W(c sqrt(e)/2))/2; the main lobe (c = 1/A_ratio, branch 0) or, once the
    side lobe -2 e^{-3/2} reaches -1/A_ratio (A_ratio >= e^{3/2}/2), that lobe first
    (c = -1/A_ratio, branch -1: the larger u, i.e. the earlier time)."""
    if a_ratio >= math.exp(1.5) / 2:
        c, branch = -1.0 / a_ratio, -1
    else:
        c, branch = 1.0 / a_ratio, 0
    W = lambertw(c * math.sqrt(math.e) / 2, branch)
    assert abs(W.imag) < 1e-12
    u = (1 - 2 * W.real) / 2
    expected = _ricker_phi(-math.sqrt(u))
    for sign in (1.0, -1.0):
        got = PulseShape("ricker").uplift_phase(sign * a_ratio)
        assert got == pytest.approx(expected, rel=1e-10, abs=1e-9)


@pytest.mark.parametrize("a_ratio", [1.2, 2.0, 4.0])
def test_uplift_under_mp_is_the_first_sample_over_the_threshold(a_ratio):
    p = PulseShape("mp", gamma=2.2, nu_deg=60.0)
    got = p.uplift_phase(a_ratio)
    phi = np.linspace(0.0, p.duration, 2_000_001)
    first = phi[np.argmax(np.abs(a_ratio * p.acc(phi)) >= 1.0)]
    assert got == pytest.approx(first, abs=2 * (phi[1] - phi[0]))
    assert abs(a_ratio * p.acc(got)) == pytest.approx(1.0, rel=1e-10)


@pytest.mark.parametrize("kwargs, match", [
    ({"shape": "square"}, "shape = 'square': must be one of sine, cosine, ricker, mp"),
    ({"cycles": 0}, "cycles = 0: must be an integer >= 1"),
    ({"cycles": 1.5}, "cycles = 1.5: must be an integer >= 1"),
    ({"cycles": True}, "cycles = True: must be an integer >= 1"),
    ({"shape": "mp", "gamma": 0.5}, "gamma = 0.5: must be a finite number >= 1"),
    ({"shape": "mp", "nu_deg": math.inf}, "nu_deg = inf: must be finite"),
])
def test_bad_parameters_are_refused(kwargs, match):
    with pytest.raises(ValueError) as err:
        PulseShape(**kwargs)
    assert str(err.value) == match
