"""Figures of the analyses' Datasets that have no figure module of their own: a risk result
(hazard curve, fragility, the rate's integrand), an IDA (the first overturning level per
record), boundaries (A_min
against x) and the IM efficiency (beta per IM). ``rocksweep.figures.by_kind`` picks one by
the Dataset's kind. Each returns a pyplot-free ``matplotlib.figure.Figure``; the legend
sits outside the data.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import xarray as xr

from rocksweep.analysis.ida import curve_end, curve_variable
from rocksweep.analysis.table import units_of
from rocksweep.figures import WIDTHS
from rocksweep.figures.style import Figure, curve_colours, grow_to_fit, log_ticks, wrap_title
from rocksweep.vocab.axes import label as axis_label
from rocksweep.vocab.outcomes import OVERTURN

# height / width of one panel stacked in a single column (``_figure``)
STACKED_ASPECT = 0.62


def _figure(width: str | None, ncols: int = 1, aspect: float = 0.75) -> tuple[Figure, Any]:
    """A figure of ``ncols`` panels side by side (height ``aspect`` x width), or, at the
    single column width, one above the other: side by side they would be too narrow to
    read. Returns (figure, 1-D array of the axes in reading order)."""
    w = WIDTHS[width][0] if width in WIDTHS else 6.4
    if width == "single" and ncols > 1:
        fig = Figure(figsize=(w, w * STACKED_ASPECT * ncols), layout="constrained")
        return fig, fig.subplots(ncols, 1, squeeze=False)[:, 0]
    fig = Figure(figsize=(w, w * aspect), layout="constrained")
    return fig, fig.subplots(1, ncols, squeeze=False)[0]


def _label(d: str, v: Any) -> str:
    v = v.item() if hasattr(v, "item") else v
    return f"{v:g}" if d == "state" and isinstance(v, float) else (
        str(v) if d == "state" else f"{d} = {v:g}" if isinstance(v, float) else f"{d} = {v}")


def _curves(da: xr.DataArray, along: str):
    """(label, 1-D values along ``along``) for every combination of the other dims."""
    others = [d for d in da.dims if d != along]
    for pos in itertools.product(*(range(da.sizes[d]) for d in others)):
        sel = dict(zip(others, pos, strict=True))
        one = da.isel(sel)
        label = ", ".join(_label(d, da[d].values[i]) if d in da.coords else f"{d} {i}"
                          for d, i in sel.items())
        yield label, sel, one.values


def risk_figure(rk: xr.Dataset, *, ax: Any = None, width: str | None = "double") -> Figure:
    """Three panels over the IM (log axes): the hazard curve lambda(IM > x), the
    fragility P(state | x) of each curve, and the integrand P(state | x) |d lambda /
    d ln x| (linear axis: its area over ln x is the state's annual rate, given in the
    legend)."""
    if ax is not None:
        axes = np.atleast_1d(ax)
        fig = axes[0].figure
    else:
        fig, axes = _figure(width, 3, 0.42)
    im, unit = rk.attrs.get("im", "IM"), rk.attrs.get("im_units", "")
    xlabel = f"{im} [{unit}]" if unit and unit != "1" else im
    a0 = axes[0]
    a0.loglog(rk["hazard_im"].values, rk["hazard_rate"].values, "o-", color="black", ms=3)
    a0.set_ylabel("annual rate of exceedance [1/yr]")
    a0.set_title("hazard", fontsize="small")
    grid = rk["im_level"].values
    curves = list(_curves(rk["fragility"], "im_level"))
    colours = curve_colours(len(curves))
    for k, (label, sel, p) in enumerate(curves):
        c = colours[k]
        rate = float(rk["annual_rate"].isel(sel))
        prob = float(rk["probability"].isel(sel))
        if len(axes) > 1:
            axes[1].semilogx(grid, p, color=c, label=label)
        if len(axes) > 2:
            dens = rk["rate_density"].isel(sel).values
            what = f"{rate:.3g}/yr, P = {prob:.3g} in {rk.attrs.get('years', 50):g} yr"
            axes[2].semilogx(grid, dens, color=c,
                             label=f"{label}: {what}" if label else what)
    if len(axes) > 1:
        axes[1].set_ylim(-0.02, 1.02)
        axes[1].set_ylabel("P(state | IM)")
        axes[1].set_title("fragility", fontsize="small")
    if len(axes) > 2:
        axes[2].set_ylabel(r"P(state | x) |d$\lambda$/d ln x| [1/yr]")
        axes[2].set_title("rate integrand", fontsize="small")
        if ax is None:  # our figure: one legend below all panels, as wide as the figure
            fig.legend(*axes[2].get_legend_handles_labels(), loc="outside lower center",
                       fontsize="x-small", frameon=False, ncol=2)
        else:
            axes[2].legend(fontsize="x-small", loc="upper center",
                           bbox_to_anchor=(0.5, -0.22), frameon=False)
    for a in axes:
        a.set_xlabel(xlabel)
        a.grid(True, which="both", alpha=0.25, linewidth=0.5)
    return fig


MAX_IDA_PANELS = 6  # more combinations of the other keys: this many, evenly chosen


def ida_figure(ida: xr.Dataset, *, ax: Any = None, width: str | None = "single") -> Figure:
    """IDA curves: max|theta|/alpha against the IM (log axis) per record, one panel per
    value of the other swept keys (lam, angle, floor.period...; at most MAX_IDA_PANELS,
    evenly chosen, the suptitle says how many of how many), in two columns beyond one
    (one at the single column width), the stripes' safe points joined, each record
    ending at its bisected first overturning level ``ida_im`` (drawn at max|theta|/alpha
    = 1, the overturning limit). An IDA of another state (attrs ``state``) ends at that
    state's level (``analysis.ida.curve_end``): "slide:D" draws the sliding displacement
    ``slide_max`` against the IM, D dashed. Without the stripes' curves: each record's
    ``ida_im`` and bracket, sorted."""
    im, unit = ida.attrs.get("im", "IM"), ida.attrs.get("im_units", "")
    xlabel = f"{im} [{unit}]" if unit and unit != "1" else im
    state = str(ida.attrs.get("state", OVERTURN))
    demand, end = curve_variable(state), curve_end(state)
    curves = demand in ida.data_vars and im in ida[demand].dims
    every = list(_curves(ida["ida_im"], "record"))
    keep = np.unique(np.linspace(0, len(every) - 1, min(MAX_IDA_PANELS, len(every)))
                     .round().astype(int))
    panels = [every[i] for i in keep]
    own = ax is None
    cols = 1
    if not own:
        axes = np.atleast_1d(np.asarray(ax, dtype=object)).ravel()
        fig = axes[0].figure
    elif curves and len(panels) > 1:
        w = WIDTHS[width][0] if width in WIDTHS else 6.4
        ncols = cols = 1 if width == "single" else 2
        nrows = int(np.ceil(len(panels) / ncols))
        fig = Figure(figsize=(w, w * (0.75 if ncols == 1 else 0.42) * nrows),
                     layout="constrained")
        grid = fig.subplots(nrows, ncols, squeeze=False)
        axes = grid.ravel()
        for a in axes[len(panels):]:
            a.set_visible(False)
    else:
        fig, axes = _figure(width, 1, 0.9)
    panel_colours = curve_colours(len(panels))
    for k, (label, sel, v) in enumerate(panels):
        if curves:
            a = axes[min(k, len(axes) - 1)]
            th = ida[demand].isel(sel).transpose("record", im)
            x = ida[im].values
            colours = curve_colours(th.sizes["record"])
            for r in range(th.sizes["record"]):
                y = th.values[r]
                c = colours[r]
                xs, ys = list(x[np.isfinite(y)]), list(y[np.isfinite(y)])
                if np.isfinite(v[r]):  # up to the bisected first level reaching the state
                    keep_r = [i for i, xx in enumerate(xs) if xx < v[r]]
                    xs, ys = [xs[i] for i in keep_r] + [v[r]], [ys[i] for i in keep_r] + [end]
                a.plot(xs, ys, "-", color=c, lw=0.8, alpha=0.8)
                if np.isfinite(v[r]):
                    a.plot([v[r]], [end], "o", color=c, ms=2.5)
            a.set_xscale("log")
            log_ticks(a.xaxis, x)
            a.set_xlabel(xlabel)
            if demand == "theta_max_over_alpha":
                a.set_ylim(0.0, 1.05)
                a.set_ylabel(r"max|$\theta$|/$\alpha$")
            else:  # the sliding displacement, its threshold D dashed
                a.set_ylim(0.0, None)
                a.axhline(end, color="0.4", lw=0.6, ls="--")
                du = units_of(ida[demand])
                a.set_ylabel("max sliding |x|" + (f" [{du}]" if du and du != "1" else ""))
            a.set_title(wrap_title(label or "IDA", fig.get_figwidth() / cols, 8.0),
                        fontsize="small")
            a.grid(True, which="both", alpha=0.25, linewidth=0.5)
            continue
        a = axes[0]
        order = np.argsort(np.where(np.isnan(v), np.inf, v))
        y = np.arange(v.size)
        lo = ida["ida_lo"].isel(sel).values[order] if "ida_lo" in ida else v[order]
        hi = ida["ida_hi"].isel(sel).values[order] if "ida_hi" in ida else v[order]
        a.errorbar(v[order], y + 0.15 * k, xerr=[v[order] - np.fmin(lo, v[order]),
                                               np.fmax(hi, v[order]) - v[order]],
                   fmt="o", ms=3, color=panel_colours[k], label=label or None)
        a.set_xscale("log")
        log_ticks(a.xaxis)
        a.set_xlabel(f"first overturning {xlabel}" if state == OVERTURN
                     else f"first {xlabel} reaching {state}")
        a.set_ylabel("record (sorted)")
        a.grid(True, which="both", alpha=0.25, linewidth=0.5)
    if not curves and axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.18),
                       frameon=False)
    if own and len(panels) < len(every):
        fig.suptitle(f"IDA: {len(panels)} of {len(every)} combinations of the other keys",
                     fontsize="small")
    if own:
        grow_to_fit(fig)
    return fig


def boundaries_figure(bd: xr.Dataset, *, ax: Any = None,
                      width: str | None = "single") -> Figure:
    """A_min against the diagram's x of ``rocksweep.boundaries``, one colour per value of
    the other swept keys (lam, shape, ...): solid where the onset is mode 1, dashed where
    it is mode 2 (the figure of ``rocksweep boundaries --plot``)."""
    xname = bd.attrs.get("x_axis") or bd["A_min"].dims[-1]
    kind = str(bd.attrs.get("kind", "flexible"))
    if ax is not None:
        fig = ax.figure
    else:
        fig, axes = _figure(width, 1, 0.8)
        ax = axes[0]
    x = bd[xname].values
    modes = {lab: v for lab, _sel, v in _curves(bd["mode"], xname)}
    lines = list(_curves(bd["A_min"], xname))
    colours = curve_colours(len(lines))
    for k, (lab, _sel, a_min) in enumerate(lines):
        for m, style, word in ((1, "-", "mode 1"), (2, "--", "mode 2")):
            y = np.where(modes[lab] == m, a_min, np.nan)
            if np.isfinite(y).any():
                ax.plot(x, y, style, color=colours[k], marker=".", ms=3,
                        label=f"{lab} ({word})" if lab else word)
    ax.set_xlabel(axis_label(xname, kind))
    ax.set_ylabel(f"{axis_label(str(bd.attrs.get('y_axis', 'A_ratio')), kind)} at "
                  "overturning onset ($A_{min}$)")
    ax.grid(True, alpha=0.25, linewidth=0.5)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.2),
                  frameon=False, ncol=2)
    return fig


def efficiency_figure(eff: xr.Dataset, *, ax: Any = None,
                      width: str | None = "single") -> Figure:
    """beta per IM (per unit of ln scale factor, ``beta_scale``, so that IMs that scale
    differently compare), one bar group per value of the other dims; lowest is best."""
    if ax is None:
        fig, axes = _figure(width, 1, 0.9)
        ax = axes[0]
    else:
        fig = ax.figure
    da = eff["beta_scale"]
    ims = [str(v) for v in eff["im"].values]
    series = list(_curves(da, "im"))
    wbar = 0.8 / max(len(series), 1)
    colours = curve_colours(len(series))
    for k, (label, _sel, v) in enumerate(series):
        ax.bar(np.arange(len(ims)) + (k - (len(series) - 1) / 2) * wbar, v, wbar,
               color=colours[k], label=label or None)
    ax.set_xticks(np.arange(len(ims)), ims, rotation=45, ha="right")
    ax.set_ylabel(r"$\beta$ in ln(scale factor) (lower: better)")
    state = eff.attrs.get("state", "overturn")
    ax.set_title(f"IM efficiency for {state}", fontsize="small")
    ax.grid(True, axis="y", alpha=0.25, linewidth=0.5)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.35),
                  frameon=False)
    return fig
