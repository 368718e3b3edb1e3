"""Kernel against the reference under a vertical ground acceleration (docs/accuracy.md).

Rigid blocks under a one-cycle sine and a vertical harmonic acting with it, both given as
two-column records (DT = 5 ms), at the default preset: A_ratio from 1.0 to 6.0 in steps of
0.05 (through the uplift and both overturning thresholds) for four cases (alpha, pulse
period [s], vertical amplitude [g], frequency [rad/s], phase [deg]); prints every point
whose outcome differs from the reference's, the thresholds the reference crosses, and
the count.

    python scripts/vertical_check.py      # ~5-10 min on 2 cores
"""

import math

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np

from rocksweep.compute.single import run_point
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody
from rocksweep.physics.ground_motion import recorded
from rocksweep.physics.points import Point
from rocksweep.physics.records import parse_record
from rocksweep.physics.reference import reference_run


def two(t, a, name):
    """A two-column record file's record (t [s], a [g])."""
    text = "\n".join(f"{ti:.8f} {ai:.10e}" for ti, ai in zip(t, a, strict=True))
    return parse_record(text.encode(), f"{name}.txt")


CASES = [(0.2, 1.0, 0.5, 2 * np.pi * 3, 0.0), (0.15, 0.5, 0.8, 2 * np.pi * 2, 45.0),
         (0.25, 2.0, 0.2, 2 * np.pi * 5, 90.0), (0.2, 1.0, 0.8, 2 * np.pi * 1.0, 180.0)]
dt = 0.005
t = np.arange(0.0, 3.0 + dt / 2, dt)
num = Numerics()
words = {0: "safe", 1: "mode1", 2: "mode2"}
bad = tot = 0
for alpha, Tp, av, wv, ph in CASES:
    h = two(t, np.where(t <= Tp, np.sin(2 * np.pi * t / Tp), 0.0), "h")
    v = two(t, np.where(t <= Tp, av * np.sin(wv * t + np.radians(ph)), 0.0), "v")
    blk = BlockBody(alpha=alpha)
    p = 2 * np.pi / 1.5
    prev = None
    motion = recorded(h, v)
    for A in np.arange(1.0, 6.0, 0.05):
        pt = Point(blk, 1.0, motion, math.nan, float(A), p=p)
        k = run_point(pt, num, history=False).outcome
        r = words[reference_run(pt, num)["outcome"]]
        tot += 1
        if k != r:
            bad += 1
            print("DIFF", alpha, Tp, av, wv, ph, round(A, 3), k, r, flush=True)
        if prev is not None and r != prev:
            print("threshold", alpha, Tp, av, round(A, 3), prev, "->", r, flush=True)
        prev = r
print("total", tot, "diff", bad)
