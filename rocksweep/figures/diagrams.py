"""Stability diagrams (Figures 3 and 4 of the paper) from a sweep result, over any two
swept axes, and line plots of 1-D sweeps.

By default x = omega/p and y = A/(g tan alpha_ref) (alpha_ref = alpha_cg for the paper's
flexible body, alpha for a block) when both are swept; ``x``/``y`` pick any other swept
axis (e.g. ``alpha_cg`` against ``A_ratio``). Each cell is coloured by what the pulse does:

- mode 2 (overturned without impact): blue. It does not depend on lam, which acts only
  at impacts;
- mode 1 (overturned after one or more impacts): red at the smallest lam, and lighter
  shades where a point first overturns in mode 1 at a larger lam, so the growth of the
  mode 1 area with lam is visible at a glance (the paper's claim). This layering is used
  when lam is swept and on neither axis;
- safe at every lam: white; not computed yet: grey.

With ``curves``, the boundary lines between classes (``rocksweep.analysis.boundaries``) of every
lam are drawn over the cells, one colour per lam. ``a_min_figure`` draws A_min(omega/p)
curves of several panels (e.g. lam values) on one axis, as the paper compares them.
Filled cells of an adaptive sweep are drawn as computed ones.

Points that are mode 1 at some lam but safe again at a larger one get a black dot;
flagged points (horizon, step or event cap, non-finite: ``STATUS_FLAGGED``) an ``x``.
Each panel also lists the mode 1 area (fraction of its points) for every lam. One panel
per pulse shape and per value of any other swept key.

A sweep with one swept numeric axis (besides lam) is drawn as max|theta|/alpha_ref against
that axis, one line per lam, the markers coloured by outcome.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from itertools import product
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from rocksweep.errors import Arg, DiagramError, flag
from rocksweep.fields import WORD_AXES
from rocksweep.figures import DEFAULT_DPI
from rocksweep.figures.style import (
    Figure,
    curve_colours,
    given_axes,
    new_axes,
    save_figure,
    wrap_title,
)
from rocksweep.store.reader import SweepResult
from rocksweep.vocab import axes as _axes
from rocksweep.vocab.axes import DIAGRAM_AXES, RECORD_X
from rocksweep.vocab.outcomes import (
    FLAGGED_WORDS,
    LIFTS_OFF,
    OUTCOME_MODE1,
    OUTCOME_MODE2,
    OUTCOME_NOT_RUN,
    OUTCOME_SAFE,
    SLIDES,
    STATUS_BIT,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from rocksweep.analysis.boundaries import AMinCurve, PanelBoundaries

__all__ = ["choose_axes", "stability_diagram", "line_diagram",
           "compare_diagram", "compare_categories",
           "sweep_figure", "stability_figure", "missing_warnings", "categories", "y_label",
           "a_min_figure"]

MAX_PANELS = 36

DEFAULT_X, DEFAULT_Y = DIAGRAM_AXES  # symbols, units: rocksweep.vocab.axes


_SAFE, _MODE2, _NOT_RUN = "#ffffff", "#4c72b0", "#bdbdbd"
_UNSURE = "#e69f00"  # rings: the outcome changes at half the step (outputs.check)
# boundary lines of the k-th lam (``curves``): dark colours apart from the cells' fills
CURVE_COLOURS = ("black", "#1b9e77", "#7570b3", "#e7298a", "#66a61e", "#a6761d")



def _fmt(v) -> str:
    return f"{v:g}" if isinstance(v, float | np.floating) else str(v)


def y_label(kind: str) -> str:
    """Label of the amplitude axis A/(g tan alpha_ref) for a body kind."""
    return _axes.label("A_ratio", kind)


def axis_label(dim: str, kind: str) -> str:
    """Axis label of a swept dimension (the paper's symbol, units where they are not 1)."""
    return _axes.label(dim, kind)


def categories(outcome: np.ndarray) -> np.ndarray:
    """Colour category per cell from outcome[n_lam, ...] (lam ascending along axis 0).

    0 not computed, 1 safe at every lam, 2 mode 2 (at the smallest lam), 3 + k mode 1 first
    at the k-th lam.
    """
    n_lam = outcome.shape[0]
    cat = np.zeros(outcome.shape[1:], np.int64)
    done_all = (outcome != OUTCOME_NOT_RUN).all(axis=0)
    cat[done_all & (outcome == OUTCOME_SAFE).all(axis=0)] = 1
    mode1 = outcome == OUTCOME_MODE1
    first = np.where(mode1.any(axis=0), mode1.argmax(axis=0), n_lam)
    for k in range(n_lam):
        cat[first == k] = 3 + k
    cat[outcome[0] == OUTCOME_MODE2] = 2
    return cat


def mode1_colours(n_lam: int) -> list:
    import matplotlib

    cmap = matplotlib.colormaps["YlOrRd"]
    if n_lam == 1:
        return [cmap(0.75)]
    return [cmap(0.85 - 0.6 * k / (n_lam - 1)) for k in range(n_lam)]


# ---------------------------------------------------------------------------------------
# Which axes to draw
# ---------------------------------------------------------------------------------------

def plottable(result: SweepResult) -> list[str]:
    """Swept numeric dimensions with two or more values (what x and y may be)."""
    return [d for d in result.dims if d not in WORD_AXES and len(result.coords[d]) >= 2]


def _flag_label(result: SweepResult) -> str:
    """The legend's words for the x marks: the flags (``FLAGGED_WORDS``) the drawn points
    carry, e.g. "flagged (uncertified)"."""
    status = np.asarray(result.arrays["status"]).astype(np.int64)[result.flagged & result.done]
    bits = int(np.bitwise_or.reduce(status)) if status.size else 0
    return "flagged (" + ", ".join(w for w in FLAGGED_WORDS if bits & STATUS_BIT[w]) + ")"


def _check_key(result: SweepResult, key: str, arg: str) -> str:
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
        x = _check_key(result, x, "x")
    if y is not None:
        y = _check_key(result, y, "y")
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
# Drawing
# ---------------------------------------------------------------------------------------

def _arrays(result: SweepResult, order: list[str], names: Sequence[str]) -> list[np.ndarray]:
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


def _coord(result: SweepResult, d: str) -> np.ndarray:
    vals = result.coords[d]
    return vals if d in WORD_AXES else np.sort(np.asarray(vals, float), kind="stable")


def _panels(result: SweepResult, panel_dims: list[str]) -> list[tuple[int, ...]]:
    panels = list(product(*(range(len(result.coords[d])) for d in panel_dims)))
    if len(panels) > MAX_PANELS:
        raise DiagramError(f"{result.path}: {len(panels)} panels "
                           f"({' x '.join(panel_dims)}); at most {MAX_PANELS} fit a figure; "
                           "choose other axes x and y or sweep fewer values")
    return panels


def _layout(result: SweepResult, panel_dims: list[str], n: int) -> tuple[int, int]:
    per_first = n // len(result.coords[panel_dims[0]]) if panel_dims else 1
    # a row per value of the first panel key (the pulse shape) when that fits, else 3 across
    ncols = per_first if len(panel_dims) >= 2 and per_first <= 4 else min(n, 3)
    return math.ceil(n / ncols), ncols


def _panel_title(result: SweepResult, panel_dims: list[str], idx: tuple[int, ...]) -> str:
    parts = []
    for d, i in zip(panel_dims, idx, strict=True):
        v = _coord(result, d)[i]
        parts.append(f"{v} pulse" if d == "shape" else f"law {v}" if d == "law"
                     else f"${_axes.latex(d)}$ = {_fmt(v)}")
    return ", ".join(parts)


def _title(result: SweepResult, on_axes: Sequence[str]) -> str:
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
            extra.append(f"${sym}$ = {_fmt(float(result.scalars[d]))}")
    return ", ".join([name, *extra])


def _fit(title: str, fig: Figure) -> str:
    """A title wrapped to the figure's width at 11 pt (``style.wrap_title``)."""
    return wrap_title(title, fig.get_figwidth(), 11.0)


def _place_axes(axes, n: int, rows_cols: tuple[int, int], size: tuple[float, float],
                what: str) -> tuple[Figure, list, bool]:
    if axes is None:
        nrows, ncols = rows_cols
        fig, grid = new_axes(nrows, ncols, (size[0] * ncols, size[1] * nrows + 0.9))
        flat = list(grid.flat)
        for ax in flat[n:]:
            ax.set_visible(False)
        return fig, flat[:n], True
    fig, flat = given_axes(axes, n, what)
    return fig, flat, False


def stability_diagram(result: SweepResult, x: str | None = None, y: str | None = None, *,
                      axes: Axes | Sequence[Axes] | None = None,
                      curves: bool = False, show_computed: bool = False) -> Figure:
    """The stability diagram of ``result`` over swept axes x and y (see the module
    docstring; defaults from ``choose_axes``). Needs the ``outcome`` and ``status``
    arrays. axes: one Axes per panel to draw into (else a new figure); curves: overlay
    the boundary lines of every lam; show_computed: shade the cells an adaptive sweep
    computed at some lam (needs the ``computed`` array). Returns the figure.
    """
    x, y = choose_axes(result, x, y)
    if y is None:
        raise DiagramError(f"{result.path}: one swept axis besides lam ({x}); a stability "
                           "diagram needs two: draw it with line_diagram (rocksweep.plot "
                           "does) or sweep another key")
    dims = list(result.dims)
    layered = "lam" in dims and "lam" not in (x, y)
    panel_dims = [d for d in dims if d not in (x, y) and not (layered and d == "lam")]
    order = [*panel_dims, *(["lam"] if layered else []), y, x]
    flagged = result.flagged & result.done
    if show_computed and "computed" not in result.arrays:
        raise DiagramError(f"{result.path}: not an adaptive sweep (no 'computed' flags): "
                           "every cell is computed")
    comp = (np.asarray(result.arrays["computed"]) > 0 if show_computed
            else np.zeros(result.shape, bool))
    # contact outputs (outputs.contact, body.mu): points where the model stops holding
    status = np.asarray(result.arrays["status"])
    contact = bool(result.scene.get("contact")) and "status" in result.arrays
    slides = ((status & STATUS_BIT[SLIDES]) != 0) & result.done
    lifts = ((status & STATUS_BIT[LIFTS_OFF]) != 0) & result.done
    # per-point error estimates (outputs.check): the outcome changes at half the step
    unsure = np.zeros(result.shape, bool)
    checked = "check_outcome" in result.arrays
    if checked:
        unsure = (np.asarray(result.arrays["check_outcome"])
                  != np.asarray(result.arrays["outcome"])) & result.done
    o, fl, cp, sl, lo, un = _arrays(result, order,
                                    ["outcome", flagged, comp, slides, lifts, unsure])
    if layered:
        lam = _coord(result, "lam")
    else:  # one layer: the fixed lam, or none when lam is on an axis
        o, fl, cp = o[..., None, :, :], fl[..., None, :, :], cp[..., None, :, :]
        sl, lo, un = sl[..., None, :, :], lo[..., None, :, :], un[..., None, :, :]
        lam = np.array([float(result.scalars["lam"])]) if "lam" in result.scalars else None
    panels = _panels(result, panel_dims)

    n_lam = o.shape[len(panel_dims)]
    m1 = mode1_colours(n_lam)
    cmap = ListedColormap([_NOT_RUN, _SAFE, _MODE2, *m1])
    norm = BoundaryNorm(np.arange(-0.5, 3 + n_lam), cmap.N)
    xs, ys = _coord(result, x), _coord(result, y)

    fig, flat, own = _place_axes(axes, len(panels), _layout(result, panel_dims, len(panels)),
                                 (4.8, 4.2), "this stability diagram")
    used = np.zeros(3 + n_lam, bool)
    any_flag = any_back = any_slide = any_lift = any_unsure = False
    lam_sym = _axes.latex("lam")
    for ax, idx in zip(flat, panels, strict=False):
        po, pf = o[idx], fl[idx]  # [n_lam, n_y, n_x]
        cat = categories(po)
        used[np.unique(cat)] = True
        ax.pcolormesh(xs, ys, cat, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        m1_any = po == OUTCOME_MODE1
        # mode 1 at some lam, safe at a larger one: against the paper's trend
        later_safe = np.zeros(cat.shape, bool)
        for k in range(n_lam - 1):
            later_safe |= m1_any[k] & (po[k + 1:] == OUTCOME_SAFE).any(axis=0)
        if later_safe.any():
            any_back = True
            yy, xx = np.nonzero(later_safe)
            ax.plot(xs[xx], ys[yy], ".", color="k", ms=2.5)
        if show_computed:  # grey veil over the computed cells, filled ones left clear
            veil = np.where(cp[idx].any(axis=0), 1.0, np.nan)
            ax.pcolormesh(xs, ys, veil, cmap=ListedColormap(["black"]), alpha=0.35,
                          shading="nearest", rasterized=True)
        if curves:
            _draw_boundaries(ax, po, xs, ys)
        any_flag |= _mark_flagged(ax, pf, xs, ys)
        u_any = un[idx].any(axis=0)
        if u_any.any():
            any_unsure = True
            yy, xx = np.nonzero(u_any)
            ax.plot(xs[xx], ys[yy], "o", mfc="none", mec=_UNSURE, ms=4, mew=0.8)
        if contact:  # hatched where the base would slide (at some lam), outlined: lift-off
            any_slide |= _hatch(ax, xs, ys, sl[idx].any(axis=0), "////", "k")
            any_lift |= _hatch(ax, xs, ys, lo[idx].any(axis=0), "....", "0.25")
        done = po != OUTCOME_NOT_RUN

        def share(k: int, po=po, done=done) -> str:
            return (f"{100 * (po[k] == OUTCOME_MODE1).sum() / done[k].sum():.1f}%"
                    if done[k].any() else "-")

        area = ([f"${lam_sym}$ = {_fmt(lv)}: {share(k)}" for k, lv in enumerate(lam)]
                if lam is not None else [f"all: {share(0)}"])
        _label_panel(ax, result, panel_dims, idx, x, y, area)

    handles = []
    if used[1]:
        handles.append(Patch(fc=_SAFE, ec="0.5", label="safe" + (f" at every ${lam_sym}$"
                                                                   if n_lam > 1 else "")))
    for k in range(n_lam):
        if n_lam == 1:
            label = "mode 1 (overturned after impacts)"
        elif k == 0:
            label = f"mode 1 at ${lam_sym}$ = {_fmt(lam[0])}"
        else:
            label = f"mode 1 from ${lam_sym}$ = {_fmt(lam[k])}"
        if used[3 + k] or n_lam > 1:
            handles.append(Patch(fc=m1[k], ec="0.5", label=label))
    if used[2]:
        handles.append(Patch(fc=_MODE2, ec="0.5", label="mode 2 (overturned, no impact)"))
    if used[0]:
        handles.append(Patch(fc=_NOT_RUN, ec="0.5", label="not computed"))
    if any_back:
        handles.append(Line2D([], [], ls="", marker=".", color="k",
                              label=f"mode 1, safe again at a larger ${lam_sym}$"))
    if any_flag:
        handles.append(Line2D([], [], ls="", marker="x", color="k",
                              label=_flag_label(result)))
    if any_unsure:
        handles.append(Line2D([], [], ls="", marker="o", mfc="none", mec=_UNSURE,
                              label="outcome changes at half the step"))
    elif checked:  # a checked file without rings says so: the check found nothing
        handles.append(Line2D([], [], ls="", marker="o", mfc="none", mec=_UNSURE,
                              label="outcome changes at half the step: none"))
    if show_computed:
        handles.append(Patch(fc="black", alpha=0.35, ec="0.5",
                             label="computed (adaptive; clear: filled)"))
    if curves:
        for k in range(n_lam):
            label = (f"boundaries at ${lam_sym}$ = {_fmt(lam[k])}" if lam is not None
                     and n_lam > 1 else "class boundaries")
            handles.append(Line2D([], [], color=CURVE_COLOURS[k % len(CURVE_COLOURS)],
                                  lw=1.0, label=label))
    mu = _mu_text(result)
    if any_slide:
        handles.append(Patch(fc="none", ec="k", hatch="////",
                             label=f"slides: friction demand > $\\mu${mu}"
                                   + (f" (at some ${lam_sym}$)" if n_lam > 1 else "")))
    if any_lift:
        handles.append(Patch(fc="none", ec="0.25", hatch="....",
                             label="lifts off: normal force < 0"))
    if own:
        ncols = _layout(result, panel_dims, len(panels))[1]
        fig.legend(handles=handles, loc="outside lower center", fontsize=8, frameon=False,
                   ncol=max(1, min(len(handles), 2 * ncols)))
        fig.suptitle(_fit(_title(result, (x, y)), fig), fontsize=11)
    else:
        _legend_outside(flat[-1], handles)
    return fig


def _mark_flagged(ax: Axes, flagged: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> bool:
    """Cross the cells flagged (undecided) at any lam or compared value (flagged[n, ny,
    nx]); whether there was one."""
    f_any = flagged.any(axis=0)
    if not f_any.any():
        return False
    yy, xx = np.nonzero(f_any)
    ax.plot(xs[xx], ys[yy], "x", color="k", ms=3.5, mew=0.7)
    return True


def _label_panel(ax: Axes, result: SweepResult, panel_dims, idx, x: str, y: str,
                 area: list[str]) -> None:
    """A diagram panel's mode 1 area box (one line per lam or compared value), title and
    axis labels."""
    ax.text(0.98, 0.02, "mode 1 area\n" + "\n".join(area), transform=ax.transAxes,
            ha="right", va="bottom", fontsize=7,
            bbox={"boxstyle": "round", "fc": "white", "ec": "0.6", "alpha": 0.85})
    ax.set_title(_panel_title(result, panel_dims, idx), fontsize=10)
    ax.set_xlabel(axis_label(x, result.kind))
    ax.set_ylabel(axis_label(y, result.kind))


def _legend_outside(ax: Axes, handles: list) -> None:
    """The legend of a diagram drawn into the caller's axes: outside them, on the right,
    and once per figure (a second diagram drawn into the same figure adds none)."""
    fig = ax.figure
    if getattr(fig, "_rocksweep_legend", False):
        return
    ax.legend(handles=handles, fontsize="small", loc="upper left",
              bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, frameon=False)
    fig._rocksweep_legend = True


# ---------------------------------------------------------------------------------------
# Comparing the values of one swept key (rocksweep.plot(compare="impact.law"))
# ---------------------------------------------------------------------------------------

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
    return f"${_axes.latex(name)}$ = {_fmt(v)}"


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
    o, fl = _arrays(result, order, ["outcome", flagged])
    values = list(_coord(result, name))
    labels = [_value_label(name, v) for v in values]
    what = "law" if name == "law" else f"${_axes.latex(name, result.kind)}$ value"
    panels = _panels(result, panel_dims)
    n_cat = 3 + (1 << n) - 1
    colours = [_NOT_RUN, _SAFE, _MODE2, *(_compare_colour(m, n) for m in range(1, 1 << n))]
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(-0.5, n_cat), cmap.N)
    xs, ys = _coord(result, x), _coord(result, y)
    fig, flat, own = _place_axes(axes, len(panels), _layout(result, panel_dims, len(panels)),
                                 (4.8, 4.2), "this comparison")
    used = np.zeros(n_cat, bool)
    any_flag = False
    for ax, idx in zip(flat, panels, strict=False):
        po, pf = o[idx], fl[idx]  # [n, n_y, n_x]
        cat = compare_categories(po)
        used[np.unique(cat)] = True
        ax.pcolormesh(xs, ys, cat, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        if curves:
            _draw_boundaries(ax, po, xs, ys)
        any_flag |= _mark_flagged(ax, pf, xs, ys)
        done = po != OUTCOME_NOT_RUN
        area = [f"{lab}: {100 * (po[k] == OUTCOME_MODE1).sum() / done[k].sum():.1f}%"
                if done[k].any() else f"{lab}: -" for k, lab in enumerate(labels)]
        _label_panel(ax, result, panel_dims, idx, x, y, area)

    handles = []
    if used[1]:
        handles.append(Patch(fc=_SAFE, ec="0.5", label=f"safe under every {what}"))
    full = (1 << n) - 1
    for m in [full, *(1 << k for k in range(n)),
              *(m for m in range(1, full) if m & (m - 1))]:
        if used[2 + m]:
            handles.append(Patch(fc=colours[2 + m], ec="0.5", label=_set_label(m, labels, what)))
    if used[2]:
        handles.append(Patch(fc=_MODE2, ec="0.5", label=f"mode 2 under every {what}"))
    if used[0]:
        handles.append(Patch(fc=_NOT_RUN, ec="0.5", label="not computed"))
    if any_flag:
        handles.append(Line2D([], [], ls="", marker="x", color="k",
                              label=_flag_label(result)))
    if curves:
        for k, lab in enumerate(labels):
            handles.append(Line2D([], [], color=CURVE_COLOURS[k % len(CURVE_COLOURS)], lw=1.0,
                                  label=f"boundaries under {lab}"))
    if own:
        ncols = _layout(result, panel_dims, len(panels))[1]
        fig.legend(handles=handles, loc="outside lower center", fontsize=8, frameon=False,
                   ncol=max(1, min(len(handles), ncols + 1)))
        fig.suptitle(_fit(_title(result, (x, y)) + f": {what}s compared", fig), fontsize=11)
    else:
        _legend_outside(flat[-1], handles)
    return fig


def _hatch(ax: Axes, xs: np.ndarray, ys: np.ndarray, mask: np.ndarray, hatch: str,
           colour: str) -> bool:
    """Hatch the cells of ``mask`` (bool[n_y, n_x]) of a diagram drawn with nearest
    shading; returns whether any cell was hatched."""
    if not mask.any():
        return False
    import matplotlib as mpl

    with mpl.rc_context({"hatch.color": colour, "hatch.linewidth": 0.6}):
        ax.pcolor(xs, ys, np.ma.masked_where(~mask, np.ones(mask.shape)), shading="nearest",
                  hatch=hatch, facecolor="none", edgecolor=colour, linewidth=0.0,
                  rasterized=False)
    return True


def _mu_text(result: SweepResult) -> str:
    """' = 0.6' when the result has one fixed mu, else '' (mu swept: one panel each)."""
    mu = result.scalars.get("mu")
    return f" = {_fmt(float(mu))}" if mu is not None else ""


def _no_suite(result: SweepResult) -> None:
    """A record suite's result (a ``record`` dimension of file names) is no diagram."""
    if "record" in result.dims:
        raise DiagramError(f"{result.path}: a record-suite result (dimension record); draw "
                           "its fragility curves (rocksweep.fragility)")


def friction_map(result: SweepResult, x: str | None = None, y: str | None = None
                 ) -> Figure:
    """The friction demand mu_required over swept axes x and y (``rocksweep.plot(mu=True)``):
    filled contours, one panel per value of every other swept key (lam included), labelled
    contour lines at mu = 0.4, 0.6, 0.8; points whose normal force went below zero (infinite
    demand, mostly on the way to overturning) in the top colour. Needs a result with
    contact outputs (``outputs.contact``)."""
    if "mu_required" not in result.arrays:
        raise DiagramError(f"{result.path}: no mu_required in this result; sweep with "
                           "contact outputs (outputs.contact: true) to draw the friction "
                           "demand")
    x, y = choose_axes(result, x, y)
    if y is None:
        raise DiagramError(f"{result.path}: one swept axis besides lam ({x}); the friction "
                           "map needs two")
    dims = list(result.dims)
    panel_dims = [d for d in dims if d not in (x, y)]
    order = [*panel_dims, y, x]
    (mu_req,) = _arrays(result, order, ["mu_required"])
    panels = _panels(result, panel_dims)
    xs, ys = _coord(result, x), _coord(result, y)
    fig, flat, _ = _place_axes(None, len(panels), _layout(result, panel_dims, len(panels)),
                               (4.8, 4.2), "this friction map")
    levels = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0, 1.5]
    import matplotlib

    cmap = matplotlib.colormaps["viridis"].with_extremes(over="#b2182b", bad="0.85")
    norm = BoundaryNorm(levels, cmap.N, extend="max")
    mesh = None
    for ax, idx in zip(flat, panels, strict=False):
        v = np.asarray(mu_req[idx], float)
        mesh = ax.pcolormesh(xs, ys, np.ma.masked_invalid(np.where(np.isinf(v), 1e9, v)),
                             cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        finite = np.where(np.isfinite(v), v, 1e9)
        if len(xs) > 1 and len(ys) > 1:
            cs = ax.contour(xs, ys, finite, levels=[0.4, 0.6, 0.8], colors="w",
                            linewidths=0.8)
            ax.clabel(cs, fontsize=7, fmt="%.1f")
        ax.set_title(_panel_title(result, panel_dims, idx), fontsize=10)
        ax.set_xlabel(axis_label(x, result.kind))
        ax.set_ylabel(axis_label(y, result.kind))
    cb = fig.colorbar(mesh, ax=flat, shrink=0.9, extend="max")
    cb.set_label(r"friction demand $\max|H|/N$ (top colour: $N < 0$ or $> 1.5$)")
    fig.suptitle(_title(result, (x, y)) + ": friction demand", fontsize=11)
    return fig


_OUTCOME_STYLE = {  # outcome code -> (marker, face colour, legend label)
    OUTCOME_SAFE: ("o", _SAFE, "safe"),
    OUTCOME_MODE1: ("^", mode1_colours(1)[0], "mode 1 (overturned after impacts)"),
    OUTCOME_MODE2: ("s", _MODE2, "mode 2 (overturned, no impact)"),
    OUTCOME_NOT_RUN: ("o", _NOT_RUN, "not computed"),
}


def line_diagram(result: SweepResult, x: str | None = None, *,
                 axes: Axes | Sequence[Axes] | None = None) -> Figure:
    """A 1-D sweep: max|theta|/alpha_ref against x, one line per lam (when lam is swept
    and not x), markers by outcome (safe, mode 1, mode 2, not computed); one panel per
    value of any other swept key. Without ``theta_max_over_alpha`` in the result's arrays
    the outcome itself is drawn. axes: one Axes per panel (else a new figure).
    """
    if x is None:
        x, _ = choose_axes(result, None, None)
    else:
        x = _check_key(result, x, "x")
    dims = list(result.dims)
    series = "lam" in dims and x != "lam"
    panel_dims = [d for d in dims if d != x and not (series and d == "lam")]
    order = [*panel_dims, *(["lam"] if series else []), x]
    has_theta = "theta_max_over_alpha" in result.arrays
    names = ["outcome", "theta_max_over_alpha" if has_theta else "outcome"]
    o, v = _arrays(result, order, names)
    if not series:
        o, v = o[..., None, :], v[..., None, :]
        lam = [float(result.scalars["lam"])] if "lam" in result.scalars else [None]
    else:
        lam = list(_coord(result, "lam"))
    panels = _panels(result, panel_dims)
    xs = _coord(result, x)
    fig, flat, own = _place_axes(axes, len(panels), _layout(result, panel_dims, len(panels)),
                                 (6.4, 4.0), "this line plot")
    import matplotlib

    cmap = matplotlib.colormaps["viridis"]
    alpha = _axes.alpha_latex(result.kind)
    used: set[int] = set()
    for ax, idx in zip(flat, panels, strict=False):
        po, pv = o[idx], v[idx]  # [n_lam, n_x]
        for k, lv in enumerate(lam):
            colour = cmap(0.85 * k / max(1, len(lam) - 1)) if len(lam) > 1 else "0.3"
            label = f"${_axes.latex('lam')}$ = {_fmt(lv)}" if lv is not None else None
            yv = pv[k].astype(float)
            yv[po[k] == OUTCOME_NOT_RUN] = np.nan
            ax.plot(xs, yv, "-", color=colour, lw=1.1, label=label, zorder=1)
            for code, (marker, face, _) in _OUTCOME_STYLE.items():
                sel = po[k] == code
                if sel.any():
                    used.add(code)
                    ax.scatter(xs[sel], np.where(np.isfinite(yv[sel]), yv[sel], 0.0),
                               marker=marker, s=22, c=[face], edgecolors=colour,
                               linewidths=0.8, zorder=2)
        ax.set_title(_panel_title(result, panel_dims, idx), fontsize=10)
        ax.set_xlabel(axis_label(x, result.kind))
        if has_theta:
            ax.set_ylabel(rf"max$|\theta|/{alpha}$")
        else:
            ax.set_yticks([0, 1, 2], ["safe", "mode 1", "mode 2"])
        ax.grid(alpha=0.3)
    handles = [Line2D([], [], ls="", marker=m, mfc=f, mec="0.3", label=lab)
               for code, (m, f, lab) in _OUTCOME_STYLE.items() if code in used]
    handles += [h for h in flat[0].get_legend_handles_labels()[0]]
    if own:
        ncols = _layout(result, panel_dims, len(panels))[1]
        fig.legend(handles=handles, loc="outside lower center", fontsize=8, frameon=False,
                   ncol=max(1, min(len(handles), 2 * ncols)))
        fig.suptitle(_fit(_title(result, (x,)), fig), fontsize=11)
    else:
        _legend_outside(flat[-1], handles)
    return fig


def sweep_figure(result: SweepResult, x: str | None = None, y: str | None = None, *,
                 axes: Axes | Sequence[Axes] | None = None,
                 curves: bool = False, show_computed: bool = False,
                 compare: str | None = None) -> Figure:
    """The figure ``rocksweep plot`` draws: a stability diagram over (x, y), or a line
    plot when the result has one swept axis besides lam (see ``choose_axes``); curves:
    the boundary lines over the diagram; show_computed: the cells an adaptive sweep
    computed shaded; compare: a swept key whose values are compared on one diagram
    (``compare_diagram``)."""
    _no_suite(result)
    if compare is not None:
        if show_computed:
            raise DiagramError("{path}: {show} draws on the stability diagram, not with "
                               "{compare}", path=result.path, show=flag("show_computed"),
                               compare=Arg("compare"))
        return compare_diagram(result, compare, x, y, axes=axes, curves=curves)
    x, y = choose_axes(result, x, y)
    if y is None:
        if curves or show_computed:
            raise DiagramError(f"{{path}}: {{curves}} and {{show}} draw on a stability "
                               f"diagram; this result has one swept axis ({x}) besides lam",
                               path=result.path, curves=flag("curves"),
                               show=flag("show_computed"))
        return line_diagram(result, x, axes=axes)
    return stability_diagram(result, x, y, axes=axes,
                             curves=curves, show_computed=show_computed)


def _draw_boundaries(ax: Axes, po: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> None:
    """The boundary lines of each lam layer of a panel (po: outcome[n_lam, ny, nx], axes
    ascending) in its colour; lines along points not computed yet are left out."""
    from rocksweep.analysis.boundaries import boundary_lines

    for k in range(po.shape[0]):
        colour = CURVE_COLOURS[k % len(CURVE_COLOURS)]
        for line in boundary_lines(po[k], np.asarray(xs, float), np.asarray(ys, float)):
            if min(line.classes) < 0:
                continue
            ax.plot(line.xy[:, 0], line.xy[:, 1], color=colour, lw=0.8,
                    ls=("-", "--", ":", "-.")[k // len(CURVE_COLOURS) % 4])


def missing_warnings(result: SweepResult) -> list[str]:
    """Warnings for the user about a result (e.g. points not computed yet)."""
    outcome = result.arrays["outcome"]
    n_missing = int((outcome == OUTCOME_NOT_RUN).sum())
    if n_missing:
        return [f"{n_missing} of {outcome.size} points not computed yet (grey); "
                "a resume of the sweep computes them"]
    return []


def stability_figure(result: SweepResult, path: str | Path, *, x: str | None = None,
                     y: str | None = None, dpi: int = DEFAULT_DPI,
                     overwrite: bool = True) -> list[str]:
    """``sweep_figure`` saved to ``path`` (.png, .pdf or .svg); returns the warnings of
    ``missing_warnings``."""
    save_figure(sweep_figure(result, x, y), path, dpi, overwrite=overwrite,
                inputs=[result.path])
    return missing_warnings(result)


# ---------------------------------------------------------------------------------------
# A_min curves (the boundaries command's figure)
# ---------------------------------------------------------------------------------------

def _where_label(where: dict[str, Any]) -> str:
    parts = []
    for k, v in where.items():
        sym = f"${_axes.latex(k)}$" if k in _axes.AXES else k
        parts.append(f"{sym} = {_fmt(v)}")
    return ", ".join(parts) or "all"


def a_min_figure(curves: Sequence[AMinCurve], bounds: Sequence[PanelBoundaries] = (),
                 title: str = "", kind: str = "flexible") -> Figure:
    """A_min(x) of every panel (``rocksweep.analysis.boundaries.a_min``) overlaid on one axis: one
    colour per panel (e.g. per lam), solid where the onset is mode 1, dashed where mode 2;
    with the boundary lines of ``bounds`` drawn thin in the same colours when given.
    kind: the body kind (labels the amplitude axis). No pyplot."""
    from rocksweep.vocab.outcomes import outcome_word

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
