"""The HDF5 result file: layout (xarray), chunks, resume checks, bad files.

Results here are synthetic (no kernel): the store must keep whatever it is given.
"""

import json

import h5py
import numpy as np
import pytest
from bodies import FIG3_YAML

import rocksweep.store.writer as writer
from rocksweep.compute.sweep import plan_chunks
from rocksweep.errors import OutputError, StoreError
from rocksweep.scene.grid import ChunkResult, Grid
from rocksweep.scene.parse import parse_scene
from rocksweep.store.format import FORMAT_VERSION, flat_slabs
from rocksweep.store.reader import read_result
from rocksweep.store.writer import SweepFile

TEXT = """# a comment kept verbatim
name: store test
""" + FIG3_YAML + """impact: {lam: [0.0, 0.2, 0.4]}
pulse: {shape: [sine, cosine], w_over_p: {start: 0.5, stop: 6, num: 5},
        A_ratio: {start: 1, stop: 8, num: 4}}
"""


def fake_chunk(scene, a: int, b: int) -> ChunkResult:
    """Values that encode the flat index, so misplaced writes show."""
    i = np.arange(a, b)
    arrays = {}
    for name, (dtype, _, _) in scene.variables().items():
        if name == "outcome":
            arrays[name] = (i % 3).astype(dtype)
        elif name == "t_overturn":
            arrays[name] = np.where(i % 3 > 0, i * 0.5, np.nan)
        else:
            arrays[name] = (i * 7 + len(name)).astype(dtype)
    return ChunkResult(a, b, arrays, 0.0)


def expected(scene, name):
    g = Grid(scene)
    return fake_chunk(scene, 0, g.size).arrays[name].reshape(g.shape)


@pytest.fixture()
def scene():
    return parse_scene(TEXT)


def write_all(path, scene, chunk=7, order=None):
    sf = SweepFile.create(path, scene)
    chunks = plan_chunks(~sf.done(), chunk)
    for k in order(len(chunks)) if order else range(len(chunks)):
        sf.write(fake_chunk(scene, *chunks[k]))
    sf.finish(1.5, 0.5)
    sf.close()


def test_flat_slabs_cover_ranges_in_order():
    for shape in [(3, 4, 5), (2, 1, 3), (7,), (2, 3), (1, 1, 4)]:
        n = int(np.prod(shape))
        for a in range(n):
            for b in range(a + 1, n + 1):
                arr = np.full(shape, -1)
                boxes = flat_slabs(shape, a, b)
                assert len(boxes) <= 2 * len(shape) - 1
                for index, x, y in boxes:
                    arr[index] = np.arange(x, y).reshape(arr[index].shape)
                ref = np.full(n, -1)
                ref[a:b] = np.arange(a, b)
                np.testing.assert_array_equal(arr.ravel(), ref)


def test_roundtrip_with_chunks_in_any_order(tmp_path, scene):
    path = tmp_path / "r.h5"
    write_all(path, scene, chunk=7, order=lambda n: np.random.default_rng(1).permutation(n))
    r = read_result(path)
    assert r.dims == ("shape", "lam", "A_ratio", "w_over_p")
    assert r.shape == (2, 3, 4, 5)
    for name in scene.variables():
        np.testing.assert_array_equal(r.arrays[name], expected(scene, name), err_msg=name)
    assert r.attrs["scene"] == TEXT  # verbatim, comment included
    assert r.attrs["format_version"] == FORMAT_VERSION
    assert r.attrs["steps_per_period"] == scene.numerics.steps_per_period
    assert r.attrs["event_tol"] == scene.numerics.event_tol
    assert r.attrs["horizon"] == scene.numerics.horizon
    assert r.attrs["complete"] is True or r.attrs["complete"] == 1
    assert r.attrs["wall_time"] == 1.5
    assert r.attrs["steps_total"] == int(expected(scene, "steps").sum())
    for k in ("rocksweep_version", "numba_version", "numpy_version", "started", "finished"):
        assert r.attrs[k]
    counts = {(c["shape"], c["lam"]): c for c in r.counts()}
    o = expected(scene, "outcome")
    assert counts[("cosine", 0.2)]["mode1"] == int((o[1, 1] == 1).sum())
    assert sum(c["safe"] + c["mode1"] + c["mode2"] for c in counts.values()) == o.size


def test_xarray_opens_with_named_coordinate_labelled_dims(tmp_path, scene):
    xr = pytest.importorskip("xarray")  # in the test extra: never skipped in CI
    path = tmp_path / "r.h5"
    write_all(path, scene)
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert ds["outcome"].dims == ("shape", "lam", "A_ratio", "w_over_p")
        assert list(ds["shape"].values) == ["sine", "cosine"]
        np.testing.assert_array_equal(ds["lam"].values, [0.0, 0.2, 0.4])
        np.testing.assert_array_equal(ds["w_over_p"].values, np.linspace(0.5, 6, 5))
        np.testing.assert_array_equal(ds["A_ratio"].values, np.linspace(1, 8, 4))
        assert float(ds.coords["wn_over_p"]) == 2.43  # unswept: scalar coordinate
        assert float(ds.coords["zeta"]) == 0.05
        sel = ds["outcome"].sel(shape="cosine", lam=0.4)
        np.testing.assert_array_equal(sel.values, expected(scene, "outcome")[1, 2])
        assert ds.attrs["scene"] == TEXT


