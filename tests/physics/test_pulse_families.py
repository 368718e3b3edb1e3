"""Pulse families in the kernel (n cycles, Ricker, Mavroeidis-Papageorgiou) against their
independent reference definitions (``rocksweep.physics.excitation``, numpy) and closed forms.

- the jitted ground acceleration and its rate equal ``PulseShape.acc``/``rate`` (A, A w);
- the rigid block uplifts when |xg''| first reaches g tan(alpha): the kernel's first
  uplift time equals ``PulseShape.uplift_phase(A_ratio) / omega`` (Brent's method on the
  reference; the Ricker's is the Lambert-W solution, tests/test_excitation.py);
- a 2-cycle sine is a 1-cycle sine followed by a second one: the 2-cycle run from rest
  and a 1-cycle run started from the 2-cycle run's state at t = 2 pi / omega (the sine's
  phase is the same) overturn at the same time;
- scene keys: cycles, shapes, gamma and nu checked with one-line errors.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rocksweep.compute.single import run_point
from rocksweep.errors import SceneError
from rocksweep.kernel import layout as L
from rocksweep.kernel.ground import any_ground_acc, any_ground_jerk
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody
from rocksweep.physics.excitation import PulseShape
from rocksweep.physics.ground_motion import pulse
from rocksweep.physics.points import Point, point_row
from rocksweep.scene.parse import parse_scene

BLOCK = BlockBody(alpha=0.2618, inertia=4.0 / 3.0)
CASES = [("sine", 1, 2.0, 90.0), ("sine", 3, 2.0, 90.0), ("cosine", 2, 2.0, 90.0),
         ("ricker", 1, 2.0, 90.0), ("mp", 1, 2.0, 90.0), ("mp", 1, 1.7, 30.0),
         ("mp", 1, 3.0, -45.0)]


def _point(shape, cycles, gamma, nu, w_over_p=2.0, A_ratio=1.7, body=BLOCK, lam=0.0):
    return Point(body, lam, pulse(shape, cycles, gamma, nu), w_over_p, A_ratio)


@pytest.mark.parametrize("shape, cycles, gamma, nu", CASES)
def test_kernel_ground_motion_is_the_reference_shape(shape, cycles, gamma, nu):
    pt = _point(shape, cycles, gamma, nu, w_over_p=1.3, A_ratio=-2.4)
    row = point_row(pt, Numerics())
    ref = PulseShape(shape, cycles, gamma, nu)
    w = 1.3  # p = 1 in the kernel
    assert row[L.PAR_TPULSE] == pytest.approx(ref.duration / w, rel=1e-15)
    t = np.linspace(0.0, row[L.PAR_TPULSE], 1001)
    acc = np.array([any_ground_acc(x, True, row) for x in t])
    jerk = np.array([any_ground_jerk(x, True, row) for x in t])
    np.testing.assert_allclose(acc, pt.A * ref.acc(w * t), rtol=1e-12, atol=1e-12 * abs(pt.A))
    np.testing.assert_allclose(jerk, pt.A * w * ref.rate(w * t), rtol=1e-12,
                               atol=1e-12 * abs(pt.A) * w)
    assert any_ground_acc(0.3, False, row) == 0.0 and any_ground_jerk(0.3, False, row) == 0.0
    assert np.max(np.abs(acc)) <= abs(pt.A) * (1 + 1e-12)  # A is the peak


def _first_uplift(run) -> float:
    h = run.history
    return float(h["t"][np.flatnonzero(h["phase"] != 0)[0]])


@pytest.mark.parametrize("shape, cycles, gamma, nu", CASES)
@pytest.mark.parametrize("A_ratio", [1.3, -2.5])
def test_rigid_block_uplifts_when_the_shape_reaches_g_tan_alpha(shape, cycles, gamma, nu,
                                                                 A_ratio):
    ref = PulseShape(shape, cycles, gamma, nu)
    phi = ref.uplift_phase(A_ratio)
    assert phi is not None
    w = 1.7
    run = run_point(_point(shape, cycles, gamma, nu, w_over_p=w, A_ratio=A_ratio),
                    Numerics.preset("fine"))
    assert run.uplifts >= 1
    assert _first_uplift(run) == pytest.approx(phi / w, abs=1e-7)


def test_no_uplift_below_the_threshold():
    for shape in ("ricker", "mp"):
        run = run_point(_point(shape, 1, 2.0, 90.0, A_ratio=0.99), Numerics())
        assert run.uplifts == 0 and run.outcome == "safe"


def test_two_cycles_are_one_cycle_after_another():
    """A 1-cycle run lands a step on its pulse's end T = 2 pi/omega: its state there, given
    as the initial state of another 1-cycle run, must continue as the 2-cycle run from rest
    does (the sine's phase at T is 0 again), so the 2-cycle run overturns at T plus the
    second run's overturning time (to the integration error at `fine`)."""
    from rocksweep.kernel import point_kernel

    w, A = 3.0, 3.2
    T = 2 * math.pi / w
    fine = Numerics.preset("fine")
    two = run_point(_point("sine", 2, 2.0, 90.0, w_over_p=w, A_ratio=A), fine)
    assert two.outcome != "safe" and two.t_overturn > T
    one = run_point(_point("sine", 1, 2.0, 90.0, w_over_p=w, A_ratio=A), fine)
    h = one.history
    k = int(np.flatnonzero(h["t"] == T)[0])  # the step landed on the pulse's end
    assert h["phase"][k] != 0  # rocking at T
    row = point_row(_point("sine", 1, 2.0, 90.0, w_over_p=w, A_ratio=A), fine)
    row[L.PAR_THETA0], row[L.PAR_THETA_DOT0] = h["theta"][k], h["theta_dot"][k]
    out = np.empty(L.N_OUT)
    point_kernel(L.KIND_RIGID, L.GROUND_PULSE)(row, out, np.empty((200_000, L.N_HIST)))
    assert out[L.OUT_OUTCOME] != L.OUTCOME_SAFE
    # 1e-5: `fine`'s error; the restarted run's steps differ after T (the rotation limit
    # predicts each step from the last one's theta'', which a restart does not carry over)
    assert out[L.OUT_T_OVERTURN] + T == pytest.approx(two.t_overturn, abs=1e-5)


BODY = """
body: {kind: block, alpha: 0.2618}
pulse: {shape: %s, w_over_p: 2.0, A_ratio: 2.0%s}
"""


@pytest.mark.parametrize("extra, msg", [
    (", cycles: 0", "pulse.cycles = 0: must be an integer in [1, 1000]"),
    (", cycles: 1.5", "pulse.cycles = 1.5: must be an integer"),
    (", gamma: 0.5", "pulse.gamma = 0.5: must be in [1, 100]"),
    (", nu: .nan", "pulse.nu = nan: must be a finite angle in degrees"),
    (", wobble: 1", "pulse.wobble: unknown key"),
])
def test_pulse_options_are_checked(extra, msg):
    with pytest.raises(SceneError, match=msg.replace("[", r"\[").replace("]", r"\]")):
        parse_scene(BODY % ("mp", extra))


def test_shapes_and_options_in_a_scene():
    sc = parse_scene(BODY % ("[sine, ricker, mp]", ", cycles: 3, nu: 45"))
    assert sc.axis("shape").values == ("sine", "ricker", "mp")
    assert sc.option("cycles") == 3 and sc.option("nu") == 45.0 and sc.option("gamma") == 2.0
    assert sc.phase_max() == pytest.approx(6 * math.pi)  # 3 cycles and the Ricker: 6 pi
    assert sc.point({"alpha": 0.2618, "inertia": 4 / 3, "lam": 0.0, "shape": "mp",
                     "w_over_p": 2.0, "A_ratio": 2.0}).excitation.nu == 45.0
    plain = parse_scene(BODY % ("sine", ""))  # the paper's scenes get no new axes
    assert [a.name for a in plain.axes] == ["shape", "alpha", "inertia", "lam", "A_ratio",
                                            "w_over_p"]
    with pytest.raises(SceneError, match="pulse.shape = 'square': must be sine, cosine, "
                                         "ricker, mp or a list of them"):
        parse_scene(BODY % ("square", ""))
