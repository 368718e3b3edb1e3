"""Classes within 0.5% of their thresholds: does `default` call them right, or flag them?

Draws random bodies and pulses (fixed seed), scans A_ratio at `fine` for every change of
class (safe, mode 1, mode 2), bisects a few of them to a threshold A*, and runs points
drawn uniformly within +-0.5% of A* at `default` (certified, ``compute.certify``), at
`default` with certification off (bare) and at `fine`. Where `default`'s unflagged class
differs from `fine`'s, the independent reference (``physics.reference``, DOP853 at rtol
1e-10) decides which is right. Printed: points, refined (re-run or probed), flagged, and
`default`'s classes that are wrong and unflagged (each one listed), `fine`'s classes the
reference contradicts where it ran (``--all-reference``: at every point), the points the
reference left undecided (its own step or event cap: no verdict; each one listed), with
the RK4 evaluations of the certified and the bare runs (their ratio: what the
certification costs on points this close, the worst case; on a whole diagram it is a few
percent, ``scripts/fingerprint.py diff``).

    python scripts/threshold_sample.py --bodies 30 --seed 1
    python scripts/threshold_sample.py --bodies 100 --seed 1 --mu 0.15 1.5
    PYTHONPATH=/path/to/other/checkout python scripts/threshold_sample.py --bodies 30 --seed 1

``--mu LO HI`` gives every body a base that may slide (docs/sliding.md), with mu drawn
log-uniformly in [LO, HI] per body after its other draws (without it the draws are the
no-slip samples' own): the kernel's sliding variants, and the sliding reference
(``physics.sliding_reference``, 0.5-40 s a point) where `default` and `fine` differ.

The third form measures another checkout's package (an older certification) on the same
points (``scripts/_here.py``).
"""

from __future__ import annotations

import argparse
import math
import time

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np

from rocksweep.analysis.bisection import bisect_thresholds
from rocksweep.compute.dispatch import run_variant
from rocksweep.errors import BodyError
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, FlexibleBody
from rocksweep.physics.points import Point, kernel_kind, point_row
from rocksweep.physics.reference import reference_run
from rocksweep.physics.sliding_reference import result_row, sliding_reference

FELL = (L.OUTCOME_MODE1, L.OUTCOME_MODE2)


def flexible_body(rng: np.random.Generator) -> FlexibleBody:
    """A random flexible body around the paper's (wn/p 1.5-8, zeta 0-0.15, alpha_cg
    0.08-0.35, alpha_A 0.15-0.6, mA/m 0.2-3, IA_ratio 0.3-1)."""
    while True:
        try:
            return FlexibleBody(
                wn_over_p=rng.uniform(1.5, 8.0), zeta=rng.uniform(0.0, 0.15),
                alpha_cg=rng.uniform(0.08, 0.35), alpha_A=rng.uniform(0.15, 0.6),
                mA_over_m=rng.uniform(0.2, 3.0), IA_ratio=rng.uniform(0.3, 1.0))
        except BodyError:  # the top mass below the base: draw again
            continue


def draw(rng: np.random.Generator, mu: tuple[float, float] | None = None) -> tuple:
    """(body, lam, shape, w_over_p, mu): a flexible body (a block one time in six); mu
    log-uniform in ``mu`` (LO, HI), or NaN (no sliding, no draw) where ``mu`` is None."""
    if rng.random() < 1 / 6:
        body = BlockBody(alpha=rng.uniform(0.1, 0.35), inertia=4.0 / 3.0)
    else:
        body = flexible_body(rng)
    drawn = (body, rng.uniform(0.0, 0.5), str(rng.choice(["sine", "cosine"])),
             rng.uniform(1.2, 9.0))
    friction = math.nan if mu is None else math.exp(rng.uniform(*np.log(mu)))
    return (*drawn, friction)


def run(points: list[Point], numerics: Numerics, refine: int | None = None) -> np.ndarray:
    """Result rows float64[n, N_OUT] of points (all of one body)."""
    rows = np.stack([point_row(p, numerics) for p in points])
    kind = kernel_kind(points[0].body)
    return run_variant(rows, kind, L.LEVEL_OUTCOME, L.GROUND_PULSE,
                       numerics.refine if refine is None else refine)


