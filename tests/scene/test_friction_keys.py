"""The friction keys ``body.mu`` (kinetic) and ``body.mu_static`` (static, >= mu, default
mu): axes like any key; bad input is one line naming the key, the value and what is
allowed, and the command line exits 2 and writes nothing (docs/sliding.md)."""

from __future__ import annotations

import pytest
import yaml
from bodies import FIG3, FIG3_YAML
from helpers import one_line_error

from rocksweep.cli import main
from rocksweep.errors import SceneError
from rocksweep.scene.grid import Grid
from rocksweep.scene.parse import parse_scene

SCENE = FIG3_YAML + """impact: {lam: [0.0, 0.4]}
pulse: {shape: sine, w_over_p: {start: 0.5, stop: 6, num: 3}, A_ratio: {start: 0.5, stop: 8,
        num: 3}}
"""


def test_mu_and_mu_static_are_axes():
    """Scalars, lists and ranges; swept, each is a dimension of the grid, after the pulse
    axes; neither is part of the body (the grid's bodies are the same)."""
    sc = parse_scene(SCENE, overrides=["body.mu=0.5", "body.mu_static=[0.5, 0.7]"])
    names = [a.name for a in sc.axes]
    assert names[-2:] == ["mu", "mu_static"]
    assert sc.axis("mu").values == (0.5,) and not sc.axis("mu").swept
    assert sc.axis("mu_static").values == (0.5, 0.7) and sc.axis("mu_static").swept
    assert sc.shape == (2, 3, 3, 2)
    assert all(a.key not in ("body.mu", "body.mu_static") for a in sc.body_axes())
    assert Grid(sc).rows(0, sc.size).rows.shape[0] == sc.size
    sc = parse_scene(SCENE, overrides=["body.mu={start: 0.2, stop: 0.8, num: 4}",
                                       "body.mu_static=0.9"])
    assert sc.axis("mu").swept and sc.shape[-1] == 4
    assert "mu_static" not in [a.name for a in parse_scene(SCENE, overrides=[
        "body.mu=0.3"]).axes]


def test_a_physical_body_keeps_its_friction():
    body = {"kind": "physical", "b": 0.2, "h": 1.5, "h_A": 0.4, "m": 100.0, "m_A": 40.0,
            "I_A": 2.0, "k": 2.0e4, "c": 50.0, "mu": 0.4, "mu_static": 0.5}
    sc = parse_scene(yaml.safe_dump({"body": body, "impact": {"lam": 0.0},
                                     "pulse": {"shape": "sine", "w_over_p": 2.0,
                                               "A_ratio": 3.0}}))
    assert sc.axis("mu").values == (0.4,) and sc.axis("mu_static").values == (0.5,)


@pytest.mark.parametrize(("overrides", "says"), [
    (["body.mu=-0.1"], "body.mu = -0.1: must be in (0, 10]"),
    (["body.mu=0"], "body.mu = 0.0: must be in (0, 10]"),
    (["body.mu=.nan"], "body.mu = nan: must be in (0, 10]"),
    (["body.mu=.inf"], "body.mu = inf: must be in (0, 10]"),
    (["body.mu=rough"], "body.mu = 'rough': must be a number"),
    (["body.mu=[0.2, -1]"], "body.mu = -1.0: must be in (0, 10]"),
    (["body.mu=0.4", "body.mu_static=-1"], "body.mu_static = -1.0: must be in (0, 10] and "
                                           "at least body.mu"),
    (["body.mu=0.4", "body.mu_static=0"], "body.mu_static = 0.0: must be in (0, 10]"),
    (["body.mu=0.4", "body.mu_static=.nan"], "body.mu_static = nan: must be in (0, 10]"),
    (["body.mu=0.4", "body.mu_static=high"], "body.mu_static = 'high': must be a number"),
    (["body.mu=0.4", "body.mu_static=0.3"], "body.mu_static = 0.3: must be at least body.mu "
                                            "(0.4 in this scene"),
    (["body.mu=[0.2, 0.6]", "body.mu_static=0.5"], "body.mu_static = 0.5: must be at least "
                                                   "body.mu (0.6 in this scene"),
    (["body.mu=0.4", "body.mu_static=[0.3, 0.5]"], "body.mu_static = 0.3: must be at least"),
    (["body.mu_static=0.5"], "body.mu_static = 0.5: needs body.mu"),
])
def test_bad_friction_is_one_line(overrides, says):
    with pytest.raises(SceneError) as err:
        parse_scene(SCENE, overrides=overrides)
    msg = str(err.value)
    assert says in msg and "\n" not in msg


def test_every_impact_law_takes_friction():
    """Every law carries a tangential impulse (docs/sliding.md): none is refused."""
    for law in ("vertical", "locked", "constant"):
        extra = ["impact.e=0.8"] if law == "constant" else []
        parse_scene(SCENE, overrides=["body.mu=0.4", f"impact.law={law}", *extra])


def test_the_command_line_exits_2_and_writes_nothing(tmp_path, cli):
    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump({"body": {**FIG3, "mu": 0.5, "mu_static": 0.4},
                                     "impact": {"lam": 0.0},
                                     "pulse": {"shape": "sine", "w_over_p": 2.0,
                                               "A_ratio": 3.0}}))
    out = tmp_path / "out.h5"
    line = one_line_error(cli.invoke(main, ["sweep", str(scene), "-o", str(out)]), 2)
    assert "body.mu_static = 0.4: must be at least body.mu" in line
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]
