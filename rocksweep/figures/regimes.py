"""The regime map of a sweep with a sliding base (``body.mu``; ``rocksweep.plot(regime=True)``,
``rocksweep plot --regime``): which contact phases the runs visit (``analysis.regimes``)
over two swept keys, e.g. mu against A/(g tan alpha) (Shenton's 1996 diagram), one colour
per regime word, one panel per value of every other swept key (lam included). Overturned
points carry the line plot's outcome marks (mode 1 a triangle, mode 2 a square), flagged
ones a cross, points not computed are grey (axes and panels: ``figures.panels``).
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from rocksweep.analysis.regimes import MAX_REGIME, REGIME, REGIME_WORDS, regime_index
from rocksweep.errors import DiagramError
from rocksweep.figures.diagrams import OUTCOME_STYLE
from rocksweep.figures.panels import (
    NOT_RUN_COLOUR,
    coord,
    figure_title,
    fitted_title,
    flag_label,
    grid_shape,
    in_order,
    map_axes,
    mark_flagged,
    panel_indices,
    panel_title,
    place_axes,
)
from rocksweep.figures.style import Figure
from rocksweep.store.reader import SweepResult
from rocksweep.vocab.axes import label as axis_label
from rocksweep.vocab.outcomes import OUTCOME_MODE1, OUTCOME_MODE2, OUTCOME_NOT_RUN

#: a fill per regime word (``REGIME_WORDS``' order): rest white; sliding blues, rocking
#: oranges, slide-rock purple; the mixtures between them, darker the more phases
REGIME_COLOURS: tuple[str, ...] = ("#ffffff", "#a6cee3", "#fdbf6f", "#cab2d6", "#b2df8a",
                                   "#1f78b4", "#ff7f00", "#6a3d9a")


def regime_map(result: SweepResult, x: str | None = None, y: str | None = None) -> Figure:
    """The contact regimes of ``result`` over swept axes x and y (defaults:
    ``choose_axes``): each cell coloured by its run's regime word, overturned cells
    marked by mode, flagged ones crossed, one panel per value of every other swept key.
    Needs the ``regime`` bit set of a sweep with ``body.mu`` (a one-line DiagramError
    otherwise, or where it holds a value that is not a bit set of the four phases)."""
    if REGIME not in result.arrays:
        raise DiagramError(f"{result.path}: no {REGIME} in this result; the contact regimes "
                           "are those of a sliding base: sweep a scene with body.mu")
    x, y, panel_dims, order = map_axes(result, x, y, "the regime map")
    flagged = result.flagged & result.done
    cat = np.where(result.done, regime_index(result.arrays[REGIME]), -1)
    bad = result.done & (cat < 0)
    if bad.any():
        v = np.asarray(result.arrays[REGIME])[bad].ravel()[0]
        raise DiagramError(f"{result.path}: {REGIME} holds {v!r} at {int(bad.sum())} computed "
                           f"points; a bit set of the four contact phases is 0 to "
                           f"{MAX_REGIME}")
    cat, out, fl = in_order(result, order, [cat + 1, "outcome", flagged])
    panels = panel_indices(result, panel_dims)
    xs, ys = coord(result, x), coord(result, y)
    fig, flat, _ = place_axes(None, len(panels), grid_shape(result, panel_dims, len(panels)),
                              (4.8, 4.2), "this regime map")
    cmap = ListedColormap([NOT_RUN_COLOUR, *REGIME_COLOURS])
    norm = BoundaryNorm(np.arange(-0.5, len(REGIME_WORDS) + 1.5), cmap.N)
    used = np.zeros(len(REGIME_WORDS) + 1, bool)
    marked: set[int] = set()
    any_flag = False
    for ax, idx in zip(flat, panels, strict=False):
        pc, po = cat[idx], out[idx]
        used[np.unique(pc)] = True
        ax.pcolormesh(xs, ys, pc, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        for code in (OUTCOME_MODE1, OUTCOME_MODE2):
            yy, xx = np.nonzero(po == code)
            if yy.size:
                marker, face, _ = OUTCOME_STYLE[code]
                marked.add(code)
                ax.scatter(xs[xx], ys[yy], marker=marker, s=16, c=[face], edgecolors="k",
                           linewidths=0.5, zorder=2)
        any_flag |= mark_flagged(ax, fl[idx][None], xs, ys)
        ax.set_title(panel_title(result, panel_dims, idx), fontsize=10)
        ax.set_xlabel(axis_label(x, result.kind))
        ax.set_ylabel(axis_label(y, result.kind))
    handles = [Patch(fc=REGIME_COLOURS[k], ec="0.5", label=w)
               for k, w in enumerate(REGIME_WORDS) if used[k + 1]]
    if used[0]:
        handles.append(Patch(fc=NOT_RUN_COLOUR, ec="0.5",
                             label=OUTCOME_STYLE[OUTCOME_NOT_RUN][2]))
    handles += [Line2D([], [], ls="", marker=OUTCOME_STYLE[c][0], mfc=OUTCOME_STYLE[c][1],
                       mec="k", label=OUTCOME_STYLE[c][2]) for c in sorted(marked)]
    if any_flag:
        handles.append(Line2D([], [], ls="", marker="x", color="k", label=flag_label(result)))
    ncols = grid_shape(result, panel_dims, len(panels))[1]
    fig.legend(handles=handles, loc="outside lower center", fontsize=8, frameon=False,
               ncol=max(1, min(len(handles), 2 * ncols)))
    fig.suptitle(fitted_title(figure_title(result, (x, y)) + ": contact regimes", fig),
                 fontsize=11)
    return fig
