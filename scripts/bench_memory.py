"""Peak memory and time of each analysis against the size of its data.

A record-suite sweep of 3 shipped records at 2 PGA stripes is run once (the real
Dataset's variables and attributes); its stripes are then widened to S levels with a
synthetic response (each record's capacity lognormal, theta_max growing towards it,
the stripes' order mixed by noise so the fractions are not monotone), and every analysis
that reads a suite runs on it: ``fragility`` (overturn; 3 nested states, each alone and
``joint``), the IM
``efficiency``, ``risk`` over a power-law hazard and the per-run ``table``. Each line
prints the points (records x stripes), the input Dataset's bytes, the analysis's peak
traced allocation (``tracemalloc``: numpy's arrays included) and its wall time.

    python scripts/bench_memory.py                    # S = 100, 600, 2000
    python scripts/bench_memory.py --stripes 2000     # one size

Target (fragility of 2000 stripes x 3 records, each state alone and ``joint``): < 1 GB
and < 10 s; the fragility lines at 2000 stripes or more say "met" or "NOT met".
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
import warnings

import _here  # noqa: F401 (this checkout's package first)
import numpy as np
import pandas as pd

SCENE = """name: bench memory
body: {wn_over_p: 2.43, zeta: 0.05, alpha_cg: 0.15, alpha_A: 0.28, mA_over_m: 0.47,
       IA_ratio: 0.56}
impact: {lam: 0.2}
ground:
  records: [%s]
  scale: {im: PGA, values: [0.2, 0.8]}
  p: 2.0
"""


def base_dataset():
    from _here import ROOT

    import rocksweep

    files = ", ".join(str(ROOT / "records" / "suite" / f"SYN0{i}.AT2") for i in (1, 2, 3))
    return rocksweep.run(SCENE % files)


def widened(ds, S: int, seed: int = 1):
    """ds with S PGA stripes from 0.05 to 2 g and a synthetic response (module docstring)."""
    rng = np.random.default_rng(seed)
    levels = np.geomspace(0.05, 2.0, S)
    wide = ds.isel(PGA=np.zeros(S, np.int64)).assign_coords(PGA=levels)
    R = ds.sizes["record"]
    cap = 0.5 * np.exp(0.4 * rng.standard_normal(R))[:, None]
    noisy = levels[None, :] * np.exp(0.05 * rng.standard_normal((R, S)))
    over = noisy >= cap
    theta = np.where(over, 10.0, noisy / cap)
    wide["outcome"] = (("record", "PGA"), np.where(over, 1, 0).astype(np.int8))
    wide["theta_max_over_alpha"] = (("record", "PGA"), theta)
    wide["uplifts"] = (("record", "PGA"), (theta > 0.05).astype(np.int32))
    wide["status"] = (("record", "PGA"), np.zeros((R, S), np.int32))
    wide["scale_factor"] = (("record", "PGA"), levels[None, :] / ds["record_pga"].values[:, None])
    return wide


#: the fragility target at 2000 stripes x 3 records: peak bytes, wall seconds
TARGET = (1e9, 10.0)


def measure(what: str, fn, points: int, nbytes: int, target: bool = False):
    """fn() timed and its peak traced allocation printed (with target: against
    ``TARGET``); returns what fn returned."""
    tracemalloc.start()
    t0 = time.perf_counter()
    out = fn()
    wall = time.perf_counter() - t0
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    met = ""
    if target:
        met = "  met" if peak < TARGET[0] and wall < TARGET[1] else "  NOT met"
    print(f"{what:<28}{points:>9}{nbytes / 1e6:>12.2f}{peak / 1e6:>12.1f}{wall:>9.2f}{met}",
          flush=True)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stripes", type=int, nargs="*", default=[100, 600, 2000])
    args = ap.parse_args()
    import rocksweep

    warnings.simplefilter("ignore")
    base = base_dataset()
    hazard = pd.DataFrame({"PGA [g]": np.geomspace(0.01, 5.0, 40),
                           "annual_rate": 1e-4 * np.geomspace(0.01, 5.0, 40) ** -2.0})
    print(f"{'analysis':<28}{'points':>9}{'input MB':>12}{'peak MB':>12}{'wall s':>9}")
    for S in args.stripes:
        ds = widened(base, S)
        n, nb = ds.sizes["record"] * S, int(ds.nbytes)
        big = S >= 2000  # the target's size: say whether it is met
        measure(f"fragility overturn S={S}", lambda ds=ds: rocksweep.fragility(ds), n, nb,
                big)
        three = measure(f"fragility 3 states S={S}", lambda ds=ds: rocksweep.fragility(
            ds, state=["theta:0.25", "theta:0.5", "overturn"]), n, nb, big)
        measure(f"fragility 3 joint S={S}", lambda ds=ds: rocksweep.fragility(
            ds, state=["theta:0.25", "theta:0.5", "overturn"], joint=True), n, nb, big)
        measure(f"efficiency S={S}", lambda ds=ds: rocksweep.im_efficiency(ds), n, nb)
        measure(f"risk S={S}", lambda fr=three: rocksweep.risk(fr, hazard), n, nb)
        measure(f"table S={S}", lambda ds=ds: rocksweep.table(ds), n, nb)


if __name__ == "__main__":
    main()
