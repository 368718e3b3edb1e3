"""A sweep of a scene that gives body.mu: the sliding base's variables in the Dataset (and
none in a scene without mu), their units and meanings, the status word ``slid``, and a
block that cannot rock (mu < tan alpha) rocking or overturning nowhere on the grid.

Cost: the rigid block's outcome-level chunk variant of the slide loop (18 s of CPU to
compile cold, docs/sliding.md "Cost"), 100 points, and the same 50 swept by the command
line and counted by ``rocksweep info``."""

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import rocksweep
from rocksweep.cli.main import main
from rocksweep.kernel import layout as L
from rocksweep.physics.records import write_at2
from rocksweep.vocab.outcomes import SLID
from rocksweep.vocab.phases import PHASE_CODE, REST, ROCK, SLIDE, SLIDE_ROCK

SCENE = {
    "name": "sliding block",
    "body": {"kind": "block", "alpha": 0.3, "mu": [0.2, 0.6]},
    "impact": {"lam": 0.0},
    "pulse": {"shape": "sine", "w_over_p": {"start": 1.0, "stop": 4.0, "num": 5},
              "A_ratio": {"start": 0.5, "stop": 4.0, "num": 5}},
}
ROCKS = (1 << PHASE_CODE[ROCK]) | (1 << PHASE_CODE[SLIDE_ROCK])


def test_sweep_with_mu_stores_the_sliding_variables():
    ds = rocksweep.run(SCENE)
    for name in ("slide_max", "slide_final", "regime"):
        assert ds[name].dims == ds["outcome"].dims and "mu" in ds[name].dims
    assert ds["slide_max"].attrs["rocksweep_units"] == "b"
    assert ds["regime"].dtype.kind == "i"
    assert list(ds["regime"].attrs["flag_masks"]) == [1, 2, 4, 8]
    assert ds["regime"].attrs["flag_meanings"].split() == [REST, SLIDE, ROCK, SLIDE_ROCK]
    slid = (ds["status"] & L.STATUS_SLID) != 0
    slipped = (ds["regime"] & ((1 << PHASE_CODE[SLIDE]) | (1 << PHASE_CODE[SLIDE_ROCK]))) != 0
    assert bool((slid == slipped).all()) and bool((slid == (ds["slide_max"] > 0)).all())
    assert bool((ds["slide_final"] <= ds["slide_max"] * (1 + 1e-12)).all())
    low = ds.sel(mu=0.2)  # mu < tan(0.3): friction caps the block's acceleration
    assert bool((low["outcome"] == 0).all()) and bool(((low["regime"] & ROCKS) == 0).all())
    assert bool(slid.sel(mu=0.2).any())
    assert bool(((ds.sel(mu=0.6)["regime"] & ROCKS) != 0).any())  # mu > tan(0.3) rocks


def test_info_counts_the_slipped_points(tmp_path, cli):
    """``rocksweep info`` of a sliding sweep counts the points whose base slipped."""
    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump(SCENE))
    out = tmp_path / "s.h5"
    r = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "-q", "-j", "1"])
    assert r.exit_code == 0, r.output
    r = cli.invoke(main, ["info", str(out)])
    assert r.exit_code == 0, r.output
    head = next(line for line in r.output.splitlines()
                if line.strip().startswith("mu ") and "mode1" in line)
    assert head.split()[-2:] == ["slid", "lifts_off"]
    slid_rows = [line.split() for line in r.output.splitlines()
                 if line.strip().startswith(("0.2 ", "0.6 "))]
    assert len(slid_rows) == 2 and all(int(row[-2]) > 0 for row in slid_rows)


def test_sweep_without_mu_has_none():
    scene = {**SCENE, "body": {"kind": "block", "alpha": 0.3}}
    ds = rocksweep.run(scene)
    assert not {"slide_max", "slide_final", "regime", "friction_loss_over_Eref"} & set(ds)


# ---------------------------------------------------------------------------------------
# sliding with the other excitations (issue 44: records, suites, floors, orientation,
# adaptive sweeps and the certification of close calls)
# ---------------------------------------------------------------------------------------

SUITE = Path(__file__).resolve().parents[2] / "records" / "suite"
H1, H2 = str(SUITE / "SYN01.AT2"), str(SUITE / "SYN02.AT2")
ALPHA = 0.3
BLOCK = {"kind": "block", "alpha": ALPHA, "mu": 0.15}  # mu < tan(alpha): it only slides
SLIDE_KEYS = ("slide_max", "slide_final")


def _runs(ground: dict, **more) -> list[dict]:
    """The summaries of every point of a block scene on this ground (``simulate``: the
    slide loop's rigid history variant on records, which tests/hard_cases compiles; a
    sweep of a record runs a chunk variant no other test compiles)."""
    sims = rocksweep.simulate({"name": "s", "body": BLOCK, "impact": {"lam": 0.0},
                               "ground": {"p": 2.0, **ground}, **more})
    return [s.summary for s in (sims if isinstance(sims, list) else [sims])]


