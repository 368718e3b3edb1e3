"""The kernel's contact outputs against the reference path.

    python scripts/contact_check.py configs/fig4a.yaml --points 30 [--seed 0]

Draws random points of a scene's grid, runs each with the RK4 kernel at the scene's preset
(contact variant) and with the reference path (DOP853, rtol 1e-10, dense output sampled and
refined: ``rocksweep.physics.reference._Contact``), and prints the relative difference of
mu_required, normal_min_over_Mg and impulse_ratio_max per point and the worst over the
points whose outcome agrees and whose values are finite.
"""

from __future__ import annotations

import argparse
import math

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np

from rocksweep.kernel import chunk_kernel
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.points import kernel_kind, point_row
from rocksweep.physics.reference import reference_run
from rocksweep.scene.grid import Grid
from rocksweep.scene.parse import load_scene

NAMES = (("mu_required", L.OUT_MU_REQ), ("normal_min_over_Mg", L.OUT_N_MIN),
         ("impulse_ratio_max", L.OUT_IMPULSE_MAX))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--points", type=int, default=30)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--safe-only", action="store_true", help="draw safe points only")
    args = ap.parse_args()
    scene = load_scene(args.scene)
    grid = Grid(scene)
    rng = np.random.default_rng(args.seed)
    worst = dict.fromkeys([n for n, _ in NAMES], 0.0)
    n_cmp = 0
    print(f"{'w/p':>6} {'A':>6} {'lam':>4} out  " + "  ".join(
        f"{n[:14]:>14} {'ref':>10} {'rel':>8}" for n, _ in NAMES))
    drawn = 0
    while drawn < args.points:
        flat = int(rng.integers(grid.size))
        point = scene.point({k: v.item() if hasattr(v, "item") else v
                             for k, v in grid.index_values(np.array([flat])).items()})
        row = point_row(point, scene.numerics)
        out = np.empty((1, L.N_OUT))
        chunk_kernel(kernel_kind(point.body), L.LEVEL_CONTACT)(row[None], out)
        if args.safe_only and out[0, L.OUT_OUTCOME] != L.OUTCOME_SAFE:
            continue
        drawn += 1
        ref = reference_run(point, scene.numerics, contact=True)
        same = ref["outcome"] == out[0, L.OUT_OUTCOME]
        cells = []
        for name, slot in NAMES:
            k, r = float(out[0, slot]), float(ref[name])
            if math.isfinite(k) and math.isfinite(r):
                rel = abs(k - r) / max(abs(r), 1e-12)
                if same:
                    worst[name] = max(worst[name], rel)
            else:
                rel = 0.0 if (k == r or (math.isnan(k) and math.isnan(r))) else math.inf
                if same and rel:
                    worst[name] = math.inf
            cells.append(f"{k:>14.6g} {r:>10.6g} {rel:>8.1e}")
        n_cmp += same
        print(f"{point.w_over_p:6.3f} {point.A_ratio:6.3f} {point.lam:4.2f} "
              f"{int(out[0, L.OUT_OUTCOME])}{'' if same else '!'}{ref['outcome']}  "
              + "  ".join(cells))
    print(f"{n_cmp} of {args.points} points with the same outcome; worst relative "
          "difference there: " + ", ".join(f"{k} {v:.2e}" for k, v in worst.items()))


if __name__ == "__main__":
    main()
