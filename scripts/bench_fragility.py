"""A FEMA-P695-sized fragility study, timed: 44 records x 16 PGA stripes x 3 lam.

Prints, measured side by side in one run:

1. the study's wall time through ``python -m rocksweep sweep SCENE -o OUT --jobs 2``, start-up
   (Python, imports, numba's cache load, reading and hashing the 44 records, their IMs)
   and HDF5 writing included: 2 112 runs of 20-40 s records on the Figure 3(a) body
   (target: < 10 s on 2 cores), then ``rocksweep fragility`` on it (overturning; then 3
   nested states, each alone and ``--joint``). The first sweep fills
   numba's cache if it is cold and is reported apart; the timed sweep is the best of
   ``--repeat``.
2. the cost of one run against the scipy reference (``rocksweep.physics.reference``,
   DOP853 with event location) on the same record, body and scaled amplitude: a few
   points across the stripes (``--ref-points``), the kernel's CPU time per run (each run
   through the sweep's own path, ``compute.dispatch.run_record``, best of 5) and the
   reference's wall time (target: kernel <= 1/300 of the reference).
3. the per-record intensity measures (PGA, PGV, Sa at 0.2 and 1 s: ``make_suite``) as a
   share of the sweep's wall time (target: < 1 %).

The 44 records: the 20 shipped (records/suite) and 24 more realisations of the same
stochastic model (scripts/make_suite.py's generator with another seed), written to a
temporary directory.

    python scripts/bench_fragility.py             # ~25 s (of which ~7 s make records)
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENE = """name: "bench: Figure 3(a) body, 44 records x 16 PGA stripes x 3 lam"
body: {wn_over_p: 2.43, zeta: 0.05, alpha_cg: 0.15, alpha_A: 0.28, mA_over_m: 0.47,
       IA_ratio: 0.56}
impact: {lam: [0.0, 0.2, 0.4]}
ground:
  records: "*.AT2"
  scale: {im: PGA, values: {start: 0.1, stop: 1.6, num: 16}}
  p: 2.0
