"""Figures ready for a journal and a notebook: every Figure rocksweep returns
saves TrueType fonts through its own ``savefig``, fits a journal width without clipping a
legend or a label, keeps titles no larger than its labels, and shows itself in a notebook
as a PNG without ``%matplotlib inline``."""

from __future__ import annotations

import ast
import io
import sys
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.text import Text

import rocksweep
from rocksweep.figures import WIDTHS
from rocksweep.figures.style import Figure

ROOT = Path(__file__).resolve().parents[2]
PKG = ROOT / "rocksweep"
SMALL = {"pulse.w_over_p": {"start": 0.5, "stop": 6, "num": 8},
         "pulse.A_ratio": {"start": 0.5, "stop": 8, "num": 8}}
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def laws():
    """Three impact laws x two lam over a small diagram (384 points)."""
    return rocksweep.run(ROOT / "configs" / "impact-laws.yaml", overrides=SMALL)


def _figures(ds):
    yield "diagram", rocksweep.plot(ds)
    yield "laws compared", rocksweep.plot(ds, compare="impact.law")
    yield "lam compared", rocksweep.plot(ds, compare="lam", curves=True)
    yield "line", rocksweep.plot(ds.isel(A_ratio=5))


def test_every_figure_module_builds_rocksweep_figures():
    """One Figure class: no module makes a bare matplotlib Figure (its savefig would
    write Type 3 fonts, a notebook would not show it); annotations may name it."""
    bare = []
    for path in sorted(PKG.rglob("*.py")):
        if path == PKG / "figures" / "style.py":
            continue
        tree = ast.parse(path.read_text())
        mpl = any(isinstance(n, ast.ImportFrom) and n.module == "matplotlib.figure"
                  and any(a.name == "Figure" for a in n.names) for n in ast.walk(tree))
        bare += [f"{path.relative_to(ROOT)}:{n.lineno}" for n in ast.walk(tree)
                 if mpl and isinstance(n, ast.Call) and isinstance(n.func, ast.Name)
                 and n.func.id == "Figure"]
    assert not bare, "matplotlib's Figure imported (use rocksweep.figures.style.Figure): " \
        + ", ".join(bare)


def test_savefig_on_a_returned_figure_embeds_truetype(laws, tmp_path):
    sims = rocksweep.simulate(ROOT / "configs" / "fig5.yaml")
    from rocksweep.figures.pulses import shapes_figure

    figs = [*(f for _, f in _figures(laws)), sims[-1].figure(), shapes_figure()]
    for k, fig in enumerate(figs):
        assert isinstance(fig, Figure)
        out = tmp_path / f"f{k}.pdf"
        fig.savefig(out)  # plain matplotlib savefig, as a user calls it
        pdf = out.read_bytes()
        assert b"/Type3" not in pdf and b"/FontFile2" in pdf, k  # TrueType embedded
        # a notebook shows it: IPython calls _repr_png_ when no backend is set up
        assert fig._repr_png_()[:8] == PNG


@pytest.fixture(scope="module")
def analyses(laws, suite_result):
    """One Dataset of every analysis kind rocksweep.plot draws (the suite's and the
    impact-law sweep's), and a spectra Dataset over w_over_p, A_ratio and lam."""
    import warnings

    import pandas as pd

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # verdicts on a 6-record suite: not the point here
        suite = rocksweep.open(suite_result)
        fr = rocksweep.fragility(suite, bootstrap=20)
        x = np.geomspace(0.01, 5.0, 20)
        hazard = pd.DataFrame({"PGA [g]": x, "annual_rate": 1e-4 * x ** -2.0})
        one_shape = rocksweep.run(ROOT / "configs" / "ci-small.yaml",
                                  overrides=["pulse.shape=sine"])
        return {"fragility": fr, "ida": rocksweep.ida(suite),
                "risk": rocksweep.risk(fr, hazard),
                "im_efficiency": rocksweep.im_efficiency(suite),
                "boundaries": rocksweep.boundaries(laws, search=False),
                "spectra": rocksweep.spectra(one_shape, search=False)}


@pytest.mark.parametrize("width", list(WIDTHS))
def test_every_analysis_figure_fits_the_journal_widths(analyses, width, tmp_path):
    """Every figure rocksweep returns, the analyses' too, at single and double
    column width: nothing outside the figure, TrueType in a PDF."""
    for kind, ds in analyses.items():
        fig = rocksweep.plot(ds, width=width)
        assert isinstance(fig, Figure), kind
        _fits(fig, kind, width)
        fig.savefig(tmp_path / f"{kind}.pdf")
        assert b"/Type3" not in (tmp_path / f"{kind}.pdf").read_bytes(), kind


