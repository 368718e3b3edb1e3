"""Accuracy of every stored quantity far outside the paper's region.

Draws a sample of random points over a wide Pi space (fixed seed): flexible bodies with
wn/p in [1, 60] (log-uniform), zeta in [0, 0.3] (a sixth exactly 0), alpha_cg in
[0.05, 0.45], alpha_A in [alpha_cg, 1.2], mA/m in [0.05, 10] (log), IA_ratio in [0.2, 1],
lam in [0, 1.5], w/p in [0.2, 12], |A_ratio| in [0.3, 20] (random sign; ``--a-max`` widens
it: ``--a-max 30`` reaches the guide's A up to 30, a sample of its own), sine or cosine
(uniform unless marked log: most pulses are far above the uplift threshold); plus a share
of rigid bodies (wn/p = inf, same ranges otherwise). Runs the reference
(``rocksweep.physics.reference``, DOP853 at rtol 1e-10) once per sample (cached with ``--cache``)
and the kernel at each setting, and prints per setting: outcome agreement, flagged runs,
and the median, 95th percentile and max of every error:

- t_overturn [p*t]: |d t_overturn| where both overturn;
- theta_rel: |d theta_max| / theta_max(reference) where both are safe and the body uplifted
  (theta_max(reference) >= 1e-2 alpha_cg; below it the run barely leaves the ground);
- theta_max [alpha_cg]: |d theta_max| / alpha_cg where both are safe;
- t_first_impact [p*t]: where both impact; impacts: |d impacts| where outcomes agree;
- energy: the kernel's own energy balance |W_in - D_damp - E_impact - E_end| / E_ref (the
  energy-accounting kernel, same step);
Errors are taken over the runs neither the kernel nor the reference flags (horizon, caps);
the flagged runs are counted apart.
- us/point: one call of the outcome kernel per body kind on the sample, best of 3.

    python scripts/wide_space.py --n 400 --seed 1 --cache /tmp/wide     # tuning sample
    python scripts/wide_space.py --n 400 --seed 2 --cache /tmp/wide     # held out
    python scripts/wide_space.py --n 400 --seed 2 --cache /tmp/wide --check --presets default

``--check`` measures the per-point error estimate of ``outputs.check`` (the difference
to a rerun at half the step) against the true errors: which points above the targets
(0.05 p*t, 1%) it catches and how many it flags.

Settings: the presets (``--presets draft,default,fine``) and any ``--setting
NAME:KEY=VALUE,KEY=VALUE`` of Numerics fields (e.g. ``x:steps_per_period=8,event_tol=1e-7``).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time
from pathlib import Path

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np

from rocksweep.analysis.accuracy import estimate_scores, format_scores
from rocksweep.fields import THETA_REL_FLOOR, check_rows
from rocksweep.kernel import chunk_kernel, warm_up
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import PRESETS, Numerics
from rocksweep.physics.bodies import FlexibleBody
from rocksweep.physics.points import Point, kernel_kind, point_row

RIGID_SHARE = 0.15
ZETA0_SHARE = 1 / 6
ERRORS = ("t_overturn", "theta_rel", "theta_max", "t_first_impact", "impacts", "energy")


def _logu(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def draw(n: int, seed: int, a_max: float = 20.0) -> list[Point]:
    """n random points of the wide Pi space (see the module docstring), reproducible;
    |A_ratio| up to ``a_max`` (at 20, the samples drawn before the option existed)."""
    rng = np.random.default_rng(seed)
    pts = []
    for _ in range(n):
        rigid = rng.uniform() < RIGID_SHARE
        a_cg = float(rng.uniform(0.05, 0.45))
        body = FlexibleBody(
            wn_over_p=math.inf if rigid else _logu(rng, 1.0, 60.0),
            zeta=0.0 if rng.uniform() < ZETA0_SHARE else float(rng.uniform(0.0, 0.3)),
            alpha_cg=a_cg, alpha_A=float(rng.uniform(a_cg, 1.2)),
            mA_over_m=_logu(rng, 0.05, 10.0), IA_ratio=float(rng.uniform(0.2, 1.0)))
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        pts.append(Point(body, lam=float(rng.uniform(0.0, 1.5)),
                         excitation="sine" if rng.uniform() < 0.5 else "cosine",
                         w_over_p=float(rng.uniform(0.2, 12.0)),
                         A_ratio=sign * float(rng.uniform(0.3, a_max))))
    return pts


def describe(p: Point) -> str:
    b = p.body
    return (f"wn/p={b.wn_over_p:.3g} zeta={b.zeta:.3g} a_cg={b.alpha_cg:.3g} "
            f"a_A={b.alpha_A:.3g} mA/m={b.mA_over_m:.3g} IA={b.IA_ratio:.3g} lam={p.lam:.3g} "
            f"{p.shape} w/p={p.w_over_p:.3g} A={p.A_ratio:.4g}")


def reference(points: list[Point], numerics: Numerics, cache: Path | None, tag: str
              ) -> tuple[np.ndarray, np.ndarray]:
    """Reference result rows float64[n, N_OUT] and seconds per point (cached)."""
    from rocksweep.physics.reference import reference_run, result_row

    path = cache / f"ref_{tag}.npz" if cache else None
    if path is not None and path.exists():
        z = np.load(path)
        return z["outs"], z["secs"]
    outs = np.empty((len(points), L.N_OUT))
    secs = np.empty(len(points))
    for i, p in enumerate(points):
        r = reference_run(p, numerics)
        outs[i] = result_row(r)
        secs[i] = r["wall_time"]
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savez(path, outs=outs, secs=secs)
    return outs, secs


def kernel(points: list[Point], numerics: Numerics, level: int = L.LEVEL_OUTCOME,
           repeat: int = 3, half: bool = False) -> tuple[np.ndarray, float]:
    """Kernel result rows float64[n, N_OUT] and us per point (one call per body kind on
    the whole sample, best of ``repeat``; compilation excluded). half: the half-step
    reruns of ``outputs.check`` (``fields.check_rows``) instead."""
    rows = np.stack([point_row(p, numerics) for p in points])
    if half:
        rows = check_rows(rows)
    kinds = np.array([kernel_kind(p.body) for p in points])
    outs = np.empty((len(points), L.N_OUT))
    best = math.inf
    for _ in range(repeat):
        t = 0.0
        for k in np.unique(kinds):
            warm_up(int(k), level)
            sel = np.flatnonzero(kinds == k)
            r, o = np.ascontiguousarray(rows[sel]), np.empty((len(sel), L.N_OUT))
            t0 = time.perf_counter()
            chunk_kernel(int(k), level)(r, o)
            t += time.perf_counter() - t0
            outs[sel] = o
        best = min(best, t)
    return outs, best / len(points) * 1e6


def errors(k: np.ndarray, r: np.ndarray, ke: np.ndarray, points: list[Point]
           ) -> dict[str, np.ndarray]:
    """Per-point errors of kernel rows k against reference rows r (NaN where a measure does
    not apply); ke: the energy kernel's rows (for the energy balance)."""
    alpha = np.array([p.body.alpha_ref for p in points])
    e_ref = np.array([p.body.E_ref for p in points])
    ok = (((k[:, L.OUT_STATUS].astype(np.int64) | r[:, L.OUT_STATUS].astype(np.int64))
           & L.STATUS_FLAGGED) == 0)
    ko = np.where(ok, k[:, L.OUT_OUTCOME], -9)
    ro = np.where(ok, r[:, L.OUT_OUTCOME], -8)
    nan = np.full(len(k), np.nan)
    safe = (ko == L.OUTCOME_SAFE) & (ro == L.OUTCOME_SAFE)
    d_th = np.abs(k[:, L.OUT_THETA_MAX] - r[:, L.OUT_THETA_MAX])
    up = safe & (r[:, L.OUT_THETA_MAX] >= THETA_REL_FLOOR * alpha)
    bal = (ke[:, L.OUT_W_IN] - ke[:, L.OUT_D_DAMP] - ke[:, L.OUT_E_IMPACT]
           - ke[:, L.OUT_E_END])
    return {
        "t_overturn": np.where(ok, np.abs(k[:, L.OUT_T_OVERTURN] - r[:, L.OUT_T_OVERTURN]),
                               nan),
        "theta_rel": np.where(up, d_th / np.where(up, r[:, L.OUT_THETA_MAX], 1.0), nan),
        "theta_max": np.where(safe, d_th / alpha, nan),
        "t_first_impact": np.where(ok, np.abs(k[:, L.OUT_T_FIRST_IMPACT]
                                              - r[:, L.OUT_T_FIRST_IMPACT]), nan),
        "impacts": np.where(ko == ro, np.abs(k[:, L.OUT_IMPACTS] - r[:, L.OUT_IMPACTS]), nan),
        "energy": np.where(ok, np.abs(bal) / e_ref, nan),
    }


