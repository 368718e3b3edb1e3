"""The fragility figure (rocksweep.figures.fragility), drawn with the Agg backend."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import PathCollection, PolyCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from test_fragility import suite_dataset  # noqa: E402

from rocksweep.analysis.fragility import fragility  # noqa: E402
from rocksweep.errors import FragilityFigureError
from rocksweep.figures.fragility import fragility_figure  # noqa: E402


def test_one_colour_per_lam_with_band_points_and_median_differences(tmp_path):
    ds = suite_dataset(n_records=40, lams=(0.0, 0.2, 0.4), medians=(0.4, 0.5, 0.6))
    ds["status"][1, 0, 0] = 2  # one flagged point: 39 records counted there
    fr = fragility(ds, bootstrap=40, seed=0)
    fig = fragility_figure(fr)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    lines = [ln for ln in ax.get_lines() if len(ln.get_xdata())]
    assert len(lines) == 3
    assert len({ln.get_color() for ln in lines}) == 3
    # each line is the fitted curve: 0.5 at its median
    for i, ln in enumerate(lines):
        x, y = np.asarray(ln.get_xdata()), np.asarray(ln.get_ydata())
        assert np.interp(float(fr["im_median"][i]), x, y) == pytest.approx(0.5, abs=0.02)
    assert sum(isinstance(c, PolyCollection) for c in ax.collections) == 3  # bands
    pts = [c for c in ax.collections if isinstance(c, PathCollection)]
    assert len(pts) == 3
    sizes = pts[1].get_sizes()
    assert sizes[0] < sizes[1]  # fewer records counted at the flagged point's level
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    m0, m2 = float(fr["im_median"][0]), float(fr["im_median"][2])
    assert f"{100 * (m2 / m0 - 1):+.0f}% vs lam = 0" in texts[2]
    assert "lam = 0.2" in texts[1] and "%" not in texts[0]
    fig.savefig(tmp_path / "f.png")
    assert (tmp_path / "f.png").stat().st_size > 1000


def test_stripe_markers_at_the_same_place_stay_readable():
    """Two lam values with the same fractions at the same stripes drew opaque
    markers over each other; each colour has its own shape and a translucent face."""
    ds = suite_dataset(n_records=20, lams=(0.0, 0.2, 0.4), medians=(0.5, 0.5, 0.5))
    fr = fragility(ds, bootstrap=0)
    fig = fragility_figure(fr)
    pts = [c for c in fig.axes[0].collections if isinstance(c, PathCollection)]
    assert len(pts) == 3
    offsets = [c.get_offsets() for c in pts]
    assert np.array_equal(offsets[0], offsets[1])  # the case: they overlap exactly
    shapes = {tuple(map(tuple, c.get_paths()[0].vertices.round(3))) for c in pts}
    assert len(shapes) == 3  # one marker shape per colour
    for c in pts:
        face, edge = c.get_facecolor()[0], c.get_edgecolor()[0]
        assert face[3] < 0.7 and edge[3] == 1.0  # see-through face, solid outline
        assert np.allclose(face[:3], edge[:3])  # the curve's colour


def test_into_given_axes_and_a_curve_without_fit():
    ds = suite_dataset(n_records=10)
    ds["outcome"][1] = 0  # lam = 0.2 never overturns: no fit
    ds["status"][1] = 1
    fr = fragility(ds)
    fig = Figure()
    ax = fig.add_subplot()
    assert fragility_figure(fr, ax=ax) is fig
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "no fit (no_failures)" in texts[1]


def test_bad_width():
    fr = fragility(suite_dataset(n_records=10))
    with pytest.raises(FragilityFigureError):
        fragility_figure(fr, width="huge")
