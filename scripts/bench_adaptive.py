"""Adaptive vs full sweeps, side by side in one run.

For each scene: the full grid and the adaptive sweep (default settings), both in memory
through the sweep driver (``rocksweep.compute.driver.sweep_arrays``) with the same workers; prints
the points computed / points in the grid, both wall times, the share of cells whose
adaptive outcome equals the full grid's, and the audit counts. ``--study`` also replays
the adaptive algorithm on the full grid's outcomes (no kernel runs: a point's class is
looked up) for every coarse level, which is how the default coarse level was chosen.

    python scripts/bench_adaptive.py                      # 7 scenes at 400 x 400
    python scripts/bench_adaptive.py --res 0 --study      # at the shipped resolution
    python scripts/bench_adaptive.py --fine               # Figure 3(a) 1000 x 1000 x 3 lam
    python scripts/bench_adaptive.py --fine --no-full     # ... adaptive only
    python scripts/bench_adaptive.py --fine --file        # ... and through a result file

``--file`` adds the time of the same adaptive sweep written to an HDF5 result file
(``rocksweep.compute.session.sweep_file``, what ``rocksweep sweep --adaptive`` runs) and checks that
its outcome equals the in-memory one.

Targets: equal outcome on >= 99.9% of cells; <= 10% of the points computed at 400 x 400,
<= 4% at 1000 x 1000; Figure 3(a) 1000 x 1000 x 3 lam in < 20 s on 2 cores.

Measured (``python scripts/bench_adaptive.py --jobs 2``, 2 shared cores; default settings,
light last levels, see ``rocksweep.compute.adaptive``): at 400 x 400, 4.69-6.28% computed and
99.9854-100% equal (Figure 4(b) worst: 70 one-point cells of 480 000); Figure 3(a) at
1000 x 1000 x 3 lam: 3.77% computed (1.81 refinement + 1.96 audit), 99.9990% equal,
4.1 s through ``rocksweep sweep --adaptive`` (the README has the table).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np

from rocksweep.compute import adaptive as ad
from rocksweep.compute import sweep as sw
from rocksweep.compute.driver import sweep_arrays
from rocksweep.scene.grid import Grid
from rocksweep.scene.model import Scene
from rocksweep.scene.parse import load_scene, parse_scene
from rocksweep.vocab.axes import DIAGRAM_AXES

ROOT = Path(__file__).resolve().parents[1]
FIGS = ("fig3a", "fig3b", "fig4a", "fig4b", "block")
# Held-out scenes with thin features (not used to write the algorithm's defaults'
# docstring claims): a slender rigid block under a cosine pulse (thin safe slivers inside
# the overturning region) and a stiff flexible body (wn/p = 50) under a cosine pulse.
THIN = {
    "block-slender-cos": """name: "held-out: slender block (alpha = 0.1), cosine pulse"
body: {kind: block, alpha: 0.1, inertia: 1.3333333333333333}
impact: {lam: [0.0, 0.5]}
pulse: {shape: cosine, w_over_p: {start: 0.15, stop: 12, num: 80},
        A_ratio: {start: 0.3, stop: 12, num: 80}}
""",
    "stiff50-cos": """name: "held-out: stiff body (wn/p = 50), cosine pulse"
body: {wn_over_p: 50, zeta: 0.05, alpha_cg: 0.15, alpha_A: 0.28, mA_over_m: 0.47,
       IA_ratio: 0.56}
impact: {lam: [0.0, 0.4]}
pulse: {shape: cosine, w_over_p: {start: 0.15, stop: 12, num: 80},
        A_ratio: {start: 0.3, stop: 24, num: 80}}
