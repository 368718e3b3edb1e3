"""Write the two ground-motion records rocksweep ships (records/*.AT2, NGA-West2 layout).

    python scripts/make_records.py                # writes records/ (refuses to overwrite)
    python scripts/make_records.py --overwrite    # regenerate in place
    python scripts/make_records.py --check        # exit 1 if the shipped files differ

No recorded motion can be downloaded here, so the project makes its own:

- ``sine_1cycle.AT2``: one cycle of sin(2 pi t / T), T = 0.5 s, amplitude 1 g, sampled
  every DT = 1e-4 s (NPTS = 5001, the last sample at t = T), exact zeros at t = 0, T/2, T
  and exact +-1 at T/4, 3T/4. Linear interpolation reproduces the sine to (w DT)^2 / 8 =
  2.0e-7 of its amplitude (plus 5e-8 from the 7 printed digits), so a record scene with
  p = 4 pi / w_over_p is the ``sine`` pulse scene of that w_over_p.
- ``synthetic_nearfault.AT2``: a near-fault-like record, 25 s at DT = 0.005 s (NPTS =
  5001): a Mavroeidis-Papageorgiou velocity pulse (T_p = 1.6 s, gamma = 2.2, nu = 60 deg,
  starting at 4 s, velocity amplitude 0.80 m/s; ``rocksweep.physics.excitation``'s ``mp`` shape)
  plus band-limited noise: white noise (numpy PCG64, seed 20240612) through a 4th-order
  zero-phase Butterworth band-pass 0.3-12 Hz, times the envelope (t/5 s)^2 exp(2 (1 -
  t/5 s)) with 1 s cosine tapers at both ends, scaled to an RMS of 0.06 g over 3-9 s; the
  noise's net velocity is removed by subtracting a multiple of the envelope, so the
  ground ends at rest (velocity ~ 0).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "records"

SINE_PERIOD = 0.5  # s
SINE_DT = 1e-4  # s
SINE_STEPS = round(SINE_PERIOD / SINE_DT)  # 5000 intervals, a multiple of 4

NF_DT = 0.005  # s
NF_DURATION = 25.0  # s
NF_SEED = 20240612
# MP pulse: period T_p [s], gamma [-], nu [deg], start [s], velocity amplitude A_v [m/s]
NF_PULSE = {"T_p": 1.6, "gamma": 2.2, "nu_deg": 60.0, "t_start": 4.0, "A_v": 0.80}
NF_BAND = (0.3, 12.0)  # Hz
NF_ENVELOPE_PEAK = 5.0  # s
NF_TAPER = 1.0  # s
NF_NOISE_RMS = 0.06  # g, over NF_RMS_WINDOW
NF_RMS_WINDOW = (3.0, 9.0)  # s


def sine_record() -> tuple[np.ndarray, float, str]:
    """(acc [g], dt [s], title) of the one-cycle sine."""
    i = np.arange(SINE_STEPS + 1)
    acc = np.sin(2.0 * math.pi * i / SINE_STEPS)
    # exact zeros and peaks where the sine has them (sin(2 pi) is -2.4e-16 in floating point)
    acc[[0, SINE_STEPS // 2, SINE_STEPS]] = 0.0
    acc[SINE_STEPS // 4], acc[3 * SINE_STEPS // 4] = 1.0, -1.0
    title = f"rocksweep synthetic: one cycle of sin(2 pi t/T), T = {SINE_PERIOD:g} s, 1 g"
    return acc, SINE_DT, title


def mp_pulse_acc(t: np.ndarray) -> np.ndarray:
    """The record's MP pulse, ground acceleration [g] at times t [s]."""
    from rocksweep.physics.bodies import G
    from rocksweep.physics.excitation import PulseShape, mp_peak

    p = NF_PULSE
    w = 2.0 * math.pi / p["T_p"]
    shape = PulseShape("mp", gamma=p["gamma"], nu_deg=p["nu_deg"])
    # peak acceleration of an MP pulse of velocity amplitude A_v: A_v w r_max / (2 gamma)
    a_peak = p["A_v"] * w * mp_peak(p["gamma"], p["nu_deg"]) / (2.0 * p["gamma"])
    return a_peak / G * shape.acc(w * (t - p["t_start"]))


