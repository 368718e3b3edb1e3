"""Options and arguments shared by several commands (as rasterio's ``rio/options.py``),
each built from the library's constants: its default, choices, range and the help's
defaults are the library's, never typed again here. Light modules only (``rocksweep
--help`` loads no numba, h5py or matplotlib).

Who uses what: ``rtol_option`` (boundaries, spectrum, fragility), ``seed_option``
(accuracy, fragility, sweep's audit), ``ci_option`` (fragility), ``json_option`` (info,
simulate, restitution, fragility, efficiency, risk), ``width_option`` (fragility,
efficiency, risk), ``backend_option`` and ``connect_timeout_option`` (sweep), ``ADAPTIVE``
(sweep's adaptive settings' help), ``dpi_option``, ``overwrite_option``, ``set_option``.
A value the library refuses is refused while the options are parsed (exit 2, before any
work), by the library's own check, naming the option.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from rocksweep.analysis.resampling import DEFAULT_CI, check_ci
from rocksweep.analysis.tolerance import DEFAULT_RTOL
from rocksweep.cli.main import said
from rocksweep.compute.arguments import CONNECT_TIMEOUT, MAX_CONNECT_TIMEOUT
from rocksweep.errors import MAX_RTOL, RocksweepError, check_rtol
from rocksweep.figures import DEFAULT_DPI, DPI_RANGE, WIDTHS
from rocksweep.vocab import settings as _settings
from rocksweep.vocab.axes import DIAGRAM_AXES

scene_argument = click.argument(
    "scene_path", metavar="SCENE.yaml", type=click.Path(dir_okay=False, path_type=Path))
result_argument = click.argument("result_path", metavar="OUT.h5",
                                 type=click.Path(path_type=Path))
set_option = click.option(
    "--set", "overrides", multiple=True, metavar="KEY=VALUE",
    help="Override a scene value, e.g. --set pulse.A_ratio=4.5 (repeatable).")
overwrite_option = click.option("--overwrite", is_flag=True,
                                help="Replace existing output files.")
dpi_option = click.option("--dpi", type=click.IntRange(*DPI_RANGE), default=DEFAULT_DPI,
                          show_default=True, help="Resolution of raster output (PNG).")
search_option = click.option(
    "--search/--no-search", default=True, show_default=True,
    help="Search below the first overturning grid value for a band narrower than the grid "
         "step (--no-search: bisect the grid's bracket only, faster, A_min then depends on "
         "the grid).")


def checked_by(check: Callable[[Any], Any]) -> Callable[..., Any]:
    """A click callback: the library's ``check`` of the value (None: not given) while the
    options are parsed; its refusal is a usage error naming the option (exit 2)."""

    def callback(_ctx: click.Context, _param: click.Parameter, value: Any) -> Any:
        if value is None:
            return None
        try:
            return check(value)
        except RocksweepError as err:
            raise click.UsageError(said(err)) from None

    return callback


def _check_rtol(value: float) -> float:
    return check_rtol(value)


def rtol_option(default: float | None = DEFAULT_RTOL, help: str | None = None) -> Any:
    """``--rtol``: a relative tolerance in (0, ``MAX_RTOL``], checked as the library checks
    it (``errors.check_rtol``); default None: not asked for."""
    return click.option(
        "--rtol", type=float, default=default, show_default=default is not None,
        callback=checked_by(_check_rtol),
        help=(help or "Relative tolerance of A_min (search below the first overturning grid "
              "value, then bisection)") + f", in (0, {MAX_RTOL:g}].")


def seed_option(default: int | None, help: str) -> Any:
    """``--seed``: a random generator's seed (an integer; the library checks its range)."""
    return click.option("--seed", type=int, default=default, show_default=default is not None,
                        help=help)


ci_option = click.option("--ci", type=float, default=DEFAULT_CI, show_default=True,
                         callback=checked_by(check_ci),
                         help="Level of the bootstrap intervals and bands, in (0, 1).")


def json_option(what: str) -> Any:
    """``--json``: print ``what`` as JSON instead of text."""
    return click.option("--json", "as_json", is_flag=True, help=f"Print {what} as JSON.")


def width_option(default: str) -> Any:
    """``--width``: a journal's column width (``figures.WIDTHS``)."""
    return click.option("--width", type=click.Choice(list(WIDTHS)), default=default,
                        show_default=True,
                        help="Figure width: a journal's " + " or ".join(WIDTHS) + " column.")


backend_option = click.option(
    "--backend", type=click.Choice(_settings.BACKENDS), default=_settings.DEFAULT_BACKEND,
    show_default=True,
    help="Local worker threads (the kernel runs outside the GIL) or a dask.distributed "
         "cluster.")
connect_timeout_option = click.option(
    "--connect-timeout", "connect_timeout", type=float, default=CONNECT_TIMEOUT,
    show_default=True, metavar="SECONDS",
    help=f"With --backend dask: wait this long for the scheduler to answer (at most "
         f"{MAX_CONNECT_TIMEOUT:g}).")

# the help of the sweep command's adaptive settings, their defaults the library's
ADAPTIVE = {
    "coarse": "Adaptive: the coarse pass takes every 2^K-th point of both diagram axes "
              f"[default: {_settings.MIN_COARSE_CELLS} coarse cells per axis]. Regions "
              "smaller than a coarse cell and touching no boundary can be missed: lower K "
              "to be safer.",
    "audit": "Adaptive: share of all points computed as a check of the fill "
             f"[default: {_settings.DEFAULT_AUDIT:g}].",
    "axes": f"Adaptive: the two diagram axes [default: {','.join(DIAGRAM_AXES)}].",
    "margin": f"Adaptive: cells refined around a mixed cell [default: "
              f"{_settings.DEFAULT_MARGIN}].",
    "final_margin": "Adaptive: the same at the last level [default: "
                    f"{_settings.DEFAULT_FINAL_MARGIN}: the last level computes only the "
                    "edges a boundary crosses, the level before probes its margin cells' "
                    "centres; >= 1 refines whole cells at both].",
    "seed": f"Adaptive: seed of the audit sample [default: {_settings.DEFAULT_SEED}].",
    "threshold": "Adaptive: warn when more than this share of audit points disagree "
                 f"[default: {_settings.DEFAULT_AUDIT_THRESHOLD:g}].",
}
