"""How close the kernel runs to a bare RK4 loop, and how much faster than the reference.

Prints, measured side by side in one run:

1. roofline: a bare fixed-step RK4 loop over the same right-hand side (``rk4_step`` of the
   flexible damped kernel, outcome level), no events, no bookkeeping: ns per step while
   rocking and in full contact, with the pulse on and off. CPU time of this thread, best of
   ``--repeat``.
2. the kernel at the scene's numerics (the default preset) on each scene (Figures 3(a) and
   4(a)): RK4 evaluations per point split into regular steps and event re-integrations,
   ns per evaluation (kernel calls only, CPU time, best of ``--repeat`` passes, measured
   between two roofline runs) and the roofline's share of it. The
   roofline for a scene is the bare loop's cost weighted by the scene's own mix of phases:
   regular steps per phase and pulse state counted exactly from time histories of a
   uniform sample (``--mix-points``), event re-integrations split in proportion to the
   events of each phase. Then microseconds per point: kernel calls on one core, and the
   real ``rocksweep sweep`` (process start, chunking, HDF5 writing included) on 1 and 2
   workers. The regular share is the regular steps' cost at the roofline over the kernel
   time: the integration no event handling could remove.
2b. the event root finders (bisection, Illinois, Hermite) on every point of each scene at
   the scene's steps and event_tol: RK4 evaluations and microseconds per point, ns per
   evaluation and the roofline's share of it, the speed-up over bisection, and how many
   outcomes differ from bisection's.
3. reference: scipy DOP853 (``rocksweep.physics.reference``) on the accuracy study's stratified
   sample (``--ref-points``; strata outcome x boundary, weights make scene estimates):
   weighted mean and median time per point, the kernel's on the same points (each a 1-row
   chunk call), the speed-up, and the outcome agreement with its standard error.
4. parallel efficiency: points/s of ``rocksweep sweep --jobs 1`` and ``--jobs 2`` on the
   same grid (the shipped one, and ``--eff-n``: 200 x 200 x 3 lam by default), efficiency
   = rate(2) / (2 rate(1)); peak memory (summed RSS of the process tree, sampled).
5. the four paper figures (3a, 3b, 4a, 4b) at N x N x 3 lam through ``rocksweep sweep
   --jobs 2``: N = ``--four-n`` (small by default); ``--paper`` runs 200 x 200 x 3 lam
   (480,000 points) once.
6. warm start: ``rocksweep simulate configs/fig2.yaml`` with numba's cache filled (best of 3).
Optional: ``--compile`` times a cold compile of every kernel variant (a fresh
NUMBA_CACHE_DIR, one subprocess; ``scripts/bench_compile.py`` compiles each variant in a
fresh process of its own, next to the start-up and the per-point costs); ``--million``
sweeps a 10^6-point grid (the rigid block scene) with ``--jobs 2`` and reports its peak
memory.

The machine may be shared: the load average is printed at the start and the end; CPU
times (items 1-2) are less sensitive to load than wall times (items 2-6).

    python scripts/bench_kernel.py                      # ~3-5 min on 2 cores
    python scripts/bench_kernel.py --paper              # + 4 figures at 200 x 200 x 3 lam
    python scripts/bench_kernel.py --tiny               # seconds: a smoke run (CI)
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np
from numba import njit

from rocksweep.analysis.accuracy import (
    Sample,
    _agreement,
    boundary_mask,
    run_kernel,
    run_reference,
    stratified_sample,
)
from rocksweep.compute.dispatch import history_capacity
from rocksweep.compute.sweep import auto_chunk_size, level, plan_chunks, prepare
from rocksweep.kernel import chunk_kernel, point_kernel, warm_up
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel.equations import contact_rhs, rocking_rhs
from rocksweep.kernel.layout import GROUND_PULSE  # a name: a literal in jitted code
from rocksweep.kernel.stepping import rk4_step
from rocksweep.scene.grid import Grid
from rocksweep.scene.model import Scene
from rocksweep.scene.parse import load_scene
from rocksweep.vocab.settings import ROOTS

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "configs"
FOUR = ("fig3a", "fig3b", "fig4a", "fig4b")
PHASES = ("rocking", "full contact")  # index 0, 1 of the mix
PULSE = ("on", "off")  # index 0, 1


def load_avg() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def grid_overrides(n: int | None) -> list[str]:
    """--set overrides that make a figure scene n x n in (w_over_p, A_ratio)."""
    if n is None:
        return []
    return [f"pulse.w_over_p.num={n}", f"pulse.A_ratio.num={n}"]


def scene_of(name: str, n: int | None) -> Scene:
    return load_scene(CONFIGS / f"{name}.yaml", grid_overrides(n))


# ----------------------------------------------------------------------------------------
# 1. roofline
# ----------------------------------------------------------------------------------------


# The same right-hand side (the kernel's own equations), inlined into the loop at numba's
# IR level: no calls, no reference counting, as tight as numba compiles this RHS.
try:
    from rocksweep.kernel.ground import pulse_acc
except ImportError:  # an older copy's package (bench_compile --against uses best_pass only)
    pulse_acc = None
_pulse = njit(inline="always")(pulse_acc) if pulse_acc is not None else None
_rocking = njit(inline="always")(rocking_rhs.py_func)
_contact = njit(inline="always")(contact_rhs.py_func)


@njit(inline="always")
def _acc(t, on, prm):
    """xg'' of the paper's pulses (``ground.ground_acc`` under GROUND_PULSE)."""
    return _pulse(GROUND_PULSE, t, on, prm)


