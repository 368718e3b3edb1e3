"""``rocksweep simulate``: single runs with energy (Figure 5)."""

from __future__ import annotations

import csv
import json
import math
from itertools import product
from pathlib import Path

import click

from rocksweep.cli.main import load, main, scene_argument, set_option, user_errors

MAX_POINTS = 12  # simulate overlays a few runs; larger grids are for `rocksweep sweep`


@main.command()
@scene_argument
@set_option
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object (a JSON list if the scene has several points).")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Draw Figure 5 (theta/alpha_cg and E/E_ref against p*t) to this file.")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Write the time history to this CSV file.")
@user_errors
def simulate(scene_path: Path, overrides: tuple[str, ...], as_json: bool,
             plot_path: Path | None, csv_path: Path | None) -> None:
    """Run one point of SCENE.yaml (or each of up to 12 points) and report what happened.

    Prints the outcome (safe, mode1: overturns after impacts, mode2: overturns without
    impact), impacts, uplifts, max |theta|/alpha_cg, the overturning time p*t, the energy
    lost in impacts and in the damper, and the accuracy setting with its cost.
    """
    from rocksweep.run import simulate as run_point

    scene = load(scene_path, overrides)
    if scene.size > MAX_POINTS:
        big = max(scene.swept, key=lambda a: len(a.values))
        raise click.ClickException(
            f"{scene_path}: {scene.size} points; simulate runs at most {MAX_POINTS} "
            f"(use `rocksweep sweep`, or pick a value with --set {big.key}=VALUE)")
    names = [a.name for a in scene.axes]
    runs = []
    for combo in product(*(a.values for a in scene.axes)):
        runs.append(run_point(scene.point(dict(zip(names, combo, strict=True))),
                              scene.single_numerics))
    swept = [a.name for a in scene.swept]

    if as_json:
        docs = [_json_safe(r.summary()) for r in runs]
        click.echo(json.dumps(docs[0] if len(docs) == 1 else docs, indent=2))
    else:
        for r in runs:
            _print_run(r, swept)
    if csv_path is not None:
        _write_csv(runs, swept, csv_path)
    if plot_path is not None:
        from rocksweep.plots import time_history_figure

        time_history_figure(runs, swept, scene.name, plot_path)
        if not as_json:
            click.echo(f"wrote {plot_path}")


def _json_safe(d: dict) -> dict:
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
            for k, v in d.items()}


def _print_run(r, swept: list[str]) -> None:
    s = r.summary()
    p = r.point
    where = ", ".join(f"{k}={getattr(p, k, None) if hasattr(p, k) else getattr(p.body, k)}"
                      for k in swept)
    head = f"[{where}] " if where else ""
    t_over = "-" if s["t_overturn"] is None else f"{s['t_overturn']:.4f}"
    click.echo(f"{head}outcome: {s['outcome']}   impacts: {s['impacts']}   "
               f"uplifts: {s['uplifts']}   max|theta|/alpha_cg: "
               f"{s['theta_max_over_alpha']:.4f}   overturns at p*t: {t_over}")
    if "impact_loss_over_Eref" in s:
        click.echo(f"  energy/E_ref: input {s['work_in_over_Eref']:.4f}, lost in impacts "
                   f"{s['impact_loss_over_Eref']:.4f} (gained {s['impact_gain_over_Eref']:.4f}"
                   f" in {s['energy_gaining_impacts']} impacts), lost in damper "
                   f"{s['damper_loss_over_Eref']:.4f}, left {s['energy_end_over_Eref']:.4f}")
    status = ", ".join(s["status"]) or "-"
    click.echo(f"  status: {status}   ended at p*t = {s['t_end']:.4f}")
    click.echo(f"  accuracy: {s['accuracy']}; {s['steps']} RK4 steps + {s['event_steps']} "
               f"event re-integrations in {s['wall_time_s'] * 1e3:.2f} ms")


def _write_csv(runs, swept: list[str], path: Path) -> None:
    tmp = path.with_name(f".{path.name}.partial")
    cols = ["t", "theta", "theta_dot", "u", "u_dot", "phase", "E", "W_in", "D_damp",
            "E_impact", "xg"]
    with tmp.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", *swept, "p_t", "theta_over_alpha", "u_over_ucr", "E_over_Eref",
                    *cols])
        for i, r in enumerate(runs):
            h, body, p = r.history, r.point.body, r.point
            fixed = [getattr(p, k) if hasattr(p, k) else getattr(p.body, k) for k in swept]
            u_cr = body.u_cr if body.u_cr else math.nan
            for j in range(len(h["t"])):
                w.writerow([i, *fixed, repr(h["t"][j]), repr(h["theta"][j] / body.alpha_ref),
                            repr(h["u"][j] / u_cr), repr(h["E"][j] / body.E_ref),
                            *(repr(float(h[c][j])) for c in cols)])
    tmp.replace(path)
