"""The figure of ``rocksweep spectrum``: rocking and overturning spectra (matplotlib only;
the computation is ``rocksweep.analysis.spectrum``)."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from rocksweep.figures.common import Figure
from rocksweep.vocab import axes as _axes

if TYPE_CHECKING:
    from rocksweep.analysis.spectrum import Spectra

# at most this many A_ratio curves per lam in the rocking spectrum (evenly picked)
MAX_CURVES = 6


def spectra_figure(sp: Spectra, figsize: tuple[float, float] | None = None) -> Figure:
    """Rocking spectra (one panel per lam: max|theta|/alpha_ref against the frequency axis,
    one curve per A_ratio, overturned points marked x) and the overturning spectrum
    (the smallest A_ratio that overturns, one curve per lam, mode 1 filled circles, mode
    2 open triangles). Other swept keys (``sp.extra``): the spectra at the first value of
    each, said in the figure's title. Returns a pyplot-free Figure."""
    note = ""
    if sp.extra:
        nl = sp.lam.size
        note = ", ".join(f"{d} = {v[0]}" for d, v in sp.extra)
        sp = dataclasses.replace(
            sp, theta_max=sp.theta_max.reshape(-1, *sp.theta_max.shape[-3:])[0],
            outcome=sp.outcome.reshape(-1, *sp.outcome.shape[-3:])[0],
            a_min=sp.a_min[:nl], extra=())
    nl = sp.lam.size
    alpha = _axes.alpha_latex(sp.kind)
    amp = _axes.latex("A_ratio", sp.kind)
    fig = Figure(figsize=figsize or (3.3 * (nl + 1), 3.4), layout="constrained")
    axes = fig.subplots(1, nl + 1, squeeze=False)[0]
    pick = np.unique(np.linspace(0, sp.A.size - 1, min(MAX_CURVES, sp.A.size)).round()
                     .astype(int))
    colors = [f"C{k}" for k in range(len(pick))]
    for k, ax in enumerate(axes[:nl]):
        for n, (c, i) in enumerate(zip(colors, pick, strict=True)):
            th = sp.theta_max[k, i]
            over = sp.outcome[k, i] > 0
            shown = np.where(over, np.nan, th)
            ax.plot(sp.x, shown, color=c, lw=1.2,
                    label=f"${amp}$ = {sp.A[i]:.3g}")
            # overturned: a row of x per curve above 1, stacked so that none hides another
            ax.plot(sp.x[over], np.full(over.sum(), 1.03 + 0.025 * n), "x", color=c, ms=3)
        ax.axhline(1.0, color="0.5", lw=0.6, ls=":")
        ax.set_ylim(0.0, 1.06 + 0.025 * len(pick))
        ax.set_xlabel(_axes.label(sp.freq))
        lam = "" if np.isnan(sp.lam[k]) else f", ${_axes.latex('lam')}$ = {sp.lam[k]:g}"
        title = "rocking spectrum" + lam
        ax.set_title(title, fontsize=9)
        ax.tick_params(labelsize=7)
    axes[0].set_ylabel(rf"max$|\theta|/{alpha}$ (x: overturned)")
    axes[0].legend(fontsize=6, loc="center right", frameon=False)
    ax = axes[nl]
    for k, c in enumerate(sp.a_min):
        color = f"C{k}"
        lam = sp.lam[k]
        ax.plot(c.x, c.a_min, color=color, lw=1.2,
                label="" if np.isnan(lam) else f"${_axes.latex('lam')}$ = {lam:g}")
        m1, m2 = c.mode == 1, c.mode == 2
        ax.plot(c.x[m1], c.a_min[m1], "o", color=color, ms=3)
        ax.plot(c.x[m2], c.a_min[m2], "^", color=color, ms=4, mfc="none")
    ax.plot([], [], "o", color="0.3", ms=3, label="mode 1")
    ax.plot([], [], "^", color="0.3", ms=4, mfc="none", label="mode 2")
    ax.set_xlabel(_axes.label(sp.freq))
    ax.set_ylabel(f"smallest ${amp}$ that overturns")
    ax.set_ylim(0.0, float(sp.A.max()) * 1.02)
    ax.set_title(f"overturning spectrum (bisected to {sp.rtol:g})", fontsize=9)
    ax.legend(fontsize=6, frameon=False)
    ax.tick_params(labelsize=7)
    fig.suptitle(sp.name + (f" ({sp.record})" if sp.record and sp.record not in sp.name
                            else "") + (f" at {note}" if note else ""), fontsize=10)
    return fig