def _fits(fig, name, width):
    """At a journal width: nothing drawn outside the figure, every axes of a readable
    height (the figure grew rather than squash it), titles no larger than the labels."""
    inches, _ = WIDTHS[width]
    assert fig.get_figwidth() == pytest.approx(inches), name
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    box = fig.bbox
    for a in [fig._suptitle, *fig.legends, *fig.axes]:
        if a is None or not a.get_visible():
            continue
        bb = a.get_tightbbox(r)
        assert (bb.x0 >= box.x0 - 1e-6 and bb.x1 <= box.x1 + 1e-6
                and bb.y0 >= box.y0 - 1e-6 and bb.y1 <= box.y1 + 1e-6), \
            f"{name} at {width}: {type(a).__name__} at {bb.extents} outside {box.extents}"
    for ax in fig.axes:
        if ax.get_visible():
            assert ax.get_position().height * fig.get_figheight() > 0.3, name
    labels = [t.get_fontsize() for ax in fig.axes
              for t in (ax.xaxis.label, ax.yaxis.label) if t.get_text()]
    titles = [ax.title for ax in fig.axes] + [fig._suptitle]
    for t in titles:
        if t is not None and t.get_text():
            assert t.get_fontsize() <= max(labels), (name, t.get_text())


@pytest.mark.parametrize("width", list(WIDTHS))
def test_journal_widths_clip_nothing_and_titles_are_no_larger_than_labels(laws, width):
    for name, fig in _journal(laws, width):
        _fits(fig, name, width)


def _journal(ds, width):
    yield "diagram", rocksweep.plot(ds, width=width)
    yield "laws compared", rocksweep.plot(ds, compare="impact.law", width=width)
    yield "lam compared", rocksweep.plot(ds, compare="lam", width=width)
    yield "line", rocksweep.plot(ds.isel(A_ratio=5), width=width)


def test_lam_is_written_as_lambda(laws):
    for name, fig in _figures(laws):
        texts = [t.get_text() for t in fig.findobj(Text)]
        plain = [t for t in texts if "lam" in t.replace(r"\lambda", "")]
        assert not plain, (name, plain)


def test_no_progress_bar_class_from_a_notebook_without_progress(monkeypatch):
    """tqdm.auto in a notebook without ipywidgets warns (TqdmWarning) even for a bar that
    is never shown: with progress=False no tqdm class is used at all (``NoBar``), and it
    takes the calls the sweep loops make of a bar."""
    from rocksweep.compute.driver import NoBar, progress_class

    monkeypatch.setitem(sys.modules, "ipykernel", sys.modules.get("ipykernel") or
                        type(sys)("ipykernel"))
    assert progress_class(False) is NoBar
    with progress_class(False)(total=3, unit="pt", disable=True) as bar:
        bar.total += 2
        bar.set_description("refine 4")
        bar.refresh()
        bar.update(5)
    assert bar.total == 5
    import tqdm.auto

    assert progress_class(True) is tqdm.auto.tqdm


def test_shapes_figure_has_a_panel_per_family():
    from rocksweep.figures.pulses import shapes_figure
    from rocksweep.vocab.ground import SHAPES

    fig = shapes_figure()
    assert len(fig.axes) == len(SHAPES)
    assert [ax.get_title() for ax in fig.axes] == ["sine", "cosine", "Ricker",
                                                   "Mavroeidis-Papageorgiou"]
    assert sum(len(ax.get_lines()) for ax in fig.axes) == 7 + 4  # 7 shapes + 4 zero lines
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=50)
    assert buf.getvalue()[:8] == PNG
    assert np.isfinite(fig.get_size_inches()).all()


def test_long_legends_and_many_curves_fit_a_single_column(suite_result):
    """Verdict-laden legend entries are wrapped, not allowed to squeeze the axes or run
    off the figure; twelve risk curves get twelve colours."""
    import warnings

    import pandas as pd
    from matplotlib.colors import to_rgba

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        suite = rocksweep.open(suite_result)
        modes = rocksweep.fragility(suite, state=["mode1", "mode2"], bootstrap=10)
        six = rocksweep.fragility(suite, state=["uplift", "theta:0.1", "theta:0.25",
                                                "theta:0.5", "overturn", "mode1"],
                                  bootstrap=0)
    fig = rocksweep.plot(modes, width="single")
    _fits(fig, "fragility mode1,mode2", "single")
    assert fig.axes[0].get_position().width > 0.7  # of the figure's width
    x = np.geomspace(0.01, 5.0, 20)
    rk = rocksweep.risk(six, pd.DataFrame({"PGA [g]": x, "annual_rate": 1e-4 * x ** -2.0}))
    fig = rocksweep.plot(rk, width="single")
    _fits(fig, "risk of 12 curves", "single")
    lines = [ln for ln in fig.axes[1].get_lines() if not ln.get_label().startswith("_")]
    assert len(lines) == 12
    assert len({to_rgba(ln.get_color()) for ln in lines}) == 12