def test_unfinished_file_marks_missing_points(tmp_path, scene):
    path = tmp_path / "r.h5"
    sf = SweepFile.create(path, scene)
    chunks = plan_chunks(~sf.done(), 11)
    for a, b in chunks[::2]:
        sf.write(fake_chunk(scene, a, b))
    sf.close()  # as if killed: no finish()
    sf = SweepFile.resume(path, scene)
    done = sf.done()
    for k, (a, b) in enumerate(chunks):
        assert done[a:b].all() if k % 2 == 0 else not done[a:b].any()
    for a, b in plan_chunks(~done, 5):
        sf.write(fake_chunk(scene, a, b))
    sf.finish(0.1, 0.0)
    sf.close()
    r = read_result(path)
    for name in scene.variables():
        np.testing.assert_array_equal(r.arrays[name], expected(scene, name), err_msg=name)
    assert r.attrs["sessions"] == 2


def test_existing_file_is_not_overwritten(tmp_path, scene):
    path = tmp_path / "r.h5"
    path.write_bytes(b"precious")
    # the one "already exists" of every writer (rocksweep.run's too): an OutputError
    with pytest.raises(OutputError, match="already exists; use resume=True to finish it or "
                                          "overwrite=True to replace it"):
        SweepFile.create(path, scene)
    assert path.read_bytes() == b"precious"
    SweepFile.create(path, scene, overwrite=True).close()
    assert read_result(path).shape == (2, 3, 4, 5)


@pytest.mark.parametrize("overwrite", [False, True])
def test_a_file_made_meanwhile_is_an_output_error_as_for_every_output(tmp_path, scene,
                                                                      monkeypatch, overwrite):
    """A file another process puts at the path after the sweep checked it (here: while
    the new file is made) is kept, and the refusal is the OutputError every output's
    publish raises, not a StoreError of its own."""
    path = tmp_path / "r.h5"
    if overwrite:
        path.write_bytes(b"old")
    real = writer.initialise

    def meanwhile(*args):
        if path.exists():
            path.unlink()  # the file told to be overwritten, replaced by another's
        path.write_bytes(b"mine")
        return real(*args)

    monkeypatch.setattr(writer, "initialise", meanwhile)
    with pytest.raises(OutputError, match="by another process meanwhile") as err:
        SweepFile.create(path, scene, overwrite=overwrite)
    assert not isinstance(err.value, StoreError)
    assert path.read_bytes() == b"mine"
    assert [p.name for p in tmp_path.iterdir()] == ["r.h5"]


def test_resume_with_a_different_scene_says_what_differs(tmp_path, scene):
    path = tmp_path / "r.h5"
    SweepFile.create(path, scene).close()
    other = parse_scene(TEXT.replace("[0.0, 0.2, 0.4]", "[0.0, 0.2]"))
    with pytest.raises(StoreError) as err:
        SweepFile.resume(path, other)
    msg = str(err.value)
    assert "\n" not in msg
    assert "impact.lam" in msg and "[0.0, 0.2, 0.4]" in msg and "[0.0, 0.2]" in msg
    finer = parse_scene(TEXT + "numerics: {accuracy: fine}\n")
    from rocksweep.numerics import PRESETS

    want = (f"numerics.steps_per_period: file {PRESETS['default'].steps_per_period}, "
            f"scene {PRESETS['fine'].steps_per_period}")
    with pytest.raises(StoreError, match=want):
        SweepFile.resume(path, finer)
    # a comment is not a different scene
    SweepFile.resume(path, parse_scene("# another comment\n" + TEXT)).close()


