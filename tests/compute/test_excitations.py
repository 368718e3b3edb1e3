"""Each distinct ground motion is computed once a run (``physics.ground_motion``): a floor
and vertical sweep in chunks of one point, on one or two threads, its single points and
its grid asked again, compute each floor motion and each vertical's samples once; and the
kernel's ground code is one rule (the scene's the most general of its points')."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

from rocksweep.compute.driver import sweep_arrays
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics import ground_motion, path
from rocksweep.physics.records import read_record, write_at2
from rocksweep.scene.grid import Grid
from rocksweep.scene.inputs import load

ROOT = Path(__file__).resolve().parents[2]
NEARFAULT = ROOT / "records" / "synthetic_nearfault.AT2"
BLOCK = {"kind": "block", "alpha": 0.2, "inertia": 4.0 / 3.0}


@pytest.fixture
def counted(monkeypatch):
    """Calls of the floor motion (``floor.floor_motion`` as the path calls it) and of the
    vertical's resampling (``ground_motion.vertical_samples``)."""
    calls = {"floor": 0, "vertical": 0}

    def wrap(module, name, key):
        real = getattr(module, name)

        def counting(*args, **kwargs):
            calls[key] += 1
            return real(*args, **kwargs)
        monkeypatch.setattr(module, name, counting)

    wrap(path, "floor_motion", "floor")
    wrap(ground_motion, "vertical_samples", "vertical")
    return calls


def floor_scene(tmp_path, periods):
    rec = read_record(NEARFAULT)
    write_at2(tmp_path / "up.AT2", 0.4 * np.roll(rec.acc, 200), rec.dt, "vertical")
    scene, _ = load({"body": BLOCK, "ground": {
        "record": str(NEARFAULT), "vertical": str(tmp_path / "up.AT2"),
        "A_ratio": [1.0, 2.5], "p": [2.0, 3.0]},
        "floor": {"period": periods, "damping": 0.05, "participation": 1.3}})
    return scene


@pytest.mark.parametrize("jobs", [1, 2])
@pytest.mark.parametrize("periods", [[0.4], [0.3, 0.6]])
def test_a_floor_and_vertical_sweep_computes_each_motion_once(tmp_path, counted, jobs,
                                                              periods):
    scene = floor_scene(tmp_path, periods)
    arrays, _ = sweep_arrays(scene, jobs=jobs, chunk_size=1)
    assert (arrays["outcome"] >= 0).all() and arrays["outcome"].size == 4 * len(periods)
    # asked again: the grid's rows, every point alone, the boundary search's points
    grid = Grid(scene)
    grid.rows(0, grid.size)
    values = grid.index_values(np.arange(grid.size))
    for i in range(grid.size):
        point = scene.point({k: v[i] for k, v in values.items()})
        assert point.excitation.vertical_acc is not None
    assert counted == {"floor": len(periods), "vertical": len(periods)}
    assert len(scene.motions) == len(periods)


def test_a_folder_suite_computes_each_records_vertical_once(tmp_path, counted):
    """A folder of PEER downloads whose UP files act: one resampling a record, however
    many stripes, chunks and threads."""
    rec = read_record(NEARFAULT)
    for i in range(2):
        a = rec.acc[500 * i:500 * i + 1500]
        for comp, f in (("000", 1.0), ("090", 0.7), ("-UP", 0.4)):
            write_at2(tmp_path / f"RSN{100 + i}_EVENT_STA{comp}.AT2", f * np.roll(a, 40 * i),
                      rec.dt, f"RSN{100 + i}")
    scene, _ = load({"body": BLOCK, "ground": {
        "records": str(tmp_path), "p": 2.0,
        "scale": {"im": "PGA_ratio", "values": [1.0, 2.0, 3.0]}}})
    arrays, _ = sweep_arrays(scene, jobs=2, chunk_size=1)
    assert arrays["outcome"].size == 6
    assert counted == {"floor": 0, "vertical": 2}
    first = {a.name: a.values[0] for a in scene.axes}
    excitations = {scene.excitation({**first, "record": n}) for n in scene.suite.names}
    assert len(excitations) == 2 and all(ex.vertical_acc is not None for ex in excitations)
    assert counted["vertical"] == 2


def test_a_scene_shipped_to_another_process_makes_its_motions_there(tmp_path, counted):
    """dask pickles the scene: the copy starts with no motions and makes its own, once,
    with the same rows."""
    scene = floor_scene(tmp_path, [0.4])
    rows = Grid(scene).rows(0, 4).rows
    copy = pickle.loads(pickle.dumps(scene))
    assert len(copy.motions) == 0 and len(scene.motions) == 1
    assert np.array_equal(Grid(copy).rows(0, 4).rows, rows, equal_nan=True)
    Grid(copy).rows(0, 4)
    assert len(copy.motions) == 1 and counted == {"floor": 2, "vertical": 2}


@pytest.mark.parametrize(("pulse", "scene_code", "codes"), [
    ({"shape": ["sine", "cosine"]}, L.GROUND_PULSE, {L.GROUND_PULSE}),
    ({"shape": ["sine", "ricker"]}, L.GROUND_ANY, {L.GROUND_PULSE, L.GROUND_ANY}),
    ({"shape": ["sine", "mp"], "vertical": {"amplitude": [0.2, 0.4], "w_over_p": 5.0}},
     L.GROUND_VERTICAL, {L.GROUND_VERTICAL}),
])
def test_the_scene_runs_the_most_general_ground_of_its_points(pulse, scene_code, codes):
    scene, _ = load({"body": BLOCK, "pulse": {"w_over_p": 2.0, "A_ratio": [1.0, 2.0],
                                              **pulse}})
    grid = Grid(scene)
    cr = grid.rows(0, grid.size)
    assert {ex.ground for ex in cr.excitations} == codes
    assert scene.ground == scene_code == ground_motion.shared_ground(codes)
    # one excitation per shape (and harmonic), each the points' own
    values = grid.index_values(np.arange(grid.size))
    for i in range(grid.size):
        point = scene.point({k: v[i] for k, v in values.items()})
        assert point.excitation is cr.excitations[cr.which[i]]