def tails(e: np.ndarray) -> tuple[int, float, float, float]:
    """(points, median, 95th percentile, max) of the finite entries."""
    e = e[np.isfinite(e)]
    if not e.size:
        return 0, math.nan, math.nan, math.nan
    return e.size, float(np.median(e)), float(np.percentile(e, 95)), float(np.max(e))


def _setting(text: str) -> tuple[str, Numerics]:
    name, _, kv = text.partition(":")
    base = Numerics.preset(name) if name in PRESETS else Numerics()
    over = {}
    fields = {f.name: f.type for f in dataclasses.fields(Numerics)}
    for item in filter(None, kv.split(",")):
        key, _, val = item.partition("=")
        if key not in fields:
            raise SystemExit(f"--setting {text}: {key} is not a Numerics field "
                             f"({', '.join(fields)})")
        over[key] = (val if key in ("root", "accuracy") else
                     int(val) if key in ("steps_per_period", "max_events") else float(val))
    return name, dataclasses.replace(base, **over)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=400)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--presets", default=",".join(PRESETS))
    ap.add_argument("--a-max", type=float, default=20.0,
                    help="largest |A_ratio| drawn (default 20; the reference cache is per value)")
    ap.add_argument("--setting", action="append", default=[])
    ap.add_argument("--cache", type=Path, default=None,
                    help="directory for the reference results (reused on the next run)")
    ap.add_argument("--worst", type=int, default=0,
                    help="list the N worst points of each error at each setting")
    ap.add_argument("--markdown", action="store_true", help="also print a markdown table")
    ap.add_argument("--check", action="store_true",
                    help="also rerun each setting at half the step (outputs.check) and "
                         "report how well the difference tells the points above the targets")
    ap.add_argument("--targets", default="0.05,0.01",
                    help="t_overturn [p*t] and theta_rel targets for --check")
    args = ap.parse_args()

    points = draw(args.n, args.seed, args.a_max)
    t0 = time.perf_counter()
    tag = f"n{args.n}_s{args.seed}" + ("" if args.a_max == 20.0 else f"_a{args.a_max:g}")
    ref, secs = reference(points, Numerics(), args.cache, tag)
    n_rigid = sum(p.body.rigid for p in points)
    print(f"wide-space sample: {args.n} points, seed {args.seed}, |A_ratio| <= {args.a_max:g} "
          f"({n_rigid} rigid); reference "
          f"{np.mean(secs) * 1e3:.0f} ms/point mean ({time.perf_counter() - t0:.0f} s here)")
    ref_flag = int(np.sum((ref[:, L.OUT_STATUS].astype(np.int64) & L.STATUS_FLAGGED) != 0))
    print("reference outcomes: " + ", ".join(
        f"{w} {int(np.sum(ref[:, L.OUT_OUTCOME] == c))}"
        for c, w in ((0, "safe"), (1, "mode1"), (2, "mode2"))) + f"; flagged {ref_flag}")
    settings = [_setting(s) for s in args.presets.split(",") if s] + [
        _setting(s) for s in args.setting]
    head = (f"{'setting':>10} {'us/pt':>7} {'agree':>7} {'flag':>4} {'rest':>4} "
            + " ".join(f"{m + ' med/p95/max':>27}" for m in ERRORS))
    print(head)
    print("-" * len(head))
    md = []
    for name, num in settings:
        outs, us = kernel(points, num)
        oute, _ = kernel(points, num, L.LEVEL_ENERGY, repeat=1)
        err = errors(outs, ref, oute, points)
        agree = float(np.mean(outs[:, L.OUT_OUTCOME] == ref[:, L.OUT_OUTCOME]))
        st = outs[:, L.OUT_STATUS].astype(np.int64)
        flag = int(np.sum((st & L.STATUS_FLAGGED) != 0))
        # "rest" where the reference still moves at the horizon: the word must mean proven
        bad_rest = int(np.sum(((st & L.STATUS_REST) != 0)
                              & ((ref[:, L.OUT_STATUS].astype(np.int64) & L.STATUS_HORIZON)
                                 != 0)))
        cells = []
        for m in ERRORS:
            _, med, p95, mx = tails(err[m])
            cells.append(f"{med:8.1e}/{p95:8.1e}/{mx:8.1e}")
        print(f"{name:>10} {us:7.1f} {100 * agree:6.2f}% {flag:>4} {bad_rest:>4} "
              + " ".join(f"{c:>27}" for c in cells), flush=True)
        md.append((name, num, us, agree, flag, err))
        if args.check:
            half, us_half = kernel(points, num, half=True)
            t_tgt, th_tgt = (float(v) for v in args.targets.split(","))
            scores = estimate_scores(outs, half, ref, err,
                                     {"t_overturn": t_tgt, "theta_rel": th_tgt})
            print(f"      check (+{us_half:.1f} us/pt): {format_scores(scores)}", flush=True)
        for m in ERRORS[: 5] if args.worst else ():
            e = np.where(np.isfinite(err[m]), err[m], -1)
            for i in np.argsort(e)[::-1][: args.worst]:
                if e[i] <= 0:
                    break
                print(f"      worst {m} {e[i]:.3g} #{i}: {describe(points[i])} "
                      f"ref t_over={ref[i, L.OUT_T_OVERTURN]:.4g} "
                      f"th={ref[i, L.OUT_THETA_MAX] / points[i].body.alpha_ref:.4g} "
                      f"ker t_over={outs[i, L.OUT_T_OVERTURN]:.4g} "
                      f"th={outs[i, L.OUT_THETA_MAX] / points[i].body.alpha_ref:.4g}")
        dis = np.flatnonzero(outs[:, L.OUT_OUTCOME] != ref[:, L.OUT_OUTCOME])
        for i in dis[: args.worst]:
            print(f"      flip #{i}: {describe(points[i])} ref {int(ref[i, L.OUT_OUTCOME])} "
                  f"st {int(ref[i, L.OUT_STATUS])} kernel {int(outs[i, L.OUT_OUTCOME])} "
                  f"st {int(outs[i, L.OUT_STATUS])}")
    print("errors: t_overturn, t_first_impact [p*t]; theta_rel relative to the reference's "
          "theta_max (safe, uplifted); theta_max [alpha_cg]; impacts |d count|; energy "
          "|balance|/E_ref (kernel); rest: runs reported 'rest' where the reference is "
          "flagged at the horizon")
    if args.markdown:
        print()
        print("| setting | us/pt | agreement | flagged | t_overturn p95 (max) | "
              "theta_max rel. p95 (max) | t_1st_impact p95 (max) | impacts p95 (max) | "
              "energy p95 (max) |")
        print("|---|---|---|---|---|---|---|---|---|")
        for name, _num, us, agree, flag, err in md:
            c = []
            for m in ("t_overturn", "theta_rel", "t_first_impact", "impacts", "energy"):
                _, _, p95, mx = tails(err[m])
                c.append(f"{p95:.1e} ({mx:.1e})")
            print(f"| {name} | {us:.0f} | {100 * agree:.2f}% | {flag} | " + " | ".join(c)
                  + " |")


if __name__ == "__main__":
    main()
