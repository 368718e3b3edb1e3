"""The work-precision diagram of ``rocksweep accuracy`` (a pyplot-free matplotlib Figure).

(a) error against the reference versus kernel time per point, log-log, one colour per
measure: the step ladder as a solid line (steps per period labelled), the tolerance ladder
as a dashed line (event_tol labelled), the presets as stars. What is plotted is what
``rocksweep.analysis.accuracy`` measures: the median over the sampled points of |d theta_max|/alpha
(points both call safe), |d t_first_impact| (both impact), |d t_overturn| (both overturn),
the *mean* |d impacts| (same outcome), and where the scene gives body.mu the relative
|d slide_max| (against the sliding reference); time is the weighted mean of one-point kernel
calls (the scene estimate), at the event root finder each setting ran with. (b) outcome
agreement with the reference versus time per point, with its standard error, the 99.5% line
that picks the default preset, and the reference's own time per point.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from rocksweep.analysis.accuracy import MEASURE_LABELS, Study
from rocksweep.figures.style import Figure, given_axes, new_axes

if TYPE_CHECKING:
    from matplotlib.axes import Axes

_COLORS = {"theta_max": "C0", "t_first_impact": "C1", "t_overturn": "C2", "impacts": "C3",
           "slide_max": "C4"}
AGREEMENT_TARGET = 99.5  # % (the rule that picks the default preset)


def _positive(v: float) -> float:
    return v if math.isfinite(v) and v > 0 else math.nan


def _rungs(table: list[dict], group: str) -> list[int]:
    """Indices of a group's settings in ladder order (finer step, then tighter tolerance)."""
    idx = [i for i, d in enumerate(table) if d["group"] == group]
    return sorted(idx, key=lambda i: (table[i]["steps_per_period"], -table[i]["event_tol"]))


def work_precision(study: Study, axes: Sequence[Axes] | None = None) -> Figure:
    """The work-precision diagram of a study (see the module docstring); axes: 2 axes to
    draw into (else a new figure). Returns the figure."""
    if axes is None:
        fig, grid = new_axes(1, 2, (13, 6.4))
        ax_a, ax_b = grid[0]
    else:
        fig, (ax_a, ax_b) = given_axes(axes, 2, "the work-precision diagram")
    table = study.table()
    w = study.sample.weight
    x = np.array([d["mean_us"] for d in table])
    groups = [d["group"] for d in table]
    names = [d["setting"] for d in table]

    curves = sorted({g for g in groups if g != "preset"})
    styles = dict(zip(curves, ["-o", "--s", ":^", "-.v", "-D", "--x"] * 4, strict=False))
    labels = {m: lab for m, lab in MEASURE_LABELS.items() if f"err_{m}" in table[0]}
    for m, label in labels.items():
        y = np.array([_positive(d[f"err_{m}"]) for d in table])
        color = _COLORS[m]
        for k, group in enumerate(curves):
            idx = _rungs(table, group)
            ax_a.plot(x[idx], y[idx], styles[group], color=color, ms=4, lw=1.2,
                      label=label if k == 0 else None)
        idx = [i for i, g in enumerate(groups) if g == "preset"]
        if idx:
            ax_a.plot(x[idx], y[idx], "*", color=color, ms=11, mec="k", mew=0.5,
                      label=None if curves else label)
    for group in curves:  # line styles name the curves
        ax_a.plot([], [], styles[group], color="0.4", ms=4, label=group)
    # label the rungs once, on the lowest curve that has a value there
    for i, d in enumerate(table):
        ys = [_positive(d[f"err_{m}"]) for m in labels]
        ys = [v for v in ys if math.isfinite(v)]
        if not ys:
            continue
        txt = (f"{d['steps_per_period']}" if d["group"].startswith("steps") else
               f"{d['event_tol']:.0e}" if d["group"].startswith("tol") else d["setting"])
        ax_a.annotate(txt, (x[i], min(ys)), textcoords="offset points", xytext=(3, -10),
                      fontsize=7, color="0.3" if d["group"] != "preset" else "k")
    ref_us = float(np.sum(study.reference_seconds * w) / np.sum(w)) * 1e6
    for ax in (ax_a, ax_b):
        ax.axvline(ref_us, color="0.4", ls=":", lw=1)
        ax.set_xscale("log")
        ax.set_xlabel("kernel time per point [us] (one core; weighted mean: scene estimate)")
        ax.grid(alpha=0.3, which="both")
    ref_name = "sliding\n reference" if study.scene.slides else "reference"
    ax_a.text(ref_us, 0.98, f" {ref_name}\n (DOP853)\n {ref_us / 1e3:.0f} ms",
              transform=ax_a.get_xaxis_transform(), va="top", fontsize=8, color="0.3")
    ax_a.set_yscale("log")
    ax_a.set_ylabel("error against the reference\n(median over points; impacts: mean)")
    ax_a.set_title("(a) error vs cost (labels: steps per period, event_tol; "
                   "stars: presets)", fontsize=9)
    ax_a.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3,
                frameon=False)

    agree = np.array([100 * d["agreement"] for d in table])
    se = np.array([100 * d["agreement_se"] for d in table])
    evals = np.array([d["evals_per_point"] for d in table])
    for group in [*curves, "preset"]:
        idx = _rungs(table, group)
        if not idx:
            continue
        style = styles.get(group, "*")
        label = group if group != "preset" else "presets (RK4 evaluations per point: " + \
            ", ".join(f"{names[i]} {evals[i]:.0f}" for i in idx) + ")"
        ax_b.errorbar(x[idx], agree[idx], yerr=se[idx], fmt=style,
                      ms=11 if group == "preset" else 4, capsize=2, lw=1.2, label=label,
                      mec="k" if group == "preset" else None)
        for j, i in enumerate(idx):
            txt = (f"{table[i]['steps_per_period']}" if group.startswith("steps") else
                   f"{table[i]['event_tol']:.0e}" if group.startswith("tol") else names[i])
            ax_b.annotate(txt, (x[i], agree[i]), textcoords="offset points",
                          xytext=(3, 5 if j % 2 == 0 else -11), fontsize=7, color="0.3")
    ax_b.axhline(AGREEMENT_TARGET, color="C3", ls="--", lw=1,
                 label=f"{AGREEMENT_TARGET}% (picks the default)")
    lo = min(float(np.nanmin(agree - se)) if agree.size else 99.0, 99.0)
    ax_b.set_ylim(max(lo - 0.5, 0.0), 100.2)
    ax_b.text(ref_us, 0.02, " reference", transform=ax_b.get_xaxis_transform(), fontsize=8,
              color="0.3")
    ax_b.set_ylabel("outcome agreement with the reference [%] (+- standard error)")
    ax_b.set_title("(b) outcome (safe / mode 1 / mode 2) agreement vs cost "
                   "(weighted: scene estimate)", fontsize=9)
    ax_b.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2,
                frameon=False)

    if axes is None:
        n, size = len(study.sample.flat), study.sample.size
        roots = sorted({d["root"] for d in table})
        fig.suptitle(f"{study.scene.name}: work-precision, {n} of {size} points; "
                     f"event root finder: {', '.join(roots)}", fontsize=11)
    return fig
