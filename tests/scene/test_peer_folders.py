"""A folder of PEER downloads as a suite: components paired by their names, a record
missing a component refused (one line) or skipped, RotD50 scaling, the vertical's IMs.

RotD50 is checked on closed forms: a one-component motion a1 = s(t), a2 = 0 projects to
|cos b| max|s|, whose median over b in [0, 180) is cos(45 deg) max|s|; a circular motion
(cos, sin) has the same peak at every angle.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import rocksweep
from rocksweep.errors import SceneError
from rocksweep.physics.path import rotd50_peaks
from rocksweep.physics.records import write_at2
from rocksweep.physics.suite import RecordWarning
from rocksweep.scene.parse import parse_scene
from rocksweep.scene.peer import peer_components

DT = 0.01


def motion(seed: int, n: int = 600) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n) * DT
    env = (t / 1.5) ** 2 * np.exp(2 * (1 - t / 1.5))
    return 0.3 * env * np.convolve(rng.normal(size=n), np.ones(5) / 5, "same")


def folder(tmp_path, n: int = 3, drop: str = "", up: bool = True):
    """PEER-named files of n records (H1 = motion, H2 = 0.8 H1, UP = 5/3 H1); ``drop`` a
    component of the second one."""
    d = tmp_path / "peer"
    d.mkdir()
    for i in range(n):
        rsn = f"RSN{100 + i}_EVENT_STA"
        for comp, scale in (("000", 0.3), ("090", 0.24), ("-UP", 0.5)):
            if (comp == "-UP" and not up) or (i == 1 and comp == drop):
                continue
            write_at2(d / f"{rsn}{comp}.AT2", scale / 0.3 * motion(3 * i + 3), DT, rsn)
    return d


def scene(d, **ground):
    return {"body": {"kind": "block", "alpha": 0.2, "inertia": 4 / 3},
            "ground": {"records": str(d), "p": 2.0, **ground}}


def test_peer_names_pair_by_rsn(tmp_path):
    names = ["RSN1158_KOCAELI_DZC270.AT2", "RSN1158_KOCAELI_DZC180.AT2",
             "RSN1158_KOCAELI_DZC-UP.AT2", "RSN9_BORREGO_B-ELC000.AT2",
             "RSN9_BORREGO_B-ELC-UP.AT2", "notes.AT2"]
    comps, odd = peer_components([tmp_path / n for n in names])
    assert [c.rsn for c in comps] == ["RSN9", "RSN1158"]
    k = comps[1]
    assert (k.h1.name, k.h2.name, k.up.name) == (names[1], names[0], names[2])
    assert comps[0].missing(True) == ["H2"]
    assert [p.name for p in odd] == ["notes.AT2"]
    assert all(c.ambiguity() is None for c in comps)


def test_a_folder_runs_as_a_suite_with_angles_and_rotd50(tmp_path):
    d = folder(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordWarning)
        ds = rocksweep.run(scene(d, angle=[0.0, 90.0], scale={
            "im": "PGA", "values": [0.2, 0.4], "component": "RotD50"}))
    assert ds["outcome"].dims == ("record", "PGA", "angle")
    assert ds.attrs["scale_component"] == "RotD50"
    # the vertical's peak as written, to the files' 7 digits
    pga_v = ds["record_pga_v"].values
    assert np.allclose(pga_v, [np.abs(0.5 / 0.3 * motion(3 * i + 3)).max() for i in range(3)],
                       rtol=1e-6)
    rot = ds["record_rotd50"].values
    assert np.allclose(ds["record_v_over_h"].values, pga_v / rot)
    # H2 = 0.8 H1 here: the projection is sqrt(1 + 0.8^2) |cos(b - phi)| H1, whose median
    # over b is sqrt(1.64) cos(45 deg) max|H1|
    h1 = np.array([np.abs(motion(3 * i + 3)).max() for i in range(3)])
    assert np.allclose(rot, math.sqrt(1.64) * math.cos(math.radians(45)) * h1, rtol=0.01)


def test_rotd50_of_closed_forms():
    t = np.linspace(0.0, 2.0, 4001)
    s = np.sin(2 * math.pi * t) * np.exp(-t)
    assert rotd50_peaks(s, np.zeros_like(s)) == pytest.approx(
        math.cos(math.radians(45)) * np.abs(s).max(), rel=0.01)
    c = np.cos(2 * math.pi * 3 * t)
    assert rotd50_peaks(c, np.sin(2 * math.pi * 3 * t)) == pytest.approx(1.0, rel=1e-3)


def test_a_missing_component_is_one_line_or_skipped(tmp_path):
    d = folder(tmp_path, drop="090")
    with pytest.raises(SceneError) as err:
        parse_scene(__import__("yaml").safe_dump(scene(d)))
    msg = str(err.value)
    assert "\n" not in msg and "RSN101 has no H2 file" in msg and "ground.missing" in msg
    with pytest.warns(RecordWarning, match="RSN101"):
        sc = parse_scene(__import__("yaml").safe_dump(scene(d, missing="skip")))
    assert len(sc.suite.records) == 2 and len(sc.suite.h2) == 2


def test_rotd50_needs_both_horizontals(tmp_path):
    from pathlib import Path

    root = Path(__file__).resolve().parents[2] / "records" / "suite"
    with pytest.raises(SceneError, match="RotD50.*both horizontals"):
        parse_scene(__import__("yaml").safe_dump(scene(
            str(root / "SYN0*.AT2"), scale={"im": "PGA", "values": [0.3],
                                             "component": "RotD50"})))


@pytest.mark.parametrize("im", ["AvgSa", "CAV", "Arias"])
def test_rotd50_of_an_im_without_that_convention_is_one_line(tmp_path, im):
    """RotD50 is the median over orientations of a peak (PGA, PGV, Sa); AvgSa, CAV and
    Arias stripes with it ended in "cannot convert float NaN to integer" (issue 45)."""
    d = folder(tmp_path, n=2, up=False)
    scale = {"im": im, "values": [0.3], "component": "RotD50"}
    with pytest.raises(SceneError) as err:
        parse_scene(__import__("yaml").safe_dump(scene(d, scale=scale)))
    msg = str(err.value)
    assert "\n" not in msg and f"ground.scale.im = {im}" in msg and "use component 'H1'" in msg


def test_a_duplicate_download_is_never_paired(tmp_path):
    """A browser's second download beside the first: H1 became the duplicate, H2 the
    original H1 and the real 090 was dropped, without a word (issue 45). Now the record
    is named with its files (refused, or skipped with a warning), and .AT2 files that are
    not PEER names are named in a warning."""
    import shutil

    d = folder(tmp_path, up=False)
    shutil.copy(d / "RSN100_EVENT_STA000.AT2", d / "RSN100_EVENT_STA000 (1).AT2")
    with pytest.raises(SceneError) as err:
        parse_scene(__import__("yaml").safe_dump(scene(d)))
    msg = str(err.value)
    assert "\n" not in msg and "RSN100 has more than two horizontal" in msg
    assert "RSN100_EVENT_STA000 (1).AT2 looks like a second download" in msg
    (d / "notes.AT2").write_text("x")
    with pytest.warns(RecordWarning) as got:
        sc = parse_scene(__import__("yaml").safe_dump(scene(d, missing="skip")))
    said = " | ".join(str(w.message) for w in got)
    assert "RSN100 has more than two" in said and "left out: notes.AT2" in said
    assert list(sc.suite.names) == ["RSN101_EVENT_STA000.AT2", "RSN102_EVENT_STA000.AT2"]
    comps = dict((c.rsn, c) for c in peer_components(list(d.iterdir()))[0])
    assert comps["RSN101"].h2.name == "RSN101_EVENT_STA090.AT2"


@pytest.mark.parametrize("kind", ["fifo", "dangling", "loop"])
def test_a_folder_entry_that_is_no_file_is_named(tmp_path, kind):
    """FIFOs, dangling and looping links were dropped without a word (issue 45)."""
    import os

    d = folder(tmp_path, up=False)
    bad = d / "RSN103_EVENT_STA000.AT2"
    {"fifo": lambda: os.mkfifo(bad), "dangling": lambda: os.symlink("gone.AT2", bad),
     "loop": lambda: os.symlink(bad.name, bad)}[kind]()
    with pytest.raises(SceneError) as err:
        parse_scene(__import__("yaml").safe_dump(scene(d)))
    msg = str(err.value)
    assert "\n" not in msg and bad.name in msg
    assert {"fifo": "FIFO", "dangling": "link to a missing file",
            "loop": "loop of symbolic links"}[kind] in msg
    with pytest.warns(RecordWarning, match=bad.name):
        sc = parse_scene(__import__("yaml").safe_dump(scene(d, missing="skip")))
    assert len(sc.suite.records) == 3


def test_a_glob_names_a_fifo_or_dangling_link_it_matches(tmp_path):
    import os

    d = folder(tmp_path, n=2, up=False)
    os.symlink("gone.AT2", d / "zz.AT2")
    with pytest.raises(SceneError, match=r"zz.AT2: a symbolic link to a missing file"):
        parse_scene(__import__("yaml").safe_dump(scene(str(d / "*.AT2"))))
    (d / "zz.AT2").unlink()
    os.mkfifo(d / "zz.AT2")
    with pytest.raises(SceneError, match=r"zz.AT2: is a FIFO"):
        parse_scene(__import__("yaml").safe_dump(scene(str(d / "*.AT2"))))
