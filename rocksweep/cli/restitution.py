"""``rocksweep restitution``: eq. (1) over lam and u/u_cr (Figure 2)."""

from __future__ import annotations

import json
from pathlib import Path

import click
import numpy as np

from rocksweep.cli.main import load, main, scene_argument, set_option, user_errors
from rocksweep.model import FlexibleBody, restitution, restitution_rigid


@main.command(name="restitution")
@scene_argument
@set_option
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Draw Figure 2 to this file.")
@click.option("--n-lam", default=101, show_default=True, type=click.IntRange(2, 100001),
              help="Number of lam values in [0, 1].")
@click.option("--n-u", default=81, show_default=True, type=click.IntRange(2, 100001),
              help="Number of u/u_cr values in [-2, 2].")
@user_errors
def restitution_cmd(scene_path: Path, overrides: tuple[str, ...], as_json: bool,
                    plot_path: Path | None, n_lam: int, n_u: int) -> None:
    """Coefficient of restitution e(lam, u/u_cr) of eq. (1) for the scene's body.

    Both transition directions: "upper" is the paper's upper sign (in rocksweep: rocking on
    the +b corner ends, u positive toward +b), "lower" the other.
    """
    scene = load(scene_path, overrides)
    body_axes = scene.body_axes()
    for a in body_axes:
        if len(a.values) != 1:
            raise click.ClickException(f"{a.key} has {len(a.values)} values: restitution "
                                       f"needs one body; pick one with --set {a.key}=VALUE")
    body = scene.make_body(**{a.name: a.values[0] for a in body_axes})
    lam = np.linspace(0.0, 1.0, n_lam)
    u_over_ucr = np.linspace(-2.0, 2.0, n_u)
    if isinstance(body, FlexibleBody) and not body.rigid:
        u = u_over_ucr * body.u_cr
        e_up = restitution(body, lam[:, None], u[None, :], upper=True)
        e_low = restitution(body, lam[:, None], u[None, :], upper=False)
    else:  # rigid: no lateral displacement, e depends on lam only
        e_up = np.repeat(restitution_rigid(body, lam)[:, None], n_u, axis=1)
        e_low = e_up.copy()
    e_housner = float(restitution_rigid(body, 0.0))
    if as_json:
        click.echo(json.dumps({"lam": lam.tolist(), "u_over_ucr": u_over_ucr.tolist(),
                               "e": {"upper": e_up.tolist(), "lower": e_low.tolist()},
                               "e_housner_rigid": e_housner}))
    else:
        i0 = 0
        j0 = int(np.argmin(abs(u_over_ucr)))
        click.echo(f"{scene.name}")
        click.echo(f"e at lam = 0, u = 0: {e_up[i0, j0]:.4f}  (Housner, same body rigid: "
                   f"{e_housner:.4f})")
        click.echo(f"e over lam in [0, 1], u/u_cr in [-2, 2]: min {e_up.min():.4f}, "
                   f"max {e_up.max():.4f}; e > 1 at {int((e_up > 1).sum())} of {e_up.size} "
                   "points (upper sign)")
    if plot_path is not None:
        from rocksweep.plots import restitution_figure

        restitution_figure(lam, u_over_ucr, e_up, e_housner, scene.name, plot_path)
        if not as_json:
            click.echo(f"wrote {plot_path}")
