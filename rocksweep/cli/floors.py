"""``rocksweep floor-spectrum``: the body's response against the building's period of a
sweep over ``floor.period`` (``rocksweep.analysis.floors``)."""

from __future__ import annotations

from pathlib import Path

import click

from rocksweep.analysis.tolerance import DEFAULT_RTOL_MANY
from rocksweep.cli.main import main, user_errors
from rocksweep.cli.options import dpi_option, overwrite_option, search_option


@main.command("floor-spectrum")
@click.argument("result_path", metavar="OUT.h5", type=click.Path(path_type=Path))
@click.option("-o", "--output", "fig_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Figure file, .png, .pdf or .svg [default: OUT-floors.png].")
@click.option("--rtol", type=float, default=DEFAULT_RTOL_MANY, show_default=True,
              help="Relative tolerance of A_min (one record or a pulse).")
@search_option
@dpi_option
@overwrite_option
@user_errors
def floor_spectrum(result_path: Path, fig_path: Path | None, rtol: float, search: bool,
                   dpi: int, overwrite: bool) -> None:
    """Floor spectrum of a sweep over floor.period: P(overturn) per stripe of a record
    suite (each and worst orientation with an angle axis), or A_min of one record or a
    pulse, against the building's period."""
    from rocksweep.analysis.floors import floor_spectrum as compute
    from rocksweep.figures import FORMATS
    from rocksweep.figures.floors import floor_spectrum_figure
    from rocksweep.figures.style import save_figure
    from rocksweep.outputs import check_output
    from rocksweep.store.dataset import result_dataset
    from rocksweep.store.reader import result_inputs

    fig_out = fig_path or result_path.with_name(result_path.stem + "-floors.png")
    inputs = result_inputs(result_path)  # the result and its records: never written over
    check_output(fig_out, overwrite=overwrite, inputs=inputs, suffixes=FORMATS)
    fs = compute(result_dataset(result_path), rtol, search)
    save_figure(floor_spectrum_figure(fs), fig_out, dpi, overwrite=overwrite, inputs=inputs)
    click.echo(f"wrote {fig_out} ({fs.attrs.get('method')})")
