"""The friction demand map of a sweep with contact outputs (``outputs.contact``;
``rocksweep.plot(mu=True)``): mu_required = max|H|/N over two swept axes, filled contours
with labelled lines at mu = 0.4, 0.6, 0.8, one panel per value of every other swept key
(axes and panels: ``figures.panels``)."""

from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.colors import BoundaryNorm

from rocksweep.errors import DiagramError
from rocksweep.figures.panels import (
    choose_axes,
    coord,
    figure_title,
    grid_shape,
    in_order,
    panel_indices,
    panel_title,
    place_axes,
)
from rocksweep.figures.style import Figure
from rocksweep.store.reader import SweepResult
from rocksweep.vocab.axes import label as axis_label


def friction_map(result: SweepResult, x: str | None = None, y: str | None = None
                 ) -> Figure:
    """The friction demand mu_required over swept axes x and y (``rocksweep.plot(mu=True)``):
    filled contours, one panel per value of every other swept key (lam included), labelled
    contour lines at mu = 0.4, 0.6, 0.8; points whose normal force went below zero (infinite
    demand, mostly on the way to overturning) in the top colour. Needs a result with
    contact outputs (``outputs.contact``)."""
    if "mu_required" not in result.arrays:
        raise DiagramError(f"{result.path}: no mu_required in this result; sweep with "
                           "contact outputs (outputs.contact: true) to draw the friction "
                           "demand")
    x, y = choose_axes(result, x, y)
    if y is None:
        raise DiagramError(f"{result.path}: one swept axis besides lam ({x}); the friction "
                           "map needs two")
    dims = list(result.dims)
    panel_dims = [d for d in dims if d not in (x, y)]
    order = [*panel_dims, y, x]
    (mu_req,) = in_order(result, order, ["mu_required"])
    panels = panel_indices(result, panel_dims)
    xs, ys = coord(result, x), coord(result, y)
    fig, flat, _ = place_axes(None, len(panels), grid_shape(result, panel_dims, len(panels)),
                              (4.8, 4.2), "this friction map")
    levels = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0, 1.5]
    cmap = matplotlib.colormaps["viridis"].with_extremes(over="#b2182b", bad="0.85")
    norm = BoundaryNorm(levels, cmap.N, extend="max")
    mesh = None
    for ax, idx in zip(flat, panels, strict=False):
        v = np.asarray(mu_req[idx], float)
        mesh = ax.pcolormesh(xs, ys, np.ma.masked_invalid(np.where(np.isinf(v), 1e9, v)),
                             cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        finite = np.where(np.isfinite(v), v, 1e9)
        if len(xs) > 1 and len(ys) > 1:
            cs = ax.contour(xs, ys, finite, levels=[0.4, 0.6, 0.8], colors="w",
                            linewidths=0.8)
            ax.clabel(cs, fontsize=7, fmt="%.1f")
        ax.set_title(panel_title(result, panel_dims, idx), fontsize=10)
        ax.set_xlabel(axis_label(x, result.kind))
        ax.set_ylabel(axis_label(y, result.kind))
    cb = fig.colorbar(mesh, ax=flat, shrink=0.9, extend="max")
    cb.set_label(r"friction demand $\max|H|/N$ (top colour: $N < 0$ or $> 1.5$)")
    fig.suptitle(figure_title(result, (x, y)) + ": friction demand", fontsize=11)
    return fig
