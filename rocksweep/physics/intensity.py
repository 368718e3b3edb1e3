"""Intensity measures of a ground-acceleration record (no numba here).

A record is given as its samples ``acc`` (float64[n], in g, as ``rocksweep.physics.records`` reads
them) at a constant interval ``dt`` [s]: acc[i] at t = i dt, linearly interpolated between
samples, the ground at rest before t = 0 and after the last sample (the convention of
``rocksweep.physics.records.GroundRecord``). Every measure here is exact for that piecewise-linear
record (except Arias, CAV and D5-95: below):

- ``pga`` [g]: max |acc| (a piecewise-linear function peaks at a sample).
- ``pgv`` [m/s]: max |v| of the ground velocity v(t) = g * integral of acc from 0 to t,
  integrated as given: no baseline correction, no filtering (a record whose velocity
  drifts keeps its drift). At the samples this is the trapezoidal rule (exact for a
  piecewise-linear acceleration); inside a step where acc changes sign the velocity has
  its extremum between the samples, and that extremum is included (closed form).
- ``sa`` [g]: pseudo-spectral acceleration omega^2 max|u| of a linear oscillator of period
  T and damping ratio zeta, u'' + 2 zeta omega u' + omega^2 u = -xg'', at rest at t = 0,
  computed with the exact recurrence for a piecewise-linear input (Nigam & Jennings 1969,
  "Calculation of response spectra from strong-motion earthquake records", BSSA 59(2)),
  written as a second-order recursive filter (``scipy.signal.lfilter``), vectorised over
  periods. Two things common codes miss are handled: the peak of the free vibration after
  the record ends (closed form from the final state), and peaks between samples for short
  periods (the record is resampled, exactly since it is piecewise linear, so that a period
  spans at least ``points_per_period`` steps, at most ``max_refine`` sub-steps per sample;
  the peak then is low by at most 1 - cos(pi / points_per_period) = 0.5 % for 32).
  Sa(T = 0) is defined as PGA, its limit.
- ``arias`` [m/s], ``cav`` [m/s], ``significant_duration`` [s]: from the samples, by the
  convention ground-motion models are fitted with (and so the hazard curves a user
  convolves with): Arias intensity I_A = pi / (2 g) dt sum a_i^2, CAV = dt sum |a_i|
  (a in m/s^2), D5-95 the time between the first samples at which the cumulative sum of
  a_i^2 (``husid``) reaches 5% and 95% of its total (Trifunac & Brady 1975). For a
  band-limited record the sample sum of a^2 is the integral of a^2 (Parseval), not an
  approximation of it; integrating the piecewise-linear interpolant instead gives 1-11%
  less on real records (it low-passes them), a convention of its own.
- ``avg_sa`` [g]: AvgSa, the geometric mean of Sa over ``AVGSA_POINTS`` periods spaced
  evenly in ln T over [T_lo, T_hi] (Eads, Miranda & Lignos 2015; Kohrangi et al. 2016).
- ``final_velocity`` [m/s]: v at the last sample (a record whose velocity does not return to
  0 drifts: the ground keeps moving after it ends).
- ``duration`` [s] = (n - 1) dt, ``sha256`` of a file's bytes.

Why our own code and not a library (both read at their source, both MIT): eqsig's
``sdof.pseudo_response_spectra`` has the same recurrence but replaces Sa by the PGA for
every T < 6 dt, stops at the record's last sample (the free vibration after it is ignored,
so long periods can come out low), keeps (n_periods, n) response arrays and uses 6.2831853
for 2 pi in one place and 2 pi in another; pyrotd computes the oscillator response in the
frequency domain (FFT with frequency-domain interpolation), not the exact time-domain
recurrence, and the versions read import ``pkg_resources``, which current setuptools no
longer ship. The recurrence is ~60 lines here, tested against closed forms and lsim.
"""

from __future__ import annotations

import math

import numpy as np

from rocksweep.physics.bodies import G  # gravity [m/s^2], the one definition
from rocksweep.vocab.ground import AVGSA_POINTS, SA_DAMPING

__all__ = ["arias", "avg_sa", "avgsa_periods", "cav", "duration",
           "final_velocity", "free_vibration", "husid", "nj_response", "pga", "pgv",
           "refined", "sa", "significant_duration", "velocity"]


