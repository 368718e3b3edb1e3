"""What every diagram of a sweep shares (the stability diagram, the comparison, the line
plot and the friction map, ``figures.diagrams``, ``figures.compare``, ``figures.friction``):
which swept axes go on x and y (``choose_axes``: x = omega/p and y = A/(g tan alpha_ref) when
both are swept), the result's arrays in drawing order (numeric axes ascending), one panel
per value of every other swept key and their grid, titles and axis labels, the fill colours
of the classes, the crosses of flagged points, the class boundary lines and the legend of
a diagram drawn into the caller's axes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from itertools import product
from typing import TYPE_CHECKING

import numpy as np

from rocksweep.errors import Arg, DiagramError
from rocksweep.fields import WORD_AXES
from rocksweep.figures.style import Figure, given_axes, new_axes, wrap_title
from rocksweep.store.reader import SweepResult
from rocksweep.vocab import axes as _axes
from rocksweep.vocab.axes import DIAGRAM_AXES, RECORD_X
from rocksweep.vocab.axes import label as axis_label
from rocksweep.vocab.outcomes import FLAGGED_WORDS, STATUS_BIT

if TYPE_CHECKING:
    from matplotlib.axes import Axes

MAX_PANELS = 36

DEFAULT_X, DEFAULT_Y = DIAGRAM_AXES  # symbols, units: rocksweep.vocab.axes

# the cells' fills: safe (at every lam or compared value), mode 2, not computed
SAFE_COLOUR, MODE2_COLOUR, NOT_RUN_COLOUR = "#ffffff", "#4c72b0", "#bdbdbd"
# boundary lines of the k-th lam (``curves``): dark colours apart from the cells' fills
CURVE_COLOURS = ("black", "#1b9e77", "#7570b3", "#e7298a", "#66a61e", "#a6761d")


def value_text(v) -> str:
    """A coordinate value as a label writes it (floats shortest, ``:g``)."""
    return f"{v:g}" if isinstance(v, float | np.floating) else str(v)


# ---------------------------------------------------------------------------------------
# Which axes to draw
# ---------------------------------------------------------------------------------------

def plottable(result: SweepResult) -> list[str]:
    """Swept numeric dimensions with two or more values (what x and y may be)."""
    return [d for d in result.dims if d not in WORD_AXES and len(result.coords[d]) >= 2]


def flag_label(result: SweepResult) -> str:
    """The legend's words for the x marks: the flags (``FLAGGED_WORDS``) the drawn points
    carry, e.g. "flagged (uncertified)"."""
    status = np.asarray(result.arrays["status"]).astype(np.int64)[result.flagged & result.done]
    bits = int(np.bitwise_or.reduce(status)) if status.size else 0
    return "flagged (" + ", ".join(w for w in FLAGGED_WORDS if bits & STATUS_BIT[w]) + ")"


def swept_dim(result: SweepResult, key: str, arg: str) -> str:
    """The dimension a swept ``key`` (a name or a scene key) names; a DiagramError naming
    the argument ``arg`` (x, y) otherwise."""
    name = key.split(".", 1)[1] if key.startswith(("body.", "pulse.", "impact.")) else key
    ok = plottable(result)
    if name not in ok:
        why = ("pulse shapes are drawn as panels, not along an axis" if name == "shape"
               else "impact laws are drawn as panels (or compared: {compare}), not along "
               "an axis" if name == "law"
               else "has one value" if name in result.dims
               else "not swept" if name in result.scalars
               else "no such axis")
        raise DiagramError(f"{{path}}: {{arg}}: {why}; swept axes: "
                           f"{', '.join(ok) or '(none with two or more values)'}",
                           path=result.path, arg=Arg(arg, key),
                           compare=Arg("compare", "impact.law"))
    return name


def choose_axes(result: SweepResult, x: str | None = None, y: str | None = None
                ) -> tuple[str, str | None]:
    """The (x, y) dimensions to draw; y None: a 1-D line plot over x.

    Defaults: x = w_over_p and y = A_ratio when swept, else other swept axes (lam last:
    it is layered in the colours when on neither axis). With fewer than two swept axes
    besides lam, a line plot over the one left (one line per lam). Keys may be given as
    names (``alpha_cg``) or scene keys (``body.alpha_cg``); errors name them as the
    arguments ``x`` and ``y``.
    """
    if x is not None:
        x = swept_dim(result, x, "x")
    if y is not None:
        y = swept_dim(result, y, "y")
    if x is not None and x == y:
        raise DiagramError(f"{{path}}: {{x}} and {{y}} are both {x}; choose two different "
                           f"swept axes: {', '.join(plottable(result))}", path=result.path,
                           x=Arg("x"), y=Arg("y"))
    axes = plottable(result)
    if not axes:
        raise DiagramError(f"{result.path}: no swept axis with two or more values to draw; "
                           "sweep at least one key (a list or a range)")
    rest = [d for d in axes if d != "lam" and d not in (x, y)]
    if x is None:
        if y is None and len(rest) < 2:
            return (rest[0] if rest else "lam"), None  # a line plot
        if DEFAULT_X in rest:
            x = DEFAULT_X
        elif RECORD_X in rest:  # a record sweep: the body's p sets its time scale
            x = RECORD_X
        else:
            pool = ([d for d in rest if d != DEFAULT_Y] or rest
                    or (["lam"] if "lam" in axes and y != "lam" else []))
            x = pool[0] if pool else None
            if x is None:
                raise DiagramError(f"{{path}}: {{y}}: no other swept axis for x; swept axes: "
                                   f"{', '.join(axes)}", path=result.path, y=Arg("y", y))
        rest = [d for d in rest if d != x]
    if y is None and rest:
        y = DEFAULT_Y if DEFAULT_Y in rest else DEFAULT_X if DEFAULT_X in rest else rest[0]
    return x, y


# ---------------------------------------------------------------------------------------
# Panels: arrays in drawing order, their grid, titles and marks
# ---------------------------------------------------------------------------------------

def in_order(result: SweepResult, order: list[str], names: Sequence[str]) -> list[np.ndarray]:
    """result arrays transposed to ``order``; numeric axes sorted ascending."""
    dims = list(result.dims)
    perm = [dims.index(d) for d in order]
    out = []
    for a in names:
        v = np.transpose(a if isinstance(a, np.ndarray) else result.arrays[a], perm)
        for axis, d in enumerate(order):
            if d not in WORD_AXES:
                v = np.take(v, np.argsort(np.asarray(result.coords[d], float), kind="stable"),
                            axis=axis)
        out.append(v)
    return out


def coord(result: SweepResult, d: str) -> np.ndarray:
    """The values of dimension ``d`` in drawing order (numeric ones ascending)."""
    vals = result.coords[d]
    return vals if d in WORD_AXES else np.sort(np.asarray(vals, float), kind="stable")


def panel_indices(result: SweepResult, panel_dims: list[str]) -> list[tuple[int, ...]]:
    """The index of every panel (one per value of each of ``panel_dims``), at most
    ``MAX_PANELS``."""
    panels = list(product(*(range(len(result.coords[d])) for d in panel_dims)))
    if len(panels) > MAX_PANELS:
        raise DiagramError(f"{result.path}: {len(panels)} panels "
                           f"({' x '.join(panel_dims)}); at most {MAX_PANELS} fit a figure; "
                           "choose other axes x and y or sweep fewer values")
    return panels


def grid_shape(result: SweepResult, panel_dims: list[str], n: int) -> tuple[int, int]:
    """(rows, columns) of ``n`` panels."""
    per_first = n // len(result.coords[panel_dims[0]]) if panel_dims else 1
    # a row per value of the first panel key (the pulse shape) when that fits, else 3 across
    ncols = per_first if len(panel_dims) >= 2 and per_first <= 4 else min(n, 3)
    return math.ceil(n / ncols), ncols


def panel_title(result: SweepResult, panel_dims: list[str], idx: tuple[int, ...]) -> str:
    """A panel's title: its values of the panel keys."""
    parts = []
    for d, i in zip(panel_dims, idx, strict=True):
        v = coord(result, d)[i]
        parts.append(f"{v} pulse" if d == "shape" else f"law {v}" if d == "law"
                     else f"${_axes.latex(d)}$ = {value_text(v)}")
    return ", ".join(parts)