def _many_curve_datasets(n: int = 12) -> dict:
    """Synthetic Datasets of every analysis figure that draws one curve per value of
    another dim, with ``n`` such values (lam, records, series)."""
    import xarray as xr

    lam = np.round(np.linspace(0.0, 0.55, n), 3)
    w = np.geomspace(0.5, 6.0, 8)
    a_min = 1.0 + lam[:, None] + 0.2 * w[None, :]
    mode = np.where(w[None, :] < 2.0, 1, 2).repeat(n, 0).astype(np.int8)
    bd = xr.Dataset({"A_min": (("lam", "w_over_p"), a_min), "mode": (("lam", "w_over_p"), mode)},
                    coords={"lam": lam, "w_over_p": w},
                    attrs={"rocksweep_kind": "boundaries", "x_axis": "w_over_p",
                           "y_axis": "A_ratio"})
    ims = ["PGA", "PGV", "Sa(0.5)", "CAV"]
    eff = xr.Dataset({"beta_scale": (("im", "lam"), 0.3 + 0.01 * np.arange(4 * n).reshape(4, n)),
                      "beta": (("im", "lam"), 0.3 + 0.01 * np.arange(4 * n).reshape(4, n))},
                     coords={"im": ims, "lam": lam}, attrs={"rocksweep_kind": "im_efficiency"})
    pga = np.geomspace(0.1, 1.6, 6)
    first = np.geomspace(0.3, 1.2, n)
    th = np.where(pga[None, :] < first[:, None], pga[None, :] / first[:, None], np.nan)
    ida = xr.Dataset({"ida_im": (("record",), first),
                      "theta_max_over_alpha": (("record", "PGA"), th)},
                     coords={"record": [f"SYN{r:02d}.AT2" for r in range(n)], "PGA": pga},
                     attrs={"rocksweep_kind": "ida", "im": "PGA", "im_units": "g"})
    A = np.linspace(0.5, 8.0, 6)
    theta = np.clip(A[None, :, None] / (2.0 + a_min[:, None, :]), 0.0, 0.99)
    out = (theta > 0.9).astype(np.int8)
    sp = xr.Dataset({"A_min": (("lam", "w_over_p"), a_min), "mode": (("lam", "w_over_p"), mode),
                     "theta_max_over_alpha": (("lam", "A_ratio", "w_over_p"), theta),
                     "outcome": (("lam", "A_ratio", "w_over_p"), out)},
                    coords={"lam": lam, "A_ratio": A, "w_over_p": w},
                    attrs={"rocksweep_kind": "spectra"})
    return {"boundaries": bd, "im_efficiency": eff, "ida": ida, "spectra": sp}


def _curve_colours(ax) -> list:
    from matplotlib.colors import to_rgba

    lines = [ln for ln in ax.get_lines() if not ln.get_label().startswith("_")
             and ln.get_linestyle() not in ("None", "")]
    return [to_rgba(ln.get_color()) for ln in lines]


@pytest.mark.parametrize("width", list(WIDTHS))
def test_twelve_curves_fit_and_get_twelve_colours(width):
    """Twelve curves (lam values, records, series): every figure fits the journal width
    (legend neither cut nor squeezing the axes) and no two curves share a colour (the
    colour cycle repeats after ten)."""
    from matplotlib.colors import to_rgba

    from rocksweep.figures.results import ida_figure

    for kind, ds in _many_curve_datasets(12).items():
        fig = rocksweep.plot(ds, width=width)
        _fits(fig, f"{kind} of 12 curves", width)
        ax = fig.axes[-1]
        if kind == "im_efficiency":
            colours = {to_rgba(p.get_facecolor()) for p in ax.patches}
        elif kind == "ida":
            colours = {to_rgba(ln.get_color()) for ln in ax.get_lines()}
        else:
            colours = set(_curve_colours(ax)) - {to_rgba("0.3")}
        assert len(colours) == 12, (kind, width, len(colours))
        legends = [leg for leg in [*fig.legends, *(a.get_legend() for a in fig.axes)]
                   if leg is not None]
        for leg in legends:
            _legend_clear_of_axes(fig, leg, kind)
        r = FigureCanvasAgg(fig).get_renderer()
        boxes = [leg.get_window_extent(r) for leg in legends]
        assert not any(boxes[i].overlaps(boxes[j]) for i in range(len(boxes))
                       for j in range(i)), f"{kind} at {width}: legends overlap"
    assert ida_figure  # the ida Dataset is drawn by ida_figure (its kind)


