"""The step rule and the certification of close calls: accuracy and price on the
four figures, side by side in one run.

    python scripts/bench_step_rule.py                 # the four figures, 3 rounds
    python scripts/bench_step_rule.py --rounds 5 fig3a

For each figure (configs/fig3a.yaml, fig3b, fig4a, fig4b; 19 200 points each) three
settings run through the same sweep dispatch (``compute.sweep.run_rows``) in one process:

- ``today``: the step rule before the current one, set explicitly: one step per point, the
  shortest of the spring period while rocking, the pulse period, 2 pi and the pulse's
  rocking scale over 5 steps (``legacy_rows``), event_tol 1e-6, rotation_step 0.25, no
  certification;
- ``default``: the `default` preset (the step follows what acts: ``numerics.step_sizes``;
  close calls re-run finer: ``compute.certify``);
- ``fine``: the `fine` preset, the outcomes both are compared with.

Printed per figure and setting: cells whose outcome differs from `fine` (and the share
equal), points refined, RK4 evaluations per point (regular + event; deterministic), and
the CPU time per point [us] (best of ``--rounds`` rounds, the rounds alternating between
the settings so that the machine's load hits them alike), with the ratio to ``today``.
Kernels are compiled and warm before the clock starts; no start-up is included.

Then what the step rule saves where the pulse is short: the figures' points with
omega/p >= 3 and a held-out-style block scene (alpha 0.25, omega/p 4-12) run with the new
steps, and with the same steps but the pulse's step kept after the pulse ends
(``dt = dt_on``): the evaluations and time the relief after the pulse saves.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import time
from pathlib import Path

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import numpy as np

from rocksweep.compute.sweep import level, run_rows
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel import warm_up
from rocksweep.numerics import Numerics, amplitude_frequency
from rocksweep.physics.points import body_omega_rock
from rocksweep.scene.grid import Grid
from rocksweep.scene.parse import load_scene, parse_scene

ROOT = Path(__file__).resolve().parents[1]
FIGS = ("fig3a", "fig3b", "fig4a", "fig4b")
BLOCK = """
name: short pulses on a block
body: {kind: block, alpha: 0.25}
impact: {lam: 0.0}
pulse: {shape: [sine, cosine], w_over_p: {start: 4, stop: 12, num: 40},
        A_ratio: {start: 0.3, stop: 30, num: 150}}
