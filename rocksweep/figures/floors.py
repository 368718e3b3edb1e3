"""The floor spectrum's figure (``rocksweep.analysis.floors.floor_spectrum``): against the
building's period, P(overturn) of a suite (one curve per stripe, line style per
orientation answer and other swept key) or A_min of one record or a pulse (one curve per
combination of the other swept keys). A pyplot-free ``matplotlib.figure.Figure``."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from rocksweep.figures.results import _curves, _figure
from rocksweep.figures.style import curve_colours
from rocksweep.vocab.axes import label as axis_label

X = "floor.period"
MAX_CURVES = 12  # more curves than this: one in every few is drawn


def floor_spectrum_figure(fs: xr.Dataset, *, ax: Any = None,
                          width: str | None = "single") -> Any:
    """P(overturn) or A_min against floor.period [s] (log x)."""
    if ax is not None:
        fig = ax.figure
    else:
        fig, axes = _figure(width, 1, 0.7)
        ax = axes[0]
    var = "p_overturn" if "p_overturn" in fs else "A_min"
    da = fs[var]
    curves = list(_curves(da, X))
    step = max(1, int(np.ceil(len(curves) / MAX_CURVES)))
    x = fs[X].values
    drawn = curves[::step]
    colours = curve_colours(len(drawn))
    for k, (label, _sel, v) in enumerate(drawn):
        ax.plot(x, v, "o-", ms=3, color=colours[k], label=label or None)
    ax.set_xscale("log")
    ax.set_xlabel(axis_label(X))
    ax.set_ylabel("P(overturn)" if var == "p_overturn" else
                  f"{axis_label('A_ratio')} at overturning onset (ground)")
    if var == "p_overturn":
        ax.set_ylim(-0.02, 1.02)
    im = str(fs.attrs.get("scale_im", "") or "")
    title = ("floor spectrum" + (f", {im} of the ground motion" if var == "p_overturn" and im
                                 and im != "none" else "")
             + (f" ({len(curves)} curves, every {step})" if step > 1 else ""))
    ax.set_title(title, fontsize="small")
    ax.grid(True, alpha=0.25, linewidth=0.5)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="x-small", loc="upper left", bbox_to_anchor=(1.02, 1.0),
                  frameon=False)
    return fig
