"""The fragility figure: empirical fractions, fitted lognormal curves and bootstrap bands.

``fragility_figure(frag)`` draws a Dataset made by ``rocksweep.analysis.fragility.fragility``
and returns a ``matplotlib.figure.Figure`` (no pyplot: no global figure registry, no
backend switch). One colour per value of ``lam`` (or of the first swept dimension when there
is no ``lam``); other swept dimensions and several states get line styles. Each curve: the
fitted Phi(ln(x / median) / beta), its bootstrap band (pointwise percentiles of the
resamples' curves, ``band_lo``/``band_hi``, when the fit was bootstrapped), and for stripes
the empirical fraction at each level with the marker's area proportional to the records
counted there (one marker shape per colour, translucent faces: markers of several colours at
one level stay readable). The legend (below the axes, never over the data) gives each median, its
change against the first colour's, and beta.
"""

from __future__ import annotations

import itertools
import math
import textwrap
from typing import TYPE_CHECKING

import matplotlib.colors
import matplotlib.font_manager
import numpy as np
import xarray as xr

from rocksweep.analysis.likelihood import lognormal_cdf
from rocksweep.analysis.risk import fragility_median
from rocksweep.errors import FragilityFigureError
from rocksweep.figures import WIDTHS
from rocksweep.figures.style import Figure, curve_colours, grow_to_fit, log_ticks

if TYPE_CHECKING:
    from matplotlib.axes import Axes

# height / width of the figure at each paper width (``rocksweep.figures.WIDTHS``)
ASPECT = {"single": 1.2, "double": 0.75}  # room for the legend below
_STYLES = ("-", "--", ":", "-.")
# Stripe markers of different colours sit on the same IM levels and often at the same
# fraction: one shape per colour and translucent faces keep every one of them visible.
_MARKERS = ("o", "s", "^", "D", "v", "P")
_MARKER_ALPHA = 0.55



def _fmt(v) -> str:
    if isinstance(v, (float, np.floating)):
        return f"{float(v):g}"
    return str(v)


