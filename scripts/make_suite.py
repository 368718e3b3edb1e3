"""Write the synthetic record suite rocksweep ships (records/suite/SYN01.AT2 ... SYN20.AT2).

    python scripts/make_suite.py                # writes records/suite/ (refuses to overwrite)
    python scripts/make_suite.py --overwrite    # regenerate in place
    python scripts/make_suite.py --check        # exit 1 if the shipped files differ

No recorded motion can be downloaded here, so the project makes a suite it may share: 20
records of the site-based stochastic ground-motion model of Rezaeian & Der Kiureghian:

- S. Rezaeian, A. Der Kiureghian (2008), "A stochastic ground motion model with separable
  temporal and spectral nonstationarities", Earthquake Engng Struct. Dyn. 37(13), 1565-1584
  (the model and its high-pass post-filter);
- S. Rezaeian, A. Der Kiureghian (2010), "Simulation of synthetic ground motions for
  specified earthquake and site characteristics", Earthquake Engng Struct. Dyn. 39(10),
  1155-1180 (its physical parameters, the values below are around their typical ones).

The model, as implemented here (times in s, accelerations in g, DT = 0.01 s):

1. Filtered white noise with a time-varying filter: for standard normal u_i at t_i = i DT,
   x(t_k) = sum_{i <= k} h(t_k - t_i; f(t_i)) u_i / sigma(t_k), where h(s; f) is the unit
   impulse response of an oscillator of frequency 2 pi f and damping ratio zeta_f,
   (w / sqrt(1 - zeta_f^2)) exp(-zeta_f w s) sin(w sqrt(1 - zeta_f^2) s), and sigma(t_k)^2
   = sum_{i <= k} h(t_k - t_i; f(t_i))^2 makes x of unit variance. The filter frequency
   drifts linearly, f(t) = f_mid + f' (t - t_mid) [Hz], kept above F_MIN. The sum is
   truncated where exp(-zeta_f 2 pi f s) < 1e-9.
2. Modulation by the gamma-shaped envelope q(t) = a1 (t - T0)^(a2 - 1) exp(-a3 (t - T0))
   (t > T0), whose (a2, a3) give the Arias-intensity build-up of the target D5-95
   (significant duration, 5 to 95 % of the Arias intensity) and t_mid (time of 45 % of it),
   and a1 gives the expected Arias intensity I_a = (pi / 2) * integral of q^2 dt [s g].
3. The high-pass post-filter: the simulated record is the acceleration y'' of a critically
   damped oscillator y'' + 2 w_c y' + w_c^2 y = a(t), w_c = 2 pi 0.2 Hz (scipy's lsim,
   exact for the piecewise-linear a), so the ground ends at rest (velocity ~ 0).

Five parameter sets ("scenarios") with four realisations each (numpy PCG64 from
SeedSequence(SEED).spawn(20)); each record runs until 99.9 % of its envelope's Arias
intensity plus 5 s, clipped to 20-40 s. The records are meant for scaled (stripe) analyses:
their amplitudes are realistic, not targeted at any site.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SUITE = ROOT / "records" / "suite"

SEED = 20261120
DT = 0.01  # s
T0 = 0.5  # s of rest before the motion starts
F_MIN = 0.3  # Hz: the filter frequency's floor
F_CORNER = 0.2  # Hz: the high-pass post-filter's corner
DURATION_RANGE = (20.0, 40.0)  # s
TAIL = 5.0  # s after 99.9 % of the envelope's Arias intensity
REALISATIONS = 4

# name: (I_a [s g], D5-95 [s], t_mid [s after T0], f_mid [Hz], f' [Hz/s], zeta_f [-])
SCENARIOS = {
    "S1": (0.05, 10.0, 6.0, 5.0, -0.10, 0.25),  # short, moderate, stiff site
    "S2": (0.10, 15.0, 9.0, 4.0, -0.08, 0.20),  # typical
    "S3": (0.03, 20.0, 11.0, 6.0, -0.05, 0.30),  # long, weak, high frequency
    "S4": (0.20, 12.0, 7.0, 3.0, -0.06, 0.20),  # strong, lower frequency
    "S5": (0.08, 22.0, 12.0, 2.5, -0.04, 0.35),  # long, soft site
}


def envelope_params(ia: float, d595: float, tmid: float) -> tuple[float, float, float]:
    """(a1, a2, a3) of q(t) = a1 t^(a2 - 1) exp(-a3 t) (t from T0) for the expected Arias
    intensity ia [s g], significant duration d595 [s] and t_mid [s]: q^2 is a gamma density
    of shape k = 2 a2 - 1 and rate 2 a3 up to a constant, so the Arias build-up is its CDF."""
    from scipy.optimize import brentq
    from scipy.special import gammainc, gammaincinv, gammaln

    def d_over_tmid(k: float) -> float:  # independent of the rate
        return (gammaincinv(k, 0.95) - gammaincinv(k, 0.05)) / gammaincinv(k, 0.45)

    k = brentq(lambda kk: d_over_tmid(kk) - d595 / tmid, 1.0 + 1e-9, 200.0)
    rate = gammaincinv(k, 0.45) / tmid
    a2, a3 = 0.5 * (k + 1.0), 0.5 * rate
    # integral of t^(k - 1) exp(-rate t) dt = Gamma(k) / rate^k; I_a = (pi/2) a1^2 * that
    log_int = gammaln(k) - k * math.log(rate)
    a1 = math.sqrt(ia / (0.5 * math.pi) * math.exp(-log_int))
    assert abs(gammainc(k, rate * tmid) - 0.45) < 1e-9
    return a1, a2, a3


def envelope(t: np.ndarray, a1: float, a2: float, a3: float) -> np.ndarray:
    s = np.maximum(t - T0, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = a1 * np.exp((a2 - 1.0) * np.log(s) - a3 * s)
    return np.where(t > T0, q, 0.0)


def record_length(a2: float, a3: float) -> float:
    from scipy.special import gammaincinv

    t999 = T0 + gammaincinv(2.0 * a2 - 1.0, 0.999) / (2.0 * a3)
    return float(np.clip(round(t999 + TAIL, 2), *DURATION_RANGE))


def filtered_noise(t: np.ndarray, u: np.ndarray, tmid: float, fmid: float, fdot: float,
                   zeta: float) -> np.ndarray:
    """Unit-variance white noise through the time-varying filter (step 1 of the model)."""
    f = np.maximum(fmid + fdot * (t - (T0 + tmid)), F_MIN)  # Hz, at the emission times
    w = 2.0 * math.pi * f
    wd = w * math.sqrt(1.0 - zeta * zeta)
    n = t.size
    n_lag = min(n, int(math.ceil(-math.log(1e-9) / (zeta * 2.0 * math.pi * F_MIN) / DT)) + 1)
    num = np.zeros(n)
    var = np.zeros(n)
    for lag in range(n_lag):  # h(lag DT; f(t_i)) for every emission i, added at k = i + lag
        s = lag * DT
        h = w / math.sqrt(1.0 - zeta * zeta) * np.exp(-zeta * w * s) * np.sin(wd * s)
        num[lag:] += h[:n - lag] * u[:n - lag]
        var[lag:] += h[:n - lag] ** 2
    return np.divide(num, np.sqrt(var), out=np.zeros(n), where=var > 0.0)


def highpass(a: np.ndarray) -> np.ndarray:
    """y'' of y'' + 2 w_c y' + w_c^2 y = a(t), from rest (step 3 of the model)."""
    from scipy.signal import lsim

    wc = 2.0 * math.pi * F_CORNER
    t = np.arange(a.size) * DT
    _, y, _ = lsim(([1.0, 0.0, 0.0], [1.0, 2.0 * wc, wc * wc]), a, t)
    return y


