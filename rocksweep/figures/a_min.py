"""A_min curves, the boundaries command's figure (``rocksweep boundaries``): the smallest
amplitude that overturns against x of every panel (e.g. per lam) on one axis, as the paper
compares them, with the class boundary lines drawn thin."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from rocksweep.figures.panels import value_text
from rocksweep.figures.style import Figure, curve_colours
from rocksweep.vocab import axes as _axes
from rocksweep.vocab.axes import label as axis_label
from rocksweep.vocab.outcomes import OUTCOME_MODE1, OUTCOME_MODE2, outcome_word

if TYPE_CHECKING:
    from rocksweep.analysis.boundaries import AMinCurve, PanelBoundaries


def _where_label(where: dict[str, Any]) -> str:
    parts = []
    for k, v in where.items():
        sym = f"${_axes.latex(k)}$" if k in _axes.AXES else k
        parts.append(f"{sym} = {value_text(v)}")
    return ", ".join(parts) or "all"


def a_min_figure(curves: Sequence[AMinCurve], bounds: Sequence[PanelBoundaries] = (),
                 title: str = "", kind: str = "flexible") -> Figure:
    """A_min(x) of every panel (``rocksweep.analysis.boundaries.a_min``) overlaid on one axis: one
    colour per panel (e.g. per lam), solid where the onset is mode 1, dashed where mode 2;
    with the boundary lines of ``bounds`` drawn thin in the same colours when given.
    kind: the body kind (labels the amplitude axis). No pyplot."""
    # one legend entry per panel and one per line style, below the axes in two columns:
    # the figure grows with the entries rather than the legend covering the curves
    rows = -(-(len(curves) + 2) // 2) if curves else 0
    fig = Figure(figsize=(6.4, 4.8 + 0.2 * rows), layout="constrained")
    ax = fig.add_subplot()
    colours = curve_colours(max(len(curves), len(bounds)))
    for k, b in enumerate(bounds):
        for line in b.lines:
            ax.plot(line.xy[:, 0], line.xy[:, 1], lw=0.5, color=colours[k], alpha=0.5)
    styles = ((OUTCOME_MODE1, "-"), (OUTCOME_MODE2, "--"))
    for k, c in enumerate(curves):
        labelled = False
        for m, style in styles:
            y = np.where(c.mode == m, c.a_min, np.nan)
            drawn = np.isfinite(y).any()
            ax.plot(c.x, y, style, color=colours[k], lw=1.5, marker=".", ms=2,
                    label=_where_label(c.where) if drawn and not labelled else None)
            labelled = labelled or drawn
    if curves:
        for m, style in styles:  # the line styles of the modes drawn
            if any(np.isfinite(np.where(c.mode == m, c.a_min, np.nan)).any() for c in curves):
                ax.plot([], [], style, color="0.3", lw=1.5, label=outcome_word(m))
        ax.set_xlabel(axis_label(curves[0].xname, kind))
        ax.set_ylabel(f"{axis_label(curves[0].yname, kind)} at overturning onset "
                      "($A_{min}$)")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.12),
                  frameon=False, ncol=2)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    return fig
