"""What a vertical ground acceleration costs a point (docs/vertical.md, docs/performance.md).

The outcome kernel on every point of a scene's grid (Figure 3(a): flexible; the block
scene: rigid; ``--n`` values per diagram axis, 3 lam), the same parameter rows through:

1. the variant the scene runs (the paper's sine: the pulse variants);
2. the GROUND_ANY variant (every shape and records) on the same rows;
3. the GROUND_VERTICAL variant with a_v = 0 (PAR_V_AMP = 0, PAR_T_AIR = inf): the price of
   the vertical code alone (its outcomes must be the pulse variant's);
4. the GROUND_VERTICAL variant with a vertical harmonic (``--amplitude`` g at ``--ratio``
   times the pulse's frequency, its steps by ``numerics.vertical_step``): a vertical scene.

Core-us per point: CPU time of this thread over the kernel calls alone (rows built before),
chunked as a 1-worker sweep chunks, the best of ``--repeat`` rounds, the four measured in
turn within each round (the machine may be shared: load average printed).

    python scripts/bench_vertical.py            # ~1-2 min on 2 cores after compiling
    python scripts/bench_vertical.py --n 20     # quicker

``--against DIR --rounds N`` (DIR holding another copy's ``rocksweep``, e.g. ``git archive
REV | tar -x -C DIR``): scenes without a vertical, this copy against DIR, each
measurement a fresh process, the order swapped every round: core-us per point of the
outcome kernel (best of 7 passes) on Figures 3(a), 4(a), the block and the Ricker scene
at small grids; the medians and their ratio.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import bench_kernel as bk
import numpy as np

from rocksweep.compute.sweep import auto_chunk_size, plan_chunks
from rocksweep.kernel import chunk_kernel, warm_up
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import step_budget, vertical_step
from rocksweep.physics.bodies import G
from rocksweep.physics.ground_motion import air_time_harmonic
from rocksweep.scene.grid import Grid


def rows_of(scene) -> tuple[np.ndarray, np.ndarray]:
    """(rows float64[size, N_PAR], kinds int64[size]) of every point of the scene."""
    grid = Grid(scene)
    cr = grid.rows(0, grid.size)
    return cr.rows, cr.kinds


def with_harmonic(rows: np.ndarray, amplitude: float, ratio: float, numerics) -> np.ndarray:
    """The rows with a vertical harmonic of ``amplitude`` g at ``ratio`` times the pulse's
    frequency, phase 0, as ``points.fill_rows`` sets it (step, cap and t_air:
    ``Excitation.fill_gravity``)."""
    out = rows.copy()
    w_v = ratio * rows[:, L.PAR_OMEGA]
    out[:, L.PAR_V_AMP] = amplitude * G
    out[:, L.PAR_V_OMEGA] = w_v
    out[:, L.PAR_V_PHASE] = 0.0
    out[:, L.PAR_T_AIR] = air_time_harmonic(amplitude, w_v, 0.0, rows[:, L.PAR_TPULSE])
    out[:, L.PAR_DT_ON] = vertical_step(rows[:, L.PAR_DT_ON], w_v, numerics.steps_per_period,
                                        numerics.pulse_steps)
    out[:, L.PAR_MAXSTEPS] = step_budget(rows[:, L.PAR_TPULSE], rows[:, L.PAR_TEND],
                                         rows[:, L.PAR_DT], out[:, L.PAR_DT_ON], numerics)
    return out


def one_pass(rows: np.ndarray, kinds: np.ndarray, ground: int) -> tuple[np.ndarray, float]:
    """(outs, CPU s) of the rows through the outcome chunk kernel of ``ground``."""
    outs = np.empty((rows.shape[0], L.N_OUT))
    cpu = 0.0
    for a, b in plan_chunks(np.ones(rows.shape[0], bool), auto_chunk_size(rows.shape[0], 1)):
        for kind in np.unique(kinds[a:b]):
            sel = np.flatnonzero(kinds[a:b] == kind) + a
            sub = np.ascontiguousarray(rows[sel])
            part = np.empty((sub.shape[0], L.N_OUT))
            fn = chunk_kernel(int(kind), L.LEVEL_OUTCOME, ground)
            c0 = time.thread_time()
            fn(sub, part)
            cpu += time.thread_time() - c0
            outs[sel] = part
    return outs, cpu


_AB_SNIPPET = """
import json, sys, time
import numpy as np
from rocksweep.kernel import chunk_kernel, warm_up
from rocksweep.kernel import layout as L
from rocksweep.scene.grid import Grid
from rocksweep.scene.parse import load_scene
res = {}
for name, n in (("fig3a", 30), ("fig4a", 24), ("block", 40), ("ricker", 24)):
    sc = load_scene(f"{sys.argv[1]}/configs/{name}.yaml", [
        f"pulse.w_over_p={{start: 0.2, stop: 6, num: {n}}}",
        f"pulse.A_ratio={{start: 0.3, stop: 12, num: {n}}}"])
    cr = Grid(sc).rows(0, sc.size)
    jobs = []
    for kind in np.unique(cr.kinds):
        warm_up(int(kind), L.LEVEL_OUTCOME, sc.ground)
        jobs.append((chunk_kernel(int(kind), L.LEVEL_OUTCOME, sc.ground),
                     np.ascontiguousarray(cr.rows[cr.kinds == kind])))
    best = np.inf
    for _ in range(7):
        c0 = time.thread_time()
        for fn, rows in jobs:
            fn(rows, np.empty((rows.shape[0], L.N_OUT)))
        best = min(best, time.thread_time() - c0)
    res[name] = best / sc.size * 1e6
