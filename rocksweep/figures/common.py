"""Figures 2 and 5 of the paper, and the one way figures are saved.

Every figure function builds and returns a ``matplotlib.figure.Figure`` (no pyplot, so no
global figure registry and no backend switch: a notebook keeps its own backend and shows
the returned figure); an optional ``axes`` argument draws into axes the caller made.
Saving is separate: ``save_figure(fig, path)`` follows the output policy of
``rocksweep.outputs`` (refuses an existing file without ``overwrite``, a device, a missing
or read-only directory, an unknown suffix; writes under a temporary name, then renames).

Stability diagrams (Figures 3 and 4) live in ``rocksweep.figures.diagrams``, the work-precision
diagram in ``rocksweep.figures.accuracy``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.figure import Figure as _MplFigure
from matplotlib.lines import Line2D

from rocksweep.outputs import atomic_path, check_output
from rocksweep.vocab import axes as _axes
from rocksweep.vocab.laws import DEFAULT_LAW, VERTICAL, law_origin

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from rocksweep.compute.single import Run

from rocksweep.errors import FigureError  # noqa: F401 (defined there; re-exported)
from rocksweep.figures import DEFAULT_DPI, FORMATS, WIDTHS  # noqa: E402,F401

# What every saved figure gets, whoever saves it: TrueType fonts in PDF and PostScript
# (Type 42), as journals ask, instead of matplotlib's Type 3.
SAVE_RC = {"pdf.fonttype": 42, "ps.fonttype": 42}
# Resolution of the image a notebook shows (``Figure._repr_png_``) [dots per inch].
NOTEBOOK_DPI = 100


class Figure(_MplFigure):
    """The figure every rocksweep figure function returns: a pyplot-free matplotlib
    ``Figure`` whose own ``savefig`` embeds TrueType fonts in PDF/PS (``SAVE_RC``) and
    which a notebook shows as a PNG without ``%matplotlib inline`` (``_repr_png_``).
    Every module builds its figures from this class (tests/figures/test_plots.py checks)."""

    def savefig(self, fname, *args, **kwargs):
        with matplotlib.rc_context(SAVE_RC):
            return super().savefig(fname, *args, **kwargs)

    def _repr_png_(self) -> bytes:
        from io import BytesIO

        buf = BytesIO()
        self.savefig(buf, format="png", dpi=NOTEBOOK_DPI)
        return buf.getvalue()


def new_axes(nrows: int, ncols: int, figsize: tuple[float, float],
             **subplots) -> tuple[Figure, np.ndarray]:
    """A pyplot-free figure with constrained layout and its axes[nrows, ncols]."""
    fig = Figure(figsize=figsize, layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **subplots)
    return fig, axes


def given_axes(axes: Axes | Sequence[Axes], n: int, what: str) -> tuple[Figure, list[Axes]]:
    """The caller's axes for a figure that needs ``n`` of them (one Axes if n == 1)."""
    seq = [axes] if hasattr(axes, "plot") else list(np.ravel(np.asarray(axes, dtype=object)))
    if len(seq) < n:
        raise FigureError(f"axes: {what} needs {n} axes, {len(seq)} given")
    return seq[0].figure, seq[:n]


def save_figure(fig: Figure, path: str | Path, dpi: int = DEFAULT_DPI, *,
                overwrite: bool = False, inputs: Iterable[str | Path] = ()) -> Path:
    """Save ``fig`` to ``path`` (.png, .pdf or .svg) atomically: complete or absent.

    Refuses (``OutputError``, one line) an existing file unless ``overwrite``, any of the
    command's ``inputs``, a device, directory, missing or read-only directory, and other
    suffixes. dpi: dots per inch of raster output (PNG; the raster parts of PDF/SVG).
    """
    path = check_output(path, overwrite=overwrite, inputs=inputs, suffixes=FORMATS)
    # TrueType fonts also for a figure the caller made (not a rocksweep Figure)
    with atomic_path(path, overwrite=overwrite) as tmp, matplotlib.rc_context(SAVE_RC):
        fig.savefig(tmp, dpi=dpi, format=path.suffix[1:].lower())
    return path