def nearfault_record() -> tuple[np.ndarray, float, str]:
    """(acc [g], dt [s], title) of the synthetic near-fault record."""
    from scipy.signal import butter, sosfiltfilt

    n = round(NF_DURATION / NF_DT) + 1
    t = np.arange(n) * NF_DT
    rng = np.random.default_rng(NF_SEED)
    white = rng.standard_normal(n)
    sos = butter(4, NF_BAND, btype="bandpass", output="sos", fs=1.0 / NF_DT)
    band = sosfiltfilt(sos, white)
    x = t / NF_ENVELOPE_PEAK
    env = x * x * np.exp(2.0 * (1.0 - x))
    ramp = np.clip(np.minimum(t, t[-1] - t) / NF_TAPER, 0.0, 1.0)
    env *= 0.5 * (1.0 - np.cos(math.pi * ramp))  # cosine tapers: exactly 0 at both ends
    noise = band * env
    win = (t >= NF_RMS_WINDOW[0]) & (t <= NF_RMS_WINDOW[1])
    noise *= NF_NOISE_RMS / math.sqrt(float(np.mean(noise[win] ** 2)))
    # remove the noise's net velocity (trapezoid rule on a uniform grid, env is 0 at both
    # ends so the rule is the plain sum; numpy >= 1.24 has no np.trapezoid)
    noise -= (noise.sum() - 0.5 * (noise[0] + noise[-1])) / env.sum() * env
    acc = mp_pulse_acc(t) + noise
    p = NF_PULSE
    title = (f"rocksweep synthetic near-fault: MP pulse T_p = {p['T_p']:g} s, gamma = "
             f"{p['gamma']:g}, nu = {p['nu_deg']:g} deg, A_v = {p['A_v']:g} m/s + noise, "
             f"seed {NF_SEED}")
    return acc, NF_DT, title


FILES = {"sine_1cycle.AT2": sine_record, "synthetic_nearfault.AT2": nearfault_record}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=RECORDS, help="directory (default records/)")
    ap.add_argument("--overwrite", action="store_true", help="replace existing files")
    ap.add_argument("--check", action="store_true",
                    help="compare the files in --out with what this script writes")
    args = ap.parse_args(argv)
    return write_records(args.out, ((name, *make()) for name, make in FILES.items()),
                         check=args.check, overwrite=args.overwrite,
                         describe=lambda path, rec: (
                             f"{path}: NPTS = {rec.npts}, DT = {rec.dt:g} s, PGA = "
                             f"{rec.pga:.7g} g, {path.stat().st_size} bytes, sha256 "
                             f"{rec.sha256}"))


def write_records(out: Path, generated, *, check: bool, overwrite: bool, describe) -> int:
    """Write each generated record (name, acc [g], DT [s], title) to ``out`` as .AT2 and
    print ``describe(path, record read back)``; with ``check``, only say whether each file
    equals what would be written. Returns the exit status (1: a file differs or cannot be
    written). Shared with ``make_suite.py``."""
    from rocksweep.cli.main import said  # the message in this command's words (--overwrite)
    from rocksweep.errors import RocksweepError
    from rocksweep.physics.records import at2_text, read_record, write_at2

    status = 0
    for name, acc, dt, title in generated:
        path = out / name
        try:
            if check:
                same = path.is_file() and path.read_text("ascii") == at2_text(acc, dt, title)
                print(f"{path}: {'up to date' if same else 'DIFFERS from the generator'}")
                status |= not same
                continue
            write_at2(path, acc, dt, title, overwrite=overwrite)
            rec = read_record(path)
        except RocksweepError as err:
            print(f"Error: {said(err)}", file=sys.stderr)
            return 1
        print(describe(path, rec))
    return status

if __name__ == "__main__":
    sys.exit(main())
