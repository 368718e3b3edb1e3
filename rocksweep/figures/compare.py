"""Comparing the values of one swept key on one diagram (``rocksweep.plot(compare=
"impact.law")``): each cell coloured by which values overturn it (under every value, only
under one, under some), white where none does, blue where every value gives mode 2; each
panel lists the mode 1 area per value, ``curves`` overlays every value's boundary lines.
Axes and panels as a stability diagram's (``figures.panels``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from rocksweep.errors import Arg, DiagramError
from rocksweep.fields import WORD_AXES
from rocksweep.figures.panels import (
    CURVE_COLOURS,
    MODE2_COLOUR,
    NOT_RUN_COLOUR,
    SAFE_COLOUR,
    choose_axes,
    coord,
    draw_boundaries,
    figure_title,
    fitted_title,
    flag_label,
    grid_shape,
    in_order,
    label_panel,
    legend_outside,
    mark_flagged,
    panel_indices,
    place_axes,
    value_text,
)
from rocksweep.figures.style import Figure
from rocksweep.store.reader import SweepResult
from rocksweep.vocab import axes as _axes
from rocksweep.vocab.outcomes import OUTCOME_MODE1, OUTCOME_MODE2, OUTCOME_NOT_RUN

if TYPE_CHECKING:
    from matplotlib.axes import Axes

MAX_COMPARED = 4  # values of the compared key: 2^4 - 1 overturning sets at most
_ALL = "#b2182b"  # overturns under every value
_ONLY = ("#ff7f00", "#33a02c", "#6a3d9a", "#b15928")  # overturns under one value only
_SOME = ("#fdbf6f", "#b2df8a", "#cab2d6", "#ffff99", "#a6cee3", "#fb9a99", "#e0e0e0",
         "#dfc27d", "#80cdc1", "#c2a5cf", "#f6e8c3")  # under some values (not one, not all)


def compare_categories(outcome: np.ndarray) -> np.ndarray:
    """Colour category per cell from outcome[n, ...] (axis 0: the compared key's values).

    0 not computed (under some value), 1 safe under every value, 2 mode 2 under every
    value, 2 + mask otherwise: mask (1 .. 2^n - 1) has bit k set where the k-th value
    overturns the cell (mode 1 or mode 2).
    """
    n = outcome.shape[0]
    over = (outcome == OUTCOME_MODE1) | (outcome == OUTCOME_MODE2)
    mask = np.zeros(outcome.shape[1:], np.int64)
    for k in range(n):
        mask |= over[k].astype(np.int64) << k
    cat = np.where(mask > 0, 2 + mask, 1)
    cat[(outcome == OUTCOME_MODE2).all(axis=0)] = 2
    cat[(outcome == OUTCOME_NOT_RUN).any(axis=0)] = 0
    return cat


def _compare_colour(mask: int, n: int) -> str:
    if mask == (1 << n) - 1:
        return _ALL
    if mask & (mask - 1) == 0:
        return _ONLY[mask.bit_length() - 1]
    others = [m for m in range(1, (1 << n) - 1) if m & (m - 1)]
    return _SOME[others.index(mask) % len(_SOME)]


def _value_label(name: str, v) -> str:
    if name in WORD_AXES:
        return str(v)
    return f"${_axes.latex(name)}$ = {value_text(v)}"


def _set_label(mask: int, labels: list[str], what: str) -> str:
    n = len(labels)
    names = [labels[k] for k in range(n) if mask >> k & 1]
    if mask == (1 << n) - 1:
        return "overturns under " + ("both " + what + "s" if n == 2 else f"every {what}")
    if len(names) == 1:
        return f"overturns only under {names[0]}"
    return f"overturns only under {', '.join(names[:-1])} and {names[-1]}"


def compare_diagram(result: SweepResult, key: str, x: str | None = None,
                    y: str | None = None, *, axes: Axes | Sequence[Axes] | None = None,
                    curves: bool = False) -> Figure:
    """One diagram per panel comparing the values of the swept key ``key`` (e.g.
    ``impact.law`` or ``lam``): each cell is coloured by which values overturn it (under
    both, only under ``locked``, only under ``vertical``, ...; blue: mode 2 under every
    value, white: safe under every value), each panel lists the mode 1 area per value;
    curves: every value's boundary lines overlaid, one colour each. One panel per value of
    the other swept keys. Needs ``outcome`` and ``status``."""
    name = key.split(".", 1)[1] if key.startswith(("body.", "pulse.", "impact.")) else key
    if name not in result.dims or len(result.coords[name]) < 2:
        swept = [d for d in result.dims if len(result.coords[d]) >= 2]
        why = "has one value" if name in result.dims else (
            "not swept" if name in result.scalars else "no such key")
        raise DiagramError(f"{{path}}: {{key}}: {why}; keys with two or more values: "
                           f"{', '.join(swept) or '(none)'}", path=result.path,
                           key=Arg("compare", key))
    n = len(result.coords[name])
    if n > MAX_COMPARED:
        raise DiagramError(f"{{path}}: {{key}}: {n} values; at most {MAX_COMPARED} can be "
                           "compared in one diagram", path=result.path,
                           key=Arg("compare", key))
    x, y = choose_axes(result, x, y)
    if y is None or name in (x, y):
        raise DiagramError(f"{{path}}: {{key}}: needs two other swept axes for the diagram "
                           f"(x {x}, y {y}); choose them with {{x}} and {{y}}",
                           path=result.path, key=Arg("compare", key), x=Arg("x"), y=Arg("y"))
    dims = list(result.dims)
    panel_dims = [d for d in dims if d not in (x, y, name)]
    order = [*panel_dims, name, y, x]
    flagged = result.flagged & result.done
    o, fl = in_order(result, order, ["outcome", flagged])
    values = list(coord(result, name))
    labels = [_value_label(name, v) for v in values]
    what = "law" if name == "law" else f"${_axes.latex(name, result.kind)}$ value"
    panels = panel_indices(result, panel_dims)
    n_cat = 3 + (1 << n) - 1
    colours = [NOT_RUN_COLOUR, SAFE_COLOUR, MODE2_COLOUR,
               *(_compare_colour(m, n) for m in range(1, 1 << n))]
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(-0.5, n_cat), cmap.N)
    xs, ys = coord(result, x), coord(result, y)
    fig, flat, own = place_axes(axes, len(panels), grid_shape(result, panel_dims, len(panels)),
                                (4.8, 4.2), "this comparison")
    used = np.zeros(n_cat, bool)
    any_flag = False
    for ax, idx in zip(flat, panels, strict=False):
        po, pf = o[idx], fl[idx]  # [n, n_y, n_x]
        cat = compare_categories(po)
        used[np.unique(cat)] = True
        ax.pcolormesh(xs, ys, cat, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        if curves:
            draw_boundaries(ax, po, xs, ys)
        any_flag |= mark_flagged(ax, pf, xs, ys)
        done = po != OUTCOME_NOT_RUN
        area = [f"{lab}: {100 * (po[k] == OUTCOME_MODE1).sum() / done[k].sum():.1f}%"
                if done[k].any() else f"{lab}: -" for k, lab in enumerate(labels)]
        label_panel(ax, result, panel_dims, idx, x, y, area)

    handles = []
    if used[1]:
        handles.append(Patch(fc=SAFE_COLOUR, ec="0.5", label=f"safe under every {what}"))
    full = (1 << n) - 1
    for m in [full, *(1 << k for k in range(n)),
              *(m for m in range(1, full) if m & (m - 1))]:
        if used[2 + m]:
            handles.append(Patch(fc=colours[2 + m], ec="0.5", label=_set_label(m, labels, what)))
    if used[2]:
        handles.append(Patch(fc=MODE2_COLOUR, ec="0.5", label=f"mode 2 under every {what}"))
    if used[0]:
        handles.append(Patch(fc=NOT_RUN_COLOUR, ec="0.5", label="not computed"))
    if any_flag:
        handles.append(Line2D([], [], ls="", marker="x", color="k",
                              label=flag_label(result)))
    if curves:
        for k, lab in enumerate(labels):
            handles.append(Line2D([], [], color=CURVE_COLOURS[k % len(CURVE_COLOURS)], lw=1.0,
                                  label=f"boundaries under {lab}"))
    if own:
        ncols = grid_shape(result, panel_dims, len(panels))[1]
        fig.legend(handles=handles, loc="outside lower center", fontsize=8, frameon=False,
                   ncol=max(1, min(len(handles), ncols + 1)))
        fig.suptitle(fitted_title(figure_title(result, (x, y)) + f": {what}s compared", fig),
                     fontsize=11)
    else:
        legend_outside(flat[-1], handles)
    return fig
