"""The one figure of rocking and overturning spectra: ``rocksweep spectrum`` and
``rocksweep.plot(rocksweep.spectra(ds))`` both draw it (matplotlib only; the computation
is ``rocksweep.analysis.spectrum``)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from rocksweep.figures.results import _curves, _figure, _label
from rocksweep.figures.style import Figure, curve_colours
from rocksweep.vocab import axes as _axes

if TYPE_CHECKING:
    import xarray as xr

    from rocksweep.analysis.spectrum import Spectra

# at most this many A_ratio curves in the rocking spectrum (evenly picked)
MAX_CURVES = 6
LAM_STYLES = ("-", "--", ":", "-.")


def spectra_figure(sp: xr.Dataset | Spectra, *, ax: Any = None,
                   width: str | None = "double") -> Figure:
    """Two panels against the frequency axis (p or w_over_p) of the spectra Dataset
    (``rocksweep.spectra``; a ``Spectra`` is drawn through its ``to_dataset``): the rocking
    spectrum (max|theta|/alpha_ref, one colour per A_ratio, one line style per lam (named
    in the legend up to four lam values), overturned points marked x above 1; other swept
    keys at their first value, named in the panel's title) and the
    overturning spectrum (the smallest A_ratio that overturns, one curve per lam, mode 1
    filled circles, mode 2 open triangles). ax: two axes to draw into; width: a journal
    width (``figures.WIDTHS``)."""
    if hasattr(sp, "to_dataset"):
        sp = sp.to_dataset()
    freq = sp["A_min"].dims[-1]
    if ax is not None:
        axes = np.atleast_1d(ax)
        fig = axes[0].figure
    else:
        fig, axes = _figure(width, 2, 0.45)
    kind = str(sp.attrs.get("kind", "flexible"))
    x = sp[freq].values
    th = sp["theta_max_over_alpha"]
    over = sp["outcome"] > 0 if "outcome" in sp else th.isnull()
    # other swept keys (an angle, a floor's period): the rocking spectrum at the first
    # value of each (the overturning spectrum draws every combination)
    first = {d: 0 for d in th.dims if d not in ("lam", "A_ratio", freq)}
    th, over = th.isel(first), over.isel(first)
    A = sp["A_ratio"].values
    pick = np.unique(np.linspace(0, A.size - 1, min(MAX_CURVES, A.size)).round().astype(int))
    n_lam = sp.sizes.get("lam", 1)
    pick_colours = curve_colours(len(pick))
    for li in range(n_lam):
        one, gone = ((th.isel(lam=li), over.isel(lam=li)) if "lam" in th.dims
                     else (th, over))
        for n, ai in enumerate(pick):
            o = gone.isel(A_ratio=ai).values
            axes[0].plot(x, np.where(o, np.nan, one.isel(A_ratio=ai).values), color=pick_colours[n],
                         ls=LAM_STYLES[li % 4], lw=1.2,
                         label=f"${_axes.latex('A_ratio', kind)}$ = {A[ai]:.3g}"
                         if li == 0 else None)
            # overturned: a row of x per curve above 1, stacked so that none hides another
            axes[0].plot(x[o], np.full(int(o.sum()), 1.03 + 0.025 * n), "x", color=pick_colours[n],
                         ms=3)
    if 1 < n_lam <= len(LAM_STYLES):  # one style per lam value: say which is which
        for li, v in enumerate(sp["lam"].values):
            axes[0].plot([], [], color="0.3", ls=LAM_STYLES[li], lw=1.2,
                         label=f"${_axes.latex('lam')}$ = {v:g}")
    axes[0].axhline(1.0, color="0.5", lw=0.6, ls=":")
    axes[0].set_ylim(0.0, 1.06 + 0.025 * len(pick))
    axes[0].set_xlabel(_axes.label(freq, kind))
    axes[0].set_ylabel(rf"max$|\theta|/{_axes.alpha_latex(kind)}$ (x: overturned)")
    # a word axis (pulse.shape) as itself, a number as %g
    at = ", ".join(_label(d, sp[d].values[0]) if d in sp.coords else d for d in first)
    axes[0].set_title("rocking spectrum" + (f" at {at}" if at else "")
                      + (" (line style: lam)" if n_lam > len(LAM_STYLES) else ""),
                      fontsize="small")
    modes = {lab: v for lab, _sel, v in _curves(sp["mode"], freq)} if "mode" in sp else {}
    onsets = list(_curves(sp["A_min"], freq))
    colours = curve_colours(len(onsets))
    for k, (lab, _sel, v) in enumerate(onsets):
        c = colours[k]
        axes[-1].plot(x, v, color=c, lw=1.2, label=lab or None)
        m = modes.get(lab, np.zeros(v.shape))
        axes[-1].plot(x[m == 1], v[m == 1], "o", color=c, ms=3)
        axes[-1].plot(x[m == 2], v[m == 2], "^", color=c, ms=4, mfc="none")
    axes[-1].plot([], [], "o", color="0.3", ms=3, label="mode 1")
    axes[-1].plot([], [], "^", color="0.3", ms=4, mfc="none", label="mode 2")
    axes[-1].set_xlabel(_axes.label(freq, kind))
    axes[-1].set_ylabel(f"{_axes.label('A_ratio', kind)} at overturning onset")
    axes[-1].set_ylim(0.0, float(A.max()) * 1.02)
    rtol = sp.attrs.get("rtol")
    axes[-1].set_title("overturning spectrum" + (f" (bisected to {rtol:g})" if rtol else ""),
                       fontsize="small")
    for a in axes:
        a.grid(True, alpha=0.25, linewidth=0.5)
        if a.get_legend_handles_labels()[0]:
            a.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.2),
                     frameon=False, ncol=3)
    title, record = str(sp.attrs.get("title", "")), str(sp.attrs.get("record", ""))
    if ax is None and title:
        fig.suptitle(title + (f" ({record})" if record and record not in title else ""),
                     fontsize="medium")
    return fig
