"""Held-out overturning spectra: A_min(omega/p) of a 300-value sweep against references.

The curves: uniform blocks (``kind: block``, alpha 0.1, 0.25, 0.4), three flexible bodies
(Table 3's body of Figures 3(a)/(b), wn/p = 2.43; the stiff body of Figure 4, wn/p = 9.82;
a third, squatter and lightly damped one, wn/p = 4), sine and cosine pulses, omega/p in
``OMEGAS``, lam 0 (``--lam`` adds values): 96 curves at lam 0.

Reference A_min (``reference_a_min``), per curve, from the reference path alone
(``rocksweep.physics.reference``, scipy DOP853 at rtol 1e-10, an integrator independent of
the RK4 kernel) over A/(g tan alpha) in [0.3, 30]:

1. the uplift threshold A_up, bisected (full contact is linear in A, so uplift is monotone);
2. a scan upwards from A_up, stopping at the first overturning value: steps of 0.2% of A_up
   up to 1.3 A_up (the narrow first bands just above the threshold at omega/p ~ 1), then
   geometric steps of 0.5% up to 30; between two safe scan values where either came
   within 20% of overturning (max|theta|/alpha >= 0.8), four more values;
3. before the scan, a hint: the first overturning value of a kernel scan at `fine` on a
   0.1% geometric grid (cheap); the reference runs at the hint and just above it, and an
   overturning there caps the scan (the scan below it still runs: only reference runs
   decide, the hint only says where to look);
4. bisection between the last safe value and the first overturning one to 1e-4 (relative).

A band narrower than the scan step that neither the scan nor the hint sees is missed; the
references are cached in ``scripts/data/bench_spectra_refs.json`` (keyed by body, shape,
lam, omega/p and the search's version), computed with joblib over ``--jobs`` processes.

The test: one ``rocksweep.run`` per body group (blocks: alpha swept) over A_ratio =
linspace(0.3, 30, 300) (step 0.0993) and the omega/p list at the preset of ``--preset``
(none given: the scene's default), then ``rocksweep.boundaries(ds, rtol=1e-4)``. Printed:
per curve the reference's and our A_min, relative error, modes, how ours was found
(``A_min_method``), then the count within 0.5% and the same mode, also for
``boundaries(..., search=False)`` (the grid's bracket only, side by side), and the wall
time of the sweeps and of boundaries (in-process, after one warm-up of the kernel
variants: no start-up or compile in the figures).

    python scripts/bench_spectra.py                    # references from the cache, then the test
    python scripts/bench_spectra.py --preset fine      # the test at another preset
    python scripts/bench_spectra.py --set steps_per_period=8 --set event_tol=1e-7
    python scripts/bench_spectra.py --refs-only --jobs 2   # (re)compute missing references
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent
if (ROOT.parent / "rocksweep").is_dir():  # measure the checkout this script is in
    sys.path.insert(0, str(ROOT.parent))
CACHE = ROOT / "data" / "bench_spectra_refs.json"
SEARCH_VERSION = 1  # bump when the reference search changes (cached entries are then stale)

A_LO, A_HI = 0.3, 30.0
N_A = 300
OMEGAS = (1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0)
SHAPES = ("sine", "cosine")
RTOL = 1e-4
TOLERANCE = 5e-3  # "within 0.5%"

# body groups: name -> (scene body section, list of swept body keys' value sets). A group is
# one scene (its swept keys are the body keys given as lists).
TABLE3 = {"zeta": 0.05, "alpha_cg": 0.15, "alpha_A": 0.28, "mA_over_m": 0.47,
          "IA_ratio": 0.56}
GROUPS: dict[str, dict[str, Any]] = {
    "block": {"kind": "block", "alpha": [0.1, 0.25, 0.4]},
    "fig3": {"wn_over_p": 2.43, **TABLE3},
    "fig4": {"wn_over_p": 9.82, **TABLE3},
    "squat": {"wn_over_p": 4.0, "zeta": 0.02, "alpha_cg": 0.25, "alpha_A": 0.45,
              "mA_over_m": 1.0, "IA_ratio": 0.56},
}

DENSE_STEP, DENSE_SPAN = 0.002, 0.3  # scan A_up (1 + k DENSE_STEP) up to (1 + DENSE_SPAN) A_up
GEOM_STEP = 0.005  # then A *= 1 + GEOM_STEP
CLOSE = 0.8  # max|theta|/alpha of a safe scan value that asks for a finer look
SUB = 4  # values added between two safe scan values where one came close
HINT_STEP = 0.001  # the kernel hint's geometric grid


# --- curves -----------------------------------------------------------------------------

def bodies(group: str) -> list[dict[str, Any]]:
    """The single bodies of a group (a body section with every swept key one value)."""
    spec = GROUPS[group]
    swept = [k for k, v in spec.items() if isinstance(v, list)]
    out = [dict(spec)]
    for k in swept:
        out = [{**b, k: v} for b in out for v in spec[k]]
    return out


def curves(lams: list[float]) -> list[dict[str, Any]]:
    """Every curve: group, body (one value per key), shape, lam, w_over_p."""
    return [{"group": g, "body": b, "shape": s, "lam": lam, "w_over_p": w}
            for g in GROUPS for b in bodies(g) for s in SHAPES for lam in lams
            for w in OMEGAS]


def curve_key(c: dict[str, Any]) -> str:
    body = ",".join(f"{k}={c['body'][k]}" for k in sorted(c["body"]))
    return f"v{SEARCH_VERSION}|{body}|{c['shape']}|lam={c['lam']}|w={c['w_over_p']}"


def make_body(spec: dict[str, Any]):
    from rocksweep.physics.bodies import BlockBody, FlexibleBody

    spec = dict(spec)
    if spec.pop("kind", "flexible") == "block":
        return BlockBody(**spec)
    return FlexibleBody(**spec)


def label(c: dict[str, Any]) -> str:
    b = c["body"]
    name = f"block a={b['alpha']}" if c["group"] == "block" else c["group"]
    return f"{name:<13} {c['shape']:<6} lam={c['lam']:<4g} w/p={c['w_over_p']:<5g}"


# --- the kernel hint ---------------------------------------------------------------------

def kernel_hints(cs: list[dict[str, Any]]) -> list[float]:
    """First overturning A_ratio of each curve on a geometric grid (ratio 1 + HINT_STEP)
    over [A_LO, A_HI] at the `fine` preset (NaN: none). A hint only, see the docstring."""
    from rocksweep.kernel import chunk_kernel, warm_up
    from rocksweep.kernel import layout as L  # noqa: N812
    from rocksweep.numerics import Numerics
    from rocksweep.physics.points import Point, kernel_kind, point_row

    num = Numerics.preset("fine")
    grid = A_LO * (1 + HINT_STEP) ** np.arange(
        int(math.log(A_HI / A_LO) / math.log1p(HINT_STEP)) + 2)
    grid = np.minimum(grid, A_HI)
    hints = []
    for c in cs:
        body = make_body(c["body"])
        kind = kernel_kind(body)
        warm_up(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE)
        rows = np.stack([point_row(Point(body, c["lam"], c["shape"], c["w_over_p"], float(a)),
                                   num) for a in grid])
        outs = np.empty((len(grid), L.N_OUT))
        chunk_kernel(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE)(rows, outs)
        over = np.flatnonzero(outs[:, L.OUT_OUTCOME] > 0)
        hints.append(float(grid[over[0]]) if over.size else math.nan)
    return hints


# --- the reference ----------------------------------------------------------------------

def reference_a_min(c: dict[str, Any], hint: float) -> dict[str, Any]:
    """The reference A_min of one curve (see the module docstring): a_min (NaN: nothing
    overturns up to A_HI), mode, lo (largest safe value below), a_up (uplift threshold),
    runs, flagged (runs with horizon or cap flags, counted safe), seconds, found ("scan",
    "hint")."""
    from rocksweep.kernel import layout as L  # noqa: N812
    from rocksweep.numerics import Numerics
    from rocksweep.physics.points import Point
    from rocksweep.physics.reference import reference_run

    t0 = time.perf_counter()
    body = make_body(c["body"])
    num = Numerics()
    seen: dict[float, tuple[int, float, int]] = {}  # A -> (outcome, theta_max/alpha, uplifts)
    flagged = 0
    caps = L.STATUS_HORIZON | L.STATUS_EVENT_CAP | L.STATUS_STEP_CAP

    def run(a: float) -> tuple[int, float, int]:
        nonlocal flagged
        if a not in seen:
            r = reference_run(Point(body, c["lam"], c["shape"], c["w_over_p"], a), num)
            flagged += bool(r["status"] & caps)
            seen[a] = (int(r["outcome"]), float(r["theta_max"]) / body.alpha_ref,
                       int(r["uplifts"]))
        return seen[a]

    def result(a_min: float, mode: int, lo: float, a_up: float, found: str) -> dict:
        return {"a_min": a_min, "mode": mode, "lo": lo, "a_up": a_up, "runs": len(seen),
                "flagged": flagged, "seconds": time.perf_counter() - t0, "found": found}

    # 1. uplift threshold
    if run(A_LO)[2] > 0:
        a_up = A_LO
    elif run(A_HI)[2] == 0:
        return result(math.nan, 0, A_HI, math.nan, "none")
    else:
        lo, hi = A_LO, A_HI
        while hi - lo > 1e-6 * hi:
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if run(mid)[2] > 0 else (mid, hi)
        a_up = hi
    if run(a_up)[0] > 0:  # overturns at the threshold (or at A_LO)
        lo = max((a for a in seen if a < a_up and seen[a][0] == 0), default=math.nan)
        return bisect(run, lo, a_up, result, a_up, "scan")
    # 3. the hint caps the scan
    cap, found = A_HI, "scan"
    if math.isfinite(hint):
        for a in (hint, hint * (1 + HINT_STEP / 2), hint * (1 + HINT_STEP)):
            if a <= A_HI and run(a)[0] > 0:
                cap, found = a, "hint"
                break
    # 2. the scan
    dense = a_up * (1 + DENSE_STEP * np.arange(1, int(DENSE_SPAN / DENSE_STEP) + 1))
    a, geom = dense[-1], []
    while a * (1 + GEOM_STEP) < A_HI:
        a *= 1 + GEOM_STEP
        geom.append(a)
    values = [float(v) for v in np.concatenate([dense, geom, [A_HI]]) if v < cap]
    prev = a_up
    for a in values:
        out = run(a)
        if out[0] == 0 and max(seen[prev][1], out[1]) >= CLOSE:
            for b in np.linspace(prev, a, SUB + 2)[1:-1]:
                if run(float(b))[0] > 0:
                    return bisect(run, prev, float(b), result, a_up, "scan")
                prev = float(b)
        if out[0] > 0:
            return bisect(run, prev, a, result, a_up, "scan")
        prev = a
    if cap < A_HI:
        return bisect(run, prev, cap, result, a_up, found)
    return result(math.nan, 0, A_HI, a_up, "none")


def bisect(run, lo: float, hi: float, result, a_up: float, found: str) -> dict:
    """Bisect between lo (safe; NaN: none known) and hi (overturns) to RTOL."""
    if math.isnan(lo):
        return result(hi, run(hi)[0], lo, a_up, found)
    while hi - lo > RTOL * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if run(mid)[0] > 0 else (mid, hi)
    return result(hi, run(hi)[0], lo, a_up, found)


def references(cs: list[dict[str, Any]], jobs: int, log=print) -> list[dict[str, Any]]:
    """The reference of every curve: from the cache, the missing ones computed (joblib over
    ``jobs`` processes) and added to it."""
    cache = json.loads(CACHE.read_text()) if CACHE.exists() else {}
    todo = [c for c in cs if curve_key(c) not in cache]
    if todo:
        from joblib import Parallel, delayed

        log(f"references: {len(todo)} of {len(cs)} curves to compute (kernel hints first)")
        t0 = time.perf_counter()
        hints = kernel_hints(todo)
        log(f"  kernel hints at `fine`: {time.perf_counter() - t0:.1f} s")
        t0 = time.perf_counter()
        done = Parallel(n_jobs=jobs, verbose=0)(
            delayed(reference_a_min)(c, h) for c, h in zip(todo, hints, strict=True))
        wall = time.perf_counter() - t0
        for c, h, r in zip(todo, hints, done, strict=True):
            cache[curve_key(c)] = {**r, "hint": h}
        CACHE.parent.mkdir(parents=True, exist_ok=True)
        tmp = CACHE.with_suffix(".tmp")
        tmp.write_text(json.dumps(cache, indent=0, sort_keys=True))
        tmp.replace(CACHE)
        secs = sum(r["seconds"] for r in done)
        log(f"  references: {wall:.0f} s wall over {jobs} processes ({secs:.0f} s summed, "
            f"{sum(r['runs'] for r in done)} reference runs)")
    return [cache[curve_key(c)] for c in cs]


# --- the test ---------------------------------------------------------------------------

def scene(group: str, lams: list[float], preset: str | None, sets: dict[str, Any]
          ) -> dict[str, Any]:
    numerics = dict(sets)
    if preset is not None:
        numerics["accuracy"] = preset
    sc = {"name": f"bench_spectra {group}", "body": GROUPS[group],
          "impact": {"lam": lams if len(lams) > 1 else lams[0]},
          "pulse": {"shape": list(SHAPES), "w_over_p": list(OMEGAS),
                    "A_ratio": {"start": A_LO, "stop": A_HI, "num": N_A}}}
    if numerics:
        sc["numerics"] = numerics
    return sc


def ours(cs: list[dict[str, Any]], lams: list[float], preset: str | None,
         sets: dict[str, Any], jobs: int, log=print) -> tuple[list[dict], dict]:
    """Our A_min of every curve: a sweep per group, then boundaries(rtol=RTOL)."""
    import rocksweep

    found: dict[str, dict] = {}
    times = {"sweep": 0.0, "boundaries": 0.0, "points": 0, "runs": 0,
             "grid_only": 0.0, "grid_only_runs": 0}
    # warm-up: load (or compile) the kernel variants outside the timed runs
    for g in GROUPS:
        small = scene(g, lams[:1], preset, sets)
        small["pulse"] = {"shape": list(SHAPES), "w_over_p": [2.0, 3.0], "A_ratio": [1.5, 3.0]}
        rocksweep.boundaries(rocksweep.run(small), rtol=1e-2)
    for g in GROUPS:
        t0 = time.perf_counter()
        ds = rocksweep.run(scene(g, lams, preset, sets), jobs=jobs)
        t1 = time.perf_counter()
        b = rocksweep.boundaries(ds, rtol=RTOL)
        t2 = time.perf_counter()
        b0 = rocksweep.boundaries(ds, rtol=RTOL, search=False)  # the grid's bracket only
        times["grid_only"] += time.perf_counter() - t2
        times["grid_only_runs"] += int(b0["runs"].sum())
        times["sweep"] += t1 - t0
        times["boundaries"] += t2 - t1
        times["points"] += int(ds["outcome"].size)
        times["runs"] += int(b["runs"].sum())
        times.setdefault("numerics", ds.attrs.get("numerics", ""))
        for c in (c for c in cs if c["group"] == g):
            sel = {"w_over_p": c["w_over_p"], "shape": c["shape"]}
            if "lam" in b.dims:
                sel["lam"] = c["lam"]
            for k, v in GROUPS[g].items():
                if isinstance(v, list):
                    sel[k] = c["body"][k]
            row, row0 = b.sel(sel), b0.sel(sel)
            method = (str(row["A_min_method"].values) if "A_min_method" in b else "")
            found[curve_key(c)] = {"a_min": float(row["A_min"]), "mode": int(row["mode"]),
                                   "runs": int(row["runs"]), "method": method,
                                   "grid_a_min": float(row0["A_min"]),
                                   "grid_mode": int(row0["mode"])}
        log(f"  {g}: {ds['outcome'].size} points, sweep {t1 - t0:.1f} s, boundaries "
            f"{t2 - t1:.1f} s ({int(b['runs'].sum())} kernel runs)")
    return [found[curve_key(c)] for c in cs], times


def agree(ref: float, ref_mode: int, ours: float, our_mode: int) -> tuple[float, bool]:
    """Relative error of our A_min and whether it counts (within TOLERANCE, same mode;
    both NaN: agree)."""
    if math.isnan(ref) and math.isnan(ours):
        return 0.0, True
    if math.isnan(ref) or math.isnan(ours):
        return math.inf, False
    err = (ours - ref) / ref
    return err, abs(err) <= TOLERANCE and ref_mode == our_mode


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--preset", default=None,
                    help="numerics.accuracy of the sweeps (default: none named, the "
                         "scene's default)")
    ap.add_argument("--set", dest="sets", action="append", default=[],
                    metavar="KEY=VALUE", help="a numerics key of the sweeps, e.g. "
                    "steps_per_period=8 (repeatable)")
    ap.add_argument("--lam", type=float, action="append", default=[],
                    help="lam values besides 0 (repeatable)")
    ap.add_argument("--jobs", type=int, default=2, help="processes for the references "
                    "and threads for the sweeps")
    ap.add_argument("--refs-only", action="store_true", help="compute the references only")
    args = ap.parse_args()
    sets = {}
    for s in args.sets:
        k, _, v = s.partition("=")
        sets[k] = json.loads(v) if v[:1].isdigit() or v[:1] in "-." else v
    lams = [0.0, *args.lam]
    cs = curves(lams)
    refs = references(cs, args.jobs)
    if args.refs_only:
        return
    import rocksweep

    print(f"rocksweep {rocksweep.__version__} from {Path(rocksweep.__file__).parent}")
    print(f"test: sweep over A_ratio linspace({A_LO}, {A_HI}, {N_A}) x omega/p {OMEGAS}, "
          f"preset {args.preset or '(scene default)'} {sets or ''}, boundaries rtol {RTOL:g}")
    mine, times = ours(cs, lams, args.preset, sets, args.jobs)
    print(f"numerics: {times.get('numerics')}")
    print(f"\n{'curve':<40} {'ref A_min':>10} {'m':>1} {'ours':>10} {'m':>1} "
          f"{'rel.err':>8}  ok  runs  method")
    good = both_none = good0 = 0
    bad = []
    for c, r, o in zip(cs, refs, mine, strict=True):
        ra, oa = r["a_min"], o["a_min"]
        err, ok = agree(ra, r["mode"], oa, o["mode"])
        good0 += agree(ra, r["mode"], o["grid_a_min"], o["grid_mode"])[1]
        both_none += math.isnan(ra) and math.isnan(oa)
        good += ok
        if not ok:
            bad.append(label(c))
        print(f"{label(c):<40} {ra:10.5f} {r['mode']:1d} {oa:10.5f} {o['mode']:1d} "
              f"{err:+8.2%}  {'ok' if ok else '--'} {o['runs']:5d}  {o['method']}")
    n = len(cs)
    print(f"\nwithin {TOLERANCE:.1%} and the same mode: {good}/{n} curves "
          f"({both_none} with no overturning up to {A_HI} in both); without the search "
          f"below the grid (search=False): {good0}/{n}")
    print(f"sweeps: {times['points']} points in {times['sweep']:.1f} s "
          f"({1e6 * times['sweep'] / times['points']:.1f} us/point wall, jobs {args.jobs}); "
          f"boundaries: {times['boundaries']:.1f} s ({times['runs']} kernel runs; "
          f"search=False {times['grid_only']:.1f} s, {times['grid_only_runs']} runs); "
          f"total {times['sweep'] + times['boundaries']:.1f} s (in-process, kernels warm)")
    ref_s = sum(r["seconds"] for r in refs)
    print(f"references (cached): {sum(r['runs'] for r in refs)} reference runs, "
          f"{ref_s:.0f} s summed over the curves' searches (wall time in the workers); "
          f"flagged reference runs {sum(r['flagged'] for r in refs)}")
    if bad:
        print("misses: " + "; ".join(bad))


if __name__ == "__main__":
    main()