def fragility_figure(frag: xr.Dataset, *, ax: Axes | None = None,
                     width: str | tuple[float, float] = "single") -> Figure:
    """Draw fragility curves; returns the Figure (``ax.figure`` when ``ax`` is given).

    frag: the Dataset of ``fragility()`` (im_median (or median in older Datasets), beta [,
    band_lo, band_hi over im_grid]
    [, fraction, n_counted over the stripe dimension]); width: "single" (3.5 in), "double"
    (7.2 in) (``rocksweep.figures.WIDTHS``) or (width, height) in inches.
    """
    if "im_grid" not in frag.coords or not ({"im_median", "median"} & set(frag.data_vars)):
        raise FragilityFigureError("not a fragility Dataset (no 'im_median' or 'im_grid')")
    median_da, _ = fragility_median(frag)
    if ax is None:
        size = ((WIDTHS[width][0], WIDTHS[width][0] * ASPECT[width])
                if isinstance(width, str) and width in WIDTHS
                else None if isinstance(width, str) else tuple(width))
        if size is None:
            raise FragilityFigureError(f"width = {width!r}: 'single', 'double' or "
                                       "(width, height) in inches")
        fig = Figure(figsize=size, layout="constrained")
        ax = fig.add_subplot()
        own = True
    else:
        fig = ax.figure
        own = False
    im, unit = frag.attrs.get("im", "IM"), frag.attrs.get("im_units", "")
    stripe = im if im in frag.dims else None
    dims = list(median_da.dims)
    colour_dim = "lam" if "lam" in dims else next((d for d in dims if d != "state"), None)
    rest = [d for d in dims if d != colour_dim]
    grid = frag["im_grid"].values
    n_col = frag.sizes[colour_dim] if colour_dim else 1
    colours = curve_colours(n_col)
    # a legend entry's lines wrapped to the figure's width at the legend's font (about
    # 100/pt characters an inch, as titles): a long verdict no longer widens the legend
    # past the figure and squeezes the axes
    pt = matplotlib.font_manager.FontProperties(size="x-small").get_size_in_points()
    chars = max(24, int(100.0 / pt * fig.get_figwidth() * 0.95))
    n_max = float(frag["n_counted"].max()) if "n_counted" in frag else 1.0
    rest_pos = list(itertools.product(*(range(frag.sizes[d]) for d in rest)))
    for ri, rpos in enumerate(rest_pos):
        style = _STYLES[ri % len(_STYLES)]
        base = frag.isel(dict(zip(rest, rpos, strict=True)))
        ref_med, ref_val = math.nan, None
        for ci in range(n_col):
            one = base.isel({colour_dim: ci}) if colour_dim else base
            med, beta = float(one[median_da.name]), float(one["beta"])
            colour = colours[ci]
            label_bits = []
            if colour_dim:
                val = frag[colour_dim].values[ci] if colour_dim in frag.coords else ci
                label_bits.append(f"{colour_dim} = {_fmt(val)}")
            for d, i in zip(rest, rpos, strict=True):
                v = frag[d].values[i] if d in frag.coords else i
                label_bits.append(_fmt(v) if d == "state" else f"{d} = {_fmt(v)}")
            if math.isfinite(med):
                text = f"median {med:.3g} {unit}".rstrip()
                if ci == 0:
                    ref_med, ref_val = med, label_bits[0] if label_bits else None
                elif math.isfinite(ref_med) and ref_val:
                    text += f" ({100.0 * (med / ref_med - 1.0):+.0f}% vs {ref_val})"
                text += f", beta {beta:.2f}" if math.isfinite(beta) else ""
                reason = str(one["reason"].values) if "reason" in one else "ok"
                text += "" if reason == "ok" else f" [{reason}]"
                # the fit's own curve (a competing-risk mode's is not a lognormal CDF)
                y = (one["curve"].values if "curve" in one
                     else lognormal_cdf(grid, med, beta))
                ax.plot(grid, y, style, color=colour,
                        label=_wrapped(", ".join(label_bits) + "\n" + text, chars))
            else:
                reason = str(one["reason"].values) if "reason" in one else "no fit"
                ax.plot([], [], style, color=colour,
                        label=_wrapped(", ".join(label_bits + [f"no fit ({reason})"]), chars))
            if "band_lo" in one:
                lo, hi = one["band_lo"].values, one["band_hi"].values
                if np.any(np.isfinite(lo)):
                    ax.fill_between(grid, lo, hi, color=colour, alpha=0.18, linewidth=0)
            if stripe and "fraction" in one:
                n = one["n_counted"].values.astype(float)
                face = matplotlib.colors.to_rgba(colour, _MARKER_ALPHA)
                ax.scatter(frag[stripe].values, one["fraction"].values,
                           s=6.0 + 40.0 * n / max(n_max, 1.0), marker=_MARKERS[ci % len(
                               _MARKERS)], facecolor=face, edgecolor=colour,
                           linewidth=0.8, zorder=3)
    ax.set_xscale("log")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlim(grid[0], grid[-1])
    ax.set_xlabel(f"{im} [{unit}]" if unit and unit != "1" else im)
    states = frag.attrs.get("states", ["overturn"])
    what = states[0] if len(states) == 1 else "state"
    ax.set_ylabel(f"P({what} | {im})")
    method = frag.attrs.get("method", "")
    boot = int(frag.attrs.get("bootstrap", 0))
    title = method + (f", {frag.attrs.get('ci', 0.9):g} band of {boot} resamples"
                      if boot else "")
    ax.set_title(title, fontsize="small")
    # below the axes: the curves and stripe markers fill the plot, a legend inside would
    # cover them
    ax.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.2),
              frameon=False)
    ax.grid(True, which="both", alpha=0.25, linewidth=0.5)
    log_ticks(ax.xaxis, frag[stripe].values if stripe else None)
    if own:  # the entries' lines below the axes: the figure grows to hold them, measured
        grow_to_fit(fig)
    return fig


def _wrapped(label: str, chars: int) -> str:
    """Each line of a legend label wrapped at ``chars`` characters (words kept whole)."""
    return "\n".join(textwrap.fill(line, chars) for line in label.strip().split("\n"))
