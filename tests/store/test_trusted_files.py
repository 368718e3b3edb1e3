"""What a result file is, said right:

- a good file held open by another handle of this process (xarray's h5netcdf) is read, or
  for writing refused as a lock with how to release it: never "damaged", never advice
  to overwrite it;
- a damaged file, or one another scene cannot resume, is not answered with --overwrite
  as the remedy for a file with results;
- a file re-saved by xarray's to_netcdf is "not written by rocksweep"; a version
  attribute that is not text is damage (one line, not a traceback);
- a suite's result keeps its records: IDA and the scene rebuild work after the record
  folder moved; an in-memory result is never read through its title (a scene named
  README.md).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr
from bodies import FIG3_YAML
from helpers import one_line_error

import rocksweep
from rocksweep.cli import main
from rocksweep.errors import StoreError
from rocksweep.store.reader import read_result, result_scene

ROOT = Path(__file__).resolve().parents[2]
SUITE = ROOT / "records" / "suite"
BODY = FIG3_YAML + "impact: {lam: 0.0}\n"
PULSE = "name: p\n" + BODY + "pulse: {shape: sine, w_over_p: [1, 2], A_ratio: [2, 4]}\n"


@pytest.fixture(scope="module")
def pulse_result(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("pulse")
    (d / "p.yaml").write_text(PULSE)
    rocksweep.run(str(d / "p.yaml"), output=d / "p.h5")
    return d / "p.h5"


def copy(src: Path, tmp_path: Path, name: str = "r.h5") -> Path:
    out = tmp_path / name
    shutil.copy(src, out)
    return out


def test_a_file_open_in_xarray_is_read_and_not_called_damaged(pulse_result, tmp_path):
    path = copy(pulse_result, tmp_path)
    before = path.read_bytes()
    held = xr.open_dataset(path, engine="h5netcdf")
    try:
        ds = rocksweep.open(path)  # readers take the holder's locking flags
        assert ds["outcome"].shape == (2, 2)
        assert read_result(path).done.all()
        (tmp_path / "p.yaml").write_text(PULSE)
        with pytest.raises(StoreError) as e:  # a writer cannot share it: a lock, said so
            rocksweep.run(str(tmp_path / "p.yaml"), output=path, resume=True)
        msg = str(e.value)
        assert "already open in this process" in msg and "ds.close()" in msg, msg
        assert "damaged" not in msg.replace("not damaged", "") and "overwrite" not in msg
    finally:
        held.close()
    assert path.read_bytes() == before
    rocksweep.run(str(tmp_path / "p.yaml"), output=path, resume=True)  # released: works


def test_a_damaged_file_is_not_answered_with_overwrite(pulse_result, tmp_path, cli):
    path = copy(pulse_result, tmp_path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    line = one_line_error(cli.invoke(main, ["info", str(path)]))
    assert "damaged or truncated" in line and "overwrite" not in line, line
    assert "-o NEW.h5" in line


def test_resuming_another_scene_keeps_the_file_first(pulse_result, tmp_path, cli):
    path = copy(pulse_result, tmp_path)
    (tmp_path / "q.yaml").write_text(PULSE.replace("lam: 0.0", "lam: 0.1"))
    line = one_line_error(cli.invoke(main, ["sweep", str(tmp_path / "q.yaml"), "-o",
                                            str(path), "--resume", "-q"]))
    assert "cannot resume, the scene differs" in line, line
    assert line.endswith("(resume with the scene, --set values and options it was made "
                         "with, or sweep this scene to another -o; --overwrite would discard "
                         "the 4 points it holds)"), line


def test_a_file_resaved_by_xarray_is_not_rocksweeps(pulse_result, tmp_path, cli):
    ds = rocksweep.open(pulse_result)
    out = tmp_path / "x.h5"
    ds.to_netcdf(out, engine="h5netcdf")
    for args in (["info", str(out)], ["plot", str(out), "-o", str(tmp_path / "x.png")]):
        line = one_line_error(cli.invoke(main, args))
        assert line.startswith(f"Error: {out}: not written by rocksweep: "), line
    with pytest.raises(StoreError, match="not written by rocksweep"):
        rocksweep.open(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.h5"]


def test_an_analysis_result_is_named_as_such_where_a_sweep_is_read(tmp_path, cli):
    """An analysis's file (``rocksweep fragility -o``: xarray writes it, with its kind)
    given where a sweep's file is read: one line naming what it is (it said "not written
    by rocksweep: saved again by xarray")."""
    out = tmp_path / "frag.h5"
    xr.Dataset({"beta": (("lam",), [0.4])}, coords={"lam": [0.0]},
               attrs={"rocksweep_kind": "fragility"}).to_netcdf(out, engine="h5netcdf")
    for args in (["info", str(out)], ["boundaries", str(out)]):
        line = one_line_error(cli.invoke(main, args))
        assert line == (f"Error: {out}: a fragility result (lognormal fragility curves of a "
                        "record suite, with verdicts), not a sweep result; this reads the "
                        "file a sweep writes (rocksweep.open reads both)"), line
    with pytest.raises(StoreError, match="a fragility result"):
        read_result(out)


