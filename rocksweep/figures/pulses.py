"""The pulse shapes' figure (docs/excitations.md's plot of ``rocksweep.physics.excitation``)."""

from __future__ import annotations

import numpy as np

from rocksweep.figures.style import Figure
from rocksweep.physics.excitation import PulseShape, default_shapes
from rocksweep.vocab.ground import SHAPE_TITLE, SHAPES


def shapes_figure(shapes: tuple[PulseShape, ...] | None = None,
                  figsize: tuple[float, float] = (10.0, 2.6)) -> Figure:
    """A figure of xg''/A against w t, one panel per family (sine, cosine, Ricker, MP).

    Shapes of the same family share a panel. Returns a pyplot-free Figure."""
    shapes = default_shapes() if shapes is None else tuple(shapes)
    families = [s for s in SHAPES if any(p.shape == s for p in shapes)]
    fig = Figure(figsize=figsize, layout="constrained")
    axes = fig.subplots(1, len(families), sharey=True, squeeze=False)[0]
    for ax, family in zip(axes, families, strict=True):
        members = [p for p in shapes if p.shape == family]
        d_max = max(p.duration for p in members)
        for k, p in enumerate(members):
            phi = np.linspace(-0.05 * d_max, 1.05 * d_max, 2000)
            ax.plot(phi, p.acc(phi), lw=1.2, ls=("-", "--", ":")[k % 3], label=p.label)
        ax.axhline(0.0, color="0.6", lw=0.5)
        ax.set_title(SHAPE_TITLE[family], fontsize=9)
        ax.set_xlabel(r"$\omega t$")
        ax.set_ylim(-1.8, 1.15)  # room below the curves for the legend
        ax.legend(fontsize=6, loc="lower center", frameon=False)
        ax.tick_params(labelsize=7)
    axes[0].set_ylabel(r"$\ddot x_g / A$")
    return fig
