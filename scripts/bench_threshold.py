"""The spring's steps near the uplift threshold (the spring-damping issue): classes and price of
the step rule before and after its damping bound, side by side in one run.

    python scripts/bench_threshold.py                  # all bodies, reference checks, figures
    python scripts/bench_threshold.py --bodies fig4a s20 --no-reference --no-figures

``before`` is the rule without the bound on RK4's numerical damping of the spring mode
(``spring_steps_before``: steps_per_period x max(1, (OMEGA_SPRING/omega_rock)^(2/5)) per
spring period); ``after`` is ``numerics.spring_steps`` as it stands. Both run at the
`default` preset (certification on), through ``compute.driver.sweep_arrays``.

1. The threshold band: A_ratio 0.9-1.4 (51) x w_over_p 0.15-1.2 (43) x lam 0, 0.4, 0.8
   (6579 points) on Figure 4's body (configs/fig4a.yaml, sine; fig4b.yaml, cosine), two
   stiffer damped bodies of other proportions (``BODIES``: wn/p = 20 and 50), three
   undamped ones (zeta = 0: wn/p 35, Figure 4's, 12) and a block (control: no spring, its
   steps must not move). Printed per body and rule:
   cells whose class differs from `fine`, how many of them are flagged (refined or uncertified), RK4
   evaluations per point; then (unless --no-reference) each differing cell run through
   the scipy reference (``physics.reference.reference_run``, rtol 1e-10, atol 1e-12):
   whether it agrees with `fine`'s class or the rule's ("ref f/r": counts; at most
   --ref-max cells, a random sample if more). w_rock is omega_rock/p, zeta_w the spring's
   physical decay rate while rocking, zeta' omega_rock [p] (``numerics.spring_decay``).
2. The four figures (19 200 points each) at `default`: RK4 evaluations per point
   (deterministic) and CPU time per point [core-us] (best of --rounds, the rounds
   alternating between the rules), with the ratio after/before, cells differing from
   `fine` (run with the rule `after`), and `fine`'s own RK4 evaluations per point under
   each rule (the bound scales with steps_per_period: `fine` pays the same factor).

3. (--wide) configs/wide-space.yaml at `default`: RK4 evaluations per point before and
   after, by zeta, CPU time per point, and how many outcomes changed.

Kernels are compiled and warm before any clock starts; start-up (imports, warm-up) is
printed apart from compute.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

T0 = time.perf_counter()
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the tree this script is in, not an installed copy

import numpy as np  # noqa: E402

import rocksweep.numerics as numerics  # noqa: E402
from rocksweep.compute.driver import sweep_arrays  # noqa: E402
from rocksweep.kernel import layout as L  # noqa: E402, N812
from rocksweep.physics.points import body_omega_rock, body_zeta_rock  # noqa: E402
from rocksweep.physics.reference import reference_run  # noqa: E402
from rocksweep.scene.parse import load_scene, parse_scene  # noqa: E402

FIGS = ("fig3a", "fig3b", "fig4a", "fig4b")
BAND = ["pulse.A_ratio={start: 0.9, stop: 1.4, num: 51}",
        "pulse.w_over_p={start: 0.15, stop: 1.2, num: 43}",
        "impact.lam=[0.0, 0.4, 0.8]"]
# name -> scene text (None: configs/NAME.yaml); the band's overrides replace its ranges.
BODIES: dict[str, str | None] = {
    "fig4a": None,
    "fig4b": None,
    "s20": """
name: stiff body wn/p 20, alpha_cg 0.25, heavy base, sine
body: {wn_over_p: 20, zeta: 0.05, alpha_cg: 0.25, alpha_A: 0.35, mA_over_m: 0.8, IA_ratio: 0.4}
impact: {lam: 0.0}
pulse: {shape: sine, w_over_p: 1, A_ratio: 1}
""",
    "s50": """
name: stiff body wn/p 50, alpha_cg 0.1, light base, low damping, cosine
body: {wn_over_p: 50, zeta: 0.02, alpha_cg: 0.1, alpha_A: 0.2, mA_over_m: 0.3, IA_ratio: 0.7}
impact: {lam: 0.0}
pulse: {shape: cosine, w_over_p: 1, A_ratio: 1}
""",
    "s35z": """
name: undamped stiff body wn/p 35 (zeta 0), alpha_cg 0.2, heavy base, sine
body: {wn_over_p: 35, zeta: 0.0, alpha_cg: 0.2, alpha_A: 0.3, mA_over_m: 1.5, IA_ratio: 0.5}
impact: {lam: 0.0}
pulse: {shape: sine, w_over_p: 1, A_ratio: 1}
""",
    "f4z": """
name: Figure 4's body undamped (zeta 0), cosine
body: {wn_over_p: 9.82, zeta: 0.0, alpha_cg: 0.15, alpha_A: 0.28, mA_over_m: 0.47, IA_ratio: 0.56}
impact: {lam: 0.0}
pulse: {shape: cosine, w_over_p: 1, A_ratio: 1}
""",
    "s12z": """