@pytest.mark.parametrize("value", [np.array([1.0, 2.0]), np.int64(3), np.array([b"a", b"b"])])
def test_a_version_attribute_that_is_not_text_is_damage(pulse_result, tmp_path, cli, value):
    path = copy(pulse_result, tmp_path)
    with h5py.File(path, "r+") as f:
        f.attrs["rocksweep_version"] = value
    line = one_line_error(cli.invoke(main, ["info", str(path)]))
    assert "damaged rocksweep result (attribute rocksweep_version is" in line, line
    with pytest.raises(StoreError, match="attribute rocksweep_version"):
        rocksweep.open(path)


def suite_scene(d: Path) -> Path:
    (d / "r").mkdir()
    for i in (1, 2):
        shutil.copy(SUITE / f"SYN0{i}.AT2", d / "r" / f"SYN0{i}.AT2")
    path = d / "s.yaml"
    path.write_text("name: s\n" + BODY + "ground:\n  records: r/*.AT2\n  scale: {im: PGA, "
                    "values: [0.3, 0.9]}\n  p: 2.0\n  periods: [0.5]\n")
    return path


def test_a_suite_result_keeps_its_records(tmp_path):
    scene = suite_scene(tmp_path)
    ds = rocksweep.run(str(scene), output=tmp_path / "s.h5")
    before = rocksweep.ida(ds, rtol=0.1)
    shutil.move(tmp_path / "r", tmp_path / "moved")  # the record folder is gone
    with h5py.File(tmp_path / "s.h5", "r") as f:  # the file's copies are the files' bytes
        for i, name in enumerate(("SYN01.AT2", "SYN02.AT2")):
            stored = bytes(f["records"][str(i)][()].tobytes())
            assert stored == (tmp_path / "moved" / name).read_bytes()
    sc = result_scene(read_result(tmp_path / "s.h5"))
    assert sc.suite.names == ("SYN01.AT2", "SYN02.AT2")
    assert [r.sha256 for r in sc.suite.records] == list(ds["record_sha256"].values)
    after = rocksweep.ida(rocksweep.open(tmp_path / "s.h5"), rtol=0.1)
    xr.testing.assert_identical(before.drop_attrs(), after.drop_attrs())
    # a copy that does not match its SHA-256 is damage, said so
    with h5py.File(tmp_path / "s.h5", "r+") as f:
        d = f["records"]["1"]
        raw = d[()]
        raw[200] ^= 0x01
        d[...] = raw
    with pytest.raises(StoreError, match="copy of record 'SYN02.AT2' does not match"):
        result_scene(read_result(tmp_path / "s.h5"))


def test_an_in_memory_result_is_never_read_through_its_title(tmp_path, monkeypatch):
    """A record scene named README.md run in memory: spectra re-read the record, never
    the file README.md (before: "README.md: not an HDF5 file")."""
    monkeypatch.chdir(tmp_path)
    Path("README.md").write_text("# not a result\n")
    shutil.copy(SUITE / "SYN03.AT2", "rec.AT2")
    sc = {"name": "README.md", **__import__("yaml").safe_load(BODY),
          "ground": {"record": str(tmp_path / "rec.AT2"), "A_ratio": [1, 3], "p": [1.0, 2.0]}}
    ds = rocksweep.run(sc)
    sp = rocksweep.spectra(ds, rtol=0.1)
    assert sp["p"].size == 2
    from rocksweep.store.reader import result_of

    res = result_of(ds)
    assert not res.in_file and "README.md" in str(res.path) and res.path != Path("README.md")


def test_flipped_bits_anywhere_are_a_read_or_one_error(pulse_result, tmp_path):
    """1-4 bits flipped anywhere in a result (dimension scales included: HDF5's
    H5DSget_num_scales raised a RuntimeError through xarray before): every reader either
    reads the file or raises a one-line RocksweepError."""
    import random

    from rocksweep.analysis.summary import read_info

    data = pulse_result.read_bytes()
    path = tmp_path / "f.h5"
    failures = 0
    for seed in range(100):
        rng = random.Random(seed)
        b = bytearray(data)
        for _ in range(rng.randint(1, 4)):
            b[rng.randrange(len(b))] ^= 1 << rng.randrange(8)
        path.write_bytes(bytes(b))
        for read in (rocksweep.open, read_result, read_info):
            try:
                read(path)
            except rocksweep.RocksweepError as err:
                assert "\n" not in str(err)
                failures += 1
    assert failures > 0  # the flips did damage something
