"""Sweep speed of the shipped figure scenes: `rocksweep sweep` at --jobs 1 and --jobs 2.

Prints, per figure and side by side in one run: wall time, points/s, the workers' CPU
time, points per CPU-second, and the jobs-2 / jobs-1 speed ratio. The CPU columns show
what the machine gave the run: on a shared machine (load average above the core count)
the wall-time ratio says little, points per CPU-second still compare.

    python scripts/sweep_speed.py [configs/fig3a.yaml ...] [--jobs 1 2]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py

ROOT = Path(__file__).resolve().parents[1]
FIGS = [ROOT / "configs" / f"{n}.yaml" for n in ("fig3a", "fig3b", "fig4a", "fig4b")]


def run(scene: Path, jobs: int, out: Path) -> dict:
    subprocess.run([sys.executable, "-c", "from rocksweep.cli import main; main()", "sweep",
                    str(scene), "-o", str(out), "--jobs", str(jobs), "--overwrite", "-q"],
                   check=True)
    with h5py.File(out, "r") as f:
        return {"points": int(f.attrs["points_total"]), "wall": float(f.attrs["wall_time"]),
                "cpu": float(f.attrs["cpu_time"])}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", type=Path, default=FIGS)
    ap.add_argument("--jobs", nargs="+", type=int, default=[1, 2])
    args = ap.parse_args()
    print(f"cores: {os.cpu_count()}, load average at start: "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(f"{'scene':<12}{'points':>8}{'jobs':>6}{'wall s':>9}{'pts/s':>9}{'CPU s':>9}"
          f"{'pts/CPU-s':>11}{'ratio':>7}")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in args.scenes:
            base = None
            for j in args.jobs:
                r = run(scene, j, Path(tmp) / "speed.h5")
                rate = r["points"] / r["wall"]
                base = base or rate
                print(f"{scene.stem:<12}{r['points']:>8}{j:>6}{r['wall']:>9.2f}{rate:>9.0f}"
                      f"{r['cpu']:>9.2f}{r['points'] / r['cpu']:>11.0f}{rate / base:>7.2f}")
    print(f"load average at end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