def thresholds(body, lam, shape, w, mu, fine: Numerics, rng, per_body: int) -> list[float]:
    """Up to per_body thresholds A* [A_ratio] of `fine`'s class on A_ratio in [1, 16]."""
    grid = np.linspace(1.0, 16.0, 61)
    cls = run([Point(body, lam, shape, w, float(a), mu=mu) for a in grid],
              fine)[:, L.OUT_OUTCOME]
    change = np.flatnonzero(cls[1:] != cls[:-1])
    pick = rng.permutation(change)[:per_body]
    lo, hi = grid[pick].copy(), grid[pick + 1].copy()
    c_lo = cls[pick]

    def classify(idx: np.ndarray, mid: np.ndarray) -> np.ndarray:
        # 1: the class across the change (hi's side), 0: lo's
        got = run([Point(body, lam, shape, w, float(m), mu=mu) for m in mid], fine)
        return (got[:, L.OUT_OUTCOME] != c_lo[idx]).astype(int)

    # 18 halvings of each bracket (rtol 0: none stops early)
    bisect_thresholds(lo, hi, np.zeros(pick.size, int), 0.0, classify, (1,), max_iter=18)
    return list(0.5 * (lo + hi))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bodies", type=int, default=30)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--per-body", type=int, default=2, help="thresholds per body")
    ap.add_argument("--points", type=int, default=5, help="points per threshold")
    ap.add_argument("--preset", default="default", help="the preset checked (default)")
    ap.add_argument("--all-reference", action="store_true",
                    help="run the reference on every point, not only where default and "
                         "fine differ (slow: ~1 s a point)")
    ap.add_argument("--mu", type=float, nargs=2, metavar=("LO", "HI"),
                    help="a base that may slide: mu log-uniform in [LO, HI] per body")
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    default, fine = Numerics.preset(a.preset), Numerics.preset("fine")
    n = refined = flagged = wrong = fine_wrong = undecided = 0
    cost = bare_cost = 0.0
    t0 = time.perf_counter()
    for _ in range(a.bodies):
        body, lam, shape, w, mu = draw(rng, a.mu)
        for a_star in thresholds(body, lam, shape, w, mu, fine, rng, a.per_body):
            pts = [Point(body, lam, shape, w, float(a_star * (1 + u)), mu=mu)
                   for u in rng.uniform(-0.005, 0.005, a.points)]
            got, bare, ref = run(pts, default), run(pts, default, 0), run(pts, fine)
            for p, g, b, f in zip(pts, got, bare, ref, strict=True):
                n += 1
                st = int(g[L.OUT_STATUS])
                refined += bool(st & L.STATUS_REFINED)
                flagged += bool(st & L.STATUS_FLAGGED)
                cost += g[L.OUT_STEPS] + g[L.OUT_EVENT_STEPS]
                bare_cost += b[L.OUT_STEPS] + b[L.OUT_EVENT_STEPS]
                same = g[L.OUT_OUTCOME] == f[L.OUT_OUTCOME]
                if st & L.STATUS_FLAGGED or (same and not a.all_reference):
                    continue
                if math.isnan(mu):
                    r = reference_run(p)
                    truth, ref_status = r["outcome"], int(r["status"])
                else:
                    r = result_row(sliding_reference(p))
                    truth, ref_status = r[L.OUT_OUTCOME], int(r[L.OUT_STATUS])
                if ref_status & L.STATUS_FLAGGED:  # its step or event cap: no verdict
                    undecided += 1
                    print(f"UNDECIDED {p}: default {int(g[L.OUT_OUTCOME])}, fine "
                          f"{int(f[L.OUT_OUTCOME])}, the reference's status {ref_status}",
                          flush=True)
                    continue
                fine_wrong += truth != f[L.OUT_OUTCOME]
                if truth != g[L.OUT_OUTCOME]:
                    wrong += 1
                    print(f"WRONG {p}: default {int(g[L.OUT_OUTCOME])} (bare "
                          f"{int(b[L.OUT_OUTCOME])}, margin {b[L.OUT_MARGIN]:.4g}), fine "
                          f"{int(f[L.OUT_OUTCOME])}, reference {truth}", flush=True)
    print(f"points {n}  refined {refined}  flagged {flagged}  wrong and unflagged {wrong}  "
          f"fine wrong (where the reference ran) {fine_wrong}  "
          f"reference undecided {undecided}  "
          f"RK4 evaluations certified/bare {cost / bare_cost:.3f} "
          f"({cost / 1e6:.2f}M / {bare_cost / 1e6:.2f}M)  "
          f"({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
