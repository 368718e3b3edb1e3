"""``rocksweep simulate``: single runs with energy (Figure 5); the runs come from
``rocksweep.compute.history.run_points``, the CSV from its ``write_history_csv``."""

from __future__ import annotations

import json
import math
from pathlib import Path

import click

from rocksweep.cli.helpers import prepare_point_kernel
from rocksweep.cli.main import load, main, said, user_errors
from rocksweep.cli.options import json_option, overwrite_option, scene_argument, set_option
from rocksweep.errors import SceneError
from rocksweep.figures import FORMATS
from rocksweep.vocab.axes import alpha_symbol

MAX_POINTS = 12  # = rocksweep.compute.history.MAX_RUNS: simulate overlays a few runs


@main.command()
@scene_argument
@set_option
@json_option("one object (a list if the scene has several points)")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Draw Figure 5 (theta/alpha_cg and E/E_ref against p*t) to this file "
                   "(.png, .pdf, .svg).")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Write the time history to this CSV file (columns: run, the swept keys, "
                   "p_t, theta_over_alpha, u_over_ucr, E_over_Eref, ...).")
@click.option("--contact", is_flag=True,
              help="Report the friction demand, the smallest normal force and the impulse "
                   "ratio (as outputs.contact: true).")
@overwrite_option
@user_errors
def simulate(scene_path: Path, overrides: tuple[str, ...], as_json: bool,
             plot_path: Path | None, csv_path: Path | None, contact: bool,
             overwrite: bool) -> None:
    """Run one point of SCENE.yaml (or each of up to 12 points) and report what happened.

    Prints the outcome (safe, mode1: overturns after impacts, mode2: overturns without
    impact), impacts, uplifts, max |theta|/alpha_cg, the overturning time p*t, the energy
    lost in impacts and in the damper, and the accuracy setting with its cost.
    """
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.compute.history import run_points, write_history_csv
    from rocksweep.outputs import check_distinct, check_output

    check_distinct({"--plot": plot_path, "--csv": csv_path})  # by resolved path
    if contact:
        overrides = (*overrides, "outputs.contact=true")
    scene = load(scene_path, overrides)
    # the scene file, its record: never written over
    if plot_path is not None:
        check_output(plot_path, overwrite=overwrite, inputs=scene.inputs, suffixes=FORMATS)
    if csv_path is not None:
        check_output(csv_path, overwrite=overwrite, inputs=scene.inputs)

    if scene.size <= MAX_POINTS:  # said when it compiles (once per machine)
        prepare_point_kernel(scene)
    try:
        runs = run_points(scene, MAX_POINTS)
    except SceneError as err:  # name the file, as scene errors do
        raise click.ClickException(f"{scene_path}: {said(err)}") from None
    swept = [a.name for a in scene.swept]

    if as_json:
        docs = [_json_safe({**r.summary(), **scene.physical_summary(),
                            **scene.floor_summary(r.point)}) for r in runs]
        click.echo(json.dumps(docs[0] if len(docs) == 1 else docs, indent=2))
    else:
        if scene.physical is not None:
            click.echo(scene.physical_words())
        for r in runs:
            _print_run(r, swept)
    if csv_path is not None:
        write_history_csv(runs, swept, csv_path, overwrite=overwrite)
        if not as_json:
            click.echo(f"wrote {csv_path}")
    if plot_path is not None:
        # lazy, not on --help: numba, matplotlib (+0.6 s)
        from rocksweep.figures.history import time_history
        from rocksweep.figures.style import save_figure

        save_figure(time_history(runs, swept, scene.name), plot_path, overwrite=overwrite,
                    inputs=scene.inputs)
        if not as_json:
            click.echo(f"wrote {plot_path}")


def _json_safe(d: dict) -> dict:
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
            for k, v in d.items()}


def _print_run(r, swept: list[str]) -> None:
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.compute.history import swept_values

    s = r.summary()
    where = ", ".join(f"{k}={v}" for k, v in zip(swept, swept_values(r, swept), strict=True))
    head = f"[{where}] " if where else ""
    t_over = "-" if s["t_overturn"] is None else f"{s['t_overturn']:.4f}"
    alpha = alpha_symbol(getattr(r.point.body, "kind", "flexible"))
    click.echo(f"{head}outcome: {s['outcome']}   impacts: {s['impacts']}   "
               f"uplifts: {s['uplifts']}   max|theta|/{alpha}: "
               f"{s['theta_max_over_alpha']:.4f}   overturns at p*t: {t_over}")
    if "impact_loss_over_Eref" in s:
        click.echo(f"  energy/E_ref: input {s['work_in_over_Eref']:.4f}, lost in impacts "
                   f"{s['impact_loss_over_Eref']:.4f} (gained {s['impact_gain_over_Eref']:.4f}"
                   f" in {s['energy_gaining_impacts']} impacts), lost in damper "
                   f"{s['damper_loss_over_Eref']:.4f}, left {s['energy_end_over_Eref']:.4f}")
    if "friction_loss_over_Eref" in s:
        click.echo(f"  friction: lost {s['friction_loss_over_Eref']:.4f} E_ref")
    if "slide_max" in s:
        click.echo(f"  sliding: max |x|/b {s['slide_max']:.4f}, final |x|/b "
                   f"{s['slide_final']:.4f}, phases {' > '.join(s['phases'])}")
    if "mu_required" in s:
        mu = "inf" if s["mu_required"] is None else f"{s['mu_required']:.4f}"
        click.echo(f"  contact: mu_required {mu}, min N/(M g) {s['normal_min_over_Mg']:.4f},"
                   f" max impulse ratio {s['impulse_ratio_max']:.4f}")
    status = ", ".join(s["status"]) or "-"
    click.echo(f"  status: {status}   ended at p*t = {s['t_end']:.4f}")
    click.echo(f"  accuracy: {s['accuracy']}; {s['steps']} RK4 steps + {s['event_steps']} "
               f"event re-integrations in {s['wall_time_s'] * 1e3:.2f} ms")
