"""A record-suite risk study, timed stage by stage: 44 records x 16 PGA stripes x 3 lam, a fit with
3 damage states, the IM efficiency and the risk over a hazard curve (target: < 15 s on 2
cores, everything in).

Stages, each timed in one Python process (``time.perf_counter``), printed with its share:

0. start-up: ``python -c "import rocksweep"`` in a fresh process (what every command pays
   once before computing; reported apart, not in the study's total);
1. scene: reading the 44 records, their IMs (PGA, PGV, Sa at 0.2 and 1 s, Arias, CAV,
   D5-95, PGV/PGA, AvgSa over 10 periods) and the admission checks
   (``rocksweep.scene.inputs.load``);
2. sweep: ``rocksweep.run(scene, jobs=2)``, 2 112 kernel runs of 20-40 s records (the
   kernel from numba's cache; a cold cache is filled first and reported apart);
3. fragility: ``rocksweep.fragility(ds, state=["theta:0.25", "theta:0.5", "overturn"],
   bootstrap=200)``;
4. efficiency: ``rocksweep.im_efficiency(ds)`` (11 IMs x 3 lam);
5. risk: ``rocksweep.risk(fr, hazard, years=50)`` over a 30-level PGA hazard curve;
6. table: ``rocksweep.table(ds)`` (one row per run).

The 44 records: the 20 shipped and 24 more realisations (``scripts/bench_fragility.py``'s
``write_records``), written to a temporary directory (not timed).

    python scripts/bench_risk.py        # ~10 s
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TARGET = 15.0  # s


def bench_fragility():
    spec = importlib.util.spec_from_file_location("bench_fragility",
                                                  ROOT / "scripts" / "bench_fragility.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def main() -> int:
    sys.path.insert(0, str(ROOT))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "import rocksweep"], env=env, check=True)
    startup = time.perf_counter() - t0

    import pandas as pd

    import rocksweep
    from rocksweep.kernel import variants  # noqa: F401  (imported before timing)
    from rocksweep.scene.inputs import load

    times: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        paths = bench_fragility().write_records(folder)
        scene = {"name": "bench_risk: 44 records x 16 PGA stripes x 3 lam",
                 "body": {"wn_over_p": 2.43, "zeta": 0.05, "alpha_cg": 0.15,
                          "alpha_A": 0.28, "mA_over_m": 0.47, "IA_ratio": 0.56},
                 "impact": {"lam": [0.0, 0.2, 0.4]},
                 "ground": {"records": [str(p) for p in paths],
                            "scale": {"im": "PGA", "values": {"start": 0.1, "stop": 1.6,
                                                              "num": 16}},
                            "p": 2.0, "periods": [0.2, 1.0]}}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the suite's large factors: said, not timed
            est = rocksweep.estimate(scene, jobs=2)
            cold = bool(getattr(est, "compile_needed", False))
            if cold:  # fill numba's cache first: the study times a warm kernel
                t = time.perf_counter()
                rocksweep.run(scene, jobs=2)
                print(f"(cold numba cache: a first sweep compiled and ran in "
                      f"{time.perf_counter() - t:.1f} s; not in the study)")
            t = time.perf_counter()
            sc, _ = load(scene)
            times["1. scene: 44 records read, IMs, checks"] = time.perf_counter() - t
            t = time.perf_counter()
            ds = rocksweep.run(scene, jobs=2)
            times["2. sweep: 2 112 runs (incl. a second scene load)"] = (
                time.perf_counter() - t)
        t = time.perf_counter()
        fr = rocksweep.fragility(ds, state=["theta:0.25", "theta:0.5", "overturn"],
                                 bootstrap=200)
        times["3. fragility: 3 states x 3 lam, 200 bootstrap"] = time.perf_counter() - t
        t = time.perf_counter()
        eff = rocksweep.im_efficiency(ds)
        times[f"4. efficiency: {eff.sizes['im']} IMs x 3 lam"] = time.perf_counter() - t
        x = np.geomspace(0.01, 4.0, 30)
        hazard = pd.DataFrame({"PGA [g]": x, "annual_rate": 2e-4 * x ** -2.2})
        t = time.perf_counter()
        rk = rocksweep.risk(fr, hazard, years=50)
        times["5. risk: 9 curves over 30 hazard levels"] = time.perf_counter() - t
        t = time.perf_counter()
        tab = rocksweep.table(ds)
        times[f"6. table: {len(tab):,} rows"] = time.perf_counter() - t

    total = sum(times.values())
    print(f"{scene['name']}: {ds.outcome.size:,} runs, {os.cpu_count()} cores visible")
    print(f"0. start-up (fresh process, import rocksweep): {startup:.2f} s (apart)")
    for k, v in times.items():
        print(f"{k:<55s} {v:7.2f} s  {100 * v / total:5.1f} %")
    verdict = "met" if total + startup < TARGET else "NOT met"
    print(f"{'study total (1-6)':<55s} {total:7.2f} s; with start-up {total + startup:.2f} s"
          f" (target < {TARGET:g} s: {verdict})")
    eff_pga = eff.beta_scale.sel(im="PGA").values
    best = [str(eff.im.values[int(np.nanargmin(eff.beta_scale.values[:, k]))])
            for k in range(eff.sizes["lam"])]
    print(f"efficiency: best IM per lam {best}; PGA's beta {np.round(eff_pga, 3).tolist()}")
    p = rk.probability.sel(state="overturn").values
    print(f"risk: P(overturn in 50 yr) per lam {np.round(p, 4).tolist()} "
          f"(bootstrap {np.round(rk.probability_lo.sel(state='overturn').values, 4).tolist()}"
          f" - {np.round(rk.probability_hi.sel(state='overturn').values, 4).tolist()})")
    print(f"load average at end: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
