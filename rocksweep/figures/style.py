"""The figure every rocksweep figure function returns, journal widths, and the one way
figures are saved.

Every figure function builds and returns a ``matplotlib.figure.Figure`` (no pyplot, so no
global figure registry and no backend switch: a notebook keeps its own backend and shows
the returned figure); an optional ``axes`` argument draws into axes the caller made.
Saving is separate: ``save_figure(fig, path)`` follows the output policy of
``rocksweep.outputs`` (refuses an existing file without ``overwrite``, a device, a missing
or read-only directory, an unknown suffix; writes under a temporary name, then renames).

Figure 2 is ``rocksweep.figures.restitution``, Figures 3 and 4 ``rocksweep.figures.diagrams``,
Figure 5 ``rocksweep.figures.history``.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Sequence
from io import BytesIO
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib import ticker
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure as _MplFigure

from rocksweep.errors import FigureError
from rocksweep.figures import DEFAULT_DPI, FORMATS, WIDTHS
from rocksweep.outputs import atomic_path, check_output

if TYPE_CHECKING:
    from matplotlib.axes import Axes

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


def curve_colours(n: int) -> list:
    """``n`` colours no two alike: matplotlib's cycle C0-C9 up to 10 curves, tab20 up to
    20, then viridis sampled evenly (the cycle repeats after 10: twelve risk curves had
    two pairs of one colour)."""
    if n <= 10:
        return [f"C{i}" for i in range(n)]
    if n <= 20:
        return [matplotlib.colormaps["tab20"](i) for i in range(n)]
    return [matplotlib.colormaps["viridis"](x) for x in np.linspace(0.0, 0.95, n)]


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
    grow_to_fit(fig)
    return fig


def grow_to_fit(fig: Figure, *, narrow_legends: bool = True) -> Figure:
    """A finished figure made as tall as its panels, labels and legends need, at its own
    width: nothing drawn outside it (a legend below the axes, a wrapped title) and every
    axes at least ``MIN_ASPECT`` as tall as wide. ``narrow_legends``: a figure legend
    wider than the figure loses a column first (``fit_width``). Text is measured as the
    saved file will draw it. Returns ``fig``."""
    inches = fig.get_figwidth()
    canvas = FigureCanvasAgg(fig)  # measures text as the saved file will
    for _ in range(FIT_ROUNDS):
        with warnings.catch_warnings():  # a layout too short to fit, until it grows
            warnings.simplefilter("ignore", UserWarning)
            canvas.draw()
        renderer = canvas.get_renderer()
        narrowed = False
        for leg in list(fig.legends) if narrow_legends else []:
            if leg._ncols > 1 and _wider(fig, renderer, leg):
                handles, labels = leg.legend_handles, [t.get_text() for t in leg.texts]
                loc = _OUTSIDE.get(getattr(leg, "_outside_loc", None) or "", "lower center")
                size = leg.texts[0].get_fontsize() if leg.texts else None
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
            return fig  # laid out as it is drawn: no draw more
        fig.set_size_inches(inches, fh + grow + 0.02)
    canvas.draw()
    return fig


def log_ticks(axis, values: Sequence[float] | np.ndarray | None = None) -> None:
    """Readable labels on a log axis (``ax.xaxis`` or ``ax.yaxis``): matplotlib labels
    the minor ticks of a range under a decade ("2x10^-1 3x10^-1 ...", overprinted at a
    journal width); here the major ticks are the data's own values when they are few
    (``values``: at most 6), else 1, 2, 5 a decade over ranges of up to two decades and
    the decades beyond, each labelled as %g; minor ticks unlabelled."""
    vals = np.unique(np.asarray(values if values is not None else [], float))
    vals = vals[np.isfinite(vals) & (vals > 0)]
    if 1 < vals.size <= 6:
        axis.set_major_locator(ticker.FixedLocator(vals))
    else:
        lo, hi = axis.get_view_interval()
        decades = np.log10(max(hi, 1e-300) / max(lo, 1e-300)) if lo > 0 else 3.0
        axis.set_major_locator(ticker.LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)
                                                 if decades <= 2.0 else (1.0,)))
    axis.set_major_formatter(ticker.FuncFormatter(lambda v, _pos: f"{v:g}"))
    axis.set_minor_formatter(ticker.NullFormatter())


# a figure legend's constrained-layout place (``Legend._outside_loc``) -> its loc
_OUTSIDE = {"lower": "outside lower center", "upper": "outside upper center",
            "left": "outside left upper", "right": "outside right upper"}