print(json.dumps(res))
"""


def against(other: Path, rounds: int) -> None:
    """Scenes without a vertical, this copy against ``other``, alternating (see above)."""
    here = Path(__file__).resolve().parents[1]
    got: dict[Path, list[dict]] = {here: [], other: []}
    for r in range(rounds):
        for tree in (here, other) if r % 2 == 0 else (other, here):
            env = {**os.environ, "PYTHONPATH": str(tree)}
            res = subprocess.run([sys.executable, "-c", _AB_SNIPPET, str(tree)], env=env,
                                 capture_output=True, text=True, check=True)
            got[tree].append(json.loads(res.stdout.splitlines()[-1]))
            print(f"  round {r + 1} {'this ' if tree == here else 'other'} "
                  + "  ".join(f"{k} {v:.2f}" for k, v in got[tree][-1].items()), flush=True)
    print(f"  {'median core-us/point':<22}{'this':>8}{'other':>8}{'this/other':>12}")
    for k in got[here][0]:
        a = float(np.median([g[k] for g in got[here]]))
        b = float(np.median([g[k] for g in got[other]]))
        print(f"  {k:<22}{a:>8.3f}{b:>8.3f}{a / b:>12.4f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=40, help="values per diagram axis")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--amplitude", type=float, default=0.3, help="[g]")
    ap.add_argument("--ratio", type=float, default=3.0, help="w_v / w of the pulse")
    ap.add_argument("--against", type=Path, help="another copy's tree (A/B, no vertical)")
    ap.add_argument("--rounds", type=int, default=6)
    args = ap.parse_args()
    print(f"bench_vertical: {os.cpu_count()} cores, load average {bk.load_avg()}")
    if args.against is not None:
        against(args.against.resolve(), args.rounds)
        print(f"load average at end {bk.load_avg()}")
        return
    for name in ("fig3a", "block"):
        scene = bk.scene_of(name, args.n)
        rows, kinds = rows_of(scene)
        zero = rows.copy()
        zero[:, L.PAR_T_AIR] = np.inf
        harm = with_harmonic(rows, args.amplitude, args.ratio, scene.numerics)
        cases = [("pulse variant", rows, L.GROUND_PULSE), ("ground variant", rows, L.GROUND_ANY),
                 ("vertical, a_v = 0", zero, L.GROUND_VERTICAL),
                 (f"vertical, {args.amplitude:g} g at {args.ratio:g} w", harm,
                  L.GROUND_VERTICAL)]
        for k in np.unique(kinds):
            for g in (L.GROUND_PULSE, L.GROUND_ANY, L.GROUND_VERTICAL):
                warm_up(int(k), L.LEVEL_OUTCOME, g)
        best = {c[0]: np.inf for c in cases}
        outs = {}
        for _ in range(args.repeat):
            for label, r, g in cases:
                outs[label], cpu = one_pass(r, kinds, g)
                best[label] = min(best[label], cpu)
        same = np.array_equal(outs["pulse variant"][:, L.OUT_OUTCOME],
                              outs["vertical, a_v = 0"][:, L.OUT_OUTCOME])
        print(f"\n{name}: {rows.shape[0]} points (outcomes with a_v = 0 equal the pulse "
              f"variant's: {same})")
        base = best["pulse variant"]
        for label, _, _ in cases:
            print(f"  {label:<28}{best[label] / rows.shape[0] * 1e6:>9.1f} core-us/point"
                  f"{best[label] / base:>8.2f}x")
    print(f"\nload average at end {bk.load_avg()}")


if __name__ == "__main__":
    main()
