"""The scene's `refine` section: the same adaptive sweep as `rocksweep sweep --adaptive`."""

import h5py
import numpy as np
import pytest

from rocksweep.cli import main
from rocksweep.errors import SceneError
from rocksweep.scene.parse import parse_scene

SCENE = """
body: {kind: block, alpha: 0.2}
pulse: {shape: sine, w_over_p: {start: 0.5, stop: 6, num: 33},
        A_ratio: {start: 0.5, stop: 6, num: 33}}
"""


def _arrays(path):
    with h5py.File(path, "r") as f:
        return {k: f[k][()] for k in ("outcome", "computed", "impacts", "t_overturn")}


def test_refine_section_equals_the_adaptive_flags(cli, tmp_path):
    with_section = tmp_path / "a.yaml"
    with_section.write_text(SCENE + "refine: {coarse: 2, audit: 0.05}\n")
    plain = tmp_path / "b.yaml"
    plain.write_text(SCENE)
    r1 = cli.invoke(main, ["sweep", str(with_section), "-o", str(tmp_path / "a.h5"), "-q"])
    r2 = cli.invoke(main, ["sweep", str(plain), "-o", str(tmp_path / "b.h5"), "-q",
                           "--adaptive", "--coarse", "2", "--audit", "0.05"])
    assert r1.exit_code == 0 and r2.exit_code == 0, r1.output + r2.output
    a, b = _arrays(tmp_path / "a.h5"), _arrays(tmp_path / "b.h5")
    assert 0 < int((a["computed"] > 0).sum()) < a["computed"].size  # really adaptive
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    # a flag overrides the section's value: a different audit share, another file
    r3 = cli.invoke(main, ["sweep", str(with_section), "-o", str(tmp_path / "c.h5"), "-q",
                           "--audit", "0"])
    assert r3.exit_code == 0, r3.output
    c = _arrays(tmp_path / "c.h5")
    assert not np.any(c["computed"] >= 2) and np.any(a["computed"] >= 2)


@pytest.mark.parametrize("section, message", [
    ("{audit: 2}", "refine.audit = 2: must be in [0, 1] (share of the filled points computed "
                   "as a check)"),
    ("{coarse: 1.5}", "refine.coarse = 1.5: must be an integer in [0, 20] (the coarse pass "
                      "takes every 2^coarse-th point of both axes)"),
    ("{axes: [w_over_p]}", "refine.axes = ['w_over_p']: must be a list of the two diagram "
                           "axes, swept ranges of the scene, e.g. [w_over_p, A_ratio]"),
    ("{rate: 1}", "refine.rate: unknown key (allowed: axes, coarse, audit, margin, "
                  "final_margin, seed, threshold)"),
])
def test_refine_section_errors(section, message):
    with pytest.raises(SceneError) as err:
        parse_scene(SCENE + f"refine: {section}\n", "s.yaml")
    assert str(err.value) == f"s.yaml: {message}"
