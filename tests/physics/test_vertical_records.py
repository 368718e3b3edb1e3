"""A record's vertical component on the horizontal's samples, and its intensity measures."""

from __future__ import annotations

import numpy as np
import pytest

from rocksweep.physics.ground_motion import same_grid, vertical_ims, vertical_samples
from rocksweep.physics.records import parse_record


def _two_column(t, a, name: str):
    text = "\n".join(f"{ti:.10g} {ai:.10g}" for ti, ai in zip(t, a, strict=True))
    return parse_record(text.encode(), f"{name}.txt")


def test_same_grid_keeps_the_samples_bit_for_bit():
    t = np.arange(11) * 0.01
    h = _two_column(t, np.sin(t * 30.0), "h")
    v = _two_column(t, 0.3 * np.cos(t * 50.0) + 0.01, "v")
    assert same_grid(v, h)
    np.testing.assert_array_equal(vertical_samples(v, h), v.acc)


def test_another_dt_is_interpolated_onto_the_horizontal_and_zero_after_its_end():
    h = _two_column(np.arange(9) * 0.02, np.linspace(-1.0, 1.0, 9), "h")
    # a vertical sampled twice as fine, linear in t (its interpolant is exact), shorter
    tv = np.arange(11) * 0.01
    v = _two_column(tv, 0.5 - 2.0 * tv, "v")
    assert not same_grid(v, h)
    got = vertical_samples(v, h)
    th = np.arange(9) * 0.02
    want = np.where(th <= 0.1 + 1e-12, 0.5 - 2.0 * th, 0.0)
    np.testing.assert_allclose(got, want, atol=1e-12)
    assert got.shape == (h.npts,)


def test_vertical_ims_are_the_peaks_as_recorded():
    t = np.arange(5) * 0.01
    h = _two_column(t, [0.0, 0.4, -0.5, 0.1, 0.0], "h")
    v = _two_column(t, [0.0, -0.2, 0.1, 0.0, 0.05], "v")
    ims = vertical_ims(v, h)
    assert ims["PGA_v"] == pytest.approx(0.2)
    assert ims["VH_ratio"] == pytest.approx(0.4)