def test_create_failure_leaves_no_file(tmp_path, scene, monkeypatch):
    path = tmp_path / "r.h5"

    def boom(*args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(writer, "initialise", boom)
    with pytest.raises(StoreError) as err:
        SweepFile.create(path, scene)
    assert str(err.value) == f"{path}: cannot write (no space left on the device); nothing written"
    assert list(tmp_path.iterdir()) == []


def test_missing_directory_is_a_clear_error(tmp_path, scene):
    with pytest.raises(OutputError, match="does not exist"):  # an output path's problem
        SweepFile.create(tmp_path / "nope" / "r.h5", scene)


@pytest.mark.parametrize("make, pattern", [
    (lambda p: p.write_text("not hdf5 at all\n"), "not an HDF5 file"),
    (lambda p: h5py.File(p, "w").close(), "not a rocksweep sweep result"),
    (lambda p: None, "no such file"),
])
def test_foreign_files_get_one_line_errors(tmp_path, make, pattern):
    path = tmp_path / "x.h5"
    make(path)
    with pytest.raises(StoreError, match=pattern) as err:
        read_result(path)
    assert "\n" not in str(err.value)


def test_damaged_and_newer_files(tmp_path, scene):
    path = tmp_path / "r.h5"
    write_all(path, scene)
    data = path.read_bytes()
    trunc = tmp_path / "t.h5"
    trunc.write_bytes(data[: len(data) // 3])
    with pytest.raises(StoreError) as err:
        read_result(trunc)
    assert str(trunc) in str(err.value) and "\n" not in str(err.value)
    with h5py.File(path, "r+") as f:
        del f["impacts"]
    with pytest.raises(StoreError, match="variable 'impacts' missing"):
        read_result(path)
    with h5py.File(path, "r+") as f:
        f.attrs["format_version"] = FORMAT_VERSION + 1
    with pytest.raises(StoreError, match="newer rocksweep"):
        read_result(path)


def test_resolved_scene_is_stored(tmp_path, scene):
    path = tmp_path / "r.h5"
    SweepFile.create(path, scene, overrides=("pulse.A_ratio={start: 1, stop: 8, num: 4}",))\
        .close()
    with h5py.File(path, "r") as f:
        stored = json.loads(f.attrs["scene_resolved"])
        assert json.loads(f.attrs["numerics"]) == scene.numerics.as_dict()
    assert stored["axes"]["impact.lam"] == {"values": [0.0, 0.2, 0.4], "swept": True}
    assert stored["overrides"] == ["pulse.A_ratio={start: 1, stop: 8, num: 4}"]


def test_cf_attributes_survive_netcdf_readers(tmp_path, scene):
    """CF conventions, units, int8 flags and per-session provenance (host, backend)
    as netCDF-4 readers (xarray + h5netcdf) see them."""
    import platform

    xr = pytest.importorskip("xarray")  # in the test extra: never skipped in CI
    path = tmp_path / "r.h5"
    sf = SweepFile.create(path, scene, backend="threads x 2")
    sf.write(fake_chunk(scene, 0, 11))
    sf.finish(1.0, 0.5)
    sf.close()
    sf = SweepFile.resume(path, scene, backend="dask tcp://h:8786")
    chunks = plan_chunks(~sf.done(), 50)
    for a, b in chunks:
        sf.write(fake_chunk(scene, a, b))
    attrs = sf.finish(2.0, 1.0)
    sf.close()
    assert attrs["complete"] is True and attrs["points_done"] == 120
    host = platform.node()
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        a = ds.attrs
        assert a["Conventions"] == "CF-1.10"
        assert a["complete"] == 1 and a["complete"].dtype == np.int8
        assert a["energy"] == 0 and a["energy"].dtype == np.int8
        assert a["sessions"] == 2 and a["host"] == host and a["backend"] == "dask tcp://h:8786"
        lines = a["history"].splitlines()
        assert len(lines) == 2
        assert "session 1" in lines[0] and f"on host {host}, backend threads x 2" in lines[0]
        assert lines[0].endswith("11 of 120 points done")
        assert "session 2" in lines[1] and "backend dask tcp://h:8786" in lines[1]
        assert lines[1].endswith("120 of 120 points done")
        assert a["finished"] and a["wall_time"] == 3.0
        want = {"w_over_p": "1", "A_ratio": "1", "lam": "1", "wn_over_p": "1", "zeta": "1",
                "alpha_cg": "rad", "alpha_A": "rad", "mA_over_m": "1", "IA_ratio": "1"}
        for name, unit in want.items():
            assert ds[name].attrs["units"] == unit, name
            assert ds[name].attrs["long_name"], name
        assert "units" not in ds["shape"].attrs
        for name in scene.variables():
            v = ds[name].attrs
            assert v["long_name"], name
            if name in ("outcome", "status"):  # flag variables: codes, no units
                assert "units" not in v and "flag_meanings" in v
            else:
                assert v["units"] == "1", name
        assert ds["t_overturn"].attrs["rocksweep_units"] == "1/p"
        assert ds["t_overturn"].attrs["long_name"] == "overturning time"  # no units in it
        # a flexible body's rotations are over alpha_cg (never "alpha_ref" in a file)
        assert ds["theta_max_over_alpha"].attrs["rocksweep_units"] == "alpha_cg"
        assert ds["A_ratio"].attrs["symbol"] == "A/(g tan alpha_cg)"


def test_session_attributes_are_rewritten_in_place(tmp_path, scene):
    """Resuming and finishing change no attribute's type or size (so they need no new
    space in the file): the file's size and its attributes' dtypes stay the same."""
    path = tmp_path / "r.h5"
    SweepFile.create(path, scene).close()
    size = path.stat().st_size
    with h5py.File(path, "r") as f:
        types = {k: f.attrs.get_id(k).dtype for k in f.attrs}
    for k in range(3):
        sf = SweepFile.resume(path, scene, backend="x" * 300)  # cut to fit, not grown
        sf.write(fake_chunk(scene, 10 * k, 10 * k + 10))
        sf.finish(1.0, 1.0)
        sf.close()
    assert path.stat().st_size == size
    with h5py.File(path, "r") as f:
        assert {k: f.attrs.get_id(k).dtype for k in f.attrs} == types
        assert f.attrs["sessions"] == 4
        assert f.attrs["backend"] == b"x" * 256