def _slid(s: dict) -> None:
    assert all(math.isfinite(s[k]) for k in SLIDE_KEYS) and s["slide_max"] > 0
    assert SLID in s["status"] and s["regime"] & (1 << PHASE_CODE[SLIDE])


def _suite() -> None:
    """Each record of a suite slides as the single-record scene of it at the same peak."""
    runs = _runs({"records": [H1, H2], "scale": {"im": "PGA", "values": [0.5]}})
    for s, rec in zip(runs, (H1, H2), strict=True):
        _slid(s)
        alone = _runs({"record": rec, "A_ratio": 0.5 / math.tan(ALPHA)})[0]
        assert s["slide_max"] == pytest.approx(alone["slide_max"], rel=1e-9)
        assert s["slide_final"] == pytest.approx(alone["slide_final"], rel=1e-9)
    assert runs[0]["slide_max"] != pytest.approx(runs[1]["slide_max"], rel=1e-3)


def _floor(tmp_path: Path) -> None:
    """A block on a building's floor slides as on a record of the motion its floor feels
    (``felt_motion``, written as an .AT2 at its own peak)."""
    ground = {"records": [H1], "scale": {"im": "PGA", "values": [0.3]}}
    floor = {"period": 0.3, "damping": 0.05, "participation": 1.3}
    s = _runs(ground, floor=floor)[0]
    _slid(s)
    felt = rocksweep.felt_motion({"name": "s", "body": BLOCK, "impact": {"lam": 0.0},
                                  "ground": {"p": 2.0, **ground}, "floor": floor})
    a_h = felt["a_h"].values
    path = write_at2(tmp_path / "floor.AT2", a_h, felt.attrs["dt"], "the floor's motion")
    alone = _runs({"record": str(path), "A_ratio": np.abs(a_h).max() / math.tan(ALPHA)})[0]
    assert s["slide_max"] == pytest.approx(alone["slide_max"], rel=1e-5)
    ground_only = _runs(ground)[0]  # the floor amplifies: the block slides farther
    assert s["slide_max"] > 2 * ground_only["slide_max"]


def _orientation() -> None:
    """Angle 0 is H1 alone; angle 180 its mirror image (a(t) = -a1(t)), which a symmetric
    block slides just as far."""
    at0, at180 = _runs({"record": H1, "h2": H2, "angle": [0, 180], "A_ratio": 1.5})
    alone = _runs({"record": H1, "A_ratio": 1.5})[0]
    for s in (at0, at180):
        _slid(s)
    assert at0["slide_max"] == pytest.approx(alone["slide_max"], rel=1e-12)
    assert at180["slide_max"] == pytest.approx(at0["slide_max"], rel=1e-9)
    assert at180["slide_final"] == pytest.approx(at0["slide_final"], rel=1e-6)


def _adaptive() -> None:
    """An adaptive sweep of a block that rocks and slides (mu 0.4 > tan 0.2): its
    computed points are the plain sweep's, sliding variables included, the filled ones
    keep the fill values, and the certification re-ran close calls (status refined)."""
    scene = {"name": "a", "body": {"kind": "block", "alpha": 0.2, "mu": 0.4},
             "impact": {"lam": 0.0},
             "pulse": {"shape": "sine", "w_over_p": {"start": 0.5, "stop": 6, "num": 64},
                       "A_ratio": {"start": 0.5, "stop": 8, "num": 64}}}
    ada, full = rocksweep.run(scene, adaptive=True), rocksweep.run(scene)
    done = ada["computed"].values > 0
    assert 0 < done.mean() < 0.5
    for name in (*SLIDE_KEYS, "regime", "outcome", "status"):
        np.testing.assert_array_equal(ada[name].values[done], full[name].values[done])
    assert np.isfinite(ada["slide_max"].values[done]).all()
    assert np.isnan(ada["slide_max"].values[~done]).all()
    assert (ada["regime"].values[~done] == -1).all()
    assert ((full["status"].values & L.STATUS_SLID) != 0).any()
    assert ((ada["status"].values[done] & L.STATUS_REFINED) != 0).any()


@pytest.mark.parametrize("case", ["suite", "floor", "orientation", "adaptive"])
def test_sliding_with_the_other_excitations(case, tmp_path):
    """body.mu with a suite, a floor, two components at an angle, an adaptive sweep: the
    sliding variables are there and finite, and each equals an independent route to the
    same motion. (A vertical (pulse.vertical, ground.vertical) slides too, checked by
    hand against the closed-form block under g (1 + c): its variants are compiled by no
    test, docs/sliding.md.)"""
    {"suite": _suite, "floor": lambda: _floor(tmp_path), "orientation": _orientation,
     "adaptive": _adaptive}[case]()
