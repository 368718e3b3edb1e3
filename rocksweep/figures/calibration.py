"""The figure of a calibration (``rocksweep.calibrate``): the measured history against the
simulated one at the estimate, the fitted impacts marked, and the half-cycle peaks the
misfit compares."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rocksweep.errors import FigureError
from rocksweep.figures.style import given_axes, new_axes

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


def calibration_figure(fit: xr.Dataset, ax: Axes | None = None) -> Figure:
    """theta/alpha_ref against p*t: the measured samples (grey), the simulation at the
    estimate (blue), the fitted simulation's impacts (ticks on the axis) and the peaks
    compared (measured: circles, simulated: crosses). fit: ``rocksweep.calibrate``'s
    Dataset; ax: an Axes to draw into (else a new figure)."""
    need = ("measured_theta", "fitted_theta", "impact_time", "estimate")
    missing = [v for v in need if v not in fit]
    if missing:
        raise FigureError(f"calibration figure: the Dataset has no {missing[0]} (give what "
                          "rocksweep.calibrate returns)")
    if ax is None:
        fig, axes = new_axes(1, 1, (9.0, 4.2))
        ax = axes[0, 0]
    else:
        fig, (ax,) = given_axes(ax, 1, "a calibration figure")
    t = fit["p_t"].values
    ax.plot(t, fit["measured_theta"].values, ".", ms=2.0, color="0.55", label="measured")
    label = ", ".join(f"{k} = {float(v):.4g} [{float(lo):.4g}, {float(hi):.4g}]"
                      for k, v, lo, hi in zip(fit["parameter"].values, fit["estimate"].values,
                                              fit["lo"].values, fit["hi"].values, strict=True))
    ax.plot(t, fit["fitted_theta"].values, "-", lw=1.1, color="C0",
            label=f"simulated at {label}")
    if "peak_time" in fit:
        ax.plot(fit["peak_time"].values, fit["measured_peak"].values, "o", mfc="none",
                color="k", ms=5, label="measured half-cycle peaks")
        fp = fit["fitted_peak"].values
        ok = np.isfinite(fp)
        ax.plot(fit["peak_time"].values[ok], fp[ok], "x", color="C3", ms=5,
                label="simulated peaks paired with them")
    imp = fit["impact_time"].values
    if imp.size:
        ax.plot(imp, np.zeros_like(imp), "|", color="C1", ms=9, mew=1.0,
                label=f"impacts of the fit ({imp.size})")
    ci = fit.attrs.get("ci", 0.95)
    ax.set_xlabel("p t")
    ax.set_ylabel(r"$\theta/\alpha$")
    ax.set_title(f"{fit.attrs.get('title', 'calibration')}: misfit "
                 f"{float(fit['misfit']):.3g} (RMS peak error), {ci:.0%} interval",
                 fontsize=9)
    ax.axhline(0.0, color="0.8", lw=0.6, zorder=0)
    ax.legend(fontsize=7, loc="upper right")
    return fig
