"""Stability diagrams (Figures 3 and 4 of the paper) from a sweep result.

x = omega/p, y = A/(g tan alpha_ref) (alpha_ref = alpha_cg for the paper's flexible body,
alpha for a block). Each cell is coloured by what the pulse does:

- mode 2 (overturned without impact): blue. It does not depend on lam, which acts only
  at impacts;
- mode 1 (overturned after one or more impacts): red at the smallest lam, and lighter
  shades where a point first overturns in mode 1 at a larger lam, so the growth of the
  mode 1 area with lam is visible at a glance (the paper's claim);
- safe at every lam: white; not computed yet: grey.

Points that are mode 1 at some lam but safe again at a larger one get a black dot;
flagged points (horizon, step or event cap, non-finite: ``STATUS_FLAGGED``) an ``x``.
Each panel also lists the mode 1 area (fraction of its points) for every lam. One panel
per pulse shape and per value of any other swept key.
"""

from __future__ import annotations

import math
from itertools import product
from pathlib import Path

import numpy as np

from rocksweep.errors import RocksweepError
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.store import SweepResult

FORMATS = (".png", ".pdf", ".svg")
MAX_PANELS = 36

SYMBOLS = {
    "lam": r"\lambda", "zeta": r"\zeta", "wn_over_p": r"\omega_n/p",
    "alpha_cg": r"\alpha_{cg}", "alpha_A": r"\alpha_A", "mA_over_m": "m_A/m",
    "IA_ratio": r"I_A/(m_A R_A^2)", "alpha": r"\alpha", "inertia": r"I_O/(M R^2)",
    "w_over_p": r"\omega/p", "A_ratio": r"A/(g\tan\alpha)",
}
# the slenderness that normalises the amplitude, per body kind (body.alpha_ref)
ALPHA_REF = {"flexible": r"\alpha_{cg}", "block": r"\alpha"}

_SAFE, _MODE2, _NOT_RUN = "#ffffff", "#4c72b0", "#bdbdbd"


class DiagramError(RocksweepError, ValueError):
    """A result that cannot be drawn as a stability diagram; ``str()`` is one line."""


def _fmt(v) -> str:
    return f"{v:g}" if isinstance(v, float | np.floating) else str(v)


def y_label(kind: str) -> str:
    alpha = ALPHA_REF.get(kind, ALPHA_REF["block"])
    return rf"$A/(g\,\tan{alpha})$"


def categories(outcome: np.ndarray) -> np.ndarray:
    """Colour category per cell from outcome[n_lam, ...] (lam ascending along axis 0).

    0 not computed, 1 safe at every lam, 2 mode 2 (at the smallest lam), 3 + k mode 1 first
    at the k-th lam.
    """
    n_lam = outcome.shape[0]
    cat = np.zeros(outcome.shape[1:], np.int64)
    done_all = (outcome != L.OUTCOME_NOT_RUN).all(axis=0)
    cat[done_all & (outcome == L.OUTCOME_SAFE).all(axis=0)] = 1
    mode1 = outcome == L.OUTCOME_MODE1
    first = np.where(mode1.any(axis=0), mode1.argmax(axis=0), n_lam)
    for k in range(n_lam):
        cat[first == k] = 3 + k
    cat[outcome[0] == L.OUTCOME_MODE2] = 2
    return cat


def mode1_colours(n_lam: int) -> list:
    import matplotlib

    cmap = matplotlib.colormaps["YlOrRd"]
    if n_lam == 1:
        return [cmap(0.75)]
    return [cmap(0.85 - 0.6 * k / (n_lam - 1)) for k in range(n_lam)]