"""
N_RECORDS = 44


def make_suite_module():
    spec = importlib.util.spec_from_file_location("make_suite", ROOT / "scripts" / "make_suite.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def write_records(folder: Path) -> list[Path]:
    """The 20 shipped records and 24 new realisations (seed + 1) as .AT2 files."""
    from rocksweep.physics.records import write_at2

    ms = make_suite_module()
    paths = []
    for f in sorted((ROOT / "records" / "suite").glob("*.AT2")):
        shutil.copy(f, folder / f.name)
        paths.append(folder / f.name)
    ms.SEED = ms.SEED + 1
    i = 0
    while len(paths) < N_RECORDS:
        acc, dt, title = ms.suite_record(i % 20)
        path = folder / f"SYN2_{i + 1:02d}.AT2"
        write_at2(path, acc, dt, title.replace("seed ", "seed+1 "))
        paths.append(path)
        i += 1
    return paths


def timed(cmd: list[str], env: dict) -> float:
    t0 = time.perf_counter()
    res = subprocess.run(cmd, env=env, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if res.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{res.stdout}{res.stderr}")
    return dt


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2, help="timed sweeps (best of)")
    ap.add_argument("--ref-points", type=int, default=3,
                    help="points compared with the reference (spread over the stripes)")
    args = ap.parse_args(argv)
    print(f"load average at start: {os.getloadavg()}")
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    with tempfile.TemporaryDirectory(prefix="rocksweep-bench-fragility-") as tmp:
        folder = Path(tmp)
        t0 = time.perf_counter()
        paths = write_records(folder)
        print(f"made {len(paths)} records in {time.perf_counter() - t0:.1f} s (not timed below)")
        scene = folder / "scene.yaml"
        scene.write_text(SCENE)
        out = folder / "frag.h5"
        sweep = [sys.executable, "-m", "rocksweep", "sweep", str(scene), "-o", str(out),
                 "--jobs", "2", "--quiet", "--overwrite"]
        first = timed(sweep, env)
        walls = [timed(sweep, env) for _ in range(max(1, args.repeat))]
        wall = min(walls)
        sys.path.insert(0, str(ROOT))
        import rocksweep

        ds = rocksweep.open(out)
        runs = int(ds["outcome"].size)
        dims = " x ".join(f"{ds.sizes[d]} {d}" for d in ds["outcome"].dims)
        npts = ds["record_npts"].values
        dt = ds["record_dt"].values
        dur = (npts - 1) * dt
        print("\n1. the study through `rocksweep sweep --jobs 2` (start-up and writing "
              "included)")
        print(f"   {runs} runs ({dims}), records of {dur.min():.1f}-{dur.max():.1f} s "
              f"({int(npts.min())}-{int(npts.max())} samples)")
        print(f"   first sweep (numba cache as found): {first:.2f} s")
        print(f"   wall time: {wall:.2f} s (best of {len(walls)}: "
              f"{', '.join(f'{w:.2f}' for w in walls)}); target < 10 s -> "
              f"{'met' if wall < 10 else 'NOT met'}")
        cpu = float(ds.attrs.get("cpu_time", float("nan")))
        print(f"   workers' CPU time on the runs: {cpu:.2f} s = {1e3 * cpu / runs:.3f} ms "
              f"a run; {int(ds.attrs['steps_total']):,} RK4 steps")
        fr = [sys.executable, "-m", "rocksweep", "fragility", str(out), "--json"]
        t_fr = timed(fr, env)
        print(f"   rocksweep fragility (200 bootstrap resamples): {t_fr:.2f} s")
        three = fr + ["--state", "theta:0.25,theta:0.5,overturn"]
        t_sep, t_joint = timed(three, env), timed(three + ["--joint"], env)
        print(f"   rocksweep fragility --state theta:0.25,theta:0.5,overturn: each state "
              f"alone {t_sep:.2f} s, --joint (one beta, its likelihood-ratio test) "
              f"{t_joint:.2f} s")

        # 2. per run against the reference
        from rocksweep.compute.dispatch import run_record
        from rocksweep.compute.sweep import level
        from rocksweep.kernel import chunk_kernel
        from rocksweep.kernel import layout as L  # noqa: N812
        from rocksweep.physics.reference import reference_run
        from rocksweep.scene.grid import Grid
        from rocksweep.scene.parse import load_scene

        sc = load_scene(scene)
        grid = Grid(sc)
        rec_i = 3  # SYN04: 26 s
        name = sc.suite.names[rec_i]
        S = len(sc.suite.levels)
        picks = np.linspace(S // 4, S - 1, max(1, args.ref_points)).round().astype(int)
        # flat indices of (lam 0.2, record rec_i, stripe s)
        flat = np.array([np.ravel_multi_index((1, rec_i, s), grid.shape) for s in picks])
        cr = grid.rows_at(flat)
        kernel = chunk_kernel(int(cr.kinds[0]), level(sc), L.GROUND_ANY)
        rows = cr.rows
        outs = np.empty((flat.size, L.N_OUT))
        print(f"\n2. one run against the scipy reference (record {name}, lam 0.2, "
              f"{sc.suite.records[rec_i].duration:.1f} s, p = 2 rad/s)")
        print(f"   {'PGA [g]':>8} {'kernel [ms]':>12} {'reference [s]':>14} {'ratio':>8} "
              f"{'outcomes':>18}")
        ratios = []
        vals = grid.index_values(flat)
        for j in range(flat.size):
            sel = np.zeros(flat.size, bool)
            sel[j] = True
            best = np.inf
            for _ in range(5):
                c0 = time.thread_time()
                run_record(kernel, rows, sel, outs, cr.excitations[int(cr.which[j])])
                best = min(best, time.thread_time() - c0)
            point = sc.point({**{a.name: a.values[0] for a in sc.axes},
                              **{k: v[j] for k, v in vals.items()}})
            t0 = time.perf_counter()
            ref = reference_run(point, sc.numerics)
            t_ref = time.perf_counter() - t0
            ratios.append(t_ref / best)
            words = {0: "safe", 1: "mode1", 2: "mode2"}
            print(f"   {vals['PGA'][j]:8.2f} {1e3 * best:12.3f} {t_ref:14.3f} "
                  f"{t_ref / best:8.0f} {words.get(int(outs[j, L.OUT_OUTCOME]), '?'):>8} / "
                  f"{words.get(int(ref['outcome']), '?'):<8}")
        worst = min(ratios)
        print(f"   the kernel costs 1/{worst:.0f} of the reference at worst (target <= 1/300 "
              f"-> {'met' if worst >= 300 else 'NOT met'})")

        # 3. the IMs' share
        from rocksweep.physics.records import read_record
        from rocksweep.physics.suite import make_suite

        recs = [read_record(p) for p in sorted(folder.glob("*.AT2"))]
        best_im = np.inf
        for _ in range(3):
            t0 = time.perf_counter()
            make_suite(recs, [r.name for r in recs], "PGA", [0.1], float("nan"),
                       float("nan"), [0.2, 1.0])
            best_im = min(best_im, time.perf_counter() - t0)
        print("\n3. the per-record IMs (PGA, PGV, Sa at 0.2 and 1 s) of the 44 records")
        print(f"   {1e3 * best_im:.1f} ms = {100 * best_im / wall:.2f} % of the sweep's wall "
              f"time (target < 1 % -> {'met' if best_im < 0.01 * wall else 'NOT met'})")
    print(f"\nload average at end: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
