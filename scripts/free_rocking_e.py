"""The coefficient of restitution a free-rocking test would give a body (impact-laws.yaml).

    python scripts/free_rocking_e.py [SCENE.yaml] [--law vertical] [--theta0 0.5]

Releases the scene's body from rest at theta0 * alpha_cg (no ground motion) under the
impact law and fits the rigid body's rule to the decay of its peak rotations, as a
free-rocking experiment does: the energy of a rigid body at a peak theta_n is
V(theta_n) = M g R_cg [cos(alpha_cg - theta_n) - cos(alpha_cg)] and an impact multiplies
it by e^2, so e_n = sqrt(V(theta_n+1) / V(theta_n)). A flexible body chatters between its
large excursions (small rocking on the spring's rebound); as a test that tracks the peaks,
only excursions above ``floor`` * alpha_cg count. Prints e_n of the first large
excursions and their geometric mean (what ``impact.e`` of law constant is set to in
configs/impact-laws.yaml).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def free_rocking_e(scene_path: Path, law: str = "vertical", theta0: float = 0.8,
                   n_impacts: int = 4, floor: float = 0.05) -> tuple[list[float], float]:
    from rocksweep.compute.dispatch import history_capacity
    from rocksweep.kernel import layout as L
    from rocksweep.kernel import point_kernel
    from rocksweep.physics.points import Point, kernel_kind, point_row
    from rocksweep.scene.parse import load_scene

    scene = load_scene(scene_path)
    body = scene.make_body(**{a.name: a.values[0] for a in scene.body_axes()})
    point = Point(body, 0.0, "sine", 1.0, 0.0, law=law)  # A = 0: no ground motion
    row = point_row(point, scene.single_numerics)
    row[L.PAR_THETA0] = theta0 * body.alpha_cg
    out = np.empty(L.N_OUT)
    hist = np.empty((history_capacity(row), L.N_HIST))
    point_kernel(kernel_kind(body), L.GROUND_PULSE)(row, out, hist)
    n = int(out[L.OUT_HIST_ROWS])
    theta, phase = hist[:n, L.HIST_THETA], hist[:n, L.HIST_PHASE]
    peaks, start = [], 0
    for i in range(1, n):  # the largest |theta| of each rocking excursion
        if phase[i] != phase[i - 1] or i == n - 1:
            peak = float(np.abs(theta[start:i]).max())
            if phase[i - 1] != 0 and peak > floor * body.alpha_cg:
                peaks.append(peak)
            start = i
    a = body.alpha_cg

    def v(th: float) -> float:
        return math.cos(a - th) - math.cos(a)

    e = [math.sqrt(v(peaks[k + 1]) / v(peaks[k])) for k in range(min(n_impacts,
                                                                     len(peaks) - 1))]
    return e, float(np.exp(np.mean(np.log(e))))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?", default=str(ROOT / "configs" / "fig3a.yaml"))
    ap.add_argument("--law", default="vertical")
    ap.add_argument("--theta0", type=float, default=0.8, help="release angle / alpha_cg")
    args = ap.parse_args()
    e, mean = free_rocking_e(Path(args.scene), args.law, args.theta0)
    print("e of the first large excursions from the peak decay:", " ".join(f"{v:.4f}" for v in e))
    print(f"geometric mean: {mean:.4f}")


if __name__ == "__main__":
    main()
