"""The spring's steps bound RK4's numerical damping of the spring mode (``numerics.spring_steps``,
SPRING_DECAY) and its phase lag over the spring's memory (SPRING_SHIFT): checked against RK4
applied to the linear oscillator here, step by step, and on a point of Figure 4(b) near the
uplift threshold and one of a lightly damped body against the scipy reference."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from bodies import FIG4

from rocksweep.compute.driver import sweep_arrays
from rocksweep.compute.single import run_point
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import PRESETS, Numerics, spring_memory, spring_steps, step_sizes
from rocksweep.physics.bodies import FlexibleBody
from rocksweep.physics.points import Point, body_omega_rock, body_zeta_rock, point_row
from rocksweep.physics.reference import reference_run
from rocksweep.scene.parse import load_scene

ROOT = Path(__file__).resolve().parents[2]


def rk4_step_matrix(omega: float, dt: float) -> np.ndarray:
    """One classical RK4 step of x'' = -omega^2 x at step dt, from the four stages taken
    here: the 2 x 2 matrix acting on (x, x')."""
    a = np.array([[0.0, 1.0], [-omega * omega, 0.0]])

    def step(x: np.ndarray) -> np.ndarray:
        k1 = a @ x
        k2 = a @ (x + dt / 2 * k1)
        k3 = a @ (x + dt / 2 * k2)
        k4 = a @ (x + dt * k3)
        return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

    return np.column_stack([step(np.array([1.0, 0.0])), step(np.array([0.0, 1.0]))])


def rk4_decay_rate(omega: float, dt: float) -> float:
    """Decay rate [1/(p t)] of the amplitude of x'' = -omega^2 x under classical RK4 at step
    dt: the spectral radius of one step's matrix."""
    return -math.log(max(abs(np.linalg.eigvals(rk4_step_matrix(omega, dt))))) / dt


def rk4_lag_rate(omega: float, dt: float) -> float:
    """How far [p t per p t] RK4's oscillation of x'' = -omega^2 x falls behind the exact
    one: 1 - (the step's rotation, the eigenvalues' argument) / (omega dt)."""
    lam = np.linalg.eigvals(rk4_step_matrix(omega, dt))
    return 1.0 - float(np.max(np.angle(lam))) / (omega * dt)


def bound(zeta_rock: float, omega_rock: float, spp: int) -> float:
    """The damping [p] the rule allows (docs/accuracy.md): min(0.1, 0.002 + zeta' omega/38)
    at 5 steps per period, (5/spp)^5 of it at spp."""
    return min(0.1, 0.002 + zeta_rock * omega_rock / 38.0) * (5.0 / spp) ** 5


def damping_steps(omega_rock: float, zeta_rock: float, spp: int) -> float:
    """The steps a spring period that hold RK4's leading-order damping, omega (2 pi/n)^5/144,
    to ``bound``."""
    return 2 * math.pi * (omega_rock / (144 * bound(zeta_rock, omega_rock, spp))) ** 0.2


@pytest.mark.parametrize("spp", [4, 5, 10, 20])
@pytest.mark.parametrize("zeta_rock", [0.0, 0.02, 0.14, 0.9])
@pytest.mark.parametrize("omega_rock", [16.0, 27.46, 60.0, 167.3, 1000.0])
def test_spring_decay_bounded(omega_rock: float, zeta_rock: float, spp: int) -> None:
    """At the rule's step (where the spring sets it) RK4 damps an oscillating spring by at
    most the bound per unit p*t; the leading-order y^6/144 the rule uses bounds the exact
    rate from above, and the rule takes no more steps than that needs."""
    dt, _ = step_sizes(omega_rock, 1.0, spp, PRESETS["default"].steps_per_period,
                       zeta_rock=zeta_rock)
    n = float(spring_steps(omega_rock, spp, zeta_rock))
    assert float(dt) == pytest.approx(2 * math.pi / (omega_rock * n))
    rate = rk4_decay_rate(omega_rock, float(dt))
    assert rate <= bound(zeta_rock, omega_rock, spp) * (1 + 1e-9)
    soft = spp * max(1.0, (27.5 / omega_rock) ** 0.4)
    damping = damping_steps(omega_rock, zeta_rock, spp)
    if n > soft * (1 + 1e-12) and n == pytest.approx(damping, rel=1e-12):
        # the bound sets the steps (not the lag's, SPRING_SHIFT): not far below it
        assert rate >= 0.5 * bound(zeta_rock, omega_rock, spp)


def test_figure4_spring_at_five_steps_was_damped_as_physics() -> None:
    """What the bound fixes: 5 steps per period of Figure 4's spring (omega_rock/p = 27.5)
    damp it at ~0.49 p, as much as the physical zeta omega_n = 0.05 x 9.82 in full contact."""
    rate = rk4_decay_rate(27.46, 2 * math.pi / (27.46 * 5))
    assert rate == pytest.approx(0.49, abs=0.01)
    assert spring_steps(27.46, 5, 0.14) >= 5 * 1.4


@pytest.mark.parametrize("spp", [5, 20])
@pytest.mark.parametrize("zeta_rock", [0.0, 0.002, 0.01, 0.05])
@pytest.mark.parametrize("omega_rock", [2.0, 10.0, 27.46])
def test_spring_phase_lag_bounded(omega_rock: float, zeta_rock: float, spp: int) -> None:
    """At the rule's step RK4's oscillating spring falls behind the exact one by at most
    0.003 (5/spp)^4 p t over its memory, min(50, 1/(zeta' omega_rock)) p t (the leading
    order (2 pi/n)^4/120 the rule uses bounds the exact lag from above), and where that
    bound sets the steps, the rule takes no more than it needs."""
    dt, _ = step_sizes(omega_rock, 1.0, spp, PRESETS["default"].steps_per_period,
                       zeta_rock=zeta_rock)
    memory = min(50.0, 1.0 / (zeta_rock * omega_rock)) if zeta_rock else 50.0
    allowed = 0.003 * (5.0 / spp) ** 4
    lag = memory * rk4_lag_rate(omega_rock, float(dt))
    assert lag <= allowed * (1 + 1e-9)
    n = float(spring_steps(omega_rock, spp, zeta_rock))
    others = max(spp * max(1.0, (27.5 / omega_rock) ** 0.4),
                 damping_steps(omega_rock, zeta_rock, spp))
    if n > others * (1 + 1e-12):  # the lag sets the steps: not far below its bound
        assert lag >= 0.5 * allowed


def test_an_undamped_soft_spring_is_stepped_for_its_phase() -> None:
    """An undamped spring keeps its lag for the whole run (50 p t): 2 pi (50/0.36)^(1/4) =
    21.6 steps a period at 5, where the damping bound asked for ~14 at 2 p (and fewer for
    stiffer ones), and twice that at 10."""
    for w in (2.0, 3.5, 27.46):
        assert float(spring_steps(w, 5, 0.0)) == pytest.approx(
            2 * math.pi * (50 / (120 * 0.003)) ** 0.25)
        assert float(spring_steps(w, 10, 0.0)) == pytest.approx(
            2 * float(spring_steps(w, 5, 0.0)))


def test_a_lightly_damped_body_is_classified_like_the_reference() -> None:
    """A threshold sample's point (seed 9): a body with zeta 0.0044 under a cosine pulse.
    Before the lag bound `default` (13 steps a spring period) overturned it in mode 1
    at the 6th impact with a margin of 11.5 x its close-call margin, so nothing checked
    it; 10 steps a period and more and the reference rock it to rest after ~114 impacts."""
    body = FlexibleBody(wn_over_p=2.1672110812976944, zeta=0.0043605299163016085,
                        alpha_cg=0.3208775675425084, alpha_A=0.3130916789266689,
                        mA_over_m=2.5795243471497966, IA_ratio=0.8780246150333455)
    point = Point(body, 0.34681454228526426, "cosine", 2.850974518852713, 7.733363941470293)
    ref = reference_run(point)
    assert int(ref["outcome"]) == 0
    run = run_point(point, Numerics.preset("default"), history=False)
    assert int(run.out[L.OUT_OUTCOME]) == 0


@pytest.mark.parametrize("omega_rock, zeta_rock", [(0.0, 0.0), (2.0, 0.14), (6.796, 0.14),
                                                   (10.0, 0.14)])
def test_soft_springs_and_rigid_bodies_keep_their_steps(omega_rock: float,
                                                        zeta_rock: float) -> None:
    """Figure 3's spring (6.8 p, zeta' = 0.14), damped ones below ~10 p and rigid bodies
    (no spring): neither the damping nor the lag bound binds, the steps stay
    steps_per_period x max(1, (27.5/omega_rock)^(2/5))."""
    for spp in (4, 5, 20):
        want = spp * max(1.0, (27.5 / omega_rock) ** 0.4) if omega_rock else math.inf
        got = float(spring_steps(omega_rock, spp, zeta_rock))
        assert got == pytest.approx(want, rel=1e-12)


def test_the_spring_memory_is_its_free_decay_time() -> None:
    """numerics.spring_memory, written into the rows (PAR_MEMORY): the e-folding time of
    the rocking spring's free vibration, 1/(zeta' omega_rock) = 2 m / (c Gamma) with
    Gamma = 1 + m h^2 / (I_A + m_A R_A^2) (u'' = -Gamma (k u + c u')/m, the top mass above
    the corner), from the body's own m, c, h, I_A: inf undamped, 0 rigid or overdamped."""
    for zeta in (0.0, 0.01, 0.05):
        body = FlexibleBody(wn_over_p=2.43, zeta=zeta, alpha_cg=0.15, alpha_A=0.28,
                            mA_over_m=0.47, IA_ratio=0.56)
        gamma = 1.0 + body.m * body.h**2 / (body.I_A + body.m_A * body.R_A**2)
        want = math.inf if zeta == 0.0 else 2.0 * body.m / (body.c * gamma)
        got = float(spring_memory(body_omega_rock(body), body_zeta_rock(body)))
        assert got == pytest.approx(want, rel=1e-12)
        row = point_row(Point(body, 0.0, "sine", 2.0, 3.0), Numerics.preset("default"))
        assert row[L.PAR_MEMORY] == got
    assert float(spring_memory(0.0, 0.0)) == 0.0  # a rigid body: no spring
    assert float(spring_memory(5.0, 1.5)) == 0.0  # overdamped: it does not ring


def test_threshold_point_of_figure4b_is_safe_at_default() -> None:
    """Figure 4(b), lam 0.4, A_ratio 1.0, w_over_p 0.375: at 5 steps per spring period
    `default` called it mode 1 (50 impacts); the reference says safe (~250 impacts)."""
    scene = load_scene(ROOT / "configs" / "fig4b.yaml",
                       ["impact.lam=0.4", "pulse.A_ratio=1.0", "pulse.w_over_p=0.375"])
    assert scene.numerics == Numerics.preset("default")
    out, _ = sweep_arrays(scene)
    point = scene.point({ax.name: ax.values[0] for ax in scene.axes})
    ref = reference_run(point, scene.numerics, rtol=1e-10, atol=1e-12)
    assert int(ref["outcome"]) == 0
    assert int(out["outcome"].ravel()[0]) == int(ref["outcome"])


def test_an_overdamped_spring_gets_no_damping_bound() -> None:
    """zeta' = zeta sqrt(Gamma) >= 1 while rocking: omega_rock is the overdamped mode's fast
    decay rate, with no oscillation for RK4 to damp; the bound is for zeta' < 1 only, and
    ``body_zeta_rock`` tells the two apart (Gamma = 1 + m h^2 / (I_A + m_A R_A^2), eq. of
    the rocking phase linearised at the top mass over the corner)."""
    for zeta, overdamped in ((0.05, False), (0.3, False), (3.0, True)):
        body = FlexibleBody(**{**FIG4, "zeta": zeta})  # Figure 4's, other zeta
        gamma = 1 + body.m * body.h ** 2 / (body.I_A + body.m_A * body.R_A ** 2)
        zr = zeta * math.sqrt(gamma)
        assert (zr >= 1) == overdamped
        w = body_omega_rock(body)
        if not overdamped:
            assert w == pytest.approx(body.omega_n * math.sqrt(gamma))
            assert body_zeta_rock(body) == pytest.approx(zr)
        else:
            assert body_zeta_rock(body) > 1.0
        want = 5 * max(1.0, (27.5 / w) ** 0.4)
        if not overdamped:
            want = max(want, 2 * math.pi * (w / (144 * bound(zr, w, 5))) ** 0.2)
        assert float(spring_steps(w, 5, body_zeta_rock(body))) == pytest.approx(want)
