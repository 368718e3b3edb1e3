"""``rocksweep restitution``: eq. (1) over lam and u/u_cr (Figure 2); the table is
``rocksweep.analysis.restitution.restitution_table``."""

from __future__ import annotations

import json
import math
from pathlib import Path

import click

from rocksweep.cli.main import load, main, user_errors
from rocksweep.cli.options import json_option, overwrite_option, scene_argument, set_option
from rocksweep.figures import FORMATS
from rocksweep.vocab.laws import CONSTANT, LAWS, LOCKED, law_origin


@main.command(name="restitution")
@scene_argument
@set_option
@json_option("one object")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Draw Figure 2 to this file (.png, .pdf, .svg).")
@overwrite_option
@click.option("--n-lam", default=101, show_default=True, type=click.IntRange(2, 100001),
              help="Number of lam values in [0, 1].")
@click.option("--n-u", default=81, show_default=True, type=click.IntRange(2, 100001),
              help="Number of u/u_cr values in [-2, 2].")
@click.option("--law", type=click.Choice(LAWS),
              help="Impact law (as --set impact.law=LAW) [default: the scene's, else "
                   "vertical: eq. (1)]; constant takes its e from impact.e.")
@user_errors
def restitution_cmd(scene_path: Path, overrides: tuple[str, ...], as_json: bool,
                    plot_path: Path | None, overwrite: bool, n_lam: int, n_u: int,
                    law: str | None) -> None:
    """Coefficient of restitution e(lam, u/u_cr) of eq. (1), or of the impact law, for the
    scene's body, and for each u/u_cr the largest lam at which an impact cannot gain
    energy (the paper: such lam "need to be avoided").

    Both transition directions: "upper" is the paper's upper sign (in rocksweep: rocking on
    the +b corner ends, u positive toward +b), "lower" the other.
    """
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.analysis.restitution import restitution_table
    from rocksweep.outputs import check_output

    if law is not None:  # e belongs to law constant alone
        given_e = [o for o in overrides if o.split("=", 1)[0].strip() == "impact.e"]
        if law != CONSTANT and given_e:
            raise click.ClickException(
                f"--set {given_e[-1]}: e is the constant law's coefficient; --law {law} "
                "computes e from the body (eq. (1)) and would ignore it: remove it, or use "
                "--law constant")
        overrides = (*overrides, f"impact.law={law}",
                     *(("impact.e=null",) if law != CONSTANT else ()))
    scene = load(scene_path, overrides)
    if plot_path is not None:  # the scene file, its records: never written over
        check_output(plot_path, overwrite=overwrite, inputs=scene.inputs, suffixes=FORMATS)
    table = restitution_table(scene, n_lam, n_u)
    if as_json:
        click.echo(json.dumps(table.as_dict()))
    else:
        e = table.e_upper
        click.echo(table.title)
        what = law_origin(table.law, table.e)
        factor = f", e_factor {table.e_factor:g}" if table.e_factor != 1.0 else ""
        click.echo(f"impact law: {table.law} ({what}{factor})")
        click.echo(f"e at lam = 0, u = 0: {table.e_at_rest:.4f}  (Housner, same body rigid: "
                   f"{table.e_housner:.4f})")
        click.echo(f"e over lam in [0, 1], u/u_cr in [-2, 2]: min {e.min():.4f}, "
                   f"max {e.max():.4f}; e > 1 at {int((e > 1).sum())} of {e.size} "
                   "points (upper sign)")
        click.echo("largest lam at which an impact cannot gain energy (upper sign"
                   + (", u' = 0" if table.law == LOCKED else "") + "):")
        u = table.u_over_ucr
        picks = [int(i) for i in dict.fromkeys(
            int(abs(u - v).argmin()) for v in (-2.0, -1.0, 0.0, 1.0, 2.0))]
        click.echo("  " + "   ".join(f"u/u_cr {u[i]:g}: {_lam_text(table.lam_limit[i])}"
                                     for i in picks))
        lim = table.lam_limit
        worst = ("every lam gains" if any(math.isnan(v) for v in lim.tolist())
                 else _lam_text(float(lim.min())))
        click.echo(f"  over u/u_cr in [-2, 2]: {worst}")
    if plot_path is not None:
        # lazy, not on --help: matplotlib (+0.4 s)
        from rocksweep.figures.restitution import restitution_map
        from rocksweep.figures.style import save_figure

        fig = restitution_map(table.lam, table.u_over_ucr, table.e_upper, table.e_housner,
                              table.title, lam_limit=table.lam_limit, law=table.law)
        save_figure(fig, plot_path, overwrite=overwrite, inputs=scene.inputs)
        if not as_json:
            click.echo(f"wrote {plot_path}")


def _lam_text(v: float) -> str:
    if math.isnan(v):
        return "none (every lam gains)"
    return "none up to 2" if v >= 2.0 else f"{v:.4f}"
