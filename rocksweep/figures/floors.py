"""The floor spectrum's figure (``rocksweep.analysis.floors.floor_spectrum``): against the
building's period, P(overturn) of a suite (one curve per stripe, line style per
orientation answer and other swept key) or A_min of one record or a pulse (one curve per
combination of the other swept keys). A pyplot-free ``matplotlib.figure.Figure``."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from rocksweep.figures.results import _curves, _figure
from rocksweep.figures.style import curve_colours, grow_to_fit, log_ticks, wrap_title
from rocksweep.vocab.axes import label as axis_label

X = "floor.period"
MAX_CURVES = 12  # more curves than this in a panel: one in every few is drawn


def floor_spectrum_figure(fs: xr.Dataset, *, ax: Any = None,
                          width: str | None = "single") -> Any:
    """P(overturn) or A_min against floor.period [s] (log x, labelled at its values or
    1-2-5 a decade): a panel per orientation answer (each, worst) with an angle axis, one
    curve per stripe and value of the other keys (at most MAX_CURVES a panel, evenly
    chosen, said in the title), one legend for the figure below the panels. ax: an Axes
    (or one per orientation answer) to draw into."""
    var = "p_overturn" if "p_overturn" in fs else "A_min"
    da = fs[var]
    panels = ([("each orientation", {"orientation": 0}), ("worst orientation",
                                                           {"orientation": 1})]
              if "orientation" in da.dims else [("", {})])
    own = ax is None
    if own:
        fig, axes = _figure(width, len(panels), 0.7)
    else:
        axes = np.atleast_1d(np.asarray(ax, dtype=object)).ravel()
        fig = axes[0].figure
    x = fs[X].values
    kind = str(fs.attrs.get("kind", "flexible"))
    step = 1
    for k, (name, sel) in enumerate(panels):
        a = axes[min(k, len(axes) - 1)]
        curves = list(_curves(da.isel(sel) if sel else da, X))
        step = max(1, int(np.ceil(len(curves) / MAX_CURVES)))
        drawn = curves[::step]
        colours = curve_colours(len(drawn))
        for c, (label, _sel, v) in enumerate(drawn):
            a.plot(x, v, "o-", ms=3, color=colours[c], label=(label or None) if k == 0
                   else None)
        a.set_xscale("log")
        log_ticks(a.xaxis, x)
        a.set_xlabel(axis_label(X))
        a.set_ylabel("P(overturn)" if var == "p_overturn" else
                     f"{axis_label('A_ratio', kind)}\nat overturning (ground)")
        if var == "p_overturn":
            a.set_ylim(-0.02, 1.02)
        more = f" ({len(drawn)} of {len(curves)} curves)" if step > 1 else ""
        if name or more:
            a.set_title(name + more, fontsize="small")
        a.grid(True, alpha=0.25, linewidth=0.5)
    im = str(fs.attrs.get("scale_im", "") or "")
    title = "floor spectrum" + (f": P(overturn) at {im} stripes of the ground motion"
                                if var == "p_overturn" and im and im != "none" else
                                ": overturning onset of the ground motion" if var == "A_min"
                                else "")
    handles, labels = axes[0].get_legend_handles_labels()
    if own:
        fig.suptitle(wrap_title(title, fig.get_figwidth(), 9.0), fontsize="small")
        if handles:
            fig.legend(handles, labels, loc="outside lower center", fontsize="x-small",
                       frameon=False, ncol=2 if len(labels) > 3 else 1)
        grow_to_fit(fig)
    elif handles:
        axes[0].legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.25),
                       frameon=False)
    return fig