def suite_record(index: int) -> tuple[np.ndarray, float, str]:
    """(acc [g], dt [s], title) of record SYN{index + 1:02d} (index 0..19)."""
    names = list(SCENARIOS)
    scen = names[index // REALISATIONS]
    ia, d595, tmid, fmid, fdot, zeta = SCENARIOS[scen]
    a1, a2, a3 = envelope_params(ia, d595, tmid)
    n = round(record_length(a2, a3) / DT) + 1
    t = np.arange(n) * DT
    rng = np.random.default_rng(np.random.SeedSequence(SEED).spawn(len(names)
                                                                  * REALISATIONS)[index])
    x = filtered_noise(t, rng.standard_normal(n), tmid, fmid, fdot, zeta)
    acc = highpass(envelope(t, a1, a2, a3) * x)
    acc[0] = 0.0  # the post-filter's direct term starts at a(0) = 0 already; make it exact
    title = (f"rocksweep synthetic, Rezaeian & Der Kiureghian (2010) site-based model, "
             f"scenario {scen} #{index % REALISATIONS + 1}: Ia = {ia:g} s.g, D5-95 = "
             f"{d595:g} s, tmid = {tmid:g} s, f_mid = {fmid:g} Hz, f' = {fdot:g} Hz/s, "
             f"zeta_f = {zeta:g}, f_c = {F_CORNER:g} Hz, seed {SEED}/{index}")
    return acc, DT, title


FILES = {f"SYN{i + 1:02d}.AT2": i for i in range(len(SCENARIOS) * REALISATIONS)}


def main(argv: list[str] | None = None) -> int:
    from make_records import write_records  # scripts/: the .AT2 writing and --check loop

    from rocksweep.physics.intensity import pgv, sa

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=SUITE, help="directory (default "
                    "records/suite/)")
    ap.add_argument("--overwrite", action="store_true", help="replace existing files")
    ap.add_argument("--check", action="store_true",
                    help="compare the files in --out with what this script writes")
    args = ap.parse_args(argv)
    if not args.check:
        args.out.mkdir(parents=True, exist_ok=True)

    def describe(path, rec) -> str:
        s02, s10 = sa(rec.acc, rec.dt, [0.2, 1.0])
        return (f"{path.name}: {rec.duration:5.1f} s, PGA = {rec.pga:.3f} g, PGV = "
                f"{pgv(rec.acc, rec.dt):.3f} m/s, Sa(0.2) = {s02:.3f} g, Sa(1.0) = "
                f"{s10:.3f} g, {path.stat().st_size} bytes")

    return write_records(args.out, ((name, *suite_record(i)) for name, i in FILES.items()),
                         check=args.check, overwrite=args.overwrite, describe=describe)

if __name__ == "__main__":
    sys.exit(main())
