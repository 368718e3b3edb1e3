"""``rocksweep spectrum``: rocking and overturning spectra of a sweep over p (or w_over_p)
and A_ratio."""

from __future__ import annotations

from pathlib import Path

import click

from rocksweep.cli.main import main, user_errors
from rocksweep.cli.options import dpi_option, overwrite_option, rtol_option, search_option
from rocksweep.figures import FORMATS


@main.command()
@click.argument("result_path", metavar="OUT.h5", type=click.Path(path_type=Path))
@click.option("-o", "--output", "fig_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Figure file, .png, .pdf or .svg [default: OUT-spectra.png].")
@rtol_option()
@search_option
@dpi_option
@overwrite_option
@user_errors
def spectrum(result_path: Path, fig_path: Path | None, rtol: float, search: bool, dpi: int,
             overwrite: bool) -> None:
    """Rocking spectrum (max|theta|/alpha_cg against p, one curve per A_ratio and lam) and
    overturning spectrum (smallest A_ratio that overturns against p, one curve per lam,
    by mode, refined by bisection) of a sweep over p (a record) or w_over_p, and A_ratio."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.analysis.spectrum import spectra
    from rocksweep.figures.spectrum import spectra_figure
    from rocksweep.figures.style import save_figure
    from rocksweep.outputs import check_output
    from rocksweep.store.reader import result_inputs

    fig_out = fig_path or result_path.with_name(result_path.stem + "-spectra.png")
    inputs = result_inputs(result_path)  # the result and its records: never written over
    check_output(fig_out, overwrite=overwrite, inputs=inputs, suffixes=FORMATS)
    sp = spectra(result_path, rtol, search)
    save_figure(spectra_figure(sp), fig_out, dpi, overwrite=overwrite, inputs=inputs)
    click.echo(f"wrote {fig_out} ({sp.runs} kernel runs to find A_min to {rtol:g})")
