"""One sweep driver: the library's in-memory sweeps (``driver.sweep_arrays``)
run the loops of ``rocksweep sweep`` (``driver.drive``) into an array sink and give what
the result file holds, bit for bit; the adaptive loop is written once
(``adaptive.run_plan``), for the kernel and for a planted class function alike."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np

import rocksweep
from rocksweep.compute import adaptive as ad
from rocksweep.compute.driver import sweep_arrays
from rocksweep.scene.parse import load_scene

ROOT = Path(__file__).resolve().parents[2]
PKG = ROOT / "rocksweep"
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
    arrays, report = sweep_arrays(scene, jobs=2, chunk_size=7)
    _same(arrays, ds)
    assert report.computed == report.points_total == scene.size and report.complete


def test_adaptive_in_memory_is_the_adaptive_result_file(tmp_path):
    scene = load_scene(ROOT / "configs" / "fig3a.yaml", SMALL)
    arrays, report = sweep_arrays(scene, jobs=1, adaptive=ad.Options(coarse=2))
    stats = report.adaptive
    ds = rocksweep.run(ROOT / "configs" / "fig3a.yaml", overrides=SMALL, adaptive=True,
                       coarse=2, output=tmp_path / "a.h5")
    _same(arrays, ds)
    assert stats.computed == int((arrays["computed"] > 0).sum()) == ds.attrs["points_computed"]
    # the batches the driver ran are the plan's: replayed on the kernel's own classes
    # (no kernel runs), the planner asks for the same batches in the same order
    truth = ds["outcome"].transpose(*ds["outcome"].dims).values.ravel()
    plan = ad.Options(coarse=2).plan(scene)
    _, computed, replay = ad.run_on_function(plan, lambda flat, _b: truth[flat])
    assert stats.batches == replay.batches and len(stats.batches) >= 3
    np.testing.assert_array_equal(computed, arrays["computed"].ravel())


def _calls(name: str) -> list[str]:
    """Where the package calls ``name`` (any ``x.name(...)`` or ``name(...)``)."""
    found = []
    for path in sorted(PKG.rglob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Call):
                f = node.func
                called = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None)
                if called == name:
                    found.append(path.relative_to(ROOT).as_posix())
    return found


def test_one_driver():
    """The chunk loop, the adaptive loop and the driver each have one caller in the
    package: nothing else loops over chunks or plans (there were three drivers,
    each with its own loop)."""
    assert _calls("next_step") == ["rocksweep/compute/adaptive.py"]  # in run_plan
    assert sorted(_calls("run_plan")) == ["rocksweep/compute/adaptive.py",  # on a function
                                          "rocksweep/compute/driver.py"]  # adaptive_loop
    assert sorted(_calls("run_chunks")) == ["rocksweep/compute/adaptive.py",  # run_batch
                                            "rocksweep/compute/driver.py"]  # every_point
    assert sorted(set(_calls("drive"))) == ["rocksweep/compute/driver.py",  # sweep_arrays
                                            "rocksweep/compute/session.py"]  # sweep_file
    for retired in ("compute", "adaptive_compute"):
        assert not hasattr(__import__("rocksweep.compute.sweep", fromlist=["x"]), retired)
        assert not hasattr(ad, retired)
    assert not hasattr(ad, "drive")


def test_an_interrupt_as_a_chunk_arrives_is_counted_as_the_file_holds_it(tmp_path,
                                                                          monkeypatch):
    """A Ctrl-C lands between any two bytecodes: here right after a finished chunk joins
    the pending ones, before the loop has read it. The chunk is written on the way out, and
    the interrupt's report (what `rocksweep sweep` prints: "interrupted: N of M points
    saved") counts exactly the points the file holds (it had counted one chunk fewer:
    `test_ctrl_c_writes_every_finished_chunk_before_it_exits`, now and then)."""
    import h5py
    import pytest

    from rocksweep.compute import sweep as sw
    from rocksweep.compute.driver import SweepInterrupted

    class Interrupting:
        """A chunk's result whose first read of its CPU time is the Ctrl-C."""

        def __init__(self, res):
            self._res, self._hit = res, False

        def __getattr__(self, name):
            if name == "cpu_seconds" and not self._hit:
                self._hit = True
                raise KeyboardInterrupt
            return getattr(self._res, name)

    real = sw.run_chunks

    def run_chunks(*args, **kwargs):
        for i, res in enumerate(real(*args, **kwargs)):
            yield Interrupting(res) if i == 2 else res

    monkeypatch.setattr(sw, "run_chunks", run_chunks)
    out = tmp_path / "r.h5"
    with pytest.raises(SweepInterrupted) as stop:
        rocksweep.run(ROOT / "configs" / "fig3a.yaml", overrides=SMALL, output=out)
    with h5py.File(out, "r") as f:
        held = int((f["outcome"][()] >= 0).sum())
    assert 0 < held < stop.value.report.points_total
    assert stop.value.report.points_done == held
