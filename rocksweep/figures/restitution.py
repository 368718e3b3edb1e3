"""Figure 2 of the paper: the coefficient of restitution e of eq. (1) against lam and
against u/u_cr (``rocksweep restitution --plot``), built on ``rocksweep.figures.style``."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from rocksweep.figures.style import Figure, given_axes, new_axes
from rocksweep.vocab.laws import DEFAULT_LAW, EQ1, law_origin

if TYPE_CHECKING:
    from matplotlib.axes import Axes

# u/u_cr -> colour: blues below 0, reds above, black at 0 (the rigid-like case must stand
# out on white, so no light middle colour of a diverging map)
_U_COLOURS = {-2.0: "#2166ac", -1.0: "#67a9cf", 0.0: "#000000", 1.0: "#ef8a62",
              2.0: "#b2182b"}


def restitution_map(lam: np.ndarray, u_over_ucr: np.ndarray, e_upper: np.ndarray,
                    e_housner: float, title: str = "",
                    axes: Sequence[Axes] | None = None, lam_limit: np.ndarray | None = None,
                    law: str = DEFAULT_LAW) -> Figure:
    """Figure 2: (a) e against lam for u/u_cr = -2, -1, 0, 1, 2; (b) e against u/u_cr at
    lam = 0 with Housner's e of the same body welded rigid.

    lam: float[n_lam]; u_over_ucr: float[n_u]; e_upper: float[n_lam, n_u], eq. (1) (or
    the impact law ``law``'s e) under the paper's upper sign (the lower sign is its
    mirror, e_lower(lam, u) = e_upper(lam, -u)); axes: 2 axes to draw into (else a new
    figure). lam_limit: float[n_u], the largest lam at which an impact cannot gain energy
    (``rocksweep.physics.impact.lam_energy_limit``; 2: none up to 2, NaN: every lam
    gains): (a) draws each curve dashed beyond it with a diamond at it, (b) draws it
    against u/u_cr on a right-hand axis.
    """
    if axes is None:
        fig, grid = new_axes(1, 2, (11, 4.6))
        ax_a, ax_b = grid[0]
    else:
        fig, (ax_a, ax_b) = given_axes(axes, 2, "the restitution figure")
    lam = np.asarray(lam, float)
    u_over_ucr = np.asarray(u_over_ucr, float)
    e_upper = np.asarray(e_upper, float)
    for v, colour in _U_COLOURS.items():
        if not u_over_ucr.min() <= v <= u_over_ucr.max():
            continue
        j = int(np.argmin(abs(u_over_ucr - v)))
        lw = 2.0 if v == 0 else 1.4
        label = f"$u/u_{{cr}}$ = {v:g}"
        if lam_limit is None:
            ax_a.plot(lam, e_upper[:, j], color=colour, lw=lw, label=label)
            continue
        lim = float(lam_limit[j])
        lim = -np.inf if np.isnan(lim) else lim
        ok = lam <= lim
        ax_a.plot(lam, np.where(ok, e_upper[:, j], np.nan), color=colour, lw=lw, label=label)
        ax_a.plot(lam, np.where(ok, np.nan, e_upper[:, j]), color=colour, lw=lw * 0.7, ls="--")
        if lam[0] <= lim <= lam[-1]:
            ax_a.plot([lim], [np.interp(lim, lam, e_upper[:, j])], "D", color=colour, ms=5)
    if lam_limit is not None:
        ax_a.plot([], [], "D", color="0.3", ms=5, ls="--", lw=1.0,
                  label=r"energy-admissible $\lambda$ (dashed: impacts gain energy)")
    ax_a.axhline(1.0, color="0.5", lw=0.6, ls="--")
    ax_a.axhline(0.0, color="0.5", lw=0.6)
    ax_a.set_xlabel(r"$\lambda$")
    ax_a.set_ylabel("$e$")
    which = "upper sign of eq. 1" if law == EQ1 else f"law {law}, upper sign"
    ax_a.set_title(rf"(a) $e$ against $\lambda$ ({which})", fontsize=10)
    ax_a.legend(fontsize=8)
    i0 = int(np.argmin(abs(lam)))
    first = law_origin(law) if law == EQ1 else f"law {law}"
    ax_b.plot(u_over_ucr, e_upper[i0], color="C0",
              label=rf"{first}, $\lambda$ = {lam[i0]:g}, upper sign")
    ax_b.plot(u_over_ucr, e_upper[i0, ::-1], color="C1", ls="--",
              label="lower sign (mirror)")
    ax_b.axhline(e_housner, color="k", lw=0.8, ls=":",
                 label=f"Housner, rigid body: {e_housner:.3f}")
    ax_b.set_xlabel(r"$u/u_{cr}$")
    ax_b.set_ylabel("$e$")
    ax_b.set_title(rf"(b) $e$ against $u/u_{{cr}}$ at $\lambda$ = {lam[i0]:g}", fontsize=10)
    if lam_limit is not None:
        ax_c = ax_b.twinx()
        ax_c.plot(u_over_ucr, lam_limit, color="C2", lw=1.2, ls="-.")
        ax_c.set_ylabel(r"largest $\lambda$ without energy gain", color="C2")
        ax_c.tick_params(axis="y", colors="C2")
        ax_b.plot([], [], color="C2", lw=1.2, ls="-.",
                  label=r"energy-admissible $\lambda$ (right axis)")
    ax_b.legend(fontsize=8)
    for ax in (ax_a, ax_b):
        ax.grid(alpha=0.3)
    if title and axes is None:
        fig.suptitle(title, fontsize=11)
    return fig