def _legend_clear_of_axes(fig, leg, name):
    """A legend placed outside its axes does not lie over any axes' plotting area."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    lb = leg.get_window_extent(canvas.get_renderer())
    for a in fig.axes:
        if a.get_legend() is leg:
            continue
        ab = a.get_window_extent()
        assert not lb.overlaps(ab), f"{name}: legend over an axes"


def test_a_min_figure_of_twelve_panels_has_twelve_colours_and_a_clear_legend():
    from matplotlib.colors import to_rgba

    from rocksweep.analysis.boundaries import AMinCurve
    from rocksweep.figures.a_min import a_min_figure

    x = np.geomspace(0.5, 6.0, 8)
    curves = [AMinCurve({"lam": round(0.05 * k, 2)}, x, 1.0 + 0.1 * k + 0.2 * x,
                        np.where(x < 2.0, 1, 2).astype(np.int8), x * np.nan, x * np.nan,
                        np.zeros(8, np.int64)) for k in range(12)]
    fig = a_min_figure(curves, title="twelve lam")
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    ax = fig.axes[0]
    assert len({to_rgba(ln.get_color()) for ln in ax.get_lines()
                if not ln.get_label().startswith("_")} - {to_rgba("0.3")}) == 12
    legends = [*fig.legends, ax.get_legend()]
    for leg in legends:
        if leg is None:
            continue
        lb = leg.get_window_extent(r)
        assert fig.bbox.x0 <= lb.x0 and lb.x1 <= fig.bbox.x1 and fig.bbox.y0 <= lb.y0 \
            and lb.y1 <= fig.bbox.y1
        assert not lb.overlaps(ax.get_window_extent()), "a_min legend over the curves"


def test_the_rocking_spectrum_names_its_line_styles_and_the_values_it_shows():
    """With up to four lam values the rocking panel's legend says which line style is
    which lam; a swept key the panel does not draw (an angle) is named at the value drawn."""
    sp = _many_curve_datasets(3)["spectra"]
    labels = rocksweep.plot(sp).axes[0].get_legend_handles_labels()[1]
    lams = [lb for lb in labels if lb.startswith("$\\lambda$")]
    assert len(lams) == 3, labels
    angled = sp.expand_dims(angle=[30.0, 60.0])
    fig = rocksweep.plot(angled)
    assert "angle = 30" in fig.axes[0].get_title()
    # a word axis (pulse.shape) is named as itself: formatting it as a number was a
    # ValueError (issue 45)
    shaped = sp.expand_dims(shape=["cosine", "sine"])
    assert "shape = cosine" in rocksweep.plot(shaped).axes[0].get_title()


def _texts_clear(fig, name):
    """No two texts of a figure overprint (tick labels, axis labels, titles, legend
    entries) and every one lies inside the figure."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    texts = [fig._suptitle] if fig._suptitle is not None else []
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        texts += [ax.title, ax.xaxis.label, ax.yaxis.label]
        for axis in (ax.xaxis, ax.yaxis):  # the ticks drawn: inside the view interval
            texts += [t.label1 for t in axis._update_ticks()]
        if ax.get_legend() is not None:
            texts += list(ax.get_legend().texts)
    for leg in fig.legends:
        texts += list(leg.texts)
    boxes = [(t.get_text(), t.get_window_extent(r).shrunk(0.98, 0.9)) for t in texts
             if t.get_visible() and t.get_text().strip()]
    box = fig.bbox
    for text, b in boxes:
        assert (b.x0 >= box.x0 - 1 and b.x1 <= box.x1 + 1 and b.y0 >= box.y0 - 1
                and b.y1 <= box.y1 + 1), f"{name}: {text!r} outside the figure"
    for i in range(len(boxes)):
        for j in range(i):
            assert not boxes[i][1].overlaps(boxes[j][1]), \
                f"{name}: {boxes[i][0]!r} over {boxes[j][0]!r}"


