"""Options and arguments shared by several commands, fed by the library's constants
(light modules only: ``rocksweep --help`` loads no numba, h5py or matplotlib)."""

from __future__ import annotations

from pathlib import Path

import click

from rocksweep.analysis.tolerance import DEFAULT_RTOL, MAX_RTOL
from rocksweep.figures import DEFAULT_DPI, DPI_RANGE

scene_argument = click.argument(
    "scene_path", metavar="SCENE.yaml", type=click.Path(dir_okay=False, path_type=Path))
result_argument = click.argument("result_path", metavar="OUT.h5",
                                 type=click.Path(path_type=Path))
set_option = click.option(
    "--set", "overrides", multiple=True, metavar="KEY=VALUE",
    help="Override a scene value, e.g. --set pulse.A_ratio=4.5 (repeatable).")
overwrite_option = click.option("--overwrite", is_flag=True,
                                help="Replace existing output files.")


def _rtol(_ctx: click.Context, _param: click.Parameter, value: float | None) -> float | None:
    """The library's one check of rtol, while the options are parsed: a bad value is a
    usage error (exit 2) before any work."""
    from rocksweep.analysis.tolerance import check_rtol
    from rocksweep.cli.main import said
    from rocksweep.errors import RocksweepError

    if value is None:
        return None
    try:
        return check_rtol(value)
    except RocksweepError as err:
        raise click.UsageError(said(err)) from None


rtol_option = click.option(
    "--rtol", type=float, default=DEFAULT_RTOL, show_default=True, callback=_rtol,
    help=f"Relative tolerance of A_min, in (0, {MAX_RTOL:g}] (search below the first "
         "overturning grid value, then bisection).")
dpi_option = click.option("--dpi", type=click.IntRange(*DPI_RANGE), default=DEFAULT_DPI,
                          show_default=True, help="Resolution of raster output (PNG).")
search_option = click.option(
    "--search/--no-search", default=True, show_default=True,
    help="Search below the first overturning grid value for a band narrower than the grid "
         "step (--no-search: bisect the grid's bracket only, faster, A_min then depends on "
         "the grid).")
