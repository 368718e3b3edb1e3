"""Figure 5 of the paper: the time history of one or more runs (input, rotation, energy,
dissipation against p*t), built on ``rocksweep.figures.style``."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from matplotlib.lines import Line2D

from rocksweep.compute.single import NO_HISTORY
from rocksweep.errors import FigureError
from rocksweep.figures.style import Figure, given_axes, new_axes
from rocksweep.vocab import axes as _axes

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from rocksweep.compute.single import Run


def _label(run: Run, swept: Sequence[str]) -> str:
    p = run.point
    kind = getattr(p.body, "kind", "flexible")
    values = {"lam": p.lam, "shape": p.shape, "w_over_p": p.w_over_p, "A_ratio": p.A_ratio}
    parts = []
    for k in swept:
        v = values.get(k, getattr(p.body, k, None))
        parts.append(f"${_axes.latex(k, kind)}$ = {v:g}" if isinstance(v, float)
                     else f"{k} = {v}")
    text = ", ".join(parts) or f"$\\lambda$ = {p.lam:g}"
    return f"{text} ({run.outcome})"


def time_history(runs: Sequence[Run], swept: Sequence[str] = (), title: str = "",
                 axes: Sequence[Axes] | None = None) -> Figure:
    """Figure 5: against p*t, (a) the input pulse xg''/A (eq. 2, the history's ``xg``
    column over the point's amplitude A), (b) theta/alpha_cg, (c) E/E_ref, (d) the energy
    dissipated in impacts and the damper / E_ref; one colour per run.

    runs: Runs with a history (``rocksweep.compute.single.run_point``, history=True); swept:
    the scene's swept axis names, which label the runs; axes: 4 axes to draw into (else a new
    figure). Returns the figure. Runs whose base may slide (body.mu, docs/sliding.md) add
    their sliding displacement x/b to (b) (dashed, right axis) and friction's loss to (d).
    """
    if axes is None:
        fig, grid = new_axes(4, 1, (7.5, 10.0), sharex=True,
                             gridspec_kw={"height_ratios": [1.0, 2.0, 1.4, 1.4]})
        ax_in, ax_th, ax_e, ax_d = grid[:, 0]
    else:
        fig, (ax_in, ax_th, ax_e, ax_d) = given_axes(axes, 4, "a time history figure")
    if not runs:
        raise FigureError("time history: no runs to draw")
    for run in runs:
        if run.history is None:
            raise FigureError(f"time history: {NO_HISTORY}")
    alpha = _axes.alpha_latex(getattr(runs[0].point.body, "kind", "flexible"))
    # one input line when every run has the same pulse shape and frequency (xg''/A is then
    # the same curve), else one per run in the run's colour
    pulses = {(r.point.shape, r.point.w_over_p, r.point.p) for r in runs}
    longest = max(runs, key=lambda r: r.history["t"][-1] if len(r.history["t"]) else 0.0)
    # records run in the record's seconds: t = (p t)/p on the time axis when every run has
    # the same p (the kernel's time is p t with p = 1 rad/s)
    records = all(r.point.record is not None for r in runs)
    ps = {r.point.p for r in runs}
    seconds = records and len(ps) == 1
    t_scale = 1.0 / next(iter(ps)) if seconds else 1.0
    ax_x = ax_th.twinx() if any("x" in r.history for r in runs) else None
    for run in runs:
        h = run.history
        body = run.point.body
        t = h["t"] * t_scale
        line, = ax_th.plot(t, h["theta"] / body.alpha_ref, lw=1.2,
                           label=_label(run, swept))
        c = line.get_color()
        ax_e.plot(t, h["E"] / body.E_ref, lw=1.2, color=c)
        ax_d.plot(t, (h["D_damp"] + h["E_impact"] + h.get("D_fric", 0.0)) / body.E_ref, lw=1.2,
                  color=c)
        if ax_x is not None and "x" in h:
            ax_x.plot(t, h["x"] / body.b, lw=1.0, ls="--", color=c)
        if run.t_overturn is not None:
            for ax in (ax_th, ax_e, ax_d):
                ax.axvline(run.t_overturn * t_scale, color=c, ls=":", lw=0.9)
        if len(pulses) > 1 or run is longest:
            a = run.point.A
            pc = c if len(pulses) > 1 else "k"
            label = (run.point.record.name if run.point.record is not None
                     else f"{run.point.shape}, $\\omega/p$ = {run.point.w_over_p:g}")
            ax_in.plot(t, h["xg"] / a if a else h["xg"], lw=1.1, color=pc, label=label)
    ax_in.axhline(0.0, color="0.6", lw=0.6)
    ax_in.set_ylabel(r"$\ddot{x}_g/A$")
    ax_in.set_ylim(-1.25, 1.25)
    ax_in.legend(fontsize=8, loc="upper right",
                 title="ground record" if records else "input pulse (eq. 2)",
                 title_fontsize=8)
    for v in (1.0, -1.0):
        ax_th.axhline(v, color="0.45", lw=0.7, ls="--")
    guides = [Line2D([], [], color="0.45", lw=0.7, ls="--",
                     label=rf"$|\theta| = {alpha}$: centre of gravity over the corner"
                     + (r" at $u = 0$" if alpha == r"\alpha_{cg}" else ""))]
    if any(r.t_overturn is not None for r in runs):
        guides.append(Line2D([], [], color="0.3", lw=0.9, ls=":",
                             label="overturning (run's colour)"))
    handles = [*ax_th.get_legend_handles_labels()[0], *guides]
    ax_th.legend(handles=handles, fontsize=8, loc="upper left")
    ax_th.set_ylabel(rf"$\theta/{alpha}$")
    ax_th.set_ylim(-3, 3)
    ax_e.set_ylabel(r"$E/E_{ref}$")
    ax_d.set_ylabel("dissipated\n" + r"$(E_d + E_{damper})/E_{ref}$")
    if ax_x is not None:
        ax_x.set_ylabel(r"sliding $x/b$ (dashed)")
        ax_d.set_ylabel("dissipated\n" + r"$(E_d + E_{damper} + E_{fric})/E_{ref}$")
    ax_d.set_xlabel(f"$t$ [s] ($p$ = {next(iter(ps)):g} rad/s)" if seconds else r"$pt$")
    for ax in (ax_in, ax_th, ax_e, ax_d):
        ax.grid(alpha=0.3)
    if title and axes is None:
        fig.suptitle(title, fontsize=10)
    return fig