name: undamped body wn/p 12, alpha_cg 0.3, cosine
body: {wn_over_p: 12, zeta: 0.0, alpha_cg: 0.3, alpha_A: 0.4, mA_over_m: 0.8, IA_ratio: 0.6}
impact: {lam: 0.0}
pulse: {shape: cosine, w_over_p: 1, A_ratio: 1}
""",
    "block": """
name: block alpha 0.15 (control)
body: {kind: block, alpha: 0.15}
impact: {lam: 0.0}
pulse: {shape: sine, w_over_p: 1, A_ratio: 1}
""",
}
RULES = ("before", "after")
FLAGS = L.STATUS_REFINED | L.STATUS_UNCERTIFIED | L.STATUS_FLAGGED


def spring_steps_before(omega_rock, steps_per_period, zeta_rock=0.0):
    """The spring's steps before the damping bound: steps_per_period x
    max(1, (OMEGA_SPRING/omega_rock)^(2/5))."""
    with np.errstate(divide="ignore"):
        return steps_per_period * np.maximum(
            1.0, (numerics.OMEGA_SPRING / np.asarray(omega_rock, float)) ** 0.4)


class rule:  # noqa: N801 (a context, used as `with rule(name):`)
    """The spring's step rule `before` the damping bound or `after` (as it stands):
    ``numerics.step_sizes`` looks ``spring_steps`` up at each call."""

    def __init__(self, name: str) -> None:
        self.steps = spring_steps_before if name == "before" else numerics.spring_steps

    def __enter__(self) -> None:
        self.saved = numerics.spring_steps
        numerics.spring_steps = self.steps

    def __exit__(self, *exc) -> None:
        numerics.spring_steps = self.saved


def scene(name: str, overrides: list[str]):
    text = BODIES.get(name)
    if text is None:
        return load_scene(ROOT / "configs" / f"{name}.yaml", overrides)
    return parse_scene(text, source=name, overrides=overrides)


def evals(a: dict) -> float:
    return float((a["steps"] + a["event_steps"]).mean())


def point_of(sc, index: tuple):
    vals = {ax.name: ax.values[0] for ax in sc.axes}
    vals.update({ax.name: ax.values[k] for ax, k in zip(sc.swept, index, strict=True)})
    return sc.point(vals), {ax.name: ax.values[k] for ax, k in zip(sc.swept, index,
                                                                    strict=True)}


def band(names: list[str], reference: bool, ref_max: int) -> None:
    print("1. threshold band: A_ratio 0.9-1.4 x w_over_p 0.15-1.2 x lam 0/0.4/0.8 "
          "(6579 points), `default` against `fine`")
    print(f"{'body':<7}{'w_rock':>9}{'zeta_w':>8}{'rule':>8}{'spring x':>9}{'differ':>7}"
          f"{'flagged':>8}{'evals/pt':>10}{'ratio':>7}{'ref f/r':>12}{'s':>6}")
    for name in names:
        sc_fine = scene(name, BAND + ["numerics.accuracy=fine"])
        fine, _ = sweep_arrays(sc_fine, jobs=2)
        sc = scene(name, BAND)
        body = sc.point({ax.name: ax.values[0] for ax in sc.axes}).body
        w, zr = body_omega_rock(body), body_zeta_rock(body)
        e0 = None
        refs: dict[tuple, int] = {}  # the reference's class per differing cell
        for r in RULES:
            t = time.perf_counter()
            with rule(r):
                a, _ = sweep_arrays(sc, jobs=2)
                factor = float(numerics.spring_steps(w, 5, zr) / 5) if w else math.nan
            diff = a["outcome"] != fine["outcome"]
            flagged = int(np.sum((a["status"][diff].astype(np.int64) & FLAGS) != 0))
            e = evals(a)
            e0 = e if e0 is None else e0
            agree_fine = agree_rule = "-"
            if reference and diff.any():
                agree_fine = agree_rule = 0
                cells = np.argwhere(diff)
                cells = cells[np.random.default_rng(0).permutation(len(cells))[:ref_max]]
                for i in cells:
                    if tuple(i) not in refs:
                        pt, _ = point_of(sc, tuple(i))
                        refs[tuple(i)] = reference_run(pt, sc.numerics, rtol=1e-10,
                                                       atol=1e-12)["outcome"]
                    ref = refs[tuple(i)]
                    agree_fine += int(ref == fine["outcome"][tuple(i)])
                    agree_rule += int(ref == a["outcome"][tuple(i)])
            checked = f"{agree_fine}/{agree_rule}" if agree_fine != "-" else "-"
            print(f"{name:<7}{w:>9.2f}{zr * w:>8.2f}{r:>8}{factor:>9.3f}{int(diff.sum()):>7}"
                  f"{flagged:>8}{e:>10.1f}{e / e0:>7.3f}{checked:>12}"
                  f"{time.perf_counter() - t:>6.1f}", flush=True)


def timed_rules(sc, rounds: int) -> tuple[dict, dict]:
    """Each rule's sweep of ``sc`` on one worker, alternating, ``rounds`` times: (arrays,
    best CPU seconds) per rule."""
    res, best = {}, {r: math.inf for r in RULES}
    for _ in range(rounds):
        for r in RULES:
            with rule(r):
                c0 = time.process_time()
                res[r], _ = sweep_arrays(sc, jobs=1)
                best[r] = min(best[r], time.process_time() - c0)
    return res, best


def figures(rounds: int) -> None:
    print(f"\n2. the four figures at `default` (19 200 points each), CPU time best of {rounds}")
    print(f"{'scene':<7}{'rule':>8}{'differ':>7}{'evals/pt':>10}{'ratio':>7}{'core-us/pt':>11}"
          f"{'ratio':>7}{'fine evals/pt':>14}")
    tot = {r: 0.0 for r in RULES}
    for fig in FIGS:
        sc_fine = load_scene(ROOT / "configs" / f"{fig}.yaml", ["numerics.accuracy=fine"])
        fine_evals = {}
        for r in RULES:
            with rule(r):
                fine, _ = sweep_arrays(sc_fine, jobs=2)  # the last: `after`, compared with
            fine_evals[r] = evals(fine)
        sc = load_scene(ROOT / "configs" / f"{fig}.yaml")
        res, best = timed_rules(sc, rounds)
        n = sc.size
        for r in RULES:
            e = evals(res[r])
            tot[r] += e
            d = int(np.sum(res[r]["outcome"] != fine["outcome"]))
            print(f"{fig:<7}{r:>8}{d:>7}{e:>10.1f}{e / evals(res['before']):>7.3f}"
                  f"{1e6 * best[r] / n:>11.2f}{best[r] / best['before']:>7.3f}"
                  f"{fine_evals[r]:>14.1f}", flush=True)
    print(f"four figures: RK4 evaluations after/before {tot['after'] / tot['before']:.3f}")


def wide(rounds: int) -> None:
    """configs/wide-space.yaml (48 384 points) at `default`: RK4 evaluations per point
    before and after, by zeta, CPU time, and the outcomes that changed."""
    sc = load_scene(ROOT / "configs" / "wide-space.yaml")
    zi = [ax.name for ax in sc.swept].index("zeta")
    zetas = sc.axis("zeta").values
    print(f"\n3. configs/wide-space.yaml at `default` ({sc.size} points), CPU time best of "
          f"{rounds}")
    res, best = timed_rules(sc, rounds)
    for r in RULES:
        e = res[r]["steps"] + res[r]["event_steps"]
        by = ", ".join(f"zeta {z:g}: {np.take(e, [k], axis=zi).mean():.0f}"
                       for k, z in enumerate(zetas))
        print(f"{r:>8} evals/pt {e.mean():.0f} ({by}); core-us/pt "
              f"{1e6 * best[r] / sc.size:.1f}")
    changed = int(np.sum(res["before"]["outcome"] != res["after"]["outcome"]))
    print(f"outcomes changed: {changed} of {sc.size}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bodies", nargs="*", default=list(BODIES))
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--no-reference", dest="reference", action="store_false")
    ap.add_argument("--ref-max", type=int, default=12,
                    help="differing cells per body and rule run through the reference "
                         "(a random sample, seed 0, if more)")
    ap.add_argument("--no-figures", dest="figures", action="store_false")
    ap.add_argument("--wide", action="store_true",
                    help="also configs/wide-space.yaml before and after (~1 min a round)")
    args = ap.parse_args()
    t_import = time.perf_counter() - T0
    t = time.perf_counter()
    for name in args.bodies:  # compile/load every kernel the runs use before any clock
        sweep_arrays(scene(name, ["pulse.A_ratio=1.0", "pulse.w_over_p=1.0",
                                  "impact.lam=0.0"]), jobs=1)
    for fig in FIGS if args.figures else ():
        sweep_arrays(load_scene(ROOT / "configs" / f"{fig}.yaml",
                                ["pulse.A_ratio=1.0", "pulse.w_over_p=1.0"]), jobs=1)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; start-up: "
          f"imports {t_import:.2f} s, kernel warm-up {time.perf_counter() - t:.2f} s; "
          f"spring decay bound at 5 steps per period: min({numerics.SPRING_DECAY}, "
          f"{numerics.SPRING_DECAY_FREE} + {numerics.SPRING_DECAY_REL:.4f} zeta_w) p\n")
    band(args.bodies, args.reference, args.ref_max)
    if args.figures:
        figures(args.rounds)
    if args.wide:
        wide(1)


if __name__ == "__main__":
    main()
