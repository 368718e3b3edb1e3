"""What the certification of close calls costs, where its RK4 evaluations go, and what it
changes: the four figures' adaptive sweeps (and full grids), side by side in one run.

For each figure (Figures 3(a), 3(b), 4(a), 4(b) at RES x RES x 3 lam, default 1000):
the adaptive sweep (default settings, in memory through the sweep driver,
``compute.driver.sweep_arrays``, ``--jobs`` workers): its RK4 evaluations (regular +
event re-integrations, every run of every computed point), the points computed, the wall
time; with ``--rules`` also where the certification's evaluations go, rule by rule
(``compute.certify``: the near-misses' probes, and the full reruns of close calls by the
rule that made them close calls and by refinement level), replayed on the computed points.

    python scripts/bench_certify.py                       # the four figures, adaptive
    python scripts/bench_certify.py --rules               # ... and per rule
    python scripts/bench_certify.py --full --res 80       # full grids, certified vs bare
    PYTHONPATH=/path/to/other/checkout python scripts/bench_certify.py   # another checkout
    python scripts/bench_certify.py --against /path/to/other/checkout --rounds 2
    python scripts/bench_certify.py --against /path/before --against /path/older   # both
    python scripts/bench_certify.py --cli --against /path/before --rounds 2   # the command

``--against`` (repeatable) runs the same sweeps of other checkouts in subprocesses,
alternating with this one's (round by round, the order reversed each round, each process
warm: its kernels compiled before it times), and prints all of them and this one's ratios
to each with the load average: the one side-by-side measurement of wall time on a shared
machine (RK4 evaluations are deterministic).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np

from rocksweep.compute import adaptive as ad
from rocksweep.compute import sweep as sw
from rocksweep.compute.driver import sweep_arrays
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.scene.parse import load_scene

try:  # the rules' labels (--rules) only
    from rocksweep.numerics import CLOSE_BAND, OVERTURN_BAND
except ImportError:  # an older checkout (--against), before the bands had names
    CLOSE_BAND, OVERTURN_BAND = 4.0, 8.0
try:
    from rocksweep.scene.grid import Grid
except ImportError:  # an older checkout (--against): the grid lived in compute/
    from rocksweep.compute.grid import Grid

ROOT = Path(__file__).resolve().parents[1]
FIGS = ("fig3a", "fig3b", "fig4a", "fig4b")


def scene(name: str, res: int):
    """A figure's scene with its two diagram axes at res x res (its ranges)."""
    base = load_scene(ROOT / "configs" / f"{name}.yaml")
    ov = []
    for ax, key in (("w_over_p", "pulse.w_over_p"), ("A_ratio", "pulse.A_ratio")):
        v = base.axis(ax).values
        ov.append(f"{key}={{start: {v[0]!r}, stop: {v[-1]!r}, num: {res}}}")
    return load_scene(ROOT / "configs" / f"{name}.yaml", ov)


def evaluations(arr: dict) -> int:
    return int(arr["steps"].sum() + arr["event_steps"].sum())


def sweep_once(name: str, res: int, jobs: int, adaptive: bool) -> dict:
    """One sweep of a figure: RK4 evaluations, points computed, wall [s], the arrays."""
    sc = scene(name, res)
    t0 = time.perf_counter()
    arr, rep = sweep_arrays(sc, jobs=jobs, adaptive=ad.Options() if adaptive else None)
    wall = time.perf_counter() - t0
    computed = rep.adaptive.computed if adaptive else int(arr["outcome"].size)
    # the certification's share (reports before it was counted have none: -1)
    refine = int(getattr(rep, "refine_evaluations", -1))
    return {"evals": evaluations(arr), "computed": computed, "wall": wall,
            "cpu": rep.cpu_s, "refine": refine, "arrays": arr}


