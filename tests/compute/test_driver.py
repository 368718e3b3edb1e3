"""One sweep driver (issue 31): the library's in-memory sweeps (``compute.sweep.compute``,
``adaptive.adaptive_compute``) run the loops of ``rocksweep sweep`` (``driver.drive``)
into an array sink, and give what the result file holds, bit for bit."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import rocksweep
from rocksweep.compute import adaptive as ad
from rocksweep.compute import sweep as sw
from rocksweep.scene.parse import load_scene

ROOT = Path(__file__).resolve().parents[2]
SMALL = ["pulse.shape=sine", "pulse.w_over_p={start: 0.5, stop: 6, num: 24}",
         "pulse.A_ratio={start: 0.5, stop: 8, num: 24}", "impact.lam=[0.0, 0.4]"]


def _same(arrays: dict, ds) -> None:
    for k, v in arrays.items():
        got = ds[k].transpose(*[d for d in ds[k].dims]).values
        assert np.array_equal(np.squeeze(v), np.squeeze(got), equal_nan=True), k


def test_in_memory_arrays_are_the_result_files(tmp_path):
    scene = load_scene(ROOT / "configs" / "fig3a.yaml", SMALL)
    out = tmp_path / "r.h5"
    ds = rocksweep.run(ROOT / "configs" / "fig3a.yaml", overrides=SMALL, output=out)
    _same(sw.compute(scene, jobs=2, chunk_size=7), ds)


def test_adaptive_in_memory_is_the_adaptive_result_file(tmp_path):
    scene = load_scene(ROOT / "configs" / "fig3a.yaml", SMALL)
    arrays, stats = ad.adaptive_compute(scene, jobs=1, coarse=2)
    ds = rocksweep.run(ROOT / "configs" / "fig3a.yaml", overrides=SMALL, adaptive=True,
                       coarse=2, output=tmp_path / "a.h5")
    _same(arrays, ds)
    assert stats.computed == int((arrays["computed"] > 0).sum()) == ds.attrs["points_computed"]


def test_no_second_sweep_loop():
    """compute and adaptive_compute hold no chunk loop of their own."""
    import inspect

    for fn in (sw.compute, ad.adaptive_compute):
        src = inspect.getsource(fn)
        assert "run_chunks" not in src and "run_batch" not in src and "sweep_arrays" in src
