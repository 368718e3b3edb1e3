"""The sliding base far outside the paper's region: the kernel at a preset against the
independent sliding reference, point by point.

Draws random points (fixed seed): rigid blocks (7 in 10; alpha in [0.1, 0.35], I = 4/3 M
R^2) and flexible bodies (``threshold_sample.flexible_body``: wn/p in [1.5, 8], zeta in
[0, 0.15], alpha_cg in [0.08, 0.35], alpha_A in [0.15, 0.6], mA/m in [0.2, 3], IA_ratio in
[0.3, 1]), mu in [0.1, 0.9], lam in
[0, 0.5], sine or cosine, w/p in [0.5, 12], A_ratio in [0.5, 30]. Runs each with the kernel
(``compute.single.run_point``, certified) and with ``physics.sliding_reference`` (DOP853 at
rtol 1e-10, ~0.5 s a point), and prints every point whose outcome differs where neither
flags its run (the reference's flag: its step cap), every safe point whose slide_max is off
by more than 2% (relative to the reference's, or to 1e-3 b where it slid less), and a
summary: outcomes wrong and unflagged, runs flagged, runs the reference left undecided,
slide_max's relative error on safe points (median, 95th percentile, max).

    python scripts/slide_check.py --n 250 --seed 2
    python scripts/slide_check.py --n 300 --seed 3 --preset draft
    python scripts/slide_check.py --n 120 --seed 5 --preset fine --mu10

``--mu10`` compares instead the kernel at mu = 10 (a base that cannot slip, but for a
normal force near 0) with the no-slip kernel at the same points: outcome, impacts and
max|theta| (prints each point that differs, and the largest max|theta| difference of the
safe points whose base did not slip).
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np
from threshold_sample import flexible_body

from rocksweep.compute.single import run_point
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody
from rocksweep.physics.points import Point
from rocksweep.physics.sliding_reference import result_row, sliding_reference


def draw(rng: np.random.Generator) -> Point:
    if rng.random() < 0.7:
        body = BlockBody(alpha=rng.uniform(0.1, 0.35), inertia=4.0 / 3.0)
    else:
        body = flexible_body(rng)
    mu = rng.uniform(0.1, 0.9)
    return Point(body, rng.uniform(0.0, 0.5), str(rng.choice(["sine", "cosine"])),
                 rng.uniform(0.5, 12.0), rng.uniform(0.5, 30.0), mu=mu)


def mu10(points: list[Point], numerics: Numerics) -> None:
    """The ``--mu10`` comparison (module docstring)."""
    worst = 0.0
    for i, p in enumerate(points):
        a = run_point(replace(p, mu=math.nan), numerics, history=False).out
        b = run_point(replace(p, mu=10.0), numerics, history=False).out
        d = abs(a[L.OUT_THETA_MAX] - b[L.OUT_THETA_MAX]) / p.body.alpha_ref
        slipped = b[L.OUT_SLIDE_MAX] > 0.0
        if a[L.OUT_OUTCOME] == L.OUTCOME_SAFE and not slipped:
            worst = max(worst, d)
        if a[L.OUT_OUTCOME] != b[L.OUT_OUTCOME] or (d > 1e-4 and slipped):
            print(f"{i}: outcome {int(a[L.OUT_OUTCOME])} / {int(b[L.OUT_OUTCOME])}, "
                  f"max|theta| {d:.2e} alpha apart, slide_max "
                  f"{b[L.OUT_SLIDE_MAX] / p.body.b:.3g} b: "
                  f"{p}", flush=True)
    print(f"points {len(points)}: safe points whose base did not slip, max|theta| apart "
          f"at most {worst:.2e} alpha")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--preset", default="default")
    ap.add_argument("--mu10", action="store_true",
                    help="mu = 10 against the no-slip kernel instead of the reference")
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    numerics = Numerics.preset(a.preset)
    if a.mu10:
        mu10([draw(rng) for _ in range(a.n)], numerics)
        return
    wrong = flagged = undecided = 0
    errs: list[float] = []
    t0 = time.perf_counter()
    for i in range(a.n):
        p = draw(rng)
        ref = sliding_reference(p)
        out = run_point(p, numerics, history=False).out
        if int(out[L.OUT_STATUS]) & L.STATUS_FLAGGED:
            flagged += 1
            continue
        if int(result_row(ref)[L.OUT_STATUS]) & L.STATUS_FLAGGED:  # e.g. its step cap
            undecided += 1
            print(f"REFERENCE {i}: {ref['status']}, the kernel {int(out[L.OUT_OUTCOME])}: "
                  f"{p}", flush=True)
            continue
        k_slide = out[L.OUT_SLIDE_MAX]
        if int(out[L.OUT_OUTCOME]) != ref["outcome"]:
            wrong += 1
            print(f"OUTCOME {i}: kernel {int(out[L.OUT_OUTCOME])}, reference "
                  f"{ref['outcome']} ({ref['status']}): {p}", flush=True)
        elif ref["outcome"] == L.OUTCOME_SAFE:
            rel = abs(k_slide - ref["slide_max"]) / max(ref["slide_max"], 1e-3 * p.body.b)
            errs.append(rel)
            if rel > 0.02:
                print(f"SLIDE {i}: slide_max {k_slide:.5g} m, reference "
                      f"{ref['slide_max']:.5g} m ({rel:.3g}): {p}", flush=True)
    e = np.array(errs) if errs else np.full(1, np.nan)
    print(f"points {a.n} at {a.preset}: outcome wrong and unflagged {wrong}, flagged "
          f"{flagged}, the reference undecided {undecided}; safe points' slide_max relative "
          f"error median {np.median(e):.2e}, "
          f"95th percentile {np.percentile(e, 95):.2e}, max {e.max():.2e} (of {len(errs)}) "
          f"({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
