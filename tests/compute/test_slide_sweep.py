"""A sweep of a scene that gives body.mu: the sliding base's variables in the Dataset (and
none in a scene without mu), their units and meanings, the status word ``slid``, and a
block that cannot rock (mu < tan alpha) rocking or overturning nowhere on the grid.

Cost: the rigid block's outcome-level chunk variant of the slide loop (18 s of CPU to
compile cold, docs/sliding.md "Cost"), 100 points, and the same 50 swept by the command
line and counted by ``rocksweep info``."""

import yaml

import rocksweep
from rocksweep.cli.main import main
from rocksweep.kernel import layout as L
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