def cli_once(name: str, res: int, jobs: int, out: Path) -> dict:
    """The figure's adaptive sweep as a user runs it: ``rocksweep sweep --adaptive`` in a
    process of its own (the rocksweep of this process's PYTHONPATH), the result an HDF5
    file. wall: the command's [s]; startup: a warm one-point sweep's of the same scene
    (interpreter, imports, numba's cache, a tiny file) [s], which ``wall - startup``
    leaves out."""
    sc = scene(name, res)
    sets = []
    for ax, key in (("w_over_p", "pulse.w_over_p"), ("A_ratio", "pulse.A_ratio")):
        v = sc.axis(ax).values
        sets += ["--set", f"{key}={{start: {v[0]!r}, stop: {v[-1]!r}, num: {res}}}"]
    base = [sys.executable, "-m", "rocksweep", "sweep", str(ROOT / "configs" / f"{name}.yaml"),
            "-o", str(out), "--overwrite", "-q", "-j", str(jobs)]

    def timed(cmd: list[str]) -> float:
        t0 = time.perf_counter()
        # run from out's folder: ``python -m`` puts the working directory first on
        # sys.path, so from a checkout it would run that checkout, not PYTHONPATH's copy
        subprocess.run(cmd, check=True, capture_output=True, cwd=out.parent)
        return time.perf_counter() - t0

    one = ["--set", "pulse.w_over_p=1.0", "--set", "pulse.A_ratio=2.0", "--set", "impact.lam=0.0"]
    timed(base + one)  # the kernel compiled (or its cache loaded) before the timings
    startup = timed(base + one)
    wall = timed(base + ["--adaptive", *sets])
    package = subprocess.run([sys.executable, "-c", "import rocksweep; print(rocksweep.__file__)"],
                             check=True, capture_output=True, text=True,
                             cwd=out.parent).stdout.strip()
    return {"wall": wall, "startup": startup, "package": str(Path(package).parent)}


def rules(name: str, res: int, arr: dict, jobs: int) -> dict:
    """The computed points of an adaptive sweep replayed: bare runs, then the
    certification with every kernel call tallied by rule and level. Returns name ->
    RK4 evaluations."""
    from rocksweep.compute import certify as cf

    sc = scene(name, res)
    grid = Grid(sc)
    flat = np.flatnonzero(arr["computed"].ravel() > 0) if "computed" in arr else \
        np.arange(grid.size)
    cr = grid.rows_at(flat)
    lvl = sw.level(sc)
    tally: dict[str, float] = {}

    def add(key: str, res_rows: np.ndarray) -> None:
        tally[key] = tally.get(key, 0.0) + float(
            (res_rows[:, L.OUT_STEPS] + res_rows[:, L.OUT_EVENT_STEPS]).sum())

    def part(sel: np.ndarray) -> None:
        rows = np.ascontiguousarray(cr.rows[sel])
        kind = int(cr.kinds[sel][0])
        from rocksweep.compute.dispatch import run_variant

        bare = run_variant(rows, kind, lvl, sc.ground, 0)
        add("bare runs", bare)
        fell = cf._fell(bare)
        close = cf.close_calls(rows, bare)
        why = np.where(close & fell, f"overturn < {OVERTURN_BAND:g} m",
                       np.where(close, "safe < m", "near-miss flipped"))
        last = bare[:, L.OUT_OUTCOME].copy()  # outcome at the level before
        before = bare[:, L.OUT_OUTCOME].copy()  # ... and the one before it

        def run(sub, idx, keep=True):
            out = run_variant(np.ascontiguousarray(sub), kind, lvl, sc.ground, 0)
            if not keep:
                add(f"probe of near-misses (1 m .. {CLOSE_BAND:g} m)", out)
                return out
            level = int(round(np.log2(rows[idx[0], L.PAR_DT] / sub[0, L.PAR_DT])))
            for j, i in enumerate(idx):
                if level >= 2:
                    reason = ("outcome changed" if last[i] != before[i]
                              else "repeated, still close")
                else:
                    reason = why[i]
                add(f"level {level}: {reason}", out[j:j + 1])
            before[idx] = last[idx]
            last[idx] = out[:, L.OUT_OUTCOME]
            return out

        outs = bare.copy()
        cf.certify(rows, outs, run, sc.numerics.refine)
        st = outs[:, L.OUT_STATUS].astype(np.int64)
        tally["points refined"] = tally.get("points refined", 0) + int(
            (st & L.STATUS_REFINED != 0).sum())
        tally["points uncertified"] = tally.get("points uncertified", 0) + int(
            (st & L.STATUS_UNCERTIFIED != 0).sum())

    halves = np.array_split(np.arange(flat.size), max(1, jobs))
    masks = []
    for h in halves:
        m = np.zeros(flat.size, bool)
        m[h] = True
        masks.append(m)
    with ThreadPoolExecutor(len(masks)) as ex:
        list(ex.map(part, masks))
    return tally