def figure_title(result: SweepResult, on_axes: Sequence[str]) -> str:
    """The scene's name, plus the unswept pulse values it does not already state (said
    once: panels name only what varies between them)."""
    name = result.name
    extra = []
    shape = result.scalars.get("shape")
    if shape is not None and f"{shape} pulse" not in name.lower():
        extra.append(f"{shape} pulse")
    for d in DIAGRAM_AXES:
        if d in result.scalars and d not in on_axes:
            sym = _axes.latex(d, result.kind)
            extra.append(f"${sym}$ = {value_text(float(result.scalars[d]))}")
    return ", ".join([name, *extra])


def fitted_title(title: str, fig: Figure) -> str:
    """A title wrapped to the figure's width at 11 pt (``style.wrap_title``)."""
    return wrap_title(title, fig.get_figwidth(), 11.0)


def place_axes(axes, n: int, rows_cols: tuple[int, int], size: tuple[float, float],
               what: str) -> tuple[Figure, list, bool]:
    """(figure, one Axes per panel, whether the figure is new): a new figure of
    ``rows_cols`` panels of ``size`` inches each, or the caller's ``axes`` (``what``: the
    figure, in the error when they do not fit)."""
    if axes is None:
        nrows, ncols = rows_cols
        fig, grid = new_axes(nrows, ncols, (size[0] * ncols, size[1] * nrows + 0.9))
        flat = list(grid.flat)
        for ax in flat[n:]:
            ax.set_visible(False)
        return fig, flat[:n], True
    fig, flat = given_axes(axes, n, what)
    return fig, flat, False