def width_style(width: str | None) -> dict:
    """matplotlib rc settings of a paper width preset (``WIDTHS``: "single" or "double"
    column); {} for None (matplotlib's defaults)."""
    if width is None:
        return {}
    if width not in WIDTHS:
        raise FigureError(f"width = {width!r}: must be one of {', '.join(WIDTHS)} (or None)")
    inches, pt = WIDTHS[width]
    return {"figure.figsize": (inches, 0.8 * inches), "font.size": pt,
            "axes.titlesize": pt, "axes.labelsize": pt, "legend.fontsize": pt - 1,
            "xtick.labelsize": pt - 1, "ytick.labelsize": pt - 1, "lines.markersize": 3}


def wrap_title(title: str, inches: float, pt: float = 11.0) -> str:
    """``title`` wrapped to a width of ``inches`` at ``pt`` points (about 100/pt
    characters an inch), so a long scene name is not cut at the edges; words inside
    mathtext ($...$) stay together. A wrapped title is wrapped anew."""
    width = max(20, int(100.0 / pt * inches))
    title = " ".join(title.split("\n"))
    if len(title) <= width:
        return title
    tokens: list[str] = []
    in_math = False  # words joined while inside $...$
    for w in title.split(" "):
        if in_math:
            tokens[-1] += " " + w
        else:
            tokens.append(w)
        if w.count("$") % 2:
            in_math = not in_math
    lines = [""]
    for t in tokens:
        if lines[-1] and len(lines[-1]) + 1 + len(t) > width:
            lines.append(t)
        else:
            lines[-1] = f"{lines[-1]} {t}" if lines[-1] else t
    return "\n".join(lines)


def _wider(fig: Figure, renderer, artist) -> bool:
    bb = artist.get_window_extent(renderer)
    return bb.x0 < fig.bbox.x0 or bb.x1 > fig.bbox.x1


# Under a journal width every axes keeps at least this height per inch of its width (the
# figure grows taller rather than squash a panel to nothing), and rounds of layout tried.
MIN_ASPECT = 0.6
FIT_ROUNDS = 12


def fit_width(fig: Figure, width: str) -> Figure:
    """Fit a finished figure to a journal width (``WIDTHS``): its width in inches, titles
    no larger than the axis labels, the suptitle wrapped to the width, every figure legend
    in as many columns as fit, and as much height as the panels, labels and legends need
    (the layout's aspect at least; every axes at least ``MIN_ASPECT`` as tall as wide).
    Nothing drawn lies outside the figure (tests/figures/test_journal.py). Returns ``fig``."""
    import warnings

    from matplotlib.backends.backend_agg import FigureCanvasAgg

    inches, pt = WIDTHS[width]
    w, h = fig.get_size_inches()
    fig.set_size_inches(inches, h * inches / w)
    for ax in fig.axes:
        for t in (ax.title, ax._left_title, ax._right_title):
            t.set_fontsize(min(t.get_fontsize(), pt))
    sup = fig._suptitle
    if sup is not None:
        sup.set_fontsize(min(sup.get_fontsize(), pt))
        sup.set_text(wrap_title(sup.get_text(), inches, sup.get_fontsize()))
    for leg in [*fig.legends, *(a.get_legend() for a in fig.axes if a.get_legend())]:
        for t in leg.texts:
            t.set_fontsize(min(t.get_fontsize(), pt - 1))
    canvas = FigureCanvasAgg(fig)  # measures text as the saved file will
    for _ in range(FIT_ROUNDS):
        with warnings.catch_warnings():  # a layout too short to fit, until it grows
            warnings.simplefilter("ignore", UserWarning)
            canvas.draw()
        renderer = canvas.get_renderer()
        narrowed = False
        for leg in list(fig.legends):
            if leg._ncols > 1 and _wider(fig, renderer, leg):
                handles, labels = leg.legend_handles, [t.get_text() for t in leg.texts]
                loc = _OUTSIDE.get(getattr(leg, "_outside_loc", None) or "", "lower center")
                size = leg.texts[0].get_fontsize() if leg.texts else pt - 1
                ncol = leg._ncols - 1
                leg.remove()
                fig.legend(handles, labels, loc=loc, fontsize=size, frameon=False, ncol=ncol)
                narrowed = True
        if narrowed:
            continue
        fh = fig.get_figheight()
        tight = fig.get_tightbbox(renderer)
        grow = max(0.0, -tight.y0) + max(0.0, tight.y1 - fh)
        shown = [a for a in fig.axes if a.get_visible()]
        if shown:
            rows = max(a.get_subplotspec().get_gridspec().nrows if a.get_subplotspec()
                       else 1 for a in shown)
            pos = [a.get_position() for a in shown]
            lack = max(MIN_ASPECT * p.width * inches - p.height * fh for p in pos)
            grow += max(0.0, lack) * rows
        if grow < 0.01:
            break
        fig.set_size_inches(inches, fh + grow + 0.02)
    canvas.draw()
    return fig


