"""``rocksweep floor-spectrum``: the body's response against the building's period of a
sweep over ``floor.period`` (``rocksweep.floor_spectrum``), as a figure and as numbers."""

from __future__ import annotations

from pathlib import Path

import click

import rocksweep
from rocksweep.analysis.tolerance import DEFAULT_RTOL_MANY
from rocksweep.cli.helpers import check_table_outputs, write_table
from rocksweep.cli.main import main, user_errors
from rocksweep.cli.options import (
    dpi_option,
    overwrite_option,
    result_argument,
    rtol_option,
    search_option,
)
from rocksweep.figures import FORMATS
from rocksweep.vocab.kinds import FLOOR_SPECTRUM

#: what ``-o`` writes the numbers as (the figure: ``figures.FORMATS``)
TABLES = (".csv", ".h5", ".hdf5", ".nc")


@main.command("floor-spectrum")
@result_argument
@click.option("-o", "--output", "outputs", multiple=True,
              type=click.Path(dir_okay=False, path_type=Path),
              help="The figure (.png, .pdf, .svg) or the numbers (.csv: one row per "
                   "building period and value of the other keys; .h5, .hdf5, .nc: the "
                   "Dataset), by suffix; repeat for both [default: OUT-floors.png].")
@rtol_option(DEFAULT_RTOL_MANY, "Relative tolerance of A_min (one record or a pulse)")
@search_option
@dpi_option
@overwrite_option
@user_errors
def floor_spectrum(result_path: Path, outputs: tuple[Path, ...], rtol: float, search: bool,
                   dpi: int, overwrite: bool) -> None:
    """Floor spectrum of a complete sweep over floor.period: P(overturn) per stripe of a
    record suite (each and worst orientation with an angle axis), or A_min of one record
    or a pulse, against the building's period."""
    # lazy, not on --help: matplotlib, h5py (+0.4 s)
    from rocksweep.figures.style import save_figure
    from rocksweep.store.reader import result_inputs

    figs = [p for p in outputs if p.suffix.lower() in FORMATS]
    tables = [p for p in outputs if p.suffix.lower() not in FORMATS]
    if len(figs) > 1 or len(tables) > 1:
        raise click.UsageError("-o: at most one figure (.png, .pdf, .svg) and one table "
                               f"({', '.join(TABLES)})")
    fig_out = figs[0] if figs else (None if tables else
                                    result_path.with_name(result_path.stem + "-floors.png"))
    out = tables[0] if tables else None
    inputs = result_inputs(result_path)  # the result and every file it was computed from
    check_table_outputs(out, fig_out, TABLES, inputs, overwrite)
    fs = rocksweep.floor_spectrum(result_path, rtol, search)
    if out is not None:
        write_table(out, rocksweep.table(fs), fs, FLOOR_SPECTRUM, overwrite)
        click.echo(f"wrote {out} ({fs.attrs.get('method')})")
    if fig_out is not None:
        save_figure(rocksweep.plot(fs), fig_out, dpi, overwrite=overwrite, inputs=inputs)
        click.echo(f"wrote {fig_out} ({fs.attrs.get('method')})")
