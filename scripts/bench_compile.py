"""What a new user waits for, and what a point costs: compile, start-up, per point, vs reference.

Prints, measured side by side in one run:

1. cold compile: each kernel variant compiled alone in a fresh process with an empty
   NUMBA_CACHE_DIR (what the first sweep of a scene pays on a fresh machine, and every
   machine again for every new kernel source): seconds of CPU and wall for ``warm_up``
   (the import of the kernel is shown apart).
2. warm start-up: commands in fresh processes with numba's cache filled, best of 3, wall
   and CPU (user + sys of the child): the interpreter alone, ``rocksweep --help``, loading
   the compiled kernel (import + ``warm_up`` from the cache), ``rocksweep info`` on a small
   result, and a whole small ``rocksweep sweep`` (Figure 3(a) at 5 x 5 x 3 lam, --jobs 1).
3. per point: the outcome kernel on every point of the paper's four figures (Figures 3(a),
   3(b), 4(a), 4(b), ``configs/fig*.yaml``, the ``default`` preset as shipped), core-us per
   point (CPU time of the calling thread, kernel calls only, chunked as a 1-worker sweep
   does, best of ``--repeat``; ``scripts/bench_kernel.py``'s ``best_pass``).
4. reference: scipy DOP853 (``rocksweep.physics.reference``) on the accuracy study's stratified
   sample of each figure (``--ref-points``): weighted mean wall ms per point (an estimate
   for the whole scene), its ratio to item 3's kernel time, and the ratio including
   start-up for a sweep of 120 000 points: ref / (kernel core-us per point of item 3 +
   warm sweep start-up (wall: serial work; its CPU time also counts OpenBLAS's idle
   threads spinning) / 120 000); the outcome agreement.

The machine may be shared: the load average is printed at the start and the end; CPU
times are less sensitive to load than wall times.

    python scripts/bench_compile.py            # ~3-4 min on 2 cores
    python scripts/bench_compile.py --quick    # ~30 s: Figure 3(a)'s variant and scene only
    python scripts/bench_compile.py --vertical # item 1 alone: vertical and ground variants
    python scripts/bench_compile.py --slide    # item 1 alone: sliding and no-slip variants

Run it against another copy of the package (e.g. the code before a change) with
``PYTHONPATH=/path/to/that/copy``: every subprocess inherits the environment.

5. A/B (``--against DIR``, DIR holding another copy's ``rocksweep`` package, e.g. ``git
   archive main | tar -x -C DIR``): rounds alternating between this copy and DIR, each
   measurement in a fresh process: item 1's cold compile of Figure 3(a)'s variant (CPU s),
   the warm whole-process wall time of a 1-point ``rocksweep sweep`` (the start-up
   target: under 0.5 s), of ``import rocksweep.cli.main`` and of ``rocksweep --help``
   (best of ``--repeat`` each), and item 3's core-us per point of Figure 3(a) (this copy's
   ``bench_kernel.best_pass`` on DIR's package), the order swapped every round; the
   median of each and the ratio this / DIR. Alone (``--against DIR --ab-only``) it takes
   ~25 s per round on 2 cores.

    python scripts/bench_compile.py --against /tmp/main --ab-only --rounds 3

6. instructions (``--instructions``, with ``--against DIR``): the instructions (valgrind's
   callgrind, Ir) of item 1's cold compile of Figure 3(a)'s variant, less those of the
   import alone, this copy and DIR side by side (one per core): deterministic, where the
   CPU seconds of item 5 vary by +-20% between single runs on a shared machine. ~12 min.

    python scripts/bench_compile.py --against /tmp/main --instructions
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(Path(__file__).resolve().parent))
import _here  # noqa: E402, F401 (this checkout's rocksweep, not an installed one)
import bench_kernel as bk  # noqa: E402  (scripts/bench_kernel.py: best_pass, scene_of)

import rocksweep  # noqa: E402
from rocksweep.analysis.accuracy import (  # noqa: E402
    Sample,
    _agreement,
    boundary_mask,
    run_reference,
    stratified_sample,
)
from rocksweep.kernel import layout as L  # noqa: E402, N812

CONFIGS = ROOT / "configs"
SWEEP_POINTS = 120_000  # the sweep size of the start-up-inclusive reference ratio
KINDS = {L.KIND_FLEXIBLE: "flexible", L.KIND_FLEXIBLE_UNDAMPED: "flexible_undamped",
         L.KIND_RIGID: "rigid"}
LEVELS = {L.LEVEL_OUTCOME: "chunk", L.LEVEL_ENERGY: "chunk_energy",
          L.LEVEL_CONTACT: "chunk_contact", None: "point_history"}
# (kind, level, ground): Figure 3(a) needs the first (flexible, damped, outcome level)
ALL_VARIANTS = ([(k, lv, L.GROUND_PULSE) for lv in LEVELS for k in KINDS]
                + [(k, L.LEVEL_OUTCOME, L.GROUND_ANY) for k in KINDS]
                + [(k, L.LEVEL_OUTCOME, L.GROUND_VERTICAL) for k in KINDS])
QUICK_VARIANTS = [(L.KIND_FLEXIBLE, L.LEVEL_OUTCOME, L.GROUND_PULSE)]
# --vertical: the vertical ground acceleration's variants beside the ground variants they
# extend (docs/vertical.md), each level a scene can ask for
VERTICAL_VARIANTS = [(k, lv, g) for k in KINDS for lv in (L.LEVEL_OUTCOME, None)
                     for g in (L.GROUND_ANY, L.GROUND_VERTICAL)]
# --slide: the sliding base's variants (a scene that gives body.mu, docs/sliding.md)
# beside the no-slip ones they replace: (kind, level, ground, contact)
SLIDE_VARIANTS = [(k, lv, L.GROUND_PULSE, c) for k in (L.KIND_FLEXIBLE, L.KIND_RIGID)
                  for lv in (L.LEVEL_OUTCOME, None)
                  for c in (L.CONTACT_NOSLIP, L.CONTACT_SLIDE)]

_COMPILE_SNIPPET = """
import json, sys, time
c0, w0 = time.process_time(), time.perf_counter()
import rocksweep
from rocksweep.kernel import warm_up
c1, w1 = time.process_time(), time.perf_counter()
kind, level, ground, *contact = json.loads(sys.argv[1])
warm_up(kind, level, ground, *contact)
c2, w2 = time.process_time(), time.perf_counter()
print(json.dumps({"import_cpu": c1 - c0, "import_wall": w1 - w0,
                  "cpu": c2 - c1, "wall": w2 - w1, "package": rocksweep.__file__}))