# a figure legend's constrained-layout place (``Legend._outside_loc``) -> its loc
_OUTSIDE = {"lower": "outside lower center", "upper": "outside upper center",
            "left": "outside left upper", "right": "outside right upper"}


# ---------------------------------------------------------------------------------------
# Figure 5: time histories
# ---------------------------------------------------------------------------------------

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
    figure). Returns the figure.
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
            raise FigureError("time history: a run without a history (simulate with "
                              "history=True)")
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
    for run in runs:
        h = run.history
        body = run.point.body
        t = h["t"] * t_scale
        line, = ax_th.plot(t, h["theta"] / body.alpha_ref, lw=1.2,
                           label=_label(run, swept))
        c = line.get_color()
        ax_e.plot(t, h["E"] / body.E_ref, lw=1.2, color=c)
        ax_d.plot(t, (h["D_damp"] + h["E_impact"]) / body.E_ref, lw=1.2, color=c)
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
    ax_d.set_xlabel(f"$t$ [s] ($p$ = {next(iter(ps)):g} rad/s)" if seconds else r"$pt$")
    for ax in (ax_in, ax_th, ax_e, ax_d):
        ax.grid(alpha=0.3)
    if title and axes is None:
        fig.suptitle(title, fontsize=10)
    return fig


def time_history_figure(runs: Sequence[Run], swept: Sequence[str], title: str,
                        path: str | Path, *, dpi: int = DEFAULT_DPI,
                        overwrite: bool = True) -> None:
    """``time_history`` saved to ``path`` (the call of ``rocksweep simulate --plot``)."""
    save_figure(time_history(runs, swept, title), path, dpi, overwrite=overwrite)


# ---------------------------------------------------------------------------------------
# Figure 2: restitution
# ---------------------------------------------------------------------------------------

# u/u_cr -> colour: blues below 0, reds above, black at 0 (the rigid-like case must stand
# out on white, so no light middle colour of a diverging map)
_U_COLOURS = {-2.0: "#2166ac", -1.0: "#67a9cf", 0.0: "#000000", 1.0: "#ef8a62",
              2.0: "#b2182b"}