def measure(args) -> dict:
    """This checkout's numbers (JSON-able): per figure, a list of rounds."""
    jobs = sw.effective_jobs(args.jobs)
    out: dict = {}
    if args.cli:
        with tempfile.TemporaryDirectory() as tmp:
            return {name: cli_once(name, args.res, jobs, Path(tmp) / "fig.h5")
                    for name in args.figures}
    for name in args.figures:
        sc = scene(name, args.res)
        sw.prepare(Grid(sc), sw.level(sc))  # compile/load outside the timings
        r = sweep_once(name, args.res, jobs, not args.full)
        item = {k: v for k, v in r.items() if k != "arrays"}
        if args.rules:
            item["rules"] = rules(name, args.res, r["arrays"], jobs)
        if args.classes:
            np.save(Path(args.classes) / f"{name}.npy", r["arrays"]["outcome"])
            np.save(Path(args.classes) / f"{name}_status.npy", r["arrays"]["status"])
        out[name] = item
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("figures", nargs="*", default=list(FIGS))
    ap.add_argument("--res", type=int, default=1000, help="points per diagram axis")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--full", action="store_true", help="full grids, not adaptive")
    ap.add_argument("--rules", action="store_true", help="evaluations per rule (replay)")
    ap.add_argument("--classes", help="save each figure's outcome here (DIR/NAME.npy; "
                    "DIR/this/NAME.npy and one folder per --against tree)")
    ap.add_argument("--cli", action="store_true",
                    help="time the rocksweep sweep --adaptive command instead (wall, and "
                    "without a warm one-point sweep's start-up)")
    ap.add_argument("--json", action="store_true", help="print one JSON line (--against)")
    ap.add_argument("--against", action="append",
                    help="another checkout, run alternately in a subprocess (repeatable)")
    ap.add_argument("--rounds", type=int, default=1)
    args = ap.parse_args()
    if args.json:
        print(json.dumps(measure(args)))
        return
    kind = "full grids" if args.full else "adaptive"
    print(f"cores: {os.cpu_count()}, jobs: {args.jobs}, {kind} "
          f"at {args.res} x {args.res} x 3 lam; load average at start: "
          + ", ".join(f"{x:.2f}" for x in os.getloadavg()), flush=True)
    others = list(args.against or [])
    if args.cli:  # every command imports the package: .pyc files as an install has them
        from bench_compile import byte_compiled

        byte_compiled(ROOT / "rocksweep", *(Path(o) / "rocksweep" for o in others))
    sides: dict[str, list] = {"this": [], **{o: [] for o in others}}
    for rnd in range(args.rounds):
        # alternate which tree goes first, round by round
        order = list(sides) if rnd % 2 else list(sides)[::-1]
        for side in order:
            env = dict(os.environ)
            if side != "this":
                env["PYTHONPATH"] = side
            cmd = [sys.executable, str(Path(__file__)), *args.figures, "--res",
                   str(args.res), "--jobs", str(args.jobs), "--json"]
            cmd += ["--full"] if args.full else []
            cmd += ["--cli"] if args.cli else []
            cmd += ["--rules"] if args.rules and side == "this" else []
            if args.classes:  # each tree's in a folder of its own
                sub = Path(args.classes) / ("this" if side == "this"
                                            else side.strip("/").replace("/", "_"))
                sub.mkdir(parents=True, exist_ok=True)
                cmd += ["--classes", str(sub)]
            load = os.getloadavg()[0]
            got = json.loads(subprocess.run(cmd, env=env, check=True, capture_output=True,
                                            text=True).stdout.strip().splitlines()[-1])
            sides[side].append(got)
            wall = sum(v["wall"] for v in got.values())
            print(f"round {rnd + 1} {side}: {wall:.1f} s wall for the figures "
                  f"(load average {load:.2f} -> {os.getloadavg()[0]:.2f})", flush=True)
    this = sides["this"]
    if args.cli:
        cli_table(args.figures, sides)
        return
    print("| figure | RK4 evaluations | of them certification | computed | wall s (best) "
          "| cpu s (best) |" + "".join(f" {o}: evaluations | ratio | wall s | ratio | cpu s "
                                      "| ratio |" for o in others))
    tot = {"e": 0, "w": 0.0, "c": 0.0, **{o: [0, 0.0, 0.0] for o in others}}
    for name in args.figures:
        e = this[0][name]["evals"]
        w = min(r[name]["wall"] for r in this)
        r = this[0][name]["refine"]
        share = (f"{r / 1e6:.1f}M ({e / (e - r):.3f}x the points' own)" if r >= 0
                 else "not counted")
        c = min(r[name]["cpu"] for r in this)
        line = (f"| {name} | {e / 1e6:.1f}M | {share} | {this[0][name]['computed']} | "
                f"{w:.2f} | {c:.1f} |")
        tot["e"] += e
        tot["w"] += w
        tot["c"] += c
        for o in others:
            oe = sides[o][0][name]["evals"]
            ow = min(r[name]["wall"] for r in sides[o])
            oc = min(r[name]["cpu"] for r in sides[o])
            tot[o][0] += oe
            tot[o][1] += ow
            tot[o][2] += oc
            line += (f" {oe / 1e6:.1f}M | {e / oe:.3f} | {ow:.2f} | {w / ow:.3f} | {oc:.1f} | "
                     f"{c / oc:.3f} |")
        print(line)
    if others:
        print(f"| all | {tot['e'] / 1e6:.1f}M | | | {tot['w']:.2f} | {tot['c']:.1f} |" + "".join(
            f" {tot[o][0] / 1e6:.1f}M | {tot['e'] / tot[o][0]:.3f} | {tot[o][1]:.2f} | "
            f"{tot['w'] / tot[o][1]:.3f} | {tot[o][2]:.1f} | {tot['c'] / tot[o][2]:.3f} |"
            for o in others))
    if args.rules:
        for name in args.figures:
            t = this[0][name]["rules"]
            print(f"{name}: where the RK4 evaluations of the computed points go (replayed)")
            total = sum(v for k, v in t.items() if not k.startswith("points"))
            for k, v in sorted(t.items()):
                if k.startswith("points"):
                    print(f"    {k}: {int(v)}")
                else:
                    print(f"    {k:<40} {v / 1e6:8.2f}M ({100 * v / total:5.1f}%)")


