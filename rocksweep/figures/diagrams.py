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
lam are drawn over the cells, one colour per lam. Filled cells of an adaptive sweep are
drawn as computed ones.

Points that are mode 1 at some lam but safe again at a larger one get a black dot;
flagged points (horizon, step or event cap, non-finite: ``STATUS_FLAGGED``) an ``x``.
Each panel also lists the mode 1 area (fraction of its points) for every lam. One panel
per pulse shape and per value of any other swept key.

A sweep with one swept numeric axis (besides lam) is drawn as max|theta|/alpha_ref against
that axis, one line per lam, the markers coloured by outcome.

``sweep_figure`` picks the figure (``rocksweep plot``): this diagram, the line plot, or the
comparison of one swept key's values (``figures.compare``). Beside them: the axes, panels
and marks they share (``figures.panels``), the friction demand map (``figures.friction``),
the A_min curves of the boundaries command (``figures.a_min``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from rocksweep.errors import Arg, DiagramError, flag
from rocksweep.figures import DEFAULT_DPI
from rocksweep.figures.compare import compare_diagram
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
    panel_title,
    place_axes,
    swept_dim,
    value_text,
)
from rocksweep.figures.style import Figure, save_figure
from rocksweep.store.reader import SweepResult
from rocksweep.vocab import axes as _axes
from rocksweep.vocab.axes import label as axis_label
from rocksweep.vocab.outcomes import (
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

__all__ = ["stability_diagram", "line_diagram", "sweep_figure", "stability_figure",
           "missing_warnings", "categories", "y_label"]

_UNSURE = "#e69f00"  # rings: the outcome changes at half the step (outputs.check)


def y_label(kind: str) -> str:
    """Label of the amplitude axis A/(g tan alpha_ref) for a body kind."""
    return _axes.label("A_ratio", kind)


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
    """The mode 1 fills of ``n_lam`` lam layers, darkest at the smallest lam."""
    cmap = matplotlib.colormaps["YlOrRd"]
    if n_lam == 1:
        return [cmap(0.75)]
    return [cmap(0.85 - 0.6 * k / (n_lam - 1)) for k in range(n_lam)]


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
    o, fl, cp, sl, lo, un = in_order(result, order,
                                     ["outcome", flagged, comp, slides, lifts, unsure])
    if layered:
        lam = coord(result, "lam")
    else:  # one layer: the fixed lam, or none when lam is on an axis
        o, fl, cp = o[..., None, :, :], fl[..., None, :, :], cp[..., None, :, :]
        sl, lo, un = sl[..., None, :, :], lo[..., None, :, :], un[..., None, :, :]
        lam = np.array([float(result.scalars["lam"])]) if "lam" in result.scalars else None
    panels = panel_indices(result, panel_dims)

    n_lam = o.shape[len(panel_dims)]
    m1 = mode1_colours(n_lam)
    cmap = ListedColormap([NOT_RUN_COLOUR, SAFE_COLOUR, MODE2_COLOUR, *m1])
    norm = BoundaryNorm(np.arange(-0.5, 3 + n_lam), cmap.N)
    xs, ys = coord(result, x), coord(result, y)

    fig, flat, own = place_axes(axes, len(panels), grid_shape(result, panel_dims, len(panels)),
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
            draw_boundaries(ax, po, xs, ys)
        any_flag |= mark_flagged(ax, pf, xs, ys)
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

        area = ([f"${lam_sym}$ = {value_text(lv)}: {share(k)}" for k, lv in enumerate(lam)]
                if lam is not None else [f"all: {share(0)}"])
        label_panel(ax, result, panel_dims, idx, x, y, area)

    handles = []
    if used[1]:
        handles.append(Patch(fc=SAFE_COLOUR, ec="0.5", label="safe" + (f" at every ${lam_sym}$"
                                                                   if n_lam > 1 else "")))
    for k in range(n_lam):
        if n_lam == 1:
            label = "mode 1 (overturned after impacts)"
        elif k == 0:
            label = f"mode 1 at ${lam_sym}$ = {value_text(lam[0])}"
        else:
            label = f"mode 1 from ${lam_sym}$ = {value_text(lam[k])}"
        if used[3 + k] or n_lam > 1:
            handles.append(Patch(fc=m1[k], ec="0.5", label=label))
    if used[2]:
        handles.append(Patch(fc=MODE2_COLOUR, ec="0.5", label="mode 2 (overturned, no impact)"))
    if used[0]:
        handles.append(Patch(fc=NOT_RUN_COLOUR, ec="0.5", label="not computed"))
    if any_back:
        handles.append(Line2D([], [], ls="", marker=".", color="k",
                              label=f"mode 1, safe again at a larger ${lam_sym}$"))
    if any_flag:
        handles.append(Line2D([], [], ls="", marker="x", color="k",
                              label=flag_label(result)))
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
            label = (f"boundaries at ${lam_sym}$ = {value_text(lam[k])}"
                     if lam is not None and n_lam > 1 else "class boundaries")
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
        ncols = grid_shape(result, panel_dims, len(panels))[1]
        fig.legend(handles=handles, loc="outside lower center", fontsize=8, frameon=False,
                   ncol=max(1, min(len(handles), 2 * ncols)))
        fig.suptitle(fitted_title(figure_title(result, (x, y)), fig), fontsize=11)
    else:
        legend_outside(flat[-1], handles)
    return fig


def _hatch(ax: Axes, xs: np.ndarray, ys: np.ndarray, mask: np.ndarray, hatch: str,
           colour: str) -> bool:
    """Hatch the cells of ``mask`` (bool[n_y, n_x]) of a diagram drawn with nearest
    shading; returns whether any cell was hatched."""
    if not mask.any():
        return False
    with matplotlib.rc_context({"hatch.color": colour, "hatch.linewidth": 0.6}):
        ax.pcolor(xs, ys, np.ma.masked_where(~mask, np.ones(mask.shape)), shading="nearest",
                  hatch=hatch, facecolor="none", edgecolor=colour, linewidth=0.0,
                  rasterized=False)
    return True


def _mu_text(result: SweepResult) -> str:
    """' = 0.6' when the result has one fixed mu, else '' (mu swept: one panel each)."""
    mu = result.scalars.get("mu")
    return f" = {value_text(float(mu))}" if mu is not None else ""


def _no_suite(result: SweepResult) -> None:
    """A record suite's result (a ``record`` dimension of file names) is no diagram."""
    if "record" in result.dims:
        raise DiagramError(f"{result.path}: a record-suite result (dimension record); draw "
                           "its fragility curves (rocksweep.fragility)")


_OUTCOME_STYLE = {  # outcome code -> (marker, face colour, legend label)
    OUTCOME_SAFE: ("o", SAFE_COLOUR, "safe"),
    OUTCOME_MODE1: ("^", mode1_colours(1)[0], "mode 1 (overturned after impacts)"),
    OUTCOME_MODE2: ("s", MODE2_COLOUR, "mode 2 (overturned, no impact)"),
    OUTCOME_NOT_RUN: ("o", NOT_RUN_COLOUR, "not computed"),
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
        x = swept_dim(result, x, "x")
    dims = list(result.dims)
    series = "lam" in dims and x != "lam"
    panel_dims = [d for d in dims if d != x and not (series and d == "lam")]
    order = [*panel_dims, *(["lam"] if series else []), x]
    has_theta = "theta_max_over_alpha" in result.arrays
    names = ["outcome", "theta_max_over_alpha" if has_theta else "outcome"]
    o, v = in_order(result, order, names)
    if not series:
        o, v = o[..., None, :], v[..., None, :]
        lam = [float(result.scalars["lam"])] if "lam" in result.scalars else [None]
    else:
        lam = list(coord(result, "lam"))
    panels = panel_indices(result, panel_dims)
    xs = coord(result, x)
    fig, flat, own = place_axes(axes, len(panels), grid_shape(result, panel_dims, len(panels)),
                                (6.4, 4.0), "this line plot")
    cmap = matplotlib.colormaps["viridis"]
    alpha = _axes.alpha_latex(result.kind)
    used: set[int] = set()
    for ax, idx in zip(flat, panels, strict=False):
        po, pv = o[idx], v[idx]  # [n_lam, n_x]
        for k, lv in enumerate(lam):
            colour = cmap(0.85 * k / max(1, len(lam) - 1)) if len(lam) > 1 else "0.3"
            label = f"${_axes.latex('lam')}$ = {value_text(lv)}" if lv is not None else None
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
        ax.set_title(panel_title(result, panel_dims, idx), fontsize=10)
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
        ncols = grid_shape(result, panel_dims, len(panels))[1]
        fig.legend(handles=handles, loc="outside lower center", fontsize=8, frameon=False,
                   ncol=max(1, min(len(handles), 2 * ncols)))
        fig.suptitle(fitted_title(figure_title(result, (x,)), fig), fontsize=11)
    else:
        legend_outside(flat[-1], handles)
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
