"""Regenerate every figure in docs/ from the current code, by one command.

    python scripts/make_docs_figures.py              # ~2 min on 2 cores
    python scripts/make_docs_figures.py --accuracy   # also docs/accuracy_fig3a.png (+~1 min)

Runs the shipped commands, exactly as the README shows them:

- ``rocksweep sweep configs/NAME.yaml --jobs 2`` and ``rocksweep plot`` for the stability
  diagrams fig3a, fig3b, fig4a, fig4b and block, at the configs' own resolution, and
  fig3a_check (Figure 3(a) with ``--check``: rings where the outcome changes at half the step);
- ``rocksweep simulate configs/fig5.yaml --plot`` (Figure 5) and ``rocksweep restitution
  configs/fig2.yaml --plot`` (Figure 2);
- ``rocksweep sweep configs/fragility-demo.yaml`` and ``rocksweep fragility --plot``: the
  overturning fragility of the Figure 3(a) body under the shipped record suite;
- ``rocksweep efficiency``, ``rocksweep fragility --state theta:0.25,theta:0.5,overturn -o``
  and ``rocksweep risk --hazard configs/hazard-example.csv --plot`` on that suite (``risk``:
  docs/efficiency.png, docs/risk.png);
- ``rocksweep sweep configs/floor-spectrum.yaml`` and ``rocksweep floor-spectrum``
  (docs/floor_spectrum.png);
- ``rocksweep sweep configs/ricker.yaml`` and ``rocksweep plot`` (docs/ricker.png),
  ``rocksweep sweep configs/record-demo.yaml`` and ``rocksweep spectrum``
  (docs/record_spectra.png), and the pulse shapes (``figures.pulses.shapes_figure``,
  docs/pulse_shapes.png): docs/excitations.md;
- ``rocksweep sweep configs/fig4a.yaml --set outputs.contact=true`` and ``rocksweep plot
  --mu`` (docs/fig4a_mu_required.png, docs/contact.md: the no-slip friction demand);
- ``rocksweep sweep configs/fig3a.yaml --set impact.lam=0.2 --set body.mu=[0.3,0.5,0.7,10]``,
  ``rocksweep plot`` and ``rocksweep plot --regime`` (docs/fig3a_sliding.png,
  docs/fig3a_regimes.png: docs/sliding.md);
- docs/calibration.md's example: ``rocksweep simulate configs/free-rocking.yaml`` at lam =
  0.3 and `fine` to CSV, 1% noise added (seed 1), ``rocksweep calibrate ... --fit
  impact.lam --plot`` (docs/calibration.png);
- with ``--accuracy``: ``rocksweep accuracy configs/fig3a.yaml --points 200 --plot``.

Everything is written to a temporary directory first and moved into docs/ when the
command succeeded, so a failure leaves the old figure in place. Sweep results are
deleted unless ``--keep DIR`` is given.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DIAGRAMS = ("fig3a", "fig3b", "fig4a", "fig4b", "block")
OTHERS = ("fig3a_check", "fig5", "fig2", "fragility", "impact_laws", "fig2_locked", "risk",
          "floor_spectrum", "ricker", "fig4a_mu_required",
          "fig3a_sliding", "record_spectra", "pulse_shapes",
          "calibration")
#: every PNG it writes into docs/ ("risk" writes efficiency.png too; "accuracy_fig3a" with
#: --accuracy): tests/test_docs_figures.py holds docs/ to these
PNGS = (*DIAGRAMS, *OTHERS, "efficiency", "accuracy_fig3a", "fig3a_regimes")


def rocksweep(*args: str) -> None:
    """Run ``rocksweep ARGS`` (this interpreter's package); stop on failure."""
    cmd = [sys.executable, "-m", "rocksweep", *args]
    print("$ rocksweep " + " ".join(args), flush=True)
    proc = subprocess.run(cmd, cwd=ROOT)
    if proc.returncode != 0:
        sys.exit(f"failed ({proc.returncode}): {' '.join(cmd)}")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--accuracy", action="store_true",
                    help="also the work-precision diagram (rocksweep accuracy, ~1 min)")
    ap.add_argument("--jobs", type=int, default=2, help="sweep worker threads [2]")
    ap.add_argument("--dpi", type=int, default=200, help="resolution of the PNGs [200]")
    ap.add_argument("--only", nargs="+", metavar="NAME",
                    choices=[*DIAGRAMS, *OTHERS, "accuracy_fig3a"],
                    help="regenerate only these figures")
    ap.add_argument("--docs", type=Path, default=ROOT / "docs", help="output directory")
    ap.add_argument("--keep", type=Path, metavar="DIR", help="keep the sweep results here")
    args = ap.parse_args(argv)
    wanted = set(args.only or [*DIAGRAMS, *OTHERS]
                 + (["accuracy_fig3a"] if args.accuracy else []))
    args.docs.mkdir(parents=True, exist_ok=True)
    if args.keep:
        args.keep.mkdir(parents=True, exist_ok=True)
    cfg = ROOT / "configs"
    made, t_all = [], time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="rocksweep-docs-") as tmp_dir:
        tmp = Path(tmp_dir)

        def publish(name: str) -> None:
            """Copy tmp/NAME.png into docs/ atomically (a partial file, then a rename)."""
            dest = args.docs / f"{name}.png"
            part = dest.with_name(f".{name}.png.partial")
            shutil.copyfile(tmp / f"{name}.png", part)
            os.replace(part, dest)
            made.append(dest)

        def sweep(scene: str, result: str, *extra: str) -> Path:
            """``rocksweep sweep configs/SCENE.yaml EXTRA... -o RESULT.h5`` (kept with
            --keep); returns the result's path."""
            h5 = (args.keep or tmp) / f"{result}.h5"
            rocksweep("sweep", str(cfg / f"{scene}.yaml"), *extra, "-o", str(h5), "--jobs",
                      str(args.jobs), "--quiet", "--overwrite")
            return h5

        for name in DIAGRAMS:
            if name not in wanted:
                continue
            t0 = time.perf_counter()
            h5 = sweep(name, name)
            rocksweep("plot", str(h5), "-o", str(tmp / f"{name}.png"), "--dpi", str(args.dpi))
            publish(name)
            print(f"  {name}: {time.perf_counter() - t0:.1f} s", flush=True)
        if "fig3a_check" in wanted:  # per-point error estimates: rings where unsure
            h5 = sweep("fig3a", "fig3a_check", "--check")
            rocksweep("plot", str(h5), "-o", str(tmp / "fig3a_check.png"), "--dpi",
                      str(args.dpi))
            publish("fig3a_check")
        if "fig5" in wanted:
            rocksweep("simulate", str(cfg / "fig5.yaml"), "--plot", str(tmp / "fig5.png"))
            publish("fig5")
        if "fig2" in wanted:
            rocksweep("restitution", str(cfg / "fig2.yaml"), "--plot", str(tmp / "fig2.png"))
            publish("fig2")
        if "fragility" in wanted:  # the record suite: overturning fragility per lam
            t0 = time.perf_counter()
            h5 = sweep("fragility-demo", "fragility")
            rocksweep("fragility", str(h5), "--plot", str(tmp / "fragility.png"), "--dpi",
                      str(args.dpi))
            publish("fragility")
            print(f"  fragility: {time.perf_counter() - t0:.1f} s", flush=True)
        if "risk" in wanted:  # IM efficiency and risk on the demo suite
            h5 = (args.keep or tmp) / "fragility.h5"
            if not h5.exists():
                sweep("fragility-demo", "fragility")
            rocksweep("efficiency", str(h5), "--plot", str(tmp / "efficiency.png"), "--dpi",
                      str(args.dpi))
            curves = tmp / "curves.h5"
            rocksweep("fragility", str(h5), "--state", "theta:0.25,theta:0.5,overturn", "-o",
                      str(curves))
            rocksweep("risk", str(curves), "--hazard", str(cfg / "hazard-example.csv"),
                      "--plot", str(tmp / "risk.png"), "--dpi", str(args.dpi))
            publish("efficiency")
            publish("risk")
        if "impact_laws" in wanted:  # which laws overturn each cell
            h5 = sweep("impact-laws", "impact_laws")
            rocksweep("plot", str(h5), "--compare", "impact.law", "-o",
                      str(tmp / "impact_laws.png"), "--dpi", str(args.dpi))
            publish("impact_laws")
        if "floor_spectrum" in wanted:  # contents on a building's floor (docs/floors.md)
            h5 = sweep("floor-spectrum", "floor_spectrum")
            rocksweep("floor-spectrum", str(h5), "-o", str(tmp / "floor_spectrum.png"),
                      "--dpi", str(args.dpi))
            publish("floor_spectrum")
        if "fig2_locked" in wanted:
            rocksweep("restitution", str(cfg / "fig2.yaml"), "--law", "locked", "--plot",
                      str(tmp / "fig2_locked.png"))
            publish("fig2_locked")
        if "ricker" in wanted:  # docs/excitations.md
            h5 = sweep("ricker", "ricker")
            rocksweep("plot", str(h5), "-o", str(tmp / "ricker.png"), "--dpi", str(args.dpi))
            publish("ricker")
        if "fig4a_mu_required" in wanted:  # docs/contact.md: the no-slip friction demand
            h5 = sweep("fig4a", "fig4a_mu_required", "--set", "outputs.contact=true")
            rocksweep("plot", str(h5), "--mu", "-o", str(tmp / "fig4a_mu_required.png"),
                      "--dpi", str(args.dpi))
            publish("fig4a_mu_required")
        if "fig3a_sliding" in wanted:  # docs/sliding.md: Figure 3(a) on a base that slides
            # mu = 10: a base that cannot slip (the no-slip model's classes, a test says)
            h5 = sweep("fig3a", "fig3a_sliding", "--set", "impact.lam=0.2", "--set",
                       "body.mu=[0.3,0.5,0.7,10]")
            rocksweep("plot", str(h5), "-o", str(tmp / "fig3a_sliding.png"), "--dpi",
                      str(args.dpi))
            publish("fig3a_sliding")
            rocksweep("plot", str(h5), "--regime", "-o", str(tmp / "fig3a_regimes.png"),
                      "--dpi", str(args.dpi))
            publish("fig3a_regimes")
        if "record_spectra" in wanted:  # docs/excitations.md
            h5 = sweep("record-demo", "record_demo")
            rocksweep("spectrum", str(h5), "-o", str(tmp / "record_spectra.png"), "--dpi",
                      str(args.dpi))
            publish("record_spectra")
        if "pulse_shapes" in wanted:  # docs/excitations.md (Python: no command draws it)
            code = ("import sys; from rocksweep.figures.pulses import shapes_figure; "
                    "from rocksweep.figures.style import save_figure; "
                    f"save_figure(shapes_figure(), sys.argv[1], {args.dpi})")
            print("$ python -c 'shapes_figure()'", flush=True)
            proc = subprocess.run([sys.executable, "-c", code, str(tmp / "pulse_shapes.png")],
                                  cwd=ROOT)
            if proc.returncode != 0:
                sys.exit(f"failed ({proc.returncode}): the pulse shapes' figure")
            publish("pulse_shapes")
        if "calibration" in wanted:  # docs/calibration.md's example, as the page runs it
            truth, measured = tmp / "truth.csv", tmp / "measured.csv"
            rocksweep("simulate", str(cfg / "free-rocking.yaml"), "--set", "impact.lam=0.3",
                      "--set", "numerics.accuracy=fine", "--csv", str(truth))
            import numpy as np
            import pandas as pd

            d = pd.read_csv(truth)
            d["theta_over_alpha"] += 0.01 * d.theta_over_alpha.abs().max() * \
                np.random.default_rng(1).standard_normal(len(d))
            d[["p_t", "theta_over_alpha"]].to_csv(measured, index=False)
            rocksweep("calibrate", str(cfg / "free-rocking.yaml"), str(measured), "--fit",
                      "impact.lam", "--plot", str(tmp / "calibration.png"), "--dpi",
                      str(args.dpi))
            publish("calibration")
        if "accuracy_fig3a" in wanted:
            t0 = time.perf_counter()
            rocksweep("accuracy", str(cfg / "fig3a.yaml"), "--points", "200", "--quiet",
                      "--plot", str(tmp / "accuracy_fig3a.png"))
            publish("accuracy_fig3a")
            print(f"  accuracy_fig3a: {time.perf_counter() - t0:.1f} s", flush=True)
    print(f"wrote {len(made)} figures in {time.perf_counter() - t_all:.1f} s:")
    for p in made:
        print(f"  {p.relative_to(ROOT) if p.is_relative_to(ROOT) else p}")


if __name__ == "__main__":
    main()
