"""``rocksweep restitution``: eq. (1) over lam and u/u_cr (Figure 2); the table is
``rocksweep.analysis.restitution.restitution_table``."""

from __future__ import annotations

import json
from pathlib import Path

import click

from rocksweep.cli.main import (
    load,
    main,
    overwrite_option,
    scene_argument,
    set_option,
    user_errors,
)


@main.command(name="restitution")
@scene_argument
@set_option
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Draw Figure 2 to this file (.png, .pdf, .svg).")
@overwrite_option
@click.option("--n-lam", default=101, show_default=True, type=click.IntRange(2, 100001),
              help="Number of lam values in [0, 1].")
@click.option("--n-u", default=81, show_default=True, type=click.IntRange(2, 100001),
              help="Number of u/u_cr values in [-2, 2].")
@user_errors
def restitution_cmd(scene_path: Path, overrides: tuple[str, ...], as_json: bool,
                    plot_path: Path | None, overwrite: bool, n_lam: int, n_u: int) -> None:
    """Coefficient of restitution e(lam, u/u_cr) of eq. (1) for the scene's body.

    Both transition directions: "upper" is the paper's upper sign (in rocksweep: rocking on
    the +b corner ends, u positive toward +b), "lower" the other.
    """
    from rocksweep.analysis.restitution import restitution_table
    from rocksweep.outputs import check_output

    if plot_path is not None:
        from rocksweep.figures.common import FORMATS

        check_output(plot_path, overwrite=overwrite, inputs=[scene_path], suffixes=FORMATS)
    table = restitution_table(load(scene_path, overrides), n_lam, n_u)
    if as_json:
        click.echo(json.dumps(table.as_dict()))
    else:
        e = table.e_upper
        click.echo(table.title)
        click.echo(f"e at lam = 0, u = 0: {table.e_at_rest:.4f}  (Housner, same body rigid: "
                   f"{table.e_housner:.4f})")
        click.echo(f"e over lam in [0, 1], u/u_cr in [-2, 2]: min {e.min():.4f}, "
                   f"max {e.max():.4f}; e > 1 at {int((e > 1).sum())} of {e.size} "
                   "points (upper sign)")
    if plot_path is not None:
        from rocksweep.figures.common import restitution_map, save_figure

        fig = restitution_map(table.lam, table.u_over_ucr, table.e_upper, table.e_housner,
                              table.title)
        save_figure(fig, plot_path, overwrite=overwrite, inputs=[scene_path])
        if not as_json:
            click.echo(f"wrote {plot_path}")