def mark_flagged(ax: Axes, flagged: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> bool:
    """Cross the cells flagged (undecided) at any lam or compared value (flagged[n, ny,
    nx]); whether there was one."""
    f_any = flagged.any(axis=0)
    if not f_any.any():
        return False
    yy, xx = np.nonzero(f_any)
    ax.plot(xs[xx], ys[yy], "x", color="k", ms=3.5, mew=0.7)
    return True


def draw_boundaries(ax: Axes, po: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> None:
    """The boundary lines of each lam layer of a panel (po: outcome[n_lam, ny, nx], axes
    ascending) in its colour; lines along points not computed yet are left out."""
    # analysis.boundaries loads numba and scipy: a diagram without curves pays for neither
    from rocksweep.analysis.boundaries import boundary_lines

    for k in range(po.shape[0]):
        colour = CURVE_COLOURS[k % len(CURVE_COLOURS)]
        for line in boundary_lines(po[k], np.asarray(xs, float), np.asarray(ys, float)):
            if min(line.classes) < 0:
                continue
            ax.plot(line.xy[:, 0], line.xy[:, 1], color=colour, lw=0.8,
                    ls=("-", "--", ":", "-.")[k // len(CURVE_COLOURS) % 4])


def label_panel(ax: Axes, result: SweepResult, panel_dims, idx, x: str, y: str,
                area: list[str]) -> None:
    """A diagram panel's mode 1 area box (one line per lam or compared value), title and
    axis labels."""
    ax.text(0.98, 0.02, "mode 1 area\n" + "\n".join(area), transform=ax.transAxes,
            ha="right", va="bottom", fontsize=7,
            bbox={"boxstyle": "round", "fc": "white", "ec": "0.6", "alpha": 0.85})
    ax.set_title(panel_title(result, panel_dims, idx), fontsize=10)
    ax.set_xlabel(axis_label(x, result.kind))
    ax.set_ylabel(axis_label(y, result.kind))


def legend_outside(ax: Axes, handles: list) -> None:
    """The legend of a diagram drawn into the caller's axes: outside them, on the right,
    and once per figure (a second diagram drawn into the same figure adds none)."""
    fig = ax.figure
    if getattr(fig, "_rocksweep_legend", False):
        return
    ax.legend(handles=handles, fontsize="small", loc="upper left",
              bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, frameon=False)
    fig._rocksweep_legend = True