def _floor_and_angle_datasets():
    """Synthetic Datasets of the new axes' figures (issue 45): a suite's floor spectrum
    over orientation x 2 stripes x 8 building periods x 8 damping values (16 curves a
    panel, more than MAX_CURVES), a pulse's A_min floor spectrum, an IDA over 4 angles x
    4 periods (16 panels' worth) and a fragility of 16 curves (4 angles x 4 periods)."""
    import xarray as xr

    T = np.geomspace(0.1, 2.0, 8)
    damp = np.linspace(0.02, 0.09, 8)
    p = np.clip(np.linspace(0, 1, 2 * 2 * 8 * 8).reshape(2, 2, 8, 8), 0, 1)
    fs = xr.Dataset({"p_overturn": (("orientation", "PGA", "floor.damping", "floor.period"),
                                    p)},
                    coords={"orientation": ["each", "worst"], "PGA": [0.3, 0.6],
                            "floor.damping": damp, "floor.period": T},
                    attrs={"rocksweep_kind": "floor_spectrum", "scale_im": "PGA",
                           "method": "share of records"})
    fa = xr.Dataset({"A_min": (("floor.period",), 1.0 + 0.2 * np.log(T))},
                    coords={"floor.period": T},
                    attrs={"rocksweep_kind": "floor_spectrum", "method": "A_min",
                           "kind": "block"})
    pga = np.array([0.1, 0.2, 0.3, 0.45, 0.6])
    first = np.geomspace(0.15, 0.5, 6)
    th = np.where(pga[None, :] < first[:, None], pga[None, :] / first[:, None], np.nan)
    th = np.broadcast_to(th, (4, 4, 6, 5)).copy()
    ida = xr.Dataset({"ida_im": (("angle", "floor.period", "record"),
                                 np.broadcast_to(first, (4, 4, 6)).copy()),
                      "theta_max_over_alpha": (("angle", "floor.period", "record", "PGA"),
                                               th)},
                     coords={"angle": [0.0, 45.0, 90.0, 135.0], "floor.period": T[:4],
                             "record": [f"RSN{r}_EV_ST000.AT2" for r in range(6)],
                             "PGA": pga},
                     attrs={"rocksweep_kind": "ida", "im": "PGA", "im_units": "g"})
    grid = np.geomspace(0.1, 1.0, 50)
    med = np.geomspace(0.2, 0.6, 16).reshape(4, 4)
    from rocksweep.analysis.likelihood import lognormal_cdf

    curve = lognormal_cdf(grid, med[..., None], 0.4)
    fr = xr.Dataset({"im_median": (("angle", "floor.period"), med),
                     "beta": (("angle", "floor.period"), np.full((4, 4), 0.4)),
                     "reason": (("angle", "floor.period"), np.full((4, 4), "ok")),
                     "curve": (("angle", "floor.period", "im_grid"), curve)},
                    coords={"angle": [0.0, 45.0, 90.0, 135.0], "floor.period": T[:4],
                            "im_grid": grid},
                    attrs={"rocksweep_kind": "fragility", "im": "PGA", "im_units": "g",
                           "method": "stripes-mle"})
    return {"floor spectrum over angles": fs, "pulse A_min floor spectrum": fa,
            "IDA panels": ida, "fragility of 16 curves": fr}


@pytest.mark.parametrize("width", [None, "single"])
def test_the_new_axes_figures_can_be_read(width):
    """Issue 45: the floor spectrum over angles (clipped title, overprinted log ticks, a
    legend of two thirds of the width), IDA panels (titles and ticks overlapping), the
    pulse A_min floor spectrum (y label clipped), a fragility of 16 curves (legend
    clipped): no text over another, none outside the figure, at the single column width
    (the double's fit: ``_fits``, as for every figure), and the floor spectra at
    matplotlib's default size too (what ``rocksweep floor-spectrum`` writes)."""
    for name, ds in _floor_and_angle_datasets().items():
        if width is None and "floor" not in name:
            continue
        fig = rocksweep.plot(ds, width=width)
        if width is not None:
            _fits(fig, name, width)
        _texts_clear(fig, f"{name} at {width}")
        if name == "floor spectrum over angles":
            assert len(fig.axes) == 2 and len(fig.legends) == 1  # a panel per answer
            assert "of 16 curves" in fig.axes[0].get_title()
        if name == "IDA panels":
            assert "6 of 16" in fig._suptitle.get_text()
