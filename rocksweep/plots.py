"""Figures (the only module that imports matplotlib): Figures 2 and 5 of the paper.

Stability diagrams (Figures 3 and 4) live in ``rocksweep.diagrams``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rocksweep.run import Run  # noqa: E402


def _label(run: Run, swept: list[str]) -> str:
    p = run.point
    values = {"lam": p.lam, "shape": p.shape, "w_over_p": p.w_over_p, "A_ratio": p.A_ratio}
    symbols = {"lam": r"$\lambda$", "w_over_p": r"$\omega/p$",
               "A_ratio": r"$A/(g\tan\alpha_{cg})$", "shape": "pulse"}
    parts = []
    for k in swept:
        v = values.get(k, getattr(p.body, k, None))
        parts.append(f"{symbols.get(k, k)} = {v:g}" if isinstance(v, float) else f"{k} = {v}")
    text = ", ".join(parts) or f"$\\lambda$ = {p.lam:g}"
    return f"{text} ({run.outcome})"


def time_history_figure(runs: list[Run], swept: list[str], title: str, path: str | Path) -> None:
    """Figure 5: theta/alpha_cg, E/E_ref and the energy dissipated against p*t, one line
    per run. Runs are Runs with a history."""
    fig, axes = plt.subplots(3, 1, figsize=(7.5, 8.5), sharex=True)
    for run in runs:
        h = run.history
        body = run.point.body
        label = _label(run, swept)
        line, = axes[0].plot(h["t"], h["theta"] / body.alpha_ref, lw=1.2, label=label)
        axes[1].plot(h["t"], h["E"] / body.E_ref, lw=1.2, color=line.get_color())
        axes[2].plot(h["t"], (h["D_damp"] + h["E_impact"]) / body.E_ref, lw=1.2,
                     color=line.get_color())
        if run.t_overturn is not None:
            axes[0].axvline(run.t_overturn, color=line.get_color(), ls=":", lw=0.8)
    axes[0].axhline(1.0, color="0.6", lw=0.6, ls="--")
    axes[0].axhline(-1.0, color="0.6", lw=0.6, ls="--")
    axes[0].set_ylabel(r"$\theta/\alpha_{cg}$")
    axes[0].set_ylim(-3, 3)
    axes[0].legend(fontsize=8, loc="upper left")
    axes[0].set_title(title, fontsize=10)
    axes[1].set_ylabel(r"$E/E_{ref}$")
    axes[2].set_ylabel(r"dissipated $(E_d + E_{damper})/E_{ref}$")
    axes[2].set_xlabel(r"$pt$")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path)


def restitution_figure(lam: np.ndarray, u_over_ucr: np.ndarray, e_upper: np.ndarray,
                       e_housner: float, title: str, path: str | Path) -> None:
    """Figure 2: (a) e against lam for several u/u_cr; (b) e against u/u_cr at lam = 0.

    e_upper: float[len(lam), len(u_over_ucr)] under the paper's upper sign (the lower sign
    is its mirror, e_lower(lam, u) = e_upper(lam, -u)).
    """
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(11, 4.5))
    picks = [v for v in (-2.0, -1.0, 0.0, 1.0, 2.0) if u_over_ucr.min() <= v <= u_over_ucr.max()]
    cmap = plt.get_cmap("coolwarm")
    for v in picks:
        j = int(np.argmin(abs(u_over_ucr - v)))
        ax_a.plot(lam, e_upper[:, j], color=cmap((v + 2) / 4), label=f"$u/u_{{cr}}$ = {v:g}")
    ax_a.axhline(1.0, color="0.5", lw=0.6, ls="--")
    ax_a.axhline(0.0, color="0.5", lw=0.6)
    ax_a.set_xlabel(r"$\lambda$")
    ax_a.set_ylabel("$e$")
    ax_a.set_title(r"(a) $e$ against $\lambda$ (upper sign of eq. 1)", fontsize=10)
    ax_a.legend(fontsize=8)
    i0 = int(np.argmin(abs(lam)))
    ax_b.plot(u_over_ucr, e_upper[i0], label=r"eq. (1), $\lambda = 0$, upper sign")
    ax_b.plot(u_over_ucr, e_upper[i0, ::-1], ls="--", label="lower sign (mirror)")
    ax_b.axhline(e_housner, color="k", lw=0.8, ls=":",
                 label=f"Housner, rigid body: {e_housner:.3f}")
    ax_b.set_xlabel(r"$u/u_{cr}$")
    ax_b.set_ylabel("$e$")
    ax_b.set_title(r"(b) $e$ against $u/u_{cr}$ at $\lambda = 0$", fontsize=10)
    ax_b.legend(fontsize=8)
    for ax in (ax_a, ax_b):
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    save_figure(fig, path)


def save_figure(fig, path: str | Path) -> None:
    """Save atomically: a figure is either complete or absent."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.partial{path.suffix}")
    try:
        fig.savefig(tmp, dpi=130)
        tmp.replace(path)
    finally:
        plt.close(fig)
        tmp.unlink(missing_ok=True)
