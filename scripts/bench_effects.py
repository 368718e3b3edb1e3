"""What each effect costs: the same grid under each effect set, measured side by side.

Grid: the Figure 4(a) pulse ranges (sine, omega/p in [0.15, 12], A/(g tan alpha_cg) in
[0.3, 24], lam = 0), N x N points (``--n``), default accuracy. Effect sets:

  everything on   flexible body wn/p = 9.82, zeta = 0.05 (Table 3), energy accounting and
                  a time history (the single-run kernel ``point_kernel``, once per point)
  run_point loop  the same, one ``rocksweep.compute.single.run_point`` call per point (what a
                  script looping over single runs pays: rows built and histories copied)
  energy          same body, energy accounting, no history (``outputs: {energy: true}``)
  outcome-only    same body, outcome and summary metrics only (what sweeps run)
  zeta=0 general  Table 3 body with zeta = 0 through the damped kernel ...
  zeta=0 undamped ... and through the undamped kernel (same physics, no damper terms)
  + check         outcome-only plus the half-step rerun of ``outputs: {check: true}``
                  (per-point error estimates)
  accurate        outcome-only at the `accurate` preset (the other way to trust the
                  overturning times and max|theta| far from the paper's region)
  rigid           Table 3 geometry with wn/p = inf (top mass welded), outcome-only
  block           uniform rigid block, alpha = 0.15 (the same slenderness), outcome-only

The grid is cut in chunks of ``--chunk`` points; every chunk is timed ``--repeat`` times
under every variant, round robin (so drifts of the machine hit all of them alike), and a
variant's time is the sum over chunks of its best time. Compilation is excluded
(``warm_up``). Prints points/s, the ratio of time per point to the everything-on kernel,
and the mean RK4 step evaluations per point (regular + event re-integrations), which
explain the ratios.

    python scripts/bench_effects.py            # 16 x 16 grid, best of 5 per chunk
"""

from __future__ import annotations

import argparse
import time

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np

from rocksweep.compute.dispatch import history_capacity
from rocksweep.compute.single import run_point
from rocksweep.fields import check_rows
from rocksweep.kernel import chunk_kernel, point_kernel, warm_up
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, FlexibleBody
from rocksweep.physics.ground_motion import pulse
from rocksweep.physics.points import Bodies, Columns, Point, fill_rows

TABLE3 = dict(wn_over_p=9.82, zeta=0.05, alpha_cg=0.15, alpha_A=0.28, mA_over_m=0.47,
              IA_ratio=0.56)


def grid_values(n: int) -> tuple[np.ndarray, np.ndarray]:
    """(w_over_p, A_ratio), each float64[n*n]: the Figure 4(a) ranges, n x n."""
    w, a = np.meshgrid(np.linspace(0.15, 12, n), np.linspace(0.3, 24, n))
    return w.ravel(), a.ravel()


def grid_rows(body, n: int, numerics: Numerics) -> np.ndarray:
    """Parameter rows float64[n*n, N_PAR] of the Figure 4(a) grid for ``body``."""
    w, a = grid_values(n)
    k = w.size
    rows = np.empty((k, L.N_PAR))
    fill_rows(rows, Bodies.of([body] * k), pulse("sine"), Columns(np.zeros(k), w, a),
              numerics)
    return rows


def run_chunk(kind: int, level: int):
    f = chunk_kernel(kind, level)

    def run(rows: np.ndarray) -> np.ndarray:
        outs = np.empty((rows.shape[0], L.N_OUT))
        f(rows, outs)
        return outs
    return run


def run_check(kind: int, level: int):
    """A chunk of a sweep with ``outputs.check``: the rows, then their half-step reruns."""
    f = chunk_kernel(kind, level)

    def run(rows: np.ndarray) -> np.ndarray:
        outs, half = np.empty((rows.shape[0], L.N_OUT)), np.empty((rows.shape[0], L.N_OUT))
        f(rows, outs)
        f(check_rows(rows), half)
        return outs
    return run


def run_history(kind: int):
    f = point_kernel(kind)

    def run(rows: np.ndarray) -> np.ndarray:
        outs = np.empty((rows.shape[0], L.N_OUT))
        hist = np.empty((max(history_capacity(r) for r in rows), L.N_HIST))
        for i in range(rows.shape[0]):
            f(rows[i], outs[i], hist)
        return outs
    return run