@njit
def _bare_rocking(prm, y0, h, n_runs, n_steps, s, on):
    """n_runs runs of n_steps classical RK4 steps rocking on corner s (flexible, damped)."""
    g = prm[L.PAR_G]  # the kernel's gravity without a vertical: the row's
    acc = 0.0
    for _ in range(n_runs):
        t = 0.0
        th, w, u, v = y0[0], y0[1], y0[2], y0[3]
        for _ in range(n_steps):
            x = _acc(t, on, prm)
            a1, b1, _, _ = _rocking(th, w, u, v, s, x, g, prm, True)
            x = _acc(t + 0.5 * h, on, prm)
            hh = 0.5 * h
            th2, w2, u2, v2 = th + hh * w, w + hh * a1, u + hh * v, v + hh * b1
            a2, b2, _, _ = _rocking(th2, w2, u2, v2, s, x, g, prm, True)
            th3, w3, u3, v3 = th + hh * w2, w + hh * a2, u + hh * v2, v + hh * b2
            a3, b3, _, _ = _rocking(th3, w3, u3, v3, s, x, g, prm, True)
            x = _acc(t + h, on, prm)
            th4, w4, u4, v4 = th + h * w3, w + h * a3, u + h * v3, v + h * b3
            a4, b4, _, _ = _rocking(th4, w4, u4, v4, s, x, g, prm, True)
            c = h / 6.0
            th, w = th + c * (w + 2.0 * (w2 + w3) + w4), w + c * (a1 + 2.0 * (a2 + a3) + a4)
            u, v = u + c * (v + 2.0 * (v2 + v3) + v4), v + c * (b1 + 2.0 * (b2 + b3) + b4)
            t += h
        acc += th + w + u + v
    return acc


@njit
def _bare_contact(prm, y0, h, n_runs, n_steps, s, on):
    """The same in full contact (u, u' only)."""
    acc = 0.0
    for _ in range(n_runs):
        t = 0.0
        u, v = y0[2], y0[3]
        for _ in range(n_steps):
            b1 = _contact(u, v, _acc(t, on, prm), prm, True)[0]
            x = _acc(t + 0.5 * h, on, prm)
            u2, v2 = u + 0.5 * h * v, v + 0.5 * h * b1
            b2 = _contact(u2, v2, x, prm, True)[0]
            u3, v3 = u + 0.5 * h * v2, v + 0.5 * h * b2
            b3 = _contact(u3, v3, x, prm, True)[0]
            u4, v4 = u + h * v3, v + h * b3
            b4 = _contact(u4, v4, _acc(t + h, on, prm), prm, True)[0]
            c = h / 6.0
            u, v = u + c * (v + 2.0 * (v2 + v3) + v4), v + c * (b1 + 2.0 * (b2 + b3) + b4)
            t += h
        acc += u + v
    return acc


