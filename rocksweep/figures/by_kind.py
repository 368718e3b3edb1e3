"""``rocksweep.plot(ds)`` for any rocksweep Dataset: the figure of its kind
(``rocksweep.analysis.kinds.dataset_kind``), in this one place."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
from matplotlib.axes import Axes

from rocksweep.analysis.files import open_any
from rocksweep.analysis.kinds import dataset_kind
from rocksweep.compute.arguments import check_flag
from rocksweep.errors import ApiError, Arg, PlotError, check_type, flag
from rocksweep.figures import results
from rocksweep.figures.calibration import calibration_figure
from rocksweep.figures.diagrams import sweep_figure
from rocksweep.figures.floors import floor_spectrum_figure
from rocksweep.figures.friction import friction_map
from rocksweep.figures.spectrum import spectra_figure
from rocksweep.figures.style import fit_width, width_style
from rocksweep.store.reader import as_result
from rocksweep.vocab.kinds import (
    BOUNDARIES,
    CALIBRATION,
    FLOOR_SPECTRUM,
    FRAGILITY,
    IDA,
    IM_EFFICIENCY,
    RISK,
    SPECTRA,
    SWEEP,
)
from rocksweep.vocab.outcomes import OVERTURN


def plot_analysis(ds: Any, *, ax: Any = None, width: str | None = None) -> Any:
    """The figure of a fragility, IDA, spectra, boundaries, risk, IM-efficiency or
    calibration Dataset (a sweep's diagram is ``rocksweep.figures.diagrams``)."""
    kind = dataset_kind(ds)
    if kind == FRAGILITY:
        from rocksweep.figures.fragility import fragility_figure  # scipy: a fragility's only

        return fragility_figure(ds, ax=ax, width=width or "single")
    if kind == CALIBRATION:
        return calibration_figure(ds, ax=ax)
    if kind == FLOOR_SPECTRUM:
        return floor_spectrum_figure(ds, ax=ax, width=width or "single")
    draw = {RISK: results.risk_figure, IDA: results.ida_figure, SPECTRA: spectra_figure,
            BOUNDARIES: results.boundaries_figure,
            IM_EFFICIENCY: results.efficiency_figure}.get(kind or "")
    if draw is None:
        raise PlotError(f"a {kind or 'foreign'} Dataset has no figure (rocksweep.plot draws "
                        "sweeps, fragility, IDA, spectra, boundaries, risk, IM-efficiency "
                        "and calibration Datasets)")
    return draw(ds, ax=ax, width=width)


def plot_any(ds: Any, x: str | None = None, y: str | None = None, *, ax: Any = None,
             curves: bool = False, show_computed: bool = False, mu: bool = False,
             width: str | None = None, compare: str | None = None) -> Any:
    """``rocksweep.plot``'s figure of any rocksweep Dataset or its file (the arguments,
    checked here first, are documented there): a sweep's diagram (``figures.diagrams``), a
    record suite's overturning fragility, an analysis's figure (``plot_analysis``), at the
    journal ``width``."""
    _check_ax(ax)
    for name, v in {"x": x, "y": y, "compare": compare, "width": width}.items():
        check_type(name, v, v is None or isinstance(v, str), "a string or None")
    for name, v in {"curves": curves, "show_computed": show_computed, "mu": mu}.items():
        check_flag(name, v)
    if isinstance(ds, str | Path):
        ds = open_any(ds)
    kind = dataset_kind(ds)
    if kind == SWEEP and "record" in ds["outcome"].dims:
        # a record suite has no stability diagram: its overturning fragility (no bootstrap;
        # rocksweep.fragility for other states and bands)
        from rocksweep.analysis.fragility import fragility as fit  # scipy.stats: ~1 s

        given = [Arg(n, v) if v is not True else flag(n) for n, v in
                 zip(("x", "y", "curves", "mu", "compare", "show_computed"),
                     (x, y, curves, mu, compare, show_computed), strict=True)
                 if v not in (None, False)]
        if given:
            raise ApiError("{arg}: a record-suite sweep is drawn as its fragility curves; the "
                           "diagram's options do not apply (rocksweep.fragility for states "
                           "and bands)", arg=given[0])

        ds, kind = fit(ds, state=OVERTURN, bootstrap=0), FRAGILITY
    if kind not in (None, SWEEP):  # an analysis's Dataset: the figure of its kind
        with matplotlib.rc_context(width_style(width)):
            fig = plot_analysis(ds, ax=ax, width=width)
        if width is not None and ax is None:
            fit_width(fig, width)
        return fig
    result = as_result(ds)
    style = width_style(width)
    with matplotlib.rc_context(style):
        if mu:
            fig = friction_map(result, x, y)
        else:
            fig = sweep_figure(result, x, y, axes=ax, curves=curves,
                               show_computed=show_computed, compare=compare)
    if style and ax is None:  # the preset's width, the layout's aspect, what fits in it
        fit_width(fig, width)
    return fig


def _check_ax(ax: Any) -> None:
    """None, a matplotlib Axes or a sequence (list, array) of them."""
    if ax is None or isinstance(ax, Axes):
        return
    items = list(np.ravel(np.asarray(ax, dtype=object))) if isinstance(
        ax, list | tuple | np.ndarray) else None
    check_type("ax", ax, bool(items) and all(isinstance(a, Axes) for a in items),
               "a matplotlib Axes, a sequence of them (one per panel) or None")
