"""What the excitation costs around the kernel, against another copy of the package (A/B).

Prints, measured side by side in one run, rounds alternating between this copy and DIR
(``--against DIR``, DIR holding another copy's ``rocksweep`` package, e.g. /work/ref/main),
the order swapped every round, each measurement in a fresh process with numba's cache
filled (a first run of each, not timed, fills it):

1. a warm 1-point sweep: the whole ``rocksweep sweep`` process (Figure 3(a)'s body at one
   pulse and lam), wall and CPU s (user + sys of the child), best of ``--repeat``:
   start-up, parse, grid, file;
2. a floor + vertical sweep in one process (``rocksweep.run`` of a scene dict, jobs 1, no
   file): the shipped near-fault record with a vertical component (written from it) under
   8 floor periods, 4 A_ratio x 4 p (128 points; 8 floor motions and their verticals),
   wall and CPU s of parse + sweep, best of ``--repeat``, and the RK4 evaluations (regular
   + event, deterministic: equal when the results are);
3. the CI grid (configs/ci-small.yaml, sine and cosine pulses) the same way: the rows of
   pulse chunks.

Then the median of each and the ratio this / DIR, with the load average at the start and
the end (the machine may be shared: read ratios, not absolute times; CPU times are less
sensitive to the load than wall times).

    python scripts/bench_excitation.py --against /work/ref/main --rounds 3   # ~1-2 min
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ONE_POINT = ["--set", "pulse.w_over_p=2.0", "--set", "pulse.A_ratio=3.0",
             "--set", "impact.lam=0.2"]

# run in a fresh process of one copy: argv = [tree, tmp, what, repeat]
_SNIPPET = r"""
import json, sys, time
from pathlib import Path
import numpy as np
tree, tmp, what, repeat = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3], int(sys.argv[4])
import rocksweep
from rocksweep.physics.records import read_record, write_at2
near = tree / "records" / "synthetic_nearfault.AT2"
if what == "floor":
    rec = read_record(near)
    up = tmp / "up.AT2"
    if not up.exists():
        write_at2(up, 0.4 * np.roll(rec.acc, 200), rec.dt, "vertical")
    scene = {"body": {"kind": "block", "alpha": 0.2, "inertia": 4 / 3},
             "ground": {"record": str(near), "vertical": str(up),
                        "A_ratio": [1.0, 2.0, 3.0, 4.0], "p": [1.5, 2.0, 2.5, 3.0]},
             "floor": {"period": [0.1, 0.15, 0.2, 0.3, 0.4, 0.6, 0.8, 1.2],
                       "damping": 0.05, "participation": 1.3}}
else:
    scene = str(tree / "configs" / "ci-small.yaml")
ds = rocksweep.run(scene)  # numba's cache loaded, the variant warm
best, cpu = float("inf"), float("inf")
for _ in range(repeat):
    t0, c0 = time.perf_counter(), time.process_time()
    ds = rocksweep.run(scene)
    best, cpu = min(best, time.perf_counter() - t0), min(cpu, time.process_time() - c0)
evals = int(ds["steps"].values.sum() + ds["event_steps"].values.sum())
print(json.dumps({"s": best, "cpu": cpu, "evals": evals, "package": rocksweep.__file__}))
"""


def env_of(tree: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    return env


def load_avg() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def one_round(tree: Path, repeat: int, tmp: str) -> dict[str, float]:
    """The three measurements of one copy, each in a fresh process."""
    env = env_of(tree)
    h5 = str(Path(tmp) / f"one-{abs(hash(str(tree)))}.h5")
    sweep = [sys.executable, "-m", "rocksweep", "sweep", str(tree / "configs" / "fig3a.yaml"),
             *ONE_POINT, "-o", h5, "--overwrite", "-q"]
    subprocess.run(sweep, check=True, capture_output=True, env=env, cwd=tmp)
    walls, cpus = [], []
    for _ in range(repeat):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(sweep, check=True, capture_output=True, env=env, cwd=tmp)
        walls.append(time.perf_counter() - t0)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime)
    out = {"start": min(walls), "start_cpu": min(cpus)}
    for what in ("floor", "ci"):
        res = subprocess.run([sys.executable, "-c", _SNIPPET, str(tree), tmp, what,
                              str(repeat)], env=env, cwd=tmp, capture_output=True,
                             text=True, check=True)
        got = json.loads(res.stdout.splitlines()[-1])
        if not got["package"].startswith(str(tree)):
            raise SystemExit(f"the subprocess imported {got['package']}, not {tree}'s")
        out[what], out[f"{what}_cpu"], out[f"{what}_evals"] = got["s"], got["cpu"], got["evals"]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--against", type=Path, required=True, metavar="DIR")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=3, help="best of this many")
    args = ap.parse_args()
    other = args.against.resolve()
    if not (other / "rocksweep" / "__init__.py").is_file():
        raise SystemExit(f"--against {other}: no rocksweep package there")
    print(f"A/B: this copy ({ROOT}) against {other}; load {load_avg()}")
    got: dict[str, list[dict[str, float]]] = {"this": [], "other": []}
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.rounds):
            pair = (("other", other), ("this", ROOT))
            for who, tree in pair[::-1] if i % 2 else pair:  # ABBA: no order bias
                r = one_round(tree, args.repeat, tmp)
                got[who].append(r)
                print(f"  round {i + 1} {who:<6} 1-point sweep {r['start']:.3f} s, floor + "
                      f"vertical {r['floor']:.3f} s, ci-small {r['ci']:.3f} s  "
                      f"(load {load_avg()})", flush=True)
    print(f"  {'median':<34}{'this':>10}{'other':>10}{'this/other':>12}")
    for key, what in (("start", "warm 1-point sweep, wall s"),
                      ("start_cpu", "warm 1-point sweep, CPU s"),
                      ("floor", "floor + vertical sweep, wall s"),
                      ("floor_cpu", "floor + vertical sweep, CPU s"),
                      ("ci", "ci-small sweep, wall s"), ("ci_cpu", "ci-small sweep, CPU s")):
        a = float(np.median([r[key] for r in got["this"]]))
        b = float(np.median([r[key] for r in got["other"]]))
        print(f"  {what:<34}{a:>10.3f}{b:>10.3f}{a / b:>12.3f}")
    for key in ("floor_evals", "ci_evals"):
        a, b = got["this"][0][key], got["other"][0][key]
        print(f"  RK4 evaluations, {key.split('_')[0]:<17}{a:>10d}{b:>10d}"
              f"{'   equal' if a == b else '   DIFFER'}")
    print(f"  load at the end {load_avg()}")


if __name__ == "__main__":
    main()
