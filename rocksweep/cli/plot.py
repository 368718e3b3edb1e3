"""``rocksweep plot``: the stability diagram of a sweep result (Figures 3 and 4), over any
two swept axes, or a line plot of a 1-D sweep; the figure of an analysis's file
(fragility, risk, efficiency ``-o .h5``)."""

from __future__ import annotations

from pathlib import Path

import click

import rocksweep
from rocksweep.cli.main import main, user_errors
from rocksweep.cli.options import dpi_option, overwrite_option
from rocksweep.figures import FORMATS
from rocksweep.vocab.kinds import SWEEP


@main.command()
@click.argument("result_path", metavar="OUT.h5", type=click.Path(path_type=Path))
@click.option("-o", "--output", "fig_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Figure file, .png, .pdf or .svg [default: OUT.png].")
@click.option("--x", "x_key", metavar="KEY",
              help="Swept axis along x, e.g. w_over_p or body.alpha_cg [default: w_over_p "
                   "when swept].")
@click.option("--y", "y_key", metavar="KEY",
              help="Swept axis along y [default: A_ratio when swept].")
@dpi_option
@click.option("--mu", "mu_map", is_flag=True,
              help="Draw the friction demand mu_required (a result with contact outputs) as "
                   "a contour map instead of the classes.")
@click.option("--regime", "regime_map", is_flag=True,
              help="Draw the contact regimes of a sliding base (a sweep with body.mu) "
                   "instead of the classes: the phases each run visited (rest, slide, rock, "
                   "slide-rock), overturned points marked, e.g. --x body.mu --y A_ratio.")
@overwrite_option
@click.option("--curves", is_flag=True,
              help="Overlay the boundary lines between classes, one colour per lam "
                   "(`rocksweep boundaries` gives them as CSV, with A_min).")
@click.option("--compare", "compare_key", metavar="KEY",
              help="Compare the values of a swept key on one diagram, e.g. impact.law: the "
                   "colour says which values overturn a cell, the mode 1 area per value in "
                   "each panel; with --curves each value's boundaries.")
@click.option("--show-computed", "show_computed", is_flag=True,
              help="Adaptive sweeps: shade the cells that were computed (the filled ones "
                   "stay clear); by default both are drawn alike.")
@user_errors
def plot(result_path: Path, fig_path: Path | None, x_key: str | None, y_key: str | None,
         dpi: int, overwrite: bool, curves: bool, show_computed: bool,
         mu_map: bool, compare_key: str | None, regime_map: bool) -> None:
    """Draw the stability diagram of a sweep: by default x = omega/p, y = A/(g tan
    alpha_cg); --x/--y pick any two swept axes. Mode 1 / mode 2 / safe regions, one panel
    per pulse shape and per other swept key, the growth of the mode 1 area with lam in
    shades of red. A sweep with one swept axis besides lam is drawn as max|theta|/alpha
    against it, markers by outcome. Cells an adaptive sweep filled are drawn as computed
    ones. With contact outputs and body.mu, the points that would slide are hatched (and
    those that would lift off dotted); --mu draws mu_required. A sweep with --check rings
    the points whose outcome changes at half the step. --compare KEY (e.g. impact.law)
    draws one diagram coloured by which of KEY's values overturn each cell. --regime draws
    the contact regimes of a sliding base (body.mu) over the two axes."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.figures.diagrams import missing_warnings
    from rocksweep.figures.style import save_figure
    from rocksweep.outputs import check_output
    from rocksweep.store.reader import as_result

    fig_out = fig_path if fig_path is not None else result_path.with_suffix(".png")
    # refuse a bad output before reading the result and drawing
    from rocksweep.store.reader import result_inputs

    inputs = result_inputs(result_path)  # the result and its records: never written over
    check_output(fig_out, overwrite=overwrite, inputs=inputs, suffixes=FORMATS)
    chosen = [o for o, v in (("--mu", mu_map), ("--regime", regime_map),
                             ("--compare", compare_key is not None)) if v]
    if len(chosen) > 1:
        raise click.ClickException(f"{chosen[0]} and {chosen[1]} draw different figures; "
                                   "give one")
    ds = rocksweep.open(result_path)  # a sweep, or an analysis's -o .h5 (its own figure)
    # lazy, not on --help: analysis.kinds (+0.1 ms)
    from rocksweep.analysis.kinds import dataset_kind

    if dataset_kind(ds) != SWEEP:
        fig = rocksweep.plot(ds)
        save_figure(fig, fig_out, dpi, overwrite=overwrite, inputs=inputs)
        click.echo(f"wrote {fig_out}")
        return
    fig = rocksweep.plot(ds, x_key, y_key, curves=curves, show_computed=show_computed,
                         mu=mu_map, compare=compare_key, regime=regime_map)
    save_figure(fig, fig_out, dpi, overwrite=overwrite, inputs=inputs)
    for w in missing_warnings(as_result(ds)):
        click.echo(f"warning: {w}", err=True)
    click.echo(f"wrote {fig_out}")
