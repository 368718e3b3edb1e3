"""Bad input of the excitation path's keys: one line naming the key, the value and what
is allowed; the command line exits 2 and writes nothing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from helpers import one_line_error

from rocksweep.cli import main
from rocksweep.errors import SceneError
from rocksweep.physics.records import read_record, write_at2
from rocksweep.scene.parse import parse_scene

ROOT = Path(__file__).resolve().parents[2]
NEARFAULT = str(ROOT / "records" / "synthetic_nearfault.AT2")
BODY = {"kind": "block", "alpha": 0.2, "inertia": 4 / 3}
GROUND = {"record": NEARFAULT, "A_ratio": 1.0, "p": 2.0}
MODE = {"period": 0.5, "damping": 0.05, "participation": 1.3}


@pytest.mark.parametrize(("extra", "says"), [
    ({"floor": {**MODE, "period": -1}}, "floor.period = -1.0: must be a finite number > 0"),
    ({"floor": {**MODE, "damping": -0.05}}, "floor.damping = -0.05: must be in (0, 1)"),
    ({"floor": {**MODE, "damping": 0.0}}, "floor.damping = 0.0: must be in (0, 1)"),
    ({"floor": {**MODE, "participation": 0}}, "floor.participation = 0.0: must be a finite "
                                             "number other than 0"),
    ({"floor": {"modes": [{**MODE, "participation": 0}]}},
     "floor.modes[0].participation = 0: must be"),
    ({"floor": {"period": 0.5, "damping": 0.05}}, "floor.participation: missing"),
    ({"floor": {**MODE, "modes": [MODE]}}, "floor.period: not with floor.modes"),
    ({"ground": {**GROUND, "angle": 30}}, "ground.angle = 30: needs the second"),
])
def test_bad_floor_and_angle_keys_are_one_line(extra, says):
    with pytest.raises(SceneError) as err:
        parse_scene(yaml.safe_dump({"body": BODY, "ground": GROUND, **extra}))
    msg = str(err.value)
    assert says in msg and "\n" not in msg


def test_an_angle_outside_0_360_and_an_h2_of_another_dt(tmp_path):
    rec = read_record(NEARFAULT)
    write_at2(tmp_path / "h2.AT2", np.roll(rec.acc, 10), rec.dt, "h2")
    write_at2(tmp_path / "slow.AT2", rec.acc, 2 * rec.dt, "h2 at 2 DT")
    for angle in (360, -10):
        with pytest.raises(SceneError, match=rf"ground.angle = {float(angle)!r}: must be in "
                                             r"\[0, 360\) deg"):
            parse_scene(yaml.safe_dump({"body": BODY, "ground": {
                **GROUND, "h2": str(tmp_path / "h2.AT2"), "angle": angle}}))
    with pytest.raises(SceneError, match=r"DT = 0.01 s differs .* \(refused, not resampled\)"):
        parse_scene(yaml.safe_dump({"body": BODY, "ground": {
            **GROUND, "h2": str(tmp_path / "slow.AT2")}}))


def test_a_free_rocking_scene_has_no_floor():
    with pytest.raises(SceneError, match="floor = .*free-rocking scene"):
        parse_scene(yaml.safe_dump({"body": BODY, "initial": {"theta_over_alpha": 0.5},
                                    "floor": MODE}))


def test_the_command_line_exits_2_and_writes_nothing(tmp_path, cli):
    scene = tmp_path / "s.yaml"
    scene.write_text(yaml.safe_dump({"body": BODY, "ground": GROUND,
                                     "floor": {**MODE, "participation": 0}}))
    out = tmp_path / "out.h5"
    line = one_line_error(cli.invoke(main, ["sweep", str(scene), "-o", str(out)]), 2)
    assert "floor.participation = 0.0" in line
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]