def run_point_loop(numerics: Numerics):
    """What a script looping over ``rocksweep.compute.single.run_point`` pays (energy + history)."""
    def run(points: np.ndarray) -> np.ndarray:
        return np.array([run_point(p, numerics, history=True).out for p in points])
    return run


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=16, help="grid is n x n (default 16)")
    ap.add_argument("--repeat", type=int, default=5,
                    help="timings per chunk and variant; the best counts (default 5)")
    ap.add_argument("--chunk", type=int, default=32, help="points per timed chunk")
    args = ap.parse_args()
    numerics = Numerics.preset("default")

    flex = FlexibleBody(**TABLE3)
    flex0 = FlexibleBody(**{**TABLE3, "zeta": 0.0})
    rigid = FlexibleBody(**{**TABLE3, "wn_over_p": float("inf")})
    block = BlockBody(alpha=0.15)
    variants = [  # (label, rows, runner, kind, level)
        ("flexible 9.82, energy + history (all on)", flex, run_history(L.KIND_FLEXIBLE),
         L.KIND_FLEXIBLE, None),
        ("run_point() loop, energy + history", flex, run_point_loop(numerics),
         L.KIND_FLEXIBLE, None),
        ("flexible 9.82, energy", flex, run_chunk(L.KIND_FLEXIBLE, L.LEVEL_ENERGY),
         L.KIND_FLEXIBLE, L.LEVEL_ENERGY),
        ("flexible 9.82, outcome-only", flex, run_chunk(L.KIND_FLEXIBLE, L.LEVEL_OUTCOME),
         L.KIND_FLEXIBLE, L.LEVEL_OUTCOME),
        ("flexible 9.82, outcome-only + check", flex,
         run_check(L.KIND_FLEXIBLE, L.LEVEL_OUTCOME), L.KIND_FLEXIBLE, L.LEVEL_OUTCOME),
        ("flexible 9.82, outcome-only, accurate", flex,
         run_chunk(L.KIND_FLEXIBLE, L.LEVEL_OUTCOME), L.KIND_FLEXIBLE, L.LEVEL_OUTCOME),
        ("zeta=0, general (damped) kernel", flex0,
         run_chunk(L.KIND_FLEXIBLE, L.LEVEL_OUTCOME), L.KIND_FLEXIBLE, L.LEVEL_OUTCOME),
        ("zeta=0, undamped kernel", flex0,
         run_chunk(L.KIND_FLEXIBLE_UNDAMPED, L.LEVEL_OUTCOME), L.KIND_FLEXIBLE_UNDAMPED,
         L.LEVEL_OUTCOME),
        ("rigid (wn/p = inf), outcome-only", rigid, run_chunk(L.KIND_RIGID, L.LEVEL_OUTCOME),
         L.KIND_RIGID, L.LEVEL_OUTCOME),
        ("block alpha=0.15, outcome-only", block, run_chunk(L.KIND_RIGID, L.LEVEL_OUTCOME),
         L.KIND_RIGID, L.LEVEL_OUTCOME),
    ]
    t0 = time.perf_counter()
    for _, _, _, kind, level in variants:
        warm_up(kind, level)
    print(f"compile/load: {time.perf_counter() - t0:.1f} s")
    rows = {label: grid_rows(body, args.n, numerics) for label, body, *_ in variants}
    rows["flexible 9.82, outcome-only, accurate"] = grid_rows(flex, args.n,
                                                              Numerics.preset("accurate"))
    w, a = grid_values(args.n)
    rows["run_point() loop, energy + history"] = np.array(
        [Point(flex, 0.0, "sine", float(wi), float(ai)) for wi, ai in zip(w, a, strict=True)],
        dtype=object)

    # Round robin over (repeat, chunk, variant); the best time of each chunk counts, so a
    # burst of load from other processes spoils one chunk's timing, not a variant's total.
    npts = args.n * args.n
    chunks = [slice(i, min(i + args.chunk, npts)) for i in range(0, npts, args.chunk)]
    best = {label: np.full(len(chunks), np.inf) for label, *_ in variants}
    outs = {label: np.empty((npts, L.N_OUT)) for label, *_ in variants}
    for _ in range(args.repeat):
        for j, c in enumerate(chunks):
            for label, _, runner, *_ in variants:
                t = time.perf_counter()
                o = runner(rows[label][c])
                best[label][j] = min(best[label][j], time.perf_counter() - t)
                outs[label][c] = o
    best = {label: float(b.sum()) for label, b in best.items()}

    ref = variants[0][0]
    print(f"grid: {args.n} x {args.n} = {npts} points (Figure 4(a) ranges, sine, lam = 0), "
          f"accuracy {numerics.describe()}, best of {args.repeat}")
    print(f"{'effect set':44s} {'points/s':>10s} {'us/point':>9s} {'x cheaper':>9s} "
          f"{'RK4/point':>10s} {'mode1':>6s} {'mode2':>6s}")
    for label, *_ in variants:
        o = outs[label]
        evals = np.mean(o[:, L.OUT_STEPS] + o[:, L.OUT_EVENT_STEPS])
        print(f"{label:44s} {npts / best[label]:10.0f} {best[label] / npts * 1e6:9.1f} "
              f"{best[ref] / best[label]:9.2f} {evals:10.0f} "
              f"{np.sum(o[:, L.OUT_OUTCOME] == L.OUTCOME_MODE1):6d} "
              f"{np.sum(o[:, L.OUT_OUTCOME] == L.OUTCOME_MODE2):6d}")
    flex_o = best["flexible 9.82, outcome-only"]
    print(f"rigid vs flexible 9.82 (both outcome-only): "
          f"{flex_o / best['rigid (wn/p = inf), outcome-only']:.1f}x cheaper per point "
          "(target >= 5)")
    print(f"outcome-only vs energy + history (flexible 9.82): {best[ref] / flex_o:.2f}x "
          "cheaper (target >= 1.5)")
    print(f"price of the per-point error estimates (outputs.check): "
          f"{best['flexible 9.82, outcome-only + check'] / flex_o:.2f}x outcome-only; of the "
          f"accurate preset: {best['flexible 9.82, outcome-only, accurate'] / flex_o:.2f}x")
    same = [("flexible 9.82, energy", ref), ("flexible 9.82, outcome-only", ref),
            ("flexible 9.82, outcome-only + check", "flexible 9.82, outcome-only"),
            ("zeta=0, undamped kernel", "zeta=0, general (damped) kernel")]
    for a, b in same:
        n_diff = int(np.sum(outs[a][:, L.OUT_OUTCOME] != outs[b][:, L.OUT_OUTCOME]))
        print(f"outcomes differing, {a!r} vs {b!r}: {n_diff}")


if __name__ == "__main__":
    main()