""",
}


def scene(name: str, res: int) -> Scene:
    """A named scene, its diagram axes at res x res (0: as shipped)."""
    if name in THIN:
        base = parse_scene(THIN[name], name)
    else:
        base = load_scene(ROOT / "configs" / f"{name}.yaml")
    if not res:
        return base
    ov = []
    for ax in DIAGRAM_AXES:
        v = base.axis(ax).values
        ov.append(f"pulse.{ax}={{start: {v[0]!r}, stop: {v[-1]!r}, num: {res}}}")
    if name in THIN:
        return parse_scene(THIN[name], name, ov)
    return load_scene(ROOT / "configs" / f"{name}.yaml", ov)


def study(full: np.ndarray, sc: Scene, levels: range) -> list[str]:
    """Replay the adaptive algorithm on known outcomes for each coarse level."""
    grid = Grid(sc)
    truth = full.ravel()
    lines = []
    for k in levels:
        plan = ad.make_plan(grid, coarse=k)
        if 2**k > min(plan.panel_shape[1:]):
            break
        out, _, st = ad.run_on_function(plan, lambda flat, _b: truth[flat])
        lines.append(f"    coarse {k} (stride {2**k:3d}, "
                     f"{(min(plan.panel_shape[1:]) - 1) / 2**k:6.1f} cells/axis): "
                     f"computed {100 * st.computed_share:6.2f}%, equal "
                     f"{100 * np.mean(out == truth):8.4f}% ({int(np.sum(out != truth))} cells "
                     f"differ), audit misses {st.audit_misses}/{st.audited}")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=[*FIGS, *THIN],
                    help=f"configs/NAME.yaml names or {', '.join(THIN)}")
    ap.add_argument("--res", type=int, default=400, help="points per diagram axis (0: shipped)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--fine", action="store_true",
                    help="Figure 3(a) at 1000 x 1000 x 3 lam (configs/fig3a-fine.yaml) only")
    ap.add_argument("--no-full", action="store_true", help="skip the full sweeps")
    ap.add_argument("--study", action="store_true", help="replay every coarse level")
    ap.add_argument("--file", action="store_true",
                    help="also time the adaptive sweep into a result file (sweep_file)")
    args = ap.parse_args()
    jobs = sw.effective_jobs(args.jobs)
    print(f"cores: {os.cpu_count()}, jobs: {jobs}, load average at start: "
          + ", ".join(f"{x:.2f}" for x in os.getloadavg()))
    if args.fine:
        todo = [("fig3a-fine", load_scene(ROOT / "configs" / "fig3a-fine.yaml"))]
    else:
        todo = [(n, scene(n, args.res)) for n in args.scenes]
    head = ("| scene | grid | computed / points | adaptive s | full s | speed-up | "
            "equal outcome | audits (misses) | default coarse |")
    rows = [head, "|" + "---|" * 9]
    for name, sc in todo:
        grid = Grid(sc)
        sw.prepare(grid, sw.level(sc))  # compile/load kernels outside the timings
        t0 = time.perf_counter()
        arr, report = sweep_arrays(sc, jobs=jobs, adaptive=ad.Options())
        st = report.adaptive
        t_ad = time.perf_counter() - t0
        if args.no_full:
            full, t_full = None, float("nan")
        else:
            t0 = time.perf_counter()
            full = sweep_arrays(sc, jobs=jobs)[0]["outcome"]
            t_full = time.perf_counter() - t0
        eq = "n/a" if full is None else (
            f"{100 * np.mean(arr['outcome'] == full):.4f}% "
            f"({int(np.sum(arr['outcome'] != full))} differ)")
        plan = ad.make_plan(grid)
        if args.file:
            import tempfile

            from rocksweep.compute.session import sweep_file
            from rocksweep.store.reader import read_result

            with tempfile.TemporaryDirectory() as tmp:
                t0 = time.perf_counter()
                sweep_file(sc, Path(tmp) / "a.h5", jobs=jobs, adaptive=ad.Options())
                t_file = time.perf_counter() - t0
                same = np.array_equal(read_result(Path(tmp) / "a.h5", ["outcome"])
                                      .arrays["outcome"], arr["outcome"])
            print(f"    {name}: through a result file {t_file:.1f} s "
                  f"(outcome {'equal to' if same else 'DIFFERS from'} the in-memory sweep)")
        rows.append(f"| {name} | {' x '.join(map(str, sc.shape))} | "
                    f"{st.computed} / {st.points} = {100 * st.computed_share:.2f}% | "
                    f"{t_ad:.1f} | {t_full:.1f} | {t_full / t_ad:.1f}x | {eq} | "
                    f"{st.audited} ({st.audit_misses}) | {plan.coarse} |")
        print(rows[-1], flush=True)
        if st.warning():
            print(f"    warning: {st.warning()}")
        if args.study and full is not None:
            print("\n".join(study(full, sc, range(0, 8))), flush=True)
    print("\n".join(rows))


if __name__ == "__main__":
    main()