def stability_figure(result: SweepResult, path: str | Path) -> list[str]:
    """Draw the stability diagram of ``result`` to ``path`` (.png, .pdf or .svg).

    Returns warnings for the user (e.g. points not computed yet).
    """
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise DiagramError(f"{path}: unknown figure format {path.suffix or '(none)'!r}; "
                           f"use {', '.join(FORMATS)}")
    for d, key in (("w_over_p", "pulse.w_over_p"), ("A_ratio", "pulse.A_ratio")):
        if d not in result.dims or len(result.coords[d]) < 2:
            raise DiagramError(f"{result.path}: {key} has one value; a stability diagram "
                               "needs pulse.w_over_p and pulse.A_ratio swept (lists or ranges)")
    outcome = result.arrays["outcome"]
    flagged = result.flagged & result.done
    dims = list(result.dims)
    panel_dims = [d for d in dims if d not in ("lam", "A_ratio", "w_over_p")]
    order = [*panel_dims, *(["lam"] if "lam" in dims else []), "A_ratio", "w_over_p"]
    perm = [dims.index(d) for d in order]
    o = np.transpose(outcome, perm)
    fl = np.transpose(flagged, perm)
    if "lam" not in dims:
        o, fl = o[..., None, :, :], fl[..., None, :, :]
        lam = np.array([result.scalars.get("lam", 0.0)], float)
    else:
        lam = np.asarray(result.coords["lam"], float)
    lam_order = np.argsort(lam, kind="stable")
    lam = lam[lam_order]
    o = np.take(o, lam_order, axis=len(panel_dims))
    fl = np.take(fl, lam_order, axis=len(panel_dims))
    panels = list(product(*(range(len(result.coords[d])) for d in panel_dims)))
    if len(panels) > MAX_PANELS:
        raise DiagramError(f"{result.path}: {len(panels)} panels "
                           f"({' x '.join(panel_dims)}); at most {MAX_PANELS} fit a figure")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from rocksweep.plots import save_figure

    n_lam = len(lam)
    m1 = mode1_colours(n_lam)
    cmap = ListedColormap([_NOT_RUN, _SAFE, _MODE2, *m1])
    norm = BoundaryNorm(np.arange(-0.5, 3 + n_lam), cmap.N)
    x = np.asarray(result.coords["w_over_p"], float)
    y = np.asarray(result.coords["A_ratio"], float)

    per_first = len(panels) // len(result.coords[panel_dims[0]]) if panel_dims else 1
    # a row per value of the first panel key (the pulse shape) when that fits, else 3 across
    ncols = per_first if len(panel_dims) >= 2 and per_first <= 4 else min(len(panels), 3)
    nrows = math.ceil(len(panels) / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.8 * ncols, 4.2 * nrows + 0.9),
                             squeeze=False, layout="constrained")
    used = np.zeros(3 + n_lam, bool)
    any_flag = any_back = False
    for ax, idx in zip(axes.flat, panels, strict=False):
        po, pf = o[idx], fl[idx]  # [n_lam, n_A, n_w]
        cat = categories(po)
        used[np.unique(cat)] = True
        ax.pcolormesh(x, y, cat, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        m1_any = po == L.OUTCOME_MODE1
        # mode 1 at some lam, safe at a larger one: against the paper's trend
        later_safe = np.zeros(cat.shape, bool)
        for k in range(n_lam - 1):
            later_safe |= m1_any[k] & (po[k + 1:] == L.OUTCOME_SAFE).any(axis=0)
        if later_safe.any():
            any_back = True
            yy, xx = np.nonzero(later_safe)
            ax.plot(x[xx], y[yy], ".", color="k", ms=2.5)
        f_any = pf.any(axis=0)
        if f_any.any():
            any_flag = True
            yy, xx = np.nonzero(f_any)
            ax.plot(x[xx], y[yy], "x", color="k", ms=3.5, mew=0.7)
        done = (po != L.OUTCOME_NOT_RUN)
        area = [f"${SYMBOLS['lam']}$ = {_fmt(lv)}: "
                + (f"{100 * (po[k] == L.OUTCOME_MODE1).sum() / done[k].sum():.1f}%"
                   if done[k].any() else "-")
                for k, lv in enumerate(lam)]
        ax.text(0.98, 0.02, "mode 1 area\n" + "\n".join(area), transform=ax.transAxes,
                ha="right", va="bottom", fontsize=7,
                bbox={"boxstyle": "round", "fc": "white", "ec": "0.6", "alpha": 0.85})
        parts = []
        for d, i in zip(panel_dims, idx, strict=True):
            v = result.coords[d][i]
            parts.append(f"{v} pulse" if d == "shape" else f"${SYMBOLS.get(d, d)}$ = {_fmt(v)}")
        if "shape" not in panel_dims and "shape" in result.scalars:
            parts.insert(0, f"{result.scalars['shape']} pulse")
        ax.set_title(", ".join(parts), fontsize=10)
        ax.set_xlabel(rf"${SYMBOLS['w_over_p']}$")
        ax.set_ylabel(y_label(result.kind))
    for ax in list(axes.flat)[len(panels):]:
        ax.set_visible(False)

    lam_sym = SYMBOLS["lam"]
    handles = []
    if used[1]:
        handles.append(Patch(fc=_SAFE, ec="0.5", label="safe" + (" at every $\\lambda$"
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
                              label="flagged (horizon/step/event cap, non-finite)"))
    fig.legend(handles=handles, loc="outside lower center", fontsize=8, frameon=False,
               ncol=max(1, min(len(handles), 2 * ncols)))
    fig.suptitle(result.name, fontsize=11)
    save_figure(fig, path)
    warnings = []
    n_missing = int((outcome == L.OUTCOME_NOT_RUN).sum())
    if n_missing:
        warnings.append(f"{n_missing} of {outcome.size} points not computed yet (grey); "
                        "finish the sweep with --resume")
    return warnings