@njit
def _bare_kernel_step(prm, y0, h, n_runs, n_steps, s, on):
    """The kernel's own ``rk4_step`` (flexible damped, outcome level) in a bare loop."""
    acc = 0.0
    for _ in range(n_runs):
        t = 0.0
        y = y0
        for _ in range(n_steps):
            y = rk4_step(t, y, h, s, on, prm, True, True, False, GROUND_PULSE)
            t += h
        acc += y[0] + y[1] + y[2] + y[3]
    return acc


def roofline(prm: np.ndarray, total_steps: int, repeat: int) -> dict[str, np.ndarray]:
    """ns per RK4 step [phase (rocking, contact), pulse (on, off)] of bare loops.

    "inlined": the roofline (RHS inlined into the loop); "rk4_step": the kernel's step
    function called from a bare loop (what the kernel's step costs before any event
    logic). Runs of 64 steps from a rocking state (theta = 0.01 rad, small u) keep the
    state in the range the kernel meets; the step is the point's own. CPU time, best of
    ``repeat``.
    """
    y0 = (0.01, -0.02, 1e-3, 0.0, 0.0, 0.0)
    h = float(prm[L.PAR_DT])
    n_steps = 64
    n_runs = max(1, total_steps // n_steps)
    res = {}
    for name, loops in (("inlined", (_bare_rocking, _bare_contact)),
                        ("rk4_step", (_bare_kernel_step, _bare_kernel_step))):
        ns = np.empty((2, 2))
        for i, (fn, s) in enumerate(zip(loops, (1, 0), strict=True)):
            fn(prm, y0, h, 1, 2, s, True)  # compile
            for j, on in enumerate((True, False)):
                best = math.inf
                for _ in range(repeat):
                    c0 = time.thread_time()
                    fn(prm, y0, h, n_runs, n_steps, s, on)
                    best = min(best, time.thread_time() - c0)
                ns[i, j] = best / (n_runs * n_steps) * 1e9
        res[name] = ns
    return res


# ----------------------------------------------------------------------------------------
# 2. the kernel on a whole scene, and its mix of phases
# ----------------------------------------------------------------------------------------


def kernel_pass(scene: Scene) -> dict:
    """Every point of the scene through the chunk kernel, as a 1-worker sweep chunks it.

    Rows are built outside the timed region; only the kernel calls are timed (CPU time of
    this thread and wall time). Returns outs float64[size, N_OUT], cpu, wall [s].
    """
    grid = Grid(scene)
    lvl = level(scene)
    prepare(grid, lvl)
    outs = np.empty((grid.size, L.N_OUT))
    cpu = wall = 0.0
    for a, b in plan_chunks(np.ones(grid.size, bool), auto_chunk_size(grid.size, 1)):
        cr = grid.rows(a, b)
        for kind in np.unique(cr.kinds):
            sel = cr.kinds == kind
            rows = np.ascontiguousarray(cr.rows[sel])
            part = np.empty((rows.shape[0], L.N_OUT))
            fn = chunk_kernel(int(kind), lvl)
            t0, c0 = time.perf_counter(), time.thread_time()
            fn(rows, part)
            cpu += time.thread_time() - c0
            wall += time.perf_counter() - t0
            outs[a:b][sel] = part
    return {"outs": outs, "cpu": cpu, "wall": wall, "grid": grid}


def best_pass(scene: Scene, repeat: int) -> dict:
    """``kernel_pass`` ``repeat`` times; the one with the least CPU time (same results)."""
    return min((kernel_pass(scene) for _ in range(max(1, repeat))), key=lambda p: p["cpu"])


def step_mix(grid: Grid, flat: np.ndarray) -> np.ndarray:
    """RK4 evaluations of the given points by [phase (rocking, contact), pulse (on, off)].

    From each point's time history (the single-run kernel: same steps as the sweep's):
    a history row later than the one before ends a regular step in that row's phase; two
    rows at one time are an event (its phase: the first row's), an overturn ends the last
    row. A point's event re-integrations are split over its events' phases and pulse
    states in proportion to their counts (a point with re-integrations but no event, a
    dip checked by the Hermite test, counts them as rocking).
    """
    cr = grid.rows_at(flat)
    counts = np.zeros((2, 2))
    cap = max(history_capacity(r) for r in cr.rows)
    hist = np.empty((cap, L.N_HIST))
    out = np.empty(L.N_OUT)
    for row, kind in zip(cr.rows, cr.kinds, strict=True):
        warm_up(int(kind))
        point_kernel(int(kind))(row, out, hist)
        n = int(out[L.OUT_HIST_ROWS])
        t, ph = hist[:n, L.HIST_T], hist[:n, L.HIST_PHASE]
        tp = row[L.PAR_TPULSE]
        dt = np.diff(t)
        step_end = np.flatnonzero(dt > 0) + 1
        for i in (0, 1):
            in_phase = (ph[step_end] != 0) if i == 0 else (ph[step_end] == 0)
            on = t[step_end - 1] < tp
            counts[i, 0] += np.sum(in_phase & on)
            counts[i, 1] += np.sum(in_phase & ~on)
        ev = np.flatnonzero(dt == 0)
        ev_counts = np.zeros((2, 2))
        for k in ev:
            ev_counts[0 if ph[k] != 0 else 1, 0 if t[k] < tp else 1] += 1
        if out[L.OUT_OUTCOME] in (L.OUTCOME_MODE1, L.OUTCOME_MODE2):
            ev_counts[0, 0 if t[n - 1] < tp else 1] += 1
        e_steps = out[L.OUT_EVENT_STEPS]
        if ev_counts.sum() > 0:
            counts += e_steps * ev_counts / ev_counts.sum()
        else:
            counts[0, 0] += e_steps
    return counts


# ----------------------------------------------------------------------------------------
# CLI runs (items 2, 4, 5, 6): subprocesses, wall time and peak memory of the process tree
# ----------------------------------------------------------------------------------------


def _rocksweep() -> list[str]:
    exe = shutil.which("rocksweep")
    return [exe] if exe else [sys.executable, "-m", "rocksweep"]


def _tree_rss(pid: int) -> int:
    """Summed resident memory [bytes] of a process and its descendants (Linux /proc)."""
    total, todo = 0, [pid]
    while todo:
        p = todo.pop()
        try:
            with open(f"/proc/{p}/status") as f:
                for line in f:
                    if line.startswith("VmRSS:"):
                        total += int(line.split()[1]) * 1024
                        break
            for task in os.listdir(f"/proc/{p}/task"):
                with open(f"/proc/{p}/task/{task}/children") as f:
                    todo += [int(c) for c in f.read().split()]
        except (OSError, ValueError):
            continue
    return total


def run_timed(cmd: list[str]) -> tuple[float, int]:
    """Run a command; return (wall time [s], peak summed RSS of its process tree [bytes])."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    peak = 0
    stop = threading.Event()

    def poll() -> None:
        nonlocal peak
        while not stop.is_set():
            peak = max(peak, _tree_rss(proc.pid))
            stop.wait(0.1)

    th = threading.Thread(target=poll, daemon=True)
    th.start()
    _, err = proc.communicate()
    wall = time.perf_counter() - t0
    stop.set()
    th.join()
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}):\n{err}")
    return wall, peak


def cli_sweep(scene_path: Path, overrides: list[str], jobs: int, out: Path) -> dict:
    """``rocksweep sweep`` in a subprocess. Returns points, process wall time, the sweep's
    own wall and CPU time (file attributes), and peak memory."""
    import h5py

    cmd = [*_rocksweep(), "sweep", str(scene_path), "-o", str(out), "--jobs", str(jobs),
           "--overwrite", "-q", *(f"--set={o}" for o in overrides)]
    wall, rss = run_timed(cmd)
    with h5py.File(out, "r") as f:
        return {"points": int(f.attrs["points_total"]), "process_wall": wall,
                "wall": float(f.attrs["wall_time"]), "cpu": float(f.attrs["cpu_time"]),
                "rss": rss}


# ----------------------------------------------------------------------------------------
# optional: cold compile of every variant
# ----------------------------------------------------------------------------------------

_COMPILE_SNIPPET = """
import time
t0 = time.perf_counter()
from rocksweep.kernel import warm_up
from rocksweep.kernel import layout as L
print(f"import {time.perf_counter() - t0:.2f}", flush=True)
names = {L.KIND_FLEXIBLE: "flexible", L.KIND_FLEXIBLE_UNDAMPED: "flexible_undamped",
         L.KIND_RIGID: "rigid"}
for lvl, tag in ((L.LEVEL_OUTCOME, "chunk"), (L.LEVEL_ENERGY, "chunk_energy"),
                 (None, "point_history")):
    for kind in (L.KIND_FLEXIBLE, L.KIND_FLEXIBLE_UNDAMPED, L.KIND_RIGID):
        t = time.perf_counter()
        warm_up(kind, lvl)
        print(f"{tag}:{names[kind]} {time.perf_counter() - t:.2f}", flush=True)
"""


def cold_compile() -> list[tuple[str, float]]:
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        res = subprocess.run([sys.executable, "-c", _COMPILE_SNIPPET], env=env,
                             capture_output=True, text=True, check=True)
    return [(ln.split()[0], float(ln.split()[1])) for ln in res.stdout.splitlines()]


# ----------------------------------------------------------------------------------------


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=["fig3a", "fig4a"],
                    help="scenes (configs/NAME.yaml) for items 2-4 (default fig3a fig4a)")
    ap.add_argument("--n", type=int, default=None,
                    help="make those scenes n x n x 3 lam (default: as shipped, 80 x 80)")
    ap.add_argument("--ref-points", type=int, default=200,
                    help="reference sample per scene (default 200)")
    ap.add_argument("--mix-points", type=int, default=400,
                    help="uniform sample per scene for the phase mix (default 400)")
    ap.add_argument("--roof-steps", type=int, default=2_000_000,
                    help="bare-loop steps per roofline figure (default 2e6)")
    ap.add_argument("--repeat", type=int, default=3,
                    help="best of this many (roofline, kernel sample timings)")
    ap.add_argument("--eff-n", type=int, default=200,
                    help="item 4 also at n x n x 3 lam (default 200: the paper's resolution, "
                         "where start-up costs are amortised as in a real sweep)")
    ap.add_argument("--four-n", type=int, default=40,
                    help="the four figures at n x n x 3 lam for item 5 (default 40)")
    ap.add_argument("--paper", action="store_true",
                    help="item 5 at 200 x 200 x 3 lam (480,000 points; once)")
    ap.add_argument("--compile", action="store_true",
                    help="also time a cold compile of every kernel variant")
    ap.add_argument("--million", action="store_true",
                    help="also sweep a 10^6-point grid (rigid block) and report its memory")
    ap.add_argument("--tiny", action="store_true",
                    help="a smoke run in seconds: 6 x 6 grids, 4 reference points")
    args = ap.parse_args()
    if args.tiny:
        args.n, args.ref_points, args.mix_points = 6, 4, 8
        # one grid size in [4] (eff_n = n) and one warm start in [6]: a smoke run
        args.roof_steps, args.repeat, args.four_n, args.eff_n = 20_000, 1, 4, 6
    four_n = 200 if args.paper else args.four_n
    seed = 0

    print(f"rocksweep kernel benchmark: {os.cpu_count()} cores, load average at start "
          f"{load_avg()}")
    scenes = {name: scene_of(name, args.n) for name in args.scenes}
    t_wall = time.perf_counter()

    # --- 1 -------------------------------------------------------------------------------
    # The roofline and the kernel are measured in turns, each the best of its rounds: the
    # speed of a shared machine drifts by 10-20% within minutes, and noise only adds time.
    roofs, passes, mixes = {}, {}, {}
    for name, scene in scenes.items():
        prm = Grid(scene).rows(0, 1).rows[0]
        roofs[name] = roofline(prm, args.roof_steps, args.repeat)
        passes[name] = best_pass(scene, args.repeat)
        again = roofline(prm, args.roof_steps, args.repeat)
        roofs[name] = {k: np.minimum(v, again[k]) for k, v in roofs[name].items()}
    print("\n[1] roofline: bare RK4 loops over the flexible damped right-hand side (no "
          f"events, no bookkeeping), ns/step, CPU time, best of {args.repeat}")
    print("    inlined: the RHS inlined into the loop (the roofline); rk4_step: the kernel's "
          "own step function called from a bare loop")
    print(f"{'scene':<8}{'loop':<10}{'rocking on':>12}{'rocking off':>12}{'contact on':>12}"
          f"{'contact off':>12}")
    for name, r in roofs.items():
        for loop, ns in r.items():
            print(f"{name:<8}{loop:<10}{ns[0, 0]:>12.1f}{ns[0, 1]:>12.1f}{ns[1, 0]:>12.1f}"
                  f"{ns[1, 1]:>12.1f}")

    # --- 2 (kernel part) -----------------------------------------------------------------
    for name in scenes:
        grid = passes[name]["grid"]
        rng = np.random.default_rng(seed)
        k = min(args.mix_points, grid.size)
        flat = np.sort(rng.choice(grid.size, size=k, replace=False)).astype(np.int64)
        mixes[name] = step_mix(grid, flat)

    # --- CLI sweeps (items 2 and 4) ------------------------------------------------------
    cli = {}  # (scene, grid size n or None, jobs) -> cli_sweep result
    with tempfile.TemporaryDirectory() as tmp:
        for name in scenes:
            for n in dict.fromkeys((args.n, args.eff_n)):
                for jobs in (1, 2):
                    cli[name, n, jobs] = cli_sweep(CONFIGS / f"{name}.yaml", grid_overrides(n),
                                                   jobs, Path(tmp) / f"{name}-{jobs}.h5")

    print(f"\n[2] kernel at the scene's numerics ({scenes[args.scenes[0]].numerics.describe()})"
          ", outcome-only")
    print("    evals = regular RK4 steps + event re-integrations per point; ns/eval: kernel "
          "calls only (CPU); roofline: bare loop at the scene's phase mix; us/pt sweep: "
          "`rocksweep sweep` wall time")
    print(f"{'scene':<8}{'points':>8}{'regular':>9}{'event':>8}{'event %':>8}{'ns/eval':>9}"
          f"{'roof ns':>9}{'roof/kern':>10}{'us/pt kern':>11}{'sweep j1':>9}{'sweep j2':>9}")
    for name in scenes:
        p = passes[name]
        o = p["outs"]
        n = o.shape[0]
        reg, evs = o[:, L.OUT_STEPS].sum(), o[:, L.OUT_EVENT_STEPS].sum()
        ns_eval = p["cpu"] / (reg + evs) * 1e9
        mix = mixes[name] / mixes[name].sum()
        roof = float(np.sum(mix * roofs[name]["inlined"]))
        print(f"{name:<8}{n:>8}{reg / n:>9.0f}{evs / n:>8.0f}{100 * evs / (reg + evs):>8.1f}"
              f"{ns_eval:>9.1f}{roof:>9.1f}{roof / ns_eval:>10.2f}{p['wall'] / n * 1e6:>11.1f}"
              f"{cli[name, args.n, 1]['wall'] / n * 1e6:>9.1f}"
              f"{cli[name, args.n, 2]['wall'] / n * 1e6:>9.1f}")
    print("    regular share: regular steps at the roofline's cost / kernel time (the part "
          "no event handling could remove)")
    for name in scenes:
        p = passes[name]
        o = p["outs"]
        mix = mixes[name] / mixes[name].sum()
        roof = float(np.sum(mix * roofs[name]["inlined"]))
        print(f"    {name}: regular share {o[:, L.OUT_STEPS].sum() * roof * 1e-9 / p['cpu']:.2f}")
    print("    phase mix of RK4 evaluations (uniform sample): "
          + "; ".join(f"{name}: " + ", ".join(
              f"{PHASES[i]} {PULSE[j]} {100 * mixes[name][i, j] / mixes[name].sum():.0f}%"
              for i in range(2) for j in range(2)) for name in scenes))

    # --- 2b: the event root finders, same points, same run ------------------------------
    print("\n[2b] event root finders at the scene's steps and event_tol: kernel calls only "
          "(CPU), every point of the scene; outcome differences against bisection")
    print("    roof/kern: the roofline at the scene's phase mix (item 2) / ns per evaluation")
    print(f"{'scene':<8}{'root':<11}{'evals/pt':>9}{'event/pt':>9}{'us/pt':>8}{'ns/eval':>9}"
          f"{'roof/kern':>10}{'vs bisection':>13}{'outcomes differ':>16}")
    for name, scene in scenes.items():
        by_root = {}
        for root in ROOTS:
            if root == scene.numerics.root:  # measured in item 2
                by_root[root] = passes[name]
                continue
            sc = dataclasses.replace(scene, numerics=dataclasses.replace(scene.numerics,
                                                                         root=root))
            by_root[root] = best_pass(sc, args.repeat)
        base = by_root["bisection"]
        roof = float(np.sum(mixes[name] / mixes[name].sum() * roofs[name]["inlined"]))
        for root, p in by_root.items():
            o = p["outs"]
            n = o.shape[0]
            ev = o[:, L.OUT_EVENT_STEPS].sum() / n
            evals = o[:, L.OUT_STEPS].sum() / n + ev
            ns_eval = p["cpu"] / (evals * n) * 1e9
            diff = int(np.sum(o[:, L.OUT_OUTCOME] != base["outs"][:, L.OUT_OUTCOME]))
            print(f"{name:<8}{root:<11}{evals:>9.0f}{ev:>9.0f}{p['cpu'] / n * 1e6:>8.1f}"
                  f"{ns_eval:>9.1f}{roof / ns_eval:>10.2f}{base['cpu'] / p['cpu']:>12.2f}x"
                  f"{diff:>16}")

    # --- 3 -------------------------------------------------------------------------------
    print("\n[3] reference (scipy DOP853, rtol 1e-10) vs kernel on the accuracy study's "
          "stratified sample (weighted means estimate the whole scene)")
    print(f"{'scene':<8}{'sample':>7}{'ref mean ms':>12}{'ref med ms':>11}{'kern mean us':>13}"
          f"{'kern med us':>12}{'speed-up mean':>14}{'median':>8}{'agree %':>14}{'flips':>6}")
    for name, scene in scenes.items():
        grid = passes[name]["grid"]
        outcome = passes[name]["outs"][:, L.OUT_OUTCOME].astype(np.int8)
        bnd = boundary_mask(outcome.reshape(grid.shape), grid.dims).ravel()
        flat, stratum, weight, strata, sizes = stratified_sample(outcome, bnd,
                                                                 args.ref_points, seed)
        sample = Sample(flat, stratum, weight, strata, sizes, grid.size, outcome, 0.0)
        ref, ref_s, _ = run_reference(scene, flat)
        kern, kern_s, _ = run_kernel(scene, flat, scene.numerics, args.repeat)
        agree = kern[:, L.OUT_OUTCOME] == ref[:, L.OUT_OUTCOME]
        share, se = _agreement(agree, sample)
        ref_mean = float(np.sum(ref_s * weight) / weight.sum())
        kern_mean = float(np.sum(kern_s * weight) / weight.sum())
        print(f"{name:<8}{len(flat):>7}{ref_mean * 1e3:>12.1f}{np.median(ref_s) * 1e3:>11.1f}"
              f"{kern_mean * 1e6:>13.1f}{np.median(kern_s) * 1e6:>12.1f}"
              f"{ref_mean / kern_mean:>14.0f}{np.median(ref_s) / np.median(kern_s):>8.0f}"
              f"{f'{100 * share:.2f}+-{100 * se:.2f}':>14}{int((~agree).sum()):>6}")

    # --- 4 -------------------------------------------------------------------------------
    print("\n[4] parallel efficiency through `rocksweep sweep` (start-up, kernel cache load, "
          "chunking, HDF5 included); eff = rate(2) / (2 rate(1)); the shipped grid and "
          f"{args.eff_n} x {args.eff_n} x 3 lam")
    print(f"{'scene':<8}{'points':>8}{'jobs':>5}{'process s':>10}{'sweep s':>9}{'pts/s':>9}"
          f"{'CPU s':>8}{'eff':>6}{'peak MB':>9}")
    for (name, n, jobs), r in cli.items():
        r1 = cli[name, n, 1]
        rate = r["points"] / r["wall"]
        eff = rate / (jobs * r1["points"] / r1["wall"])
        print(f"{name:<8}{r['points']:>8}{jobs:>5}{r['process_wall']:>10.2f}"
              f"{r['wall']:>9.2f}{rate:>9.0f}{r['cpu']:>8.2f}{eff:>6.2f}"
              f"{r['rss'] / 2**20:>9.0f}")

    # --- 5 -------------------------------------------------------------------------------
    print(f"\n[5] the four figures at {four_n} x {four_n} x 3 lam, `rocksweep sweep --jobs 2`"
          + (" (--paper)" if args.paper else " (small version; --paper: 200 x 200)"))
    print(f"{'scene':<8}{'points':>8}{'process s':>10}{'sweep s':>9}{'pts/s':>9}{'peak MB':>9}")
    tot_pts = tot_wall = tot_proc = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for name in FOUR:
            r = cli_sweep(CONFIGS / f"{name}.yaml", grid_overrides(four_n), 2,
                          Path(tmp) / f"{name}.h5")
            tot_pts += r["points"]
            tot_wall += r["wall"]
            tot_proc += r["process_wall"]
            print(f"{name:<8}{r['points']:>8}{r['process_wall']:>10.2f}{r['wall']:>9.2f}"
                  f"{r['points'] / r['wall']:>9.0f}{r['rss'] / 2**20:>9.0f}")
    print(f"{'total':<8}{int(tot_pts):>8}{tot_proc:>10.2f}{tot_wall:>9.2f}"
          f"{tot_pts / tot_wall:>9.0f}")

    # --- 6 -------------------------------------------------------------------------------
    cmd = [*_rocksweep(), "simulate", str(CONFIGS / "fig2.yaml")]
    run_timed(cmd)  # fills numba's cache for the single-run variant if needed
    warm = min(run_timed(cmd)[0] for _ in range(max(1, args.repeat)))
    print(f"\n[6] warm start: `rocksweep simulate configs/fig2.yaml` {warm:.2f} s "
          f"(best of {max(1, args.repeat)}, numba cache filled)")

    if args.million:
        overrides = ["pulse.w_over_p.num=708", "pulse.A_ratio.num=707"]
        with tempfile.TemporaryDirectory() as tmp:
            r = cli_sweep(CONFIGS / "block.yaml", overrides, 2, Path(tmp) / "million.h5")
        print(f"\n[7] 10^6-point grid (configs/block.yaml, 2 x 708 x 707 = {r['points']} "
              f"points) --jobs 2: {r['process_wall']:.1f} s, peak memory (summed RSS of the "
              f"process tree) {r['rss'] / 2**20:.0f} MB")

    if args.compile:
        res = cold_compile()
        print("\n[8] cold compile (fresh NUMBA_CACHE_DIR, one process, in this order), s:")
        for what, secs in res:
            print(f"    {what:<32}{secs:>7.2f}")
        print(f"    {'total':<32}{sum(s for _, s in res):>7.2f}")

    print(f"\nbenchmark wall time {time.perf_counter() - t_wall:.0f} s; load average at end "
          f"{load_avg()}")


if __name__ == "__main__":
    main()
