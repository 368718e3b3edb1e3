"""A floor spectrum, timed: 20 building periods x 20 records x 5 PGA stripes = 2000 runs.

The body (Figure 3(a)'s, lam 0.2) stands on the floor of a one-mode building (damping
5%, participation 1.3) of periods 0.1-2 s (20, log-spaced), under the 20 shipped records
(records/suite, 20-40 s) scaled to 5 PGA stripes, p = 2 rad/s. Prints, measured in one
run on this machine (warm: numba's cache filled by a first sweep, reported apart):

1. start-up: the same sweep at one floor period and one stripe (20 runs, 1% of the study):
   Python, imports, reading and hashing the records, their IMs, the scene's cost check
   (which builds the longest and finest floor motions), writing the file;
2. the sweep through ``python -m rocksweep sweep SCENE -o OUT --jobs 2`` (start-up,
   the 400 floor motions and HDF5 writing included; target < 15 s on 2 cores), best of
   ``--repeat``, and compute = wall - start-up;
3. the 400 floor motions alone (``physics.floor.floor_motion``, their ring-down included),
   one thread, and the floor motions' mean length against the records'.

    python scripts/bench_floors.py            # ~1 min on 2 cores
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import _here  # noqa: F401 (this checkout's package first)

ROOT = Path(__file__).resolve().parents[1]
SCENE = f"""name: "bench: floor spectrum, 20 periods x 20 records x 5 PGA stripes"
body: {{wn_over_p: 2.43, zeta: 0.05, alpha_cg: 0.15, alpha_A: 0.28, mA_over_m: 0.47,
       IA_ratio: 0.56}}
impact: {{lam: 0.2}}
ground:
  records: "{ROOT / 'records' / 'suite'}/*.AT2"
  scale: {{im: PGA, values: [0.1, 0.2, 0.4, 0.8, 1.6]}}
  p: 2.0
floor: {{period: {{start: 0.1, stop: 2.0, num: 20}}, damping: 0.05, participation: 1.3}}
"""


CPU: dict[float, float] = {}  # wall time of a command -> its CPU seconds (user + sys)


def timed(cmd: list[str], env: dict) -> float:
    """Wall seconds of a command (its CPU seconds, children included, in ``CPU``)."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    res = subprocess.run(cmd, env=env, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{res.stdout}{res.stderr}")
    CPU[dt] = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return dt


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="timed sweeps (best of)")
    args = ap.parse_args(argv)
    print(f"load average at start: {os.getloadavg()}")
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    with tempfile.TemporaryDirectory(prefix="rocksweep-bench-floors-") as tmp:
        scene = Path(tmp) / "scene.yaml"
        scene.write_text(SCENE)
        out = Path(tmp) / "floors.h5"
        base = [sys.executable, "-m", "rocksweep", "sweep", str(scene), "-o", str(out),
                "--jobs", "2", "--quiet", "--overwrite"]
        first = timed(base, env)
        one = [*base, "--set", "floor.period=0.5", "--set", "ground.scale.values=[0.4]"]
        starts = [timed(one, env) for _ in range(max(1, args.repeat))]
        walls = [timed(base, env) for _ in range(max(1, args.repeat))]
        start, wall = min(starts), min(walls)
        import numpy as np

        import rocksweep

        ds = rocksweep.open(out)
        runs = int(ds["outcome"].size)
        dims = " x ".join(f"{ds.sizes[d]} {d}" for d in ds["outcome"].dims)
        print(f"\n{runs} runs ({dims}); first sweep (numba cache as found): {first:.2f} s")
        print(f"1. start-up (the sweep of 1 period x 1 stripe): {start:.2f} s wall, "
              f"{CPU[start]:.2f} s CPU (best of {len(starts)})")
        print(f"2. sweep --jobs 2: {wall:.2f} s wall, {CPU[wall]:.2f} s CPU (best of "
              f"{len(walls)}: {', '.join(f'{w:.2f}' for w in walls)}); compute = wall - "
              f"start-up = {wall - start:.2f} s; target < 15 s -> "
              f"{'met' if wall < 15 else 'NOT met'} (at load {os.getloadavg()[0]:.1f} on "
              f"{os.cpu_count()} cores)")
        cpu = float(ds.attrs.get("cpu_time", float("nan")))
        print(f"   workers' CPU time: {cpu:.2f} s = {1e3 * cpu / runs:.2f} ms a run; "
              f"{int(ds.attrs['steps_total']):,} RK4 steps; overturned "
              f"{float((ds['outcome'] > 0).mean()):.0%}")

        from rocksweep.physics.floor import Mode, floor_motion
        from rocksweep.scene.parse import load_scene

        sc = load_scene(scene)
        periods = sc.axis("floor.period").values
        t0 = time.perf_counter()
        lengths = []
        for rec in sc.suite.records:
            for T in periods:
                acc, h = floor_motion(rec.acc, rec.dt, (Mode(T, 0.05, 1.3),))
                lengths.append(((acc.size - 1) * h, rec.duration))
        t_fl = time.perf_counter() - t0
        ln = np.array(lengths)
        print(f"3. the {len(lengths)} floor motions alone: {t_fl:.2f} s (one thread); "
              f"{ln[:, 0].mean():.1f} s long on average against the records' "
              f"{ln[:, 1].mean():.1f} s (ring-down)")
    print(f"\nload average at end: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
