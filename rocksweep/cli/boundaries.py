"""``rocksweep boundaries``: the A_min curves (bisected) and the boundary lines of a sweep
result, as CSV or HDF5 and as a figure (the library side is ``rocksweep.analysis.boundaries``)."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import click

from rocksweep.cli.main import main, user_errors
from rocksweep.cli.options import dpi_option, overwrite_option, rtol_option, search_option
from rocksweep.figures import FORMATS


@main.command()
@click.argument("result_path", metavar="OUT.h5", type=click.Path(path_type=Path))
@click.option("-o", "--output", "csv_path", type=click.Path(dir_okay=False, path_type=Path),
              help="A_min curves as CSV (.csv), or as HDF5 (.h5, .hdf5) with the boundary "
                   "lines too [default: OUT-amin.csv].")
@click.option("--lines", "lines_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Also write the boundary polylines as CSV (one row per vertex).")
@rtol_option()
@search_option
@click.option("--mode", type=click.Choice(["1", "2"]), default=None,
              help="A_min of this overturning mode only [default: either].")
@click.option("--plot", "fig_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Figure of the A_min curves of every lam (and shape) on one axis, "
                   ".png, .pdf or .svg.")
@dpi_option
@overwrite_option
@user_errors
def boundaries(result_path: Path, csv_path: Path | None, lines_path: Path | None,
               rtol: float, search: bool, mode: str | None, fig_path: Path | None,
               dpi: int, overwrite: bool) -> None:
    """The boundaries of the stability diagram of a sweep result (over omega/p and
    A/(g tan alpha)), for each lam and pulse shape: A_min(omega/p), the smallest amplitude
    that overturns, to --rtol whatever the grid's spacing (a search below the first
    overturning grid value, near the uplift threshold and where the response came close,
    then a bisection; kernel runs at the sweep's accuracy), with the mode it overturns in
    and how it was found (column method); and the lines between classes as polylines.
    Works on adaptive and regular results."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.analysis import boundaries as bd
    from rocksweep.analysis.files import csv_text, write_curves_h5
    from rocksweep.figures.style import save_figure
    from rocksweep.outputs import check_distinct, check_output, write_atomic
    from rocksweep.store.reader import read_result

    out = csv_path if csv_path is not None else result_path.with_name(
        result_path.stem + "-amin.csv")
    h5 = out.suffix.lower() in (".h5", ".hdf5")
    if out.suffix.lower() not in bd.CURVE_SUFFIXES:
        raise click.ClickException(
            f"-o {out}: unsupported suffix {out.suffix or '(none)'!r}; use "
            f"{', '.join(bd.CURVE_SUFFIXES[:-1])} or {bd.CURVE_SUFFIXES[-1]}")
    # refuse bad outputs before any kernel run
    from rocksweep.store.reader import result_inputs

    inputs = result_inputs(result_path)  # the result and its records: never written over
    check_distinct({"-o": out, "--lines": lines_path, "--plot": fig_path})
    check_output(out, overwrite=overwrite, inputs=inputs)
    if lines_path is not None:
        check_output(lines_path, overwrite=overwrite, inputs=inputs)
    if fig_path is not None:
        check_output(fig_path, overwrite=overwrite, inputs=inputs, suffixes=FORMATS)
    result = read_result(result_path, list(bd.RESPONSE))
    curves, bounds = bd.result_curves(result, rtol, None if mode is None else int(mode),
                                      search=search)

    def write_text(text: str):
        return lambda tmp: tmp.write_text(text)

    rows = bd.a_min_rows(curves)
    runs = int(sum(int(c.runs.sum()) for c in curves))
    if h5:
        attrs = {"source": str(result_path), "rtol": rtol, "search": int(search),
                 "mode": "any" if mode is None else f"mode{mode}"}
        write_atomic(out, lambda tmp: write_curves_h5(tmp, curves, bounds, attrs),
                     overwrite=overwrite)
        n = sum(len(b.lines) for b in bounds)
        also = f", {n} boundary lines"
    else:
        write_atomic(out, write_text(csv_text(rows)), overwrite=overwrite)
        also = ""
    click.echo(f"wrote {out} ({len(rows)} A_min values over {len(curves)} panel(s){also}, "
               f"{runs} kernel runs for the search and the bisection to rtol {rtol:g}"
               f"{_methods(curves)})")
    if lines_path is not None:
        lrows = bd.boundary_rows(bounds)
        write_atomic(lines_path, write_text(csv_text(lrows)), overwrite=overwrite)
        n = sum(len(b.lines) for b in bounds)
        click.echo(f"wrote {lines_path} ({n} boundary lines, {len(lrows)} vertices)")
    if fig_path is not None:
        # lazy, not on --help: matplotlib, h5py (+0.5 s)
        from rocksweep.figures.a_min import a_min_figure

        fig = a_min_figure(curves, bounds, title=result.name, kind=result.kind)
        save_figure(fig, fig_path, dpi, overwrite=overwrite, inputs=inputs)
        click.echo(f"wrote {fig_path}")


def _methods(curves) -> str:
    """How the A_min values were found, counted (", 3 searched below grid, ...")."""
    n = Counter(w for c in curves for w, a in zip(c.method_words, c.a_min, strict=True)
                if a == a and w != "grid+bisection")
    return "".join(f", {k} {w}" for w, k in sorted(n.items()))
