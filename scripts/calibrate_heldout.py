"""Held-out check of ``rocksweep.calibrate``'s verdicts and accuracy on cases it was not
tuned on.

    python scripts/calibrate_heldout.py            # every case, ~2-3 min on 2 cores
    python scripts/calibrate_heldout.py --quick    # every third case

Each case is a body (rigid blocks released from a tilt; flexible bodies under a pulse),
an impact law (``vertical``: fit impact.lam; ``constant``: fit impact.e), a truth, a
history and a noise level (0-2% of the largest |theta|, Gaussian, seeded). The histories
are made two ways, neither the fit's own runs: ``rocksweep.simulate`` at accuracy `fine`
(Hermite interpolation of its rows at the sample times), and the scipy reference
(``rocksweep.physics.reference``: DOP853 with its own events; its dense output sampled).
The bodies, pulses, truths and noise draws are none of scripts/bench_calibrate.py's or the
tests'. Two cases must not be ok: a block under the vertical law fitted to a block whose
e (0.6, law constant) no lam gives ("misfit"), and the damping of a stiff body (wn_over_p
60: the spring hardly moves) searched within bounds (0.05, 0.15) narrower than what the
history resolves ("unidentifiable": its interval spans them). The last three are a right
model whose body overturns after one impact (reported apart: ok while off by more than
the tolerance is a wrong verdict; unidentifiable or misfit is not).

Prints per case: truth, estimate, 95% interval, reason, the misfit ratio (the peaks' RMS
error over the dof / the noise the verdict compares it with, ``MISFIT_RATIO`` = 3 the
limit); then how many good fits are ok and within lam +-0.03, e +-0.02.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import rocksweep  # noqa: E402
from rocksweep.analysis import calibrate as C  # noqa: E402
from rocksweep.analysis.peaks import hermite  # noqa: E402
from rocksweep.physics import reference as R  # noqa: E402
from rocksweep.scene.inputs import load  # noqa: E402

TOL = {"impact.lam": 0.03, "impact.e": 0.02}
DT = 0.02  # sample step [p t]


def block(alpha: float, theta0: float, law: str, value: float) -> dict:
    impact = {"lam": value} if law == "vertical" else {"lam": 0.0, "law": "constant",
                                                        "e": value}
    return {"name": "held-out block", "body": {"kind": "block", "alpha": alpha},
            "impact": impact, "initial": {"theta_over_alpha": theta0}}


def flexible(body: dict, shape: str, w: float, A: float, law: str, value: float) -> dict:
    impact = {"lam": value} if law == "vertical" else {"lam": 0.0, "law": "constant",
                                                        "e": value}
    return {"name": "held-out flexible", "body": body, "impact": impact,
            "pulse": {"shape": shape, "w_over_p": w, "A_ratio": A}}


# flexible bodies of none of the tests' or the benchmark's dimensions
SLENDER = {"wn_over_p": 3.6, "zeta": 0.03, "alpha_cg": 0.12, "alpha_A": 0.22,
           "mA_over_m": 0.6, "IA_ratio": 0.5}
SQUAT = {"wn_over_p": 6.5, "zeta": 0.08, "alpha_cg": 0.2, "alpha_A": 0.35,
         "mA_over_m": 0.35, "IA_ratio": 0.7}
RIGIDISH = {**SQUAT, "wn_over_p": 60.0}

# (label, scene maker(value), key, truth, start, source, noise, expected)
CASES = [
    ("block a.18 vert", lambda v: block(0.18, 0.8, "vertical", v), "impact.lam", 0.15, 0.0,
     "ref", 0.0, "ok"),
    ("block a.18 vert", lambda v: block(0.18, 0.8, "vertical", v), "impact.lam", 0.15, 0.0,
     "fine", 0.01, "ok"),
    ("block a.3 vert", lambda v: block(0.3, 0.55, "vertical", v), "impact.lam", 0.35, 0.1,
     "ref", 0.005, "ok"),
    ("block a.3 vert", lambda v: block(0.3, 0.55, "vertical", v), "impact.lam", 0.35, 0.1,
     "fine", 0.02, "ok"),
    ("block a.22 const", lambda v: block(0.22, 0.65, "constant", v), "impact.e", 0.78, 0.9,
     "ref", 0.01, "ok"),
    ("block a.22 const", lambda v: block(0.22, 0.65, "constant", v), "impact.e", 0.78, 0.9,
     "fine", 0.0, "ok"),
    ("block a.12 const", lambda v: block(0.12, 0.75, "constant", v), "impact.e", 0.93, 0.8,
     "ref", 0.02, "ok"),
    ("block a.12 const", lambda v: block(0.12, 0.75, "constant", v), "impact.e", 0.93, 0.8,
     "fine", 0.005, "ok"),
    ("slender sine vert", lambda v: flexible(SLENDER, "sine", 5.0, 2.5, "vertical", v),
     "impact.lam", 0.25, 0.0, "ref", 0.01, "ok"),
    ("slender sine vert", lambda v: flexible(SLENDER, "sine", 5.0, 2.5, "vertical", v),
     "impact.lam", 0.25, 0.0, "fine", 0.02, "ok"),
    ("squat cos vert", lambda v: flexible(SQUAT, "cosine", 4.0, 3.0, "vertical", v),
     "impact.lam", 0.12, 0.4, "ref", 0.005, "ok"),
    ("squat cos vert", lambda v: flexible(SQUAT, "cosine", 4.0, 3.0, "vertical", v),
     "impact.lam", 0.12, 0.4, "fine", 0.0, "ok"),
    ("slender cos const", lambda v: flexible(SLENDER, "cosine", 6.0, 4.0, "constant", v),
     "impact.e", 0.85, 0.7, "ref", 0.01, "ok"),
    ("squat sine const", lambda v: flexible(SQUAT, "sine", 3.5, 1.2, "constant", v),
     "impact.e", 0.7, 0.85, "fine", 0.015, "ok"),
    ("block a.25 vert", lambda v: block(0.25, 0.6, "vertical", v), "impact.lam", 0.05, 0.3,
     "ref", 0.015, "ok"),
    ("block a.25 vert", lambda v: block(0.25, 0.6, "vertical", v), "impact.lam", 0.5, 0.3,
     "fine", 0.01, "ok"),
    ("block a.16 const", lambda v: block(0.16, 0.5, "constant", v), "impact.e", 0.86, 0.95,
     "ref", 0.005, "ok"),
    ("slender sine const", lambda v: flexible(SLENDER, "sine", 4.5, 1.8, "constant", v),
     "impact.e", 0.6, 0.8, "ref", 0.005, "ok"),
    ("squat cos const", lambda v: flexible(SQUAT, "cosine", 5.0, 2.5, "constant", v),
     "impact.e", 0.9, 0.75, "ref", 0.02, "ok"),
    ("slender cos vert", lambda v: flexible(SLENDER, "cosine", 6.0, 4.0, "vertical", v),
     "impact.lam", 0.4, 0.1, "ref", 0.0, "ok"),
    ("squat sine vert", lambda v: flexible(SQUAT, "sine", 3.0, 1.0, "vertical", v),
     "impact.lam", 0.0, 0.3, "fine", 0.01, "ok"),
    # must not be ok
    ("block a.2 e.6 as vert", lambda v: block(0.2, 0.7, "constant", 0.6) if v is None else
     block(0.2, 0.7, "vertical", v), "impact.lam", math.nan, 0.0, "ref", 0.01, "misfit"),
    ("rigid-ish zeta", lambda v: flexible({**RIGIDISH, "zeta": v}, "sine", 4.0, 1.4,
                                          "vertical", 0.2), "body.zeta", 0.1, 0.12, "fine",
     0.01, "unidentifiable"),
    # the model is right, but the body overturns after one impact (2 half cycles, the
    # second a plateau at pi/2)
    *(("squat sine const fall", lambda v: flexible(SQUAT, "sine", 3.5, 2.0, "constant", v),
       "impact.e", 0.7, 0.85, "fine", level, "fall") for level in (0.005, 0.01, 0.015)),
]
#: search bounds of a case (default: the fit's): the stiff body's damping is resolved to
#: ~[0.01, 0.5] at 1% noise (its profile is flat across these narrower bounds)
BOUNDS = {"rigid-ish zeta": {"body.zeta": (0.05, 0.15)}}


def reference_history(scene: dict, t: np.ndarray) -> np.ndarray:
    """theta / alpha_ref at the times t [p t] of the scene's one point, from the scipy
    reference's dense output (each rocking phase's; 0 in full contact)."""
    sc, _ = load(scene)
    point = sc.point({a.name: a.values[0] for a in sc.axes})
    phases: list[tuple[float, float, object]] = []  # (t start, t stop, dense solution)
    rocking, contact = R._rocking, R._contact

    def rock(pb, t0, y0, s, t1, on):
        out = rocking(pb, t0, y0, s, t1, on)
        phases.append((t0, out[1], pb.last_sol))
        return out

    def still(pb, t0, y0, t1, on):
        out = contact(pb, t0, y0, t1, on)
        phases.append((t0, out[1], None))
        return out

    R._rocking, R._contact = rock, still
    try:
        R.reference_run(point, sc.single_numerics, early_exit=False)
    finally:
        R._rocking, R._contact = rocking, contact
    theta = np.zeros(t.size)
    for t0, t1, sol in phases:
        sel = (t >= t0) & (t <= t1)
        if sol is not None and sel.any():
            theta[sel] = sol.sol(t[sel])[0]
    return theta / point.body.alpha_ref


def fine_history(scene: dict, t: np.ndarray) -> np.ndarray:
    h = rocksweep.simulate(scene, {"numerics.accuracy": "fine"}).history
    tt, th, dth = (h[v].values for v in ("p_t", "theta_over_alpha", "theta_dot_over_alpha"))
    y = hermite(tt, th, dth, t)
    return np.where(t <= tt[-1], y, th[-1])


def measurement(make, truth: float, source: str, noise: float, seed: int):
    import pandas as pd

    scene = make(None if math.isnan(truth) else truth)
    span = rocksweep.simulate(scene, {"numerics.accuracy": "fine"}).history.p_t.values[-1]
    t = np.arange(0.0, span + 3.0, DT)
    y = (reference_history if source == "ref" else fine_history)(scene, t)
    rng = np.random.default_rng(seed)
    y = y + noise * np.abs(y).max() * rng.standard_normal(t.size)
    return pd.DataFrame({"p_t": t, "theta_over_alpha": y})


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    cases = CASES[::3] + [c for c in CASES if c[7] != "ok"] if args.quick else CASES
    print(f"{'case':<22} {'src':<4} {'noise':>5} {'key':<10} {'truth':>6} {'est':>7} "
          f"{'95% interval':>17} {'ratio':>6}  reason")
    good = within = ok = 0
    bad_said = []
    falls: list[bool] = []
    t_all = time.perf_counter()
    for i, (label, make, key, truth, start, src, noise, expect) in enumerate(cases):
        df = measurement(make, truth, src, noise, seed=100 + i)
        scene = make(start)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fit = rocksweep.calibrate(scene, df, [key], bounds=BOUNDS.get(label))
        one = fit.sel(parameter=key)
        est, lo, hi = float(one.estimate), float(one.lo), float(one.hi)
        reason = str(fit["reason"].item())
        n, dof = int(fit.attrs["n_peaks"]), int(fit["dof"])
        ratio = float(fit["misfit"]) * math.sqrt(n / max(dof, 1)) / float(fit["noise"])
        mark = ""
        if expect == "fall":
            inside = abs(est - truth) <= TOL[key]
            wrong = reason == "ok" and not inside
            falls.append(wrong)
            mark = "  <-- ok and beyond the target" if wrong else ""
        elif expect == "ok":
            good += 1
            inside = abs(est - truth) <= TOL[key] if key in TOL else True
            ok += reason == "ok"
            within += inside and reason == "ok"
            if reason != "ok" or not inside:
                mark = "  <-- " + ("not ok" if reason != "ok" else "beyond the target")
        else:
            said = expect in reason.split(",")
            bad_said.append(said)
            mark = "" if said else f"  <-- should say {expect}"
        print(f"{label:<22} {src:<4} {100 * noise:>4.1f}% {key.split('.')[1]:<10} "
              f"{truth:>6.3f} {est:>7.4f} [{lo:>7.4f}, {hi:>7.4f}] {ratio:>6.2f}  "
              f"{reason}{mark}")
    print(f"\ngood fits ok: {ok}/{good}; ok and within lam +-0.03, e +-0.02: "
          f"{within}/{good}; misfit/unidentifiable cases that say so: "
          f"{sum(bad_said)}/{len(bad_said)} (MISFIT_RATIO {C.MISFIT_RATIO:g}); "
          f"{time.perf_counter() - t_all:.0f} s")
    if falls:
        print(f"a body overturning after one impact: {sum(falls)}/{len(falls)} say ok with "
              "an estimate beyond the target")
    return 0


if __name__ == "__main__":
    sys.exit(main())