def _check(acc, dt: float) -> np.ndarray:
    a = np.asarray(acc, dtype=np.float64)
    if a.ndim != 1 or a.size < 2:
        raise ValueError(f"acc must be a 1-D array of at least 2 samples, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError("acc holds NaN or inf")
    if not (math.isfinite(dt) and dt > 0.0):
        raise ValueError(f"dt = {dt!r}: must be a finite number > 0 [s]")
    return a


def pga(acc) -> float:
    """Peak ground acceleration max |acc| [units of acc, g for project records]."""
    a = np.asarray(acc, dtype=np.float64)
    if a.size == 0:
        raise ValueError("acc is empty")
    return float(np.max(np.abs(a)))


def velocity(acc, dt: float, *, g: float = G) -> np.ndarray:
    """Ground velocity at the samples [m/s], float64[n]: v_0 = 0, trapezoidal rule (exact
    for the piecewise-linear record), acc in g (pass ``g=1`` for acc in m/s^2); no
    baseline correction."""
    a = _check(acc, dt)
    v = np.empty_like(a)
    v[0] = 0.0
    np.cumsum(0.5 * dt * (a[1:] + a[:-1]), out=v[1:])
    return g * v


def pgv(acc, dt: float, *, g: float = G) -> float:
    """Peak ground velocity max |v(t)| [m/s] of the record as given (acc in g; ``g=1`` for
    acc in m/s^2): trapezoidal integration from v(0) = 0, no baseline correction, the
    extremum inside a step where acc changes sign included (v is quadratic there)."""
    a = _check(acc, dt)
    v = velocity(a, dt, g=g)
    peak = float(np.max(np.abs(v)))
    a0, a1 = a[:-1], a[1:]
    cross = (a0 * a1) < 0.0  # acc changes sign strictly inside the step: v has an extremum
    if np.any(cross):
        a0c, a1c = a0[cross], a1[cross]
        # v(tau) = v_i + g (a0 tau + (a1 - a0) tau^2 / (2 dt)), extremum at a(tau) = 0
        vstar = v[:-1][cross] - g * a0c * a0c * dt / (2.0 * (a1c - a0c))
        peak = max(peak, float(np.max(np.abs(vstar))))
    return peak


def final_velocity(acc, dt: float, *, g: float = G) -> float:
    """Ground velocity at the record's last sample [m/s] (``velocity``): 0 for a record
    whose baseline was corrected, the drift of one that was not."""
    return float(velocity(acc, dt, g=g)[-1])


def husid(acc, dt: float) -> np.ndarray:
    """Cumulative sum dt sum_{i<=k} acc_i^2 at the samples [g^2 s], float64[n]: the Husid
    curve by the sample-sum convention (module docstring); its last entry is the total."""
    a = _check(acc, dt)
    return np.cumsum(a * a) * float(dt)


def arias(acc, dt: float, *, g: float = G) -> float:
    """Arias intensity I_A = pi / (2 G) dt sum (g acc_i)^2 [m/s] (the sample sum, module
    docstring): acc in g (``g`` the m/s^2 in one unit of acc; the pi / (2 G) is always
    gravity's)."""
    return float(math.pi / (2.0 * G) * g * g * husid(acc, dt)[-1])


def cav(acc, dt: float, *, g: float = G) -> float:
    """Cumulative absolute velocity dt sum |g acc_i| [m/s] (the sample sum, module
    docstring; acc in g)."""
    a = _check(acc, dt)
    return float(g * float(dt) * np.sum(np.abs(a)))


def significant_duration(acc, dt: float, lo: float = 0.05, hi: float = 0.95) -> float:
    """D5-95 [s] (``lo``, ``hi`` the fractions): (k_hi - k_lo) dt, k the first sample at
    which the cumulative sum of acc^2 (``husid``) reaches that fraction of its total. NaN
    for a record of zeros."""
    h = husid(acc, dt)
    total = h[-1]
    if not total > 0.0:
        return math.nan
    k_lo, k_hi = np.searchsorted(h, [lo * total, hi * total], side="left")
    return float((int(k_hi) - int(k_lo)) * float(dt))


def avgsa_periods(t_lo: float, t_hi: float, n: int = AVGSA_POINTS) -> np.ndarray:
    """The periods of AvgSa [s]: ``n`` evenly spaced in ln T over [t_lo, t_hi]."""
    return np.geomspace(float(t_lo), float(t_hi), int(n))


def avg_sa(acc, dt: float, t_lo: float, t_hi: float, zeta: float = SA_DAMPING,
           n: int = AVGSA_POINTS) -> float:
    """AvgSa [g]: the geometric mean of Sa(T) (``sa``, damping ``zeta``) over the periods
    ``avgsa_periods(t_lo, t_hi, n)`` [s] (0 < t_lo <= t_hi)."""
    if not (0.0 < t_lo <= t_hi and math.isfinite(t_hi)):
        raise ValueError(f"AvgSa periods ({t_lo!r}, {t_hi!r}): need 0 < T_lo <= T_hi")
    return float(np.exp(np.mean(np.log(sa(acc, dt, avgsa_periods(t_lo, t_hi, n), zeta)))))


def duration(acc, dt: float) -> float:
    """Time of the last sample (n - 1) dt [s]."""
    return (np.asarray(acc).size - 1) * float(dt)


def _nj_coefficients(w: float, zeta: float, h: float):
    """Nigam-Jennings matrices A (2x2) and B0, B1 (2,) for step h: the state s = (u, u')
    obeys s_{k+1} = A s_k + B0 x_k + B1 x_{k+1} for u'' + 2 zeta w u' + w^2 u = x(t), x
    linear over the step."""
    wd = w * math.sqrt(1.0 - zeta * zeta)
    e = math.exp(-zeta * w * h)
    c, s = math.cos(wd * h), math.sin(wd * h)
    r = zeta / math.sqrt(1.0 - zeta * zeta)
    A = np.array([[e * (c + r * s), e * s / wd],
                  [-w * w * e * s / wd, e * (c - r * s)]])
    # response to x = 1 (constant) and to x = t/h (ramp) over one step, from rest
    # u_step(h) = (1 - e (c + r s)) / w^2; u_step'(h) = e s / wd
    us, vs = (1.0 - e * (c + r * s)) / (w * w), e * s / wd
    # ramp x = t/h: particular solution u_p = (t/h - 2 zeta / w) / w^2, u_p' = 1/(h w^2)
    u0p, v0p = -2.0 * zeta / (w ** 3 * h), 1.0 / (h * w * w)  # u_p(0), u_p'(0)
    uhp = A[0, 0] * u0p + A[0, 1] * v0p  # homogeneous propagation of the particular IC
    vhp = A[1, 0] * u0p + A[1, 1] * v0p
    ur = (1.0 - 2.0 * zeta / (w * h)) / (w * w) - uhp  # u_ramp(h) from rest
    vr = v0p - vhp  # u_ramp'(h) from rest
    # x over the step = x_k (1 - t/h) + x_{k+1} t/h
    B0 = np.array([us - ur, vs - vr])
    B1 = np.array([ur, vr])
    return A, B0, B1


def _free_peak(u: float, v: float, w: float, zeta: float) -> float:
    """max |u(t)|, t >= 0, of the free vibration starting from (u, v)."""
    wd = w * math.sqrt(1.0 - zeta * zeta)
    B = (v + zeta * w * u) / wd
    S = zeta * w * B + wd * u  # u'(t) = e^{-zeta w t} (v cos(wd t) - S sin(wd t))
    if v == 0.0 and S == 0.0:
        return abs(u)
    th = math.atan2(v, S) % math.pi  # first zero of u' at wd t = th (th = 0: t = 0 is one)
    t1 = (th if th > 0.0 else math.pi) / wd
    u1 = math.exp(-zeta * w * t1) * (u * math.cos(wd * t1) + B * math.sin(wd * t1))
    return max(abs(u), abs(u1))  # later extrema are smaller: u(t + pi/wd) = -decay u(t)


def refined(acc: np.ndarray, dt: float, m: int) -> np.ndarray:
    """The piecewise-linear record at m times its samples (exact: it is linear between
    samples): float64[(n - 1) m + 1] at t = k dt / m."""
    t_f = np.arange((acc.size - 1) * m + 1) * (dt / m)
    return np.interp(t_f, np.arange(acc.size) * dt, acc)


def nj_response(x, w: float, zeta: float, h: float, *, rate: bool = False):
    """The exact response of u'' + 2 zeta w u' + w^2 u = x(t), at rest at t = 0, to the
    piecewise-linear load x (float64[n], x_k at t = k h): the Nigam-Jennings recurrence
    (``_nj_coefficients``) written as a second-order recursive filter (``lfilter``).
    Returns (u, v_end): u float64[n] at the samples and the rate u' at the last sample;
    with ``rate`` (u, v), v = u' float64[n] at every sample (a second filter, same
    denominator)."""
    # here, not at import: scipy.signal costs a scene (and every command) ~0.3 s of start-up
    from scipy.signal import lfilter

    A, B0, B1 = _nj_coefficients(w, zeta, h)
    # the recurrence as a filter: u = H(z) x with
    # H = [B1u, B0u - a22 B1u + a12 B1v, a12 B0v - a22 B0u] / [1, -tr A, det A]
    den = np.array([1.0, -(A[0, 0] + A[1, 1]), A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]])
    nu = np.array([B1[0], B0[0] - A[1, 1] * B1[0] + A[0, 1] * B1[1],
                   A[0, 1] * B0[1] - A[1, 1] * B0[0]])
    # initial filter state (transposed direct form II) that starts the state at rest
    # with x_0 possibly != 0: u_0 = 0 and u_1 = B0[0] x_0 + B1[0] x_1
    zu = np.array([-nu[0] * x[0], (B0[0] - nu[1]) * x[0]])
    u = lfilter(nu, den, x, zi=zu)[0]
    if rate:
        # V = [B1v, B0v - a11 B1v + a21 B1u, a21 B0u - a11 B0v] / the same denominator
        nv = np.array([B1[1], B0[1] - A[0, 0] * B1[1] + A[1, 0] * B1[0],
                       A[1, 0] * B0[0] - A[0, 0] * B0[1]])
        zv = np.array([-nv[0] * x[0], (B0[1] - nv[1]) * x[0]])
        return u, lfilter(nv, den, x, zi=zv)[0]
    # the rate at the end only (for the free vibration after the record), from the
    # recurrence's first row over the last step, then its second row: one filter
    # instead of two (u' over the whole record is never needed)
    if u.size > 1:
        v_prev = (u[-1] - A[0, 0] * u[-2] - B0[0] * x[-2] - B1[0] * x[-1]) / A[0, 1]
        v_end = A[1, 0] * u[-2] + A[1, 1] * v_prev + B0[1] * x[-2] + B1[1] * x[-1]
    else:
        v_end = 0.0
    return u, v_end