"""


def legacy_rows(scene, rows: np.ndarray) -> np.ndarray:
    """The rows of today's step rule (before the current one) at 5 steps per period: one step
    min(2 pi/omega_rock, 2 pi/omega, 2 pi, 2 pi/omega_amp)/5 for the whole run, the step
    cap from it (20 x t_end/dt + 200 x max_events), certification off (PAR_CLOSE 0)."""
    out = rows.copy()
    body = scene.point({a.name: a.values[0] for a in scene.axes}).body
    w_rock = body_omega_rock(body)
    two_pi = 2 * math.pi
    omega = rows[:, L.PAR_OMEGA]
    a_ratio = rows[:, L.PAR_AMP] / (9.81 * np.tan(rows[:, L.PAR_ALPHA_REF]))
    w_amp = amplitude_frequency(a_ratio, rows[:, L.PAR_ALPHA_REF])
    with np.errstate(divide="ignore"):
        period = np.minimum.reduce([np.full(len(rows), two_pi / w_rock if w_rock else np.inf),
                                    two_pi / omega, np.full(len(rows), two_pi),
                                    two_pi / w_amp])
    dt = period / 5
    out[:, L.PAR_DT] = dt
    out[:, L.PAR_DT_ON] = dt
    out[:, L.PAR_MAXSTEPS] = 20 * np.ceil(rows[:, L.PAR_TEND] / dt) + 200 * 5000
    out[:, L.PAR_CLOSE] = 0.0
    return out


def settings(scene):
    """name -> (scene with those numerics, its rows, its chunk rows)."""
    out = {}
    for name, num in (("today", Numerics.preset("default", refine=0)),
                      ("default", Numerics.preset("default")),
                      ("fine", Numerics.preset("fine"))):
        sc = dataclasses.replace(scene, numerics=num)
        grid = Grid(sc)
        cr = grid.rows(0, grid.size)
        rows = legacy_rows(sc, cr.rows) if name == "today" else cr.rows
        out[name] = (sc, rows, cr)
    return out


def timed(runs: dict, rounds: int) -> tuple[dict, dict]:
    """Results and best CPU seconds of each setting, the rounds alternating."""
    best = {k: math.inf for k in runs}
    res = {}
    for _ in range(rounds):
        for name, (sc, rows, cr) in runs.items():
            c0 = time.process_time()
            res[name] = run_rows(cr, rows, level(sc), sc)
            best[name] = min(best[name], time.process_time() - c0)
    return res, best


def evals(outs: np.ndarray) -> np.ndarray:
    return outs[:, L.OUT_STEPS] + outs[:, L.OUT_EVENT_STEPS]


def figures(names: list[str], rounds: int) -> None:
    print(f"{'scene':<8}{'setting':<9}{'differ':>7}{'equal %':>10}{'refined':>9}"
          f"{'evals/pt':>10}{'ratio':>7}{'us/pt':>8}{'ratio':>7}")
    for fig in names:
        scene = load_scene(ROOT / "configs" / f"{fig}.yaml")
        runs = settings(scene)
        for kind in Grid(scene).kinds():
            warm_up(int(kind), level(scene), scene.ground)
        res, best = timed(runs, rounds)
        n = res["fine"].shape[0]
        ref = res["fine"][:, L.OUT_OUTCOME]
        e0, t0 = evals(res["today"]).mean(), best["today"]
        for name, outs in res.items():
            d = int(np.sum(outs[:, L.OUT_OUTCOME] != ref))
            refined = int(np.sum((outs[:, L.OUT_STATUS].astype(np.int64)
                                  & L.STATUS_REFINED) != 0))
            e = evals(outs).mean()
            print(f"{fig:<8}{name:<9}{d:>7}{100 * (1 - d / n):>10.3f}{refined:>9}{e:>10.1f}"
                  f"{e / e0:>7.3f}{1e6 * best[name] / n:>8.2f}{best[name] / t0:>7.3f}")


def saving(names: list[str], rounds: int) -> None:
    """Evaluations and time of the new steps against the same steps with the pulse's step
    kept after the pulse, on short pulses (certification off: the steps alone)."""
    print("\nwhat the relief after the pulse saves (short pulses; certification off)")
    print(f"{'scene':<22}{'points':>8}{'evals kept':>12}{'evals new':>11}{'saved %':>9}"
          f"{'us kept':>9}{'us new':>8}")
    scenes = [(f"{f} w/p>=3", load_scene(ROOT / "configs" / f"{f}.yaml")) for f in names]
    scenes.append(("block w/p 4-12", parse_scene(BLOCK)))
    for label, scene in scenes:
        sc = dataclasses.replace(scene, numerics=Numerics.preset("default", refine=0))
        grid = Grid(sc)
        cr = grid.rows(0, grid.size)
        keep = cr.rows[:, L.PAR_OMEGA] >= 3.0
        cr = dataclasses.replace(cr, rows=cr.rows[keep], kinds=cr.kinds[keep],
                                 alpha_ref=cr.alpha_ref[keep], E_ref=cr.E_ref[keep])
        kept = cr.rows.copy()
        kept[:, L.PAR_DT] = kept[:, L.PAR_DT_ON]
        kept[:, L.PAR_MAXSTEPS] = 20 * np.ceil(kept[:, L.PAR_TEND] / kept[:, L.PAR_DT]) + 1e6
        for kind in np.unique(cr.kinds):
            warm_up(int(kind), level(sc), sc.ground)
        res, best = timed({"kept": (sc, kept, cr), "new": (sc, cr.rows, cr)}, rounds)
        ek, en = evals(res["kept"]).mean(), evals(res["new"]).mean()
        n = len(cr.rows)
        print(f"{label:<22}{n:>8}{ek:>12.1f}{en:>11.1f}{100 * (1 - en / ek):>9.1f}"
              f"{1e6 * best['kept'] / n:>9.2f}{1e6 * best['new'] / n:>8.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("figures", nargs="*", default=list(FIGS))
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; CPU time, "
          f"best of {args.rounds} rounds")
    figures(args.figures, args.rounds)
    saving(args.figures, args.rounds)


if __name__ == "__main__":
    main()
