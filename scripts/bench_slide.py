"""What the sliding base costs: Figure 3(a)'s grid swept at body.mu values against the
no-slip sweep, measured side by side in one run (docs/sliding.md, "Cost").

    python scripts/bench_slide.py                 # mu 0.5, the full 80 x 80 x 3 grid
    python scripts/bench_slide.py --mu 0.3 0.5 0.7 --num 40 --repeat 3

Each sweep runs once to compile (or load) its variant, then ``--repeat`` times on one
thread (``compute.driver.sweep_arrays``, jobs=1: the certification of close calls
included, as a sweep runs it); the best time per point is reported, with the RK4
evaluations per point (regular + event steps: a count, not a timing, so it does not move
with the machine's load) and the ratios to the no-slip sweep. Prints the load average.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _sweep(sets: list[str], repeat: int) -> tuple[float, float, int, dict]:
    from rocksweep.compute.driver import sweep_arrays
    from rocksweep.scene.parse import load_scene

    scene = load_scene(ROOT / "configs" / "fig3a.yaml", sets)
    sweep_arrays(scene, jobs=1)  # compile or load the variant
    best = np.inf
    arrays: dict = {}
    for _ in range(repeat):
        t0 = time.perf_counter()
        arrays = sweep_arrays(scene, jobs=1)[0]
        best = min(best, time.perf_counter() - t0)
    n = scene.size
    evals = float(np.sum(arrays["steps"]) + np.sum(arrays["event_steps"]))
    return best / n, evals / n, n, arrays


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mu", type=float, nargs="+", default=[0.5])
    ap.add_argument("--num", type=int, default=80, help="points per axis (80: the paper's)")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    grid = [f"pulse.w_over_p={{start: 0.075, stop: 6, num: {args.num}}}",
            f"pulse.A_ratio={{start: 0.1, stop: 8, num: {args.num}}}"]
    print(f"load average {os.getloadavg()[0]:.2f}; Figure 3(a)'s grid, {args.num} x "
          f"{args.num} x 3 lam, one thread, best of {args.repeat}")
    t0, e0, n, base = _sweep(grid, args.repeat)
    print(f"no slip   : {t0 * 1e6:8.1f} us/point  {e0:8.1f} RK4 evaluations/point  "
          f"({n} points)")
    for mu in args.mu:
        t, e, _, arr = _sweep([*grid, f"body.mu={mu}"], args.repeat)
        same = float(np.mean(arr["outcome"] == base["outcome"]))
        slid = float(np.mean(arr["slide_max"] > 0))
        print(f"mu = {mu:<5g}: {t * 1e6:8.1f} us/point  {e:8.1f} RK4 evaluations/point  "
              f"time x{t / t0:.2f}, evaluations x{e / e0:.2f}; outcome as no slip at "
              f"{same:.1%} of the points, slid at {slid:.1%}")
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
