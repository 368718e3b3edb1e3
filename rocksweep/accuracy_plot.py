"""The work-precision diagram of ``rocksweep accuracy`` (matplotlib, Agg backend).

(a) error against the reference versus kernel time per point, log-log, one colour per
measure: the step ladder as a solid line (steps per period labelled), the tolerance ladder
as a dashed line (event_tol labelled), the presets as stars. (b) outcome agreement with the
reference versus time per point, with its standard error, the 99.5% line that picks the
default preset, and the reference's own time per point.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rocksweep.accuracy import MEASURE_LABELS, Study  # noqa: E402
from rocksweep.plots import save_figure  # noqa: E402

_COLORS = {"theta_max": "C0", "t_first_impact": "C1", "t_overturn": "C2", "impacts": "C3"}
AGREEMENT_TARGET = 99.5  # % (the rule that picks the default preset)


def _positive(v: float) -> float:
    return v if math.isfinite(v) and v > 0 else math.nan


def _rungs(table: list[dict], group: str) -> list[int]:
    """Indices of a group's settings in ladder order (finer step, then tighter tolerance)."""
    idx = [i for i, d in enumerate(table) if d["group"] == group]
    return sorted(idx, key=lambda i: (table[i]["steps_per_period"], -table[i]["event_tol"]))


def work_precision_figure(study: Study, path: str | Path) -> None:
    """Draw the work-precision diagram of a study to ``path`` (PNG, PDF, SVG...)."""
    table = study.table()
    w = study.sample.weight
    x = np.array([d["mean_us"] for d in table])
    groups = [d["group"] for d in table]
    names = [d["setting"] for d in table]
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(13, 6.2), layout="constrained")

    curves = sorted({g for g in groups if g != "preset"})
    styles = dict(zip(curves, ["-o", "--s", ":^", "-.v", "-D", "--x"] * 4, strict=False))
    for m, label in MEASURE_LABELS.items():
        y = np.array([_positive(d[f"err_{m}"]) for d in table])
        color = _COLORS[m]
        for k, group in enumerate(curves):
            idx = _rungs(table, group)
            ax_a.plot(x[idx], y[idx], styles[group], color=color, ms=4, lw=1.2,
                      label=label if k == 0 else None)
        idx = [i for i, g in enumerate(groups) if g == "preset"]
        ax_a.plot(x[idx], y[idx], "*", color=color, ms=11, mec="k", mew=0.5)
    for group in curves:  # line styles name the curves
        ax_a.plot([], [], styles[group], color="0.4", ms=4, label=group)
    # label the rungs once, on the lowest curve that has a value there
    for i, d in enumerate(table):
        ys = [_positive(d[f"err_{m}"]) for m in MEASURE_LABELS]
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
        ax.set_xlabel("kernel time per point [us] (one core; weighted mean, scene estimate)")
        ax.grid(alpha=0.3, which="both")
    ax_a.text(ref_us, 0.98, " reference\n (DOP853)",
              transform=ax_a.get_xaxis_transform(), va="top", fontsize=8, color="0.3")
    ax_a.set_yscale("log")
    ax_a.set_ylabel("median error against the reference")
    ax_a.set_title("(a) error vs cost (labels: steps per period, event_tol; "
                   "stars: presets)", fontsize=9)
    ax_a.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3,
                frameon=False)

    agree = np.array([100 * d["agreement"] for d in table])
    se = np.array([100 * d["agreement_se"] for d in table])
    for group in [*curves, "preset"]:
        style = styles.get(group, "*")
        idx = _rungs(table, group)
        lab = group
        ax_b.errorbar(x[idx], agree[idx], yerr=se[idx], fmt=style, ms=11 if group == "preset"
                      else 4, capsize=2, lw=1.2, label=lab,
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
    ax_b.set_title("(b) outcome (safe / mode 1 / mode 2) agreement vs cost", fontsize=9)
    ax_b.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3,
                frameon=False)

    n, size = len(study.sample.flat), study.sample.size
    fig.suptitle(f"{study.scene.name}: work-precision, {n} of {size} points", fontsize=11)
    save_figure(fig, path)