def restitution_map(lam: np.ndarray, u_over_ucr: np.ndarray, e_upper: np.ndarray,
                    e_housner: float, title: str = "",
                    axes: Sequence[Axes] | None = None, lam_limit: np.ndarray | None = None,
                    law: str = DEFAULT_LAW) -> Figure:
    """Figure 2: (a) e against lam for u/u_cr = -2, -1, 0, 1, 2; (b) e against u/u_cr at
    lam = 0 with Housner's e of the same body welded rigid.

    lam: float[n_lam]; u_over_ucr: float[n_u]; e_upper: float[n_lam, n_u], eq. (1) (or
    the impact law ``law``'s e) under the paper's upper sign (the lower sign is its
    mirror, e_lower(lam, u) = e_upper(lam, -u)); axes: 2 axes to draw into (else a new
    figure). lam_limit: float[n_u], the largest lam at which an impact cannot gain energy
    (``rocksweep.physics.impact.lam_energy_limit``; 2: none up to 2, NaN: every lam
    gains): (a) draws each curve dashed beyond it with a diamond at it, (b) draws it
    against u/u_cr on a right-hand axis.
    """
    if axes is None:
        fig, grid = new_axes(1, 2, (11, 4.6))
        ax_a, ax_b = grid[0]
    else:
        fig, (ax_a, ax_b) = given_axes(axes, 2, "the restitution figure")
    lam = np.asarray(lam, float)
    u_over_ucr = np.asarray(u_over_ucr, float)
    e_upper = np.asarray(e_upper, float)
    for v, colour in _U_COLOURS.items():
        if not u_over_ucr.min() <= v <= u_over_ucr.max():
            continue
        j = int(np.argmin(abs(u_over_ucr - v)))
        lw = 2.0 if v == 0 else 1.4
        label = f"$u/u_{{cr}}$ = {v:g}"
        if lam_limit is None:
            ax_a.plot(lam, e_upper[:, j], color=colour, lw=lw, label=label)
            continue
        lim = float(lam_limit[j])
        lim = -np.inf if np.isnan(lim) else lim
        ok = lam <= lim
        ax_a.plot(lam, np.where(ok, e_upper[:, j], np.nan), color=colour, lw=lw, label=label)
        ax_a.plot(lam, np.where(ok, np.nan, e_upper[:, j]), color=colour, lw=lw * 0.7, ls="--")
        if lam[0] <= lim <= lam[-1]:
            ax_a.plot([lim], [np.interp(lim, lam, e_upper[:, j])], "D", color=colour, ms=5)
    if lam_limit is not None:
        ax_a.plot([], [], "D", color="0.3", ms=5, ls="--", lw=1.0,
                  label=r"energy-admissible $\lambda$ (dashed: impacts gain energy)")
    ax_a.axhline(1.0, color="0.5", lw=0.6, ls="--")
    ax_a.axhline(0.0, color="0.5", lw=0.6)
    ax_a.set_xlabel(r"$\lambda$")
    ax_a.set_ylabel("$e$")
    which = "upper sign of eq. 1" if law == VERTICAL else f"law {law}, upper sign"
    ax_a.set_title(rf"(a) $e$ against $\lambda$ ({which})", fontsize=10)
    ax_a.legend(fontsize=8)
    i0 = int(np.argmin(abs(lam)))
    first = law_origin(law) if law == VERTICAL else f"law {law}"
    ax_b.plot(u_over_ucr, e_upper[i0], color="C0",
              label=rf"{first}, $\lambda$ = {lam[i0]:g}, upper sign")
    ax_b.plot(u_over_ucr, e_upper[i0, ::-1], color="C1", ls="--",
              label="lower sign (mirror)")
    ax_b.axhline(e_housner, color="k", lw=0.8, ls=":",
                 label=f"Housner, rigid body: {e_housner:.3f}")
    ax_b.set_xlabel(r"$u/u_{cr}$")
    ax_b.set_ylabel("$e$")
    ax_b.set_title(rf"(b) $e$ against $u/u_{{cr}}$ at $\lambda$ = {lam[i0]:g}", fontsize=10)
    if lam_limit is not None:
        ax_c = ax_b.twinx()
        ax_c.plot(u_over_ucr, lam_limit, color="C2", lw=1.2, ls="-.")
        ax_c.set_ylabel(r"largest $\lambda$ without energy gain", color="C2")
        ax_c.tick_params(axis="y", colors="C2")
        ax_b.plot([], [], color="C2", lw=1.2, ls="-.",
                  label=r"energy-admissible $\lambda$ (right axis)")
    ax_b.legend(fontsize=8)
    for ax in (ax_a, ax_b):
        ax.grid(alpha=0.3)
    if title and axes is None:
        fig.suptitle(title, fontsize=11)
    return fig


def restitution_figure(lam: np.ndarray, u_over_ucr: np.ndarray, e_upper: np.ndarray,
                       e_housner: float, title: str, path: str | Path, *,
                       dpi: int = DEFAULT_DPI, overwrite: bool = True) -> None:
    """``restitution_map`` saved to ``path`` (the call of ``rocksweep restitution --plot``)."""
    save_figure(restitution_map(lam, u_over_ucr, e_upper, e_housner, title), path, dpi,
                overwrite=overwrite)
