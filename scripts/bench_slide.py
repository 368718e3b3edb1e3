"""What the sliding base costs: Figure 3(a)'s grid swept at body.mu values against the
no-slip sweep, measured side by side in one run (docs/sliding.md, "Cost").

    python scripts/bench_slide.py                 # mu 0.5, the full 80 x 80 x 3 grid
    python scripts/bench_slide.py --mu 0.3 0.5 0.7 --num 40 --repeat 3

Each sweep runs once to compile (or load) its variant, then ``--repeat`` rounds, the
scenes alternating within a round, each on one thread (``compute.driver.sweep_arrays``,
jobs=1: the certification of close calls included, as a sweep runs it); the best CPU
time of the process per point is reported (less sensitive to a shared machine's load than
wall time), with the RK4 evaluations per point (regular + event steps: a count, not a
timing) and the ratios to the no-slip sweep. Prints the load average.
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


def _scene(sets: list[str]):
    from rocksweep.compute.driver import sweep_arrays
    from rocksweep.scene.parse import load_scene

    scene = load_scene(ROOT / "configs" / "fig3a.yaml", sets)
    sweep_arrays(scene, jobs=1)  # compile or load the variant
    return scene


def _timed(scene) -> tuple[float, dict]:
    """(CPU seconds per point, arrays) of one sweep of the scene on one thread."""
    from rocksweep.compute.driver import sweep_arrays

    c0 = time.process_time()
    arrays = sweep_arrays(scene, jobs=1)[0]
    return (time.process_time() - c0) / scene.size, arrays


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mu", type=float, nargs="+", default=[0.5])
    ap.add_argument("--num", type=int, default=80, help="points per axis (80: the paper's)")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    grid = [f"pulse.w_over_p={{start: 0.075, stop: 6, num: {args.num}}}",
            f"pulse.A_ratio={{start: 0.1, stop: 8, num: {args.num}}}"]
    print(f"load average {os.getloadavg()[0]:.2f}; Figure 3(a)'s grid, {args.num} x "
          f"{args.num} x 3 lam, one thread, CPU time, best of {args.repeat} alternating rounds")
    scenes = [_scene(grid), *(_scene([*grid, f"body.mu={mu}"]) for mu in args.mu)]
    best = [np.inf] * len(scenes)
    arrays: list[dict] = [{}] * len(scenes)
    for _ in range(args.repeat):
        for i, sc in enumerate(scenes):
            t, arrays[i] = _timed(sc)
            best[i] = min(best[i], t)
    evals = [float(np.sum(a["steps"]) + np.sum(a["event_steps"])) / sc.size
             for a, sc in zip(arrays, scenes, strict=True)]
    t0, e0, base = best[0], evals[0], arrays[0]
    print(f"no slip   : {t0 * 1e6:8.1f} us/point  {e0:8.1f} RK4 evaluations/point  "
          f"({scenes[0].size} points)")
    for mu, t, e, arr in zip(args.mu, best[1:], evals[1:], arrays[1:], strict=True):
        same = float(np.mean(arr["outcome"] == base["outcome"]))
        slid = float(np.mean(arr["slide_max"] > 0))
        print(f"mu = {mu:<5g}: {t * 1e6:8.1f} us/point  {e:8.1f} RK4 evaluations/point  "
              f"time x{t / t0:.2f}, evaluations x{e / e0:.2f}; outcome as no slip at "
              f"{same:.1%} of the points, slid at {slid:.1%}")
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