def cli_table(figures: list[str], sides: dict[str, list]) -> None:
    """The ``--cli`` rounds: per figure and tree, the best command wall and the best
    wall less its round's start-up; this tree's ratios to each other tree."""
    names = list(sides)
    print("| figure |" + "".join(f" {n}: wall s | less start-up |" for n in names)
          + "".join(f" this / {n}: wall | less start-up |" for n in names[1:]))
    tot = {n: [0.0, 0.0] for n in names}
    for name in [*figures, "all"]:
        line = f"| {name} |"
        best = {}
        for n in names:
            if name == "all":
                w, c = tot[n]
            else:
                w = min(r[name]["wall"] for r in sides[n])
                c = min(r[name]["wall"] - r[name]["startup"] for r in sides[n])
                tot[n][0] += w
                tot[n][1] += c
            best[n] = (w, c)
            line += f" {w:.2f} | {c:.2f} |"
        for n in names[1:]:
            line += f" {best['this'][0] / best[n][0]:.3f} | {best['this'][1] / best[n][1]:.3f} |"
        print(line)
    print("the commands ran: " + ", ".join(
        f"{n} {sorted({r[f]['package'] for r in sides[n] for f in figures})}" for n in names))
    print("start-up (warm one-point sweep, best): " + ", ".join(
        f"{n} {min(r[f]['startup'] for r in sides[n] for f in figures):.2f} s" for n in names))


if __name__ == "__main__":
    main()
