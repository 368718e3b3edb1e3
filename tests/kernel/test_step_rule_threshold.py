"""A rigid body just above its uplift threshold gets more steps while the pulse acts
(``numerics.threshold_factor``): the rocking there is driven by the small difference between
the ground's push and gravity. Checked on the classic block against the scipy reference."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rocksweep.compute.driver import sweep_arrays
from rocksweep.numerics import THRESHOLD_CAP, step_sizes, threshold_factor
from rocksweep.physics.reference import reference_run
from rocksweep.scene.parse import load_scene

ROOT = Path(__file__).resolve().parents[2]


def test_the_factor_rises_towards_the_threshold_and_leaves_the_rest_alone():
    A = np.array([0.5, 1.0, 1.0 + 1e-12, 1.2, 2.0, 10.0, -2.0])
    f = threshold_factor(A, True)
    assert f[0] == f[1] == 1.0  # below the threshold a rigid body does not lift off
    assert f[2] == THRESHOLD_CAP
    assert f[3] == pytest.approx(math.sqrt(1.2 / 0.2))
    assert f[4] == pytest.approx(math.sqrt(2.0)) == f[6]  # the sign of A: its direction
    assert f[5] == pytest.approx(math.sqrt(10 / 9))
    assert (threshold_factor(A, False) == 1.0).all()  # flexible bodies: the spring's rule
    # step_sizes: the pulse's step of a rigid body (omega_rock = 0) shrinks by it, a
    # flexible body's (omega_rock > 0) does not, the step after the pulse never
    for rock, want in ((0.0, math.sqrt(2.0)), (6.8, 1.0)):
        dt0, on0 = step_sizes(rock, 1.0, 5, 12, 0.0, 0.0, 0.0)
        dt1, on1 = step_sizes(rock, 1.0, 5, 12, 0.0, 0.0, 2.0)
        assert dt1 == dt0 and on0 / on1 == pytest.approx(want)


@pytest.mark.parametrize("A_ratio, w_over_p", [(1.04, 0.35), (1.05, 0.45), (1.06, 0.35)])
def test_a_block_just_above_its_threshold_is_classed_as_the_reference_classes_it(
        A_ratio, w_over_p):
    """Points of the classic block's threshold band where the pulse's own steps alone
    gave another class than the scipy reference (at rtol 1e-10 and 1e-12 alike)."""
    sc = load_scene(ROOT / "configs" / "block.yaml",
                    ["pulse.shape=sine", f"pulse.A_ratio={A_ratio}", f"pulse.w_over_p={w_over_p}"])
    ours = int(sweep_arrays(sc)[0]["outcome"].ravel()[0])
    point = sc.point({a.name: a.values[0] for a in sc.axes})
    assert ours == reference_run(point, sc.numerics, rtol=1e-10, atol=1e-12)["outcome"]


def test_the_cost_check_sees_the_threshold_factor(monkeypatch):
    """The admission's step cap (largest at the grid's corners, except along A_ratio just
    above 1, where a rigid body's pulse takes the most steps): a cap between the corners'
    and the near-threshold point's refuses the scene at that point."""
    from rocksweep.errors import SceneError
    from rocksweep.numerics import Numerics
    from rocksweep.physics.points import run_cost
    from rocksweep.scene import admission

    grid = ["pulse.shape=sine", "pulse.w_over_p=6.0", "pulse.A_ratio=[0.5, 1.02, 8.0]"]
    num = Numerics()

    def cap(a):
        return float(run_cost(np.array([0.0]), np.array([0.2618]), np.array([6.0]),
                              np.array([a]), num)[4][0])

    assert cap(1.02) > max(cap(0.5), cap(8.0))
    monkeypatch.setattr(admission, "MAX_POINT_STEPS", 0.5 * (cap(1.02) + max(cap(0.5),
                                                                          cap(8.0))))
    with pytest.raises(SceneError, match="1.02"):
        load_scene(ROOT / "configs" / "block.yaml", grid)