def free_vibration(u: float, v: float, w: float, zeta: float, tau) -> tuple:
    """The free vibration of u'' + 2 zeta w u' + w^2 u = 0 from (u, v) at tau = 0:
    (u(tau), u'(tau)), float64 like ``tau`` [s] (0 <= zeta < 1)."""
    wd = w * math.sqrt(1.0 - zeta * zeta)
    tau = np.asarray(tau, dtype=np.float64)
    B = (v + zeta * w * u) / wd
    e = np.exp(-zeta * w * tau)
    c, s = np.cos(wd * tau), np.sin(wd * tau)
    return (e * (u * c + B * s),
            e * ((B * wd - zeta * w * u) * c - (u * wd + zeta * w * B) * s))


def sa(acc, dt: float, periods, zeta: float = SA_DAMPING, *, points_per_period: int = 32,
       max_refine: int = 64) -> np.ndarray:
    """Pseudo-spectral acceleration Sa(T) = (2 pi / T)^2 max_t |u(t)| [units of acc: g for
    project records], float64[n_periods] for ``periods`` [s] (any shape, flattened order
    kept; T = 0 gives PGA). Exact Nigam-Jennings recurrence for the piecewise-linear record
    (module docstring), from rest, the free vibration after the record included; 0 <= zeta
    < 1. A period shorter than ``points_per_period`` steps is computed on the record
    resampled at dt / m, m = min(ceil(points_per_period dt / T), max_refine)."""
    a = _check(acc, dt)
    T = np.asarray(periods, dtype=np.float64).ravel()
    if not np.all(np.isfinite(T)) or np.any(T < 0.0):
        raise ValueError("periods must be finite and >= 0 [s]")
    if not (0.0 <= zeta < 1.0):
        raise ValueError(f"zeta = {zeta!r}: must be in [0, 1)")
    out = np.empty(T.size)
    resampled: dict[int, np.ndarray] = {1: a}
    for j, Tj in enumerate(T):
        if Tj == 0.0:
            out[j] = pga(a)
            continue
        w = 2.0 * math.pi / Tj
        m = int(min(max(math.ceil(points_per_period * dt / Tj), 1), max_refine))
        if m not in resampled:
            resampled[m] = refined(a, dt, m)
        x = -resampled[m]  # u'' + 2 zeta w u' + w^2 u = -xg''
        u, v_end = nj_response(x, w, zeta, dt / m)
        peak = max(float(np.max(np.abs(u))), _free_peak(float(u[-1]), float(v_end), w, zeta))
        out[j] = w * w * peak
    return out