"""


def child_env(tree: Path | None = None, **extra: str) -> dict[str, str]:
    """The environment of the subprocesses: they import the same rocksweep as this process
    (its parent directory first on PYTHONPATH; they run in a temporary directory, so that
    ``python -c`` / ``-m`` does not put the current directory first instead), or the one
    in ``tree`` (item 5)."""
    pkg_parent = str(tree or Path(rocksweep.__file__).resolve().parents[1])
    path = os.pathsep.join(p for p in (pkg_parent, os.environ.get("PYTHONPATH")) if p)
    return {**os.environ, "PYTHONPATH": path, **extra}


GROUNDS = {L.GROUND_PULSE: "", L.GROUND_ANY: "_ground", L.GROUND_VERTICAL: "_vertical"}


def variant_name(kind: int, level: int | None, ground: int, contact: int = 0) -> str:
    return f"{LEVELS[level]}_{KINDS[kind]}{GROUNDS[ground]}{'_slide' if contact else ''}"


def cold_compile(variant: tuple, tree: Path | None = None) -> dict:
    """Compile one variant in a fresh process with an empty NUMBA_CACHE_DIR."""
    with tempfile.TemporaryDirectory() as cache:
        res = subprocess.run([sys.executable, "-c", _COMPILE_SNIPPET, json.dumps(variant)],
                             env=child_env(tree, NUMBA_CACHE_DIR=cache), cwd=cache,
                             capture_output=True, text=True, check=True)
    return json.loads(res.stdout.splitlines()[-1])


def timed(cmd: list[str], repeat: int, tree: Path | None = None) -> tuple[float, float]:
    """(wall, CPU) seconds of a command in a fresh process (importing the rocksweep of
    ``tree``, default this one), the best of ``repeat``; CPU is the child's user + sys
    time."""
    best_wall = best_cpu = float("inf")
    for _ in range(repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                       env=child_env(tree), cwd=tempfile.gettempdir())
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        best_wall, best_cpu = min(best_wall, wall), min(best_cpu, cpu)
    return best_wall, best_cpu


def startup(repeat: int, quick: bool) -> dict[str, tuple[float, float]]:
    """Warm start-up of commands (numba's cache filled first)."""
    py = sys.executable
    rs = [py, "-m", "rocksweep"]
    small = ["--set", "pulse.w_over_p.num=5", "--set", "pulse.A_ratio.num=5"]
    res = {}
    with tempfile.TemporaryDirectory() as tmp:
        h5 = str(Path(tmp) / "small.h5")
        sweep = [*rs, "sweep", str(CONFIGS / "fig3a.yaml"), *small, "-o", h5, "--overwrite",
                 "-q", "-j", "1"]
        # fills the cache, writes the small result
        subprocess.run(sweep, check=True, capture_output=True, env=child_env(), cwd=tmp)
        res["python -c pass"] = timed([py, "-c", "pass"], repeat)
        res["rocksweep --help"] = timed([*rs, "--help"], repeat)
        res["kernel: import + warm_up (cache)"] = timed(
            [py, "-c", "from rocksweep.kernel import warm_up; warm_up(0, 0)"], repeat)
        if not quick:
            res["rocksweep info (75 points)"] = timed([*rs, "info", h5], repeat)
        res["rocksweep sweep fig3a 5x5x3, -j 1"] = timed(sweep, repeat)
    return res


def per_point(names: list[str], repeat: int) -> dict[str, dict]:
    """Core-us per point of the outcome kernel on every point of each scene."""
    out = {}
    for name in names:
        scene = bk.scene_of(name, None)
        bk.kernel_pass(scene)  # loads (or compiles) the variant
        p = bk.best_pass(scene, repeat)
        o = p["outs"]
        n = o.shape[0]
        out[name] = {"scene": scene, "pass": p, "n": n, "us": p["cpu"] / n * 1e6,
                     "evals": (o[:, L.OUT_STEPS].sum() + o[:, L.OUT_EVENT_STEPS].sum()) / n}
    return out


_PER_POINT_SNIPPET = """
import json, sys
sys.path.append(sys.argv[1])  # last: first, _here would put this checkout before PYTHONPATH's
import bench_kernel as bk
import rocksweep
scene = bk.scene_of(sys.argv[2], None)
bk.kernel_pass(scene)
p = bk.best_pass(scene, int(sys.argv[3]))
print(json.dumps({"us": p["cpu"] / p["outs"].shape[0] * 1e6, "package": rocksweep.__file__}))
"""
# a 1-point sweep (Figure 3(a)'s body at one pulse and lam): the start-up target
ONE_POINT = ["--set", "pulse.w_over_p=2.0", "--set", "pulse.A_ratio=3.0",
             "--set", "impact.lam=0.2"]


def ab_round(tree: Path | None, repeat: int, tmp: str) -> dict[str, float]:
    """Item 5's measurements of one copy (``tree``; None: this one), each in a fresh
    process: cold compile CPU s, warm 1-point sweep, ``import rocksweep.cli.main`` and
    ``rocksweep --help`` wall s (best of ``repeat``), fig3a core-us per point."""
    package = str((tree or Path(rocksweep.__file__).resolve().parents[1]) / "rocksweep")
    comp = cold_compile(QUICK_VARIANTS[0], tree)
    if not comp["package"].startswith(package):
        raise SystemExit(f"the subprocess imported {comp['package']}, not {package}")
    h5 = str(Path(tmp) / f"one-{'this' if tree is None else 'other'}.h5")
    sweep = [sys.executable, "-m", "rocksweep", "sweep", str(CONFIGS / "fig3a.yaml"),
             *ONE_POINT, "-o", h5, "--overwrite", "-q"]
    subprocess.run(sweep, check=True, capture_output=True, env=child_env(tree), cwd=tmp)
    # warm start-up (numba's cache now filled), and without a kernel: the command line's
    # import, and --help
    starts = {k: timed(cmd, repeat, tree)[0] for k, cmd in (
        ("start", sweep), ("import", [sys.executable, "-c", "import rocksweep.cli.main"]),
        ("help", [sys.executable, "-m", "rocksweep", "--help"]))}
    # the copy's own bench_kernel where it has one: this copy's imports names an old
    # package lacks; both time the same thing (``best_pass`` of ``kernel_pass``)
    own = None if tree is None else tree / "scripts"
    scripts = own if own is not None and (own / "bench_kernel.py").is_file() else HERE
    res = subprocess.run([sys.executable, "-c", _PER_POINT_SNIPPET, str(scripts),
                          "fig3a", str(repeat)], env=child_env(tree), cwd=tmp,
                         capture_output=True, text=True, check=True)
    pp = json.loads(res.stdout.splitlines()[-1])
    if not pp["package"].startswith(package):
        raise SystemExit(f"the per-point subprocess imported {pp['package']}, not {package}")
    return {"compile": comp["cpu"], "us": pp["us"], **starts}


def byte_compiled(*packages: Path) -> None:
    """Write the packages' .pyc files, as ``pip install`` does: with
    PYTHONDONTWRITEBYTECODE set (this sandbox sets it), a copy made by ``git archive``, or
    a module changed since its .pyc, is compiled from source by every process that
    imports it (~0.1-0.3 s of a command), and the side that has fewer .pyc files loses."""
    import compileall

    for pkg in packages:
        compileall.compile_dir(str(pkg), quiet=1)


def against(other: Path, rounds: int, repeat: int) -> None:
    """Item 5: this copy and ``other`` alternately, ``rounds`` times; medians and ratios."""
    if not (other / "rocksweep" / "__init__.py").is_file():
        raise SystemExit(f"--against {other}: no rocksweep package there")
    print(f"\n[5] A/B against {other}: {rounds} rounds alternating, each measurement a "
          "fresh process (load average beside each round)")
    got: dict[str, list[dict[str, float]]] = {"this": [], "other": []}
    byte_compiled(ROOT / "rocksweep", other / "rocksweep")
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(rounds):
            pair = (("other", other), ("this", None))
            for who, tree in pair[::-1] if i % 2 else pair:  # ABBA: no order bias
                r = ab_round(tree, repeat, tmp)
                got[who].append(r)
                print(f"    round {i + 1} {who:<6} compile {r['compile']:5.2f} s CPU, 1-point "
                      f"sweep {r['start']:5.3f} s wall, fig3a {r['us']:6.2f} core-us/pt, "
                      f"import {r['import']:5.3f} s, --help {r['help']:5.3f} s  "
                      f"(load {bk.load_avg()})", flush=True)
    print(f"    {'median':<28}{'this':>10}{'other':>10}{'this/other':>12}")
    for key, what in (("compile", "cold compile, CPU s"), ("start", "1-point sweep, wall s"),
                      ("us", "fig3a, core-us/pt"), ("import", "import cli.main, wall s"),
                      ("help", "rocksweep --help, wall s")):
        a = float(np.median([r[key] for r in got["this"]]))
        b = float(np.median([r[key] for r in got["other"]]))
        print(f"    {what:<28}{a:>10.3f}{b:>10.3f}{a / b:>12.3f}")


_VALGRIND_SNIPPET = """
import rocksweep
from rocksweep.kernel import warm_up
if {compile}:
    warm_up(0, 0, 0)
"""


def _callgrind(tree: Path | None, compile_too: bool, tmp: str) -> subprocess.Popen:
    """A callgrind run (Ir only, no cache simulation) of the import, and the cold compile of
    Figure 3(a)'s variant if ``compile_too``, in a fresh process with an empty cache."""
    cache = tempfile.mkdtemp(dir=tmp)
    code = _VALGRIND_SNIPPET.format(compile=compile_too)
    return subprocess.Popen(
        ["valgrind", "--tool=callgrind", f"--callgrind-out-file={cache}/cg.out",
         sys.executable, "-c", code],
        env=child_env(tree, NUMBA_CACHE_DIR=cache, PYTHONMALLOC="malloc"), cwd=cache,
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def _collected(proc: subprocess.Popen) -> int:
    err = proc.communicate()[1]
    if proc.returncode:
        raise SystemExit(f"callgrind failed:\n{err[-2000:]}")
    return int(err.split("Collected :")[1].split()[0])


def instructions(other: Path) -> None:
    """Item 6: the cold compile's instructions, this copy and ``other`` side by side."""
    if shutil.which("valgrind") is None:
        raise SystemExit("--instructions needs valgrind on PATH")
    print(f"\n[6] instructions of Figure 3(a)'s cold compile (callgrind Ir, less the "
          f"import's), this copy and {other} side by side", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        got = {}
        for compile_too in (True, False):
            procs = {who: _callgrind(tree, compile_too, tmp)
                     for who, tree in (("this", None), ("other", other))}
            got[compile_too] = {who: _collected(p) for who, p in procs.items()}
    comp = {who: got[True][who] - got[False][who] for who in ("this", "other")}
    print(f"    {'':<28}{'this':>10}{'other':>10}{'this/other':>12}")
    for what, d in (("import, G instructions", got[False]), ("cold compile, G instr.", comp)):
        print(f"    {what:<28}{d['this'] / 1e9:>10.2f}{d['other'] / 1e9:>10.2f}"
              f"{d['this'] / d['other']:>12.3f}")


def reference(name: str, pp: dict, points: int, seed: int = 0) -> dict:
    """The reference on the accuracy study's stratified sample of a scene
    (``run_reference``, as the accuracy study and ``bench_kernel.py`` time it): its
    weighted mean wall time per point (an estimate for the whole scene, like item 3's
    kernel time; scipy's solver is single-threaded Python), and the outcome agreement with
    the kernel."""
    scene, grid = pp["scene"], pp["pass"]["grid"]
    outs = pp["pass"]["outs"]
    outcome = outs[:, L.OUT_OUTCOME].astype(np.int8)
    bnd = boundary_mask(outcome.reshape(grid.shape), grid.dims).ravel()
    flat, stratum, weight, strata, sizes = stratified_sample(outcome, bnd, points, seed)
    sample = Sample(flat, stratum, weight, strata, sizes, grid.size, outcome, 0.0)
    ref, secs, _ = run_reference(scene, flat)
    agree = outs[flat, L.OUT_OUTCOME] == ref[:, L.OUT_OUTCOME]
    share, se = _agreement(agree, sample)
    return {"n": len(flat), "ref_ms": float(np.sum(secs * weight) / weight.sum()) * 1e3,
            "agree": share, "se": se}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="Figure 3(a) only: its variant, its scene, 20 reference points")
    ap.add_argument("--vertical", action="store_true",
                    help="item 1 only, for the vertical variants beside the ground ones")
    ap.add_argument("--slide", action="store_true",
                    help="item 1 only, for the sliding base's variants beside the no-slip ones")
    ap.add_argument("--repeat", type=int, default=3, help="best of this many (items 2-4)")
    ap.add_argument("--ref-points", type=int, default=100,
                    help="reference sample per figure (default 100)")
    ap.add_argument("--no-compile", action="store_true", help="skip item 1")
    ap.add_argument("--against", type=Path, metavar="DIR",
                    help="item 5: A/B against the rocksweep package in DIR")
    ap.add_argument("--rounds", type=int, default=3, help="item 5's alternating rounds")
    ap.add_argument("--ab-only", action="store_true", help="item 5 only (with --against)")
    ap.add_argument("--instructions", action="store_true",
                    help="item 6 only (with --against): the cold compile's instructions")
    args = ap.parse_args()
    if args.instructions:
        if args.against is None:
            raise SystemExit("--instructions needs --against DIR")
        instructions(args.against.resolve())
        return
    if args.ab_only:
        if args.against is None:
            raise SystemExit("--ab-only needs --against DIR")
        print(f"rocksweep compile/start-up A/B ({Path(rocksweep.__file__).parent}): "
              f"{os.cpu_count()} cores, load average at start {bk.load_avg()}", flush=True)
        against(args.against.resolve(), args.rounds, args.repeat)
        print(f"load average at end {bk.load_avg()}")
        return
    variants = (VERTICAL_VARIANTS if args.vertical else SLIDE_VARIANTS if args.slide
                else QUICK_VARIANTS if args.quick else ALL_VARIANTS)
    figures = ["fig3a"] if args.quick else list(bk.FOUR)
    ref_points = 20 if args.quick else args.ref_points

    print(f"rocksweep compile/start-up benchmark ({Path(rocksweep.__file__).parent}): "
          f"{os.cpu_count()} cores, load average at start {bk.load_avg()}", flush=True)
    t_all = time.perf_counter()

    if not args.no_compile:
        print("\n[1] cold compile, one variant per fresh process, empty NUMBA_CACHE_DIR "
              "(s; the kernel's import apart)")
        print(f"    {'variant':<36}{'CPU s':>8}{'wall s':>8}{'import CPU s':>14}")
        for v in variants:
            r = cold_compile(v)
            if Path(r["package"]).resolve() != Path(rocksweep.__file__).resolve():
                raise SystemExit(f"the subprocess imported {r['package']}")
            print(f"    {variant_name(*v):<36}{r['cpu']:>8.2f}{r['wall']:>8.2f}"
                  f"{r['import_cpu']:>14.2f}", flush=True)
    if args.vertical or args.slide:
        print(f"load average at end {bk.load_avg()}")
        return

    print(f"\n[2] warm start-up (numba's cache filled), best of {args.repeat}")
    print(f"    {'command':<40}{'wall s':>8}{'CPU s':>8}")
    st = startup(args.repeat, args.quick)
    for what, (wall, cpu) in st.items():
        print(f"    {what:<40}{wall:>8.2f}{cpu:>8.2f}", flush=True)
    # the sweep's start-up is serial work; its CPU time also counts the idle spinning of
    # OpenBLAS's threads (numpy's and scipy's; 0.1-0.2 s, more on an idle machine)
    start_wall = st["rocksweep sweep fig3a 5x5x3, -j 1"][0]

    print(f"\n[3] outcome kernel on every point of the figures (default preset as shipped), "
          f"CPU of the calling thread, best of {args.repeat}")
    print(f"    {'figure':<8}{'points':>8}{'RK4 evals/pt':>14}{'core-us/pt':>12}")
    pp = per_point(figures, args.repeat)
    for name, r in pp.items():
        print(f"    {name:<8}{r['n']:>8}{r['evals']:>14.1f}{r['us']:>12.2f}", flush=True)

    print(f"\n[4] reference (scipy DOP853, rtol 1e-10): wall ms per point, weighted mean over "
          f"the accuracy study's stratified sample ({ref_points} points per figure: an "
          "estimate for the whole scene), against item 3's kernel time on the whole scene")
    print(f"    incl. start-up: ref / (kernel + item 2's sweep start-up {start_wall:.2f} s (wall) "
          f"/ {SWEEP_POINTS} points)")
    print(f"    {'figure':<8}{'sample':>7}{'ref ms/pt':>10}{'kern us/pt':>11}{'ratio':>8}"
          f"{'incl. start-up':>15}{'agree %':>15}")
    for name in figures:
        r = reference(name, pp[name], ref_points)
        kern = pp[name]["us"]
        incl = r["ref_ms"] * 1e3 / (kern + start_wall / SWEEP_POINTS * 1e6)
        agree = f"{100 * r['agree']:.2f}+-{100 * r['se']:.2f}"
        print(f"    {name:<8}{r['n']:>7}{r['ref_ms']:>10.1f}{kern:>11.1f}"
              f"{r['ref_ms'] * 1e3 / kern:>7.0f}x{incl:>14.0f}x{agree:>15}", flush=True)

    if args.against is not None:
        against(args.against.resolve(), args.rounds, args.repeat)

    print(f"\nbenchmark wall time {time.perf_counter() - t_all:.0f} s; load average at end "
          f"{bk.load_avg()}")


if __name__ == "__main__":
    main()
