"""Peak memory of ``rocksweep.risk`` against the hazard's length: a fragility of 3 curves
with ``--samples`` bootstrap resamples over hazard curves of 1e3 to 2e5 levels, each size
in a fresh process (peak resident set, ``ru_maxrss``), the start-up's peak (importing
rocksweep, building the inputs) printed apart. The integral takes its quadrature nodes in
chunks (``analysis.risk.CHUNK_ELEMENTS``), so the peak grows with the hazard only by its
nodes (levels x 16 x 2 float64) and not by levels x 16 x curves x samples (1.43 GiB for
200 000 levels, 20 resamples, before). Target: < 1 GB at 200 000 levels.

    python scripts/bench_risk_memory.py            # ~1 min
    python scripts/bench_risk_memory.py --samples 200
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import _here  # noqa: F401  (this checkout's package)

CHILD = r"""
import resource, sys, time
import numpy as np, pandas as pd, xarray as xr
import rocksweep
n, samples, run = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3] == "1"
x = np.geomspace(1e-3, 10.0, n)
hz = pd.DataFrame({"PGA [g]": x, "annual_rate": 1e-4 * x ** -2.0})
rng = np.random.default_rng(0)
med = np.array([0.2, 0.4, 0.8])
fr = xr.Dataset({"im_median": (("lam",), med), "beta": (("lam",), np.full(3, 0.4)),
                 "im_median_samples": (("lam", "sample"), med[:, None] * np.exp(
                     0.1 * rng.standard_normal((3, samples)))),
                 "beta_samples": (("lam", "sample"), 0.4 + 0.05 * rng.random((3, samples)))},
                coords={"lam": [0.0, 0.2, 0.4]},
                attrs={"im": "PGA", "im_units": "g", "ci": 0.9})
t = time.perf_counter()
if run:
    rk = rocksweep.risk(fr, hz)
    assert np.isfinite(rk.annual_rate.values).all()
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024, time.perf_counter() - t)
"""


def peak(n: int, samples: int, run: bool) -> tuple[int, float]:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path[1:3])}
    out = subprocess.run([sys.executable, "-c", CHILD, str(n), str(samples), "1" if run
                          else "0"], capture_output=True, text=True, env=env, check=True)
    b, s = out.stdout.split()
    return int(b), float(s)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20)
    a = ap.parse_args()
    t0 = time.perf_counter()
    base, _ = peak(200_000, a.samples, False)
    print(f"risk: 3 curves x {a.samples} resamples; start-up and inputs at 200 000 levels: "
          f"peak {base / 2**20:.0f} MiB")
    print(f"{'levels':>8}  {'peak MiB':>9}  {'risk s':>7}")
    worst = 0
    for n in (1_000, 10_000, 100_000, 200_000):
        b, s = peak(n, a.samples, True)
        worst = max(worst, b)
        print(f"{n:8d}  {b / 2**20:9.0f}  {s:7.2f}")
    print(f"largest peak {worst / 2**20:.0f} MiB (target < 1024); "
          f"{time.perf_counter() - t0:.0f} s in all")
    return 0 if worst < 2**30 else 1


if __name__ == "__main__":
    sys.exit(main())
