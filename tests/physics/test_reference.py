"""The reference path: checked against closed forms, conservation laws and eq. (6), then
against the RK4 kernel (agreement that tightens as the kernel's step shrinks)."""

import math

import numpy as np
import pytest
from bodies import BODY3, table3
from scipy.integrate import quad

from rocksweep.compute.single import run_point
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, FlexibleBody, impact_energy_loss, restitution_rigid
from rocksweep.physics.points import Point
from rocksweep.physics.reference import reference_run

BLOCK = BlockBody(alpha=0.2)


def _impacts(run: dict) -> list[dict]:
    return [e for e in run["events"] if e["kind"] == "impact"]


# ----------------------------------------------------------------------------------------
# Closed forms (rigid block)
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("A_ratio", [1.3, 2.0, 4.0])
def test_rigid_block_uplifts_when_the_ground_reaches_g_tan_alpha(A_ratio):
    """Rigid uplift: |xg''| = g tan(alpha), i.e. A sin(omega t) = g tan(alpha)."""
    p = Point(BLOCK, 0.0, "sine", 6.0, A_ratio)
    run = reference_run(p, events=True)
    first = run["events"][0]
    assert first["kind"] == "uplift" and first["s_after"] == -1  # xg'' > 0 tips toward -b
    assert first["t"] == pytest.approx(math.asin(1.0 / A_ratio) / p.omega, abs=1e-12)


def test_rigid_block_below_the_uplift_threshold_never_moves():
    run = reference_run(Point(BLOCK, 0.0, "cosine", 2.0, 0.95))
    assert run["uplifts"] == 0 and run["impacts"] == 0 and run["theta_max"] == 0.0
    assert run["outcome"] == L.OUTCOME_SAFE and run["status"] & L.STATUS_REST


def _half_cycle(body: BlockBody, w: float) -> float:
    """Time from theta = 0 with |theta'| = w back to theta = 0 (free rocking, exact).

    Energy: theta'^2 = w^2 - 2 p^2 (cos(alpha - theta) - cos alpha), p^2 = M g R / I_O.
    """
    a, p2 = body.alpha, body.p**2
    th_max = a - math.acos(math.cos(a) + w * w / (2 * p2))

    def dt(v: float) -> float:  # theta = th_max (1 - v^2) removes the 1/sqrt singularity
        th = th_max * (1 - v * v)
        rate2 = w * w - 2 * p2 * (math.cos(a - th) - math.cos(a))
        return 2 * v * th_max / math.sqrt(max(rate2, 1e-300))

    return 2 * quad(dt, 0.0, 1.0, epsabs=1e-13, epsrel=1e-12, limit=200)[0]


@pytest.mark.parametrize("lam", [0.0, 0.4])
def test_rigid_block_free_rocking_matches_the_elliptic_half_cycles(lam):
    """After the pulse: every interval between impacts is the exact free half cycle, and
    every impact multiplies theta' by Housner's / Chatzis' rigid restitution."""
    p = Point(BLOCK, lam, "sine", 6.0, 2.0)
    run = reference_run(p, events=True, early_exit=False)
    imp = _impacts(run)
    e_rigid = float(restitution_rigid(BLOCK, lam))
    checked = 0
    for a, b in zip(imp[:-1], imp[1:], strict=True):
        if a["t"] <= p.t_pulse or a["s_after"] == 0 or checked == 8:
            continue
        assert a["theta_dot_after"] / a["theta_dot_before"] == pytest.approx(e_rigid, rel=1e-12)
        assert b["t"] - a["t"] == pytest.approx(_half_cycle(BLOCK, abs(a["theta_dot_after"])),
                                                abs=1e-9)
        checked += 1
    assert checked == 8


def test_rigid_block_released_from_rest_hits_the_ground_at_the_closed_form_time():
    """Free rocking from (theta0, 0): the first impact comes after half a half cycle, and
    the kernel, started from the same state, agrees."""
    theta0 = 0.6 * BLOCK.alpha
    a, p2 = BLOCK.alpha, BLOCK.p**2
    w0 = math.sqrt(2 * p2 * (math.cos(a - theta0) - math.cos(a)))  # |theta'| at theta = 0
    p = Point(BLOCK, 0.0, "sine", 100.0, 0.0)  # no ground motion
    run = reference_run(p, theta0=theta0, theta_dot0=0.0, early_exit=False, events=True)
    first = _impacts(run)[0]
    assert first["t"] == pytest.approx(0.5 * _half_cycle(BLOCK, w0), abs=1e-9)
    assert abs(first["theta_dot_before"]) == pytest.approx(w0, rel=1e-9)
    assert run["theta_max"] == pytest.approx(theta0, abs=1e-15)


def test_rigid_block_bounded_exit_matches_the_kernel():
    """After the pulse a rigid body below its overturning energy stops early (safe); both
    paths stop at the same impact and predict the same largest rotation."""
    p = Point(BLOCK, 0.0, "sine", 6.0, 2.0)
    ref = reference_run(p)
    run = run_point(p, Numerics(steps_per_period=40, event_tol=1e-12), history=False)
    assert ref["status"] & L.STATUS_BOUNDED and int(run.out[L.OUT_STATUS]) & L.STATUS_BOUNDED
    assert ref["outcome"] == run.out[L.OUT_OUTCOME] == L.OUTCOME_SAFE
    assert ref["impacts"] == run.out[L.OUT_IMPACTS]
    assert run.out[L.OUT_THETA_MAX] == pytest.approx(ref["theta_max"], abs=1e-6)
    full = reference_run(p, early_exit=False)  # following every impact: the same maximum
    assert full["outcome"] == L.OUTCOME_SAFE and full["impacts"] > 100
    assert full["theta_max"] == pytest.approx(ref["theta_max"], abs=1e-9)


# ----------------------------------------------------------------------------------------
# Conservation and eq. (6) (flexible body)
# ----------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def undamped_run():
    body = FlexibleBody(**table3(zeta=0.0))
    p = Point(body, 0.0, "sine", 3.0, 3.0)
    return body, p, reference_run(p, Numerics(horizon=30.0), events=True)


def test_undamped_energy_is_conserved_between_events_after_the_pulse(undamped_run):
    body, p, run = undamped_run
    ev = run["events"]
    drift = [(b["energy_before"] - a["energy_after"]) / body.E_ref
             for a, b in zip(ev[:-1], ev[1:], strict=True) if a["t"] > p.t_pulse]
    assert len(drift) > 100
    assert max(abs(d) for d in drift) < 1e-9


def test_impact_energy_loss_is_eq6(undamped_run):
    """Energy before - after each rocking-to-rocking impact equals eq. (6) of the paper."""
    body, _, run = undamped_run
    checked = 0
    for e in _impacts(run):
        if e["s_after"] == 0:
            continue
        e_d = impact_energy_loss(body, e["e"], e["u"], e["theta_dot_before"],
                                 e["s_before"] == 1)
        assert e["energy_before"] - e["energy_after"] == pytest.approx(
            float(e_d), abs=1e-12 * body.E_ref)
        checked += 1
    assert checked > 100


def test_impact_keeps_the_top_mass_horizontal_momentum(undamped_run):
    body, _, run = undamped_run
    for e in _impacts(run)[:50]:
        before = e["u_dot_before"] + body.h * e["theta_dot_before"]
        after = e["u_dot_after"] + body.h * e["theta_dot_after"]
        assert after == pytest.approx(before, abs=1e-14)


# ----------------------------------------------------------------------------------------
# Reference against the kernel
# ----------------------------------------------------------------------------------------

CASES = {
    # Figure 5's pulse: safe after 91 impacts (lam = 0), mode 1 after 3 impacts (lam = 0.4)
    "safe": Point(BODY3, 0.0, "sine", 5.3, 5.0),
    "mode1": Point(BODY3, 0.4, "sine", 5.3, 5.0),
    "mode2": Point(BODY3, 0.2, "sine", 2.0, 3.0),
    "cosine_mode1": Point(BODY3, 0.0, "cosine", 3.0, 6.0),
}


def _kernel_impacts(run) -> list[float]:
    """Times of the kernel's impacts: phase changes out of rocking (the history records
    the state on both sides of each event)."""
    t, ph = run.history["t"], run.history["phase"]
    return [float(t[i]) for i in range(len(t) - 1)
            if t[i] == t[i + 1] and ph[i] != 0 and ph[i] != ph[i + 1]]


@pytest.fixture(scope="module")
def references():
    return {k: reference_run(p, events=True) for k, p in CASES.items()}


@pytest.mark.parametrize("name", list(CASES))
def test_kernel_agrees_with_the_reference_tighter_as_the_step_shrinks(name, references):
    ref = references[name]
    ref_impacts = [e["t"] for e in _impacts(ref)][:3]
    for spp in (10, 20, 40):
        bound = 5e-3 * (10 / spp) ** 4  # RK4: error ~ step^4
        run = run_point(CASES[name], Numerics(steps_per_period=spp, event_tol=1e-12))
        o = run.out
        assert o[L.OUT_OUTCOME] == ref["outcome"], spp
        assert o[L.OUT_IMPACTS] == ref["impacts"], spp
        assert o[L.OUT_UPLIFTS] == ref["uplifts"], spp
        k_impacts = _kernel_impacts(run)[:3]
        assert len(k_impacts) == len(ref_impacts)
        if ref_impacts:
            assert np.max(np.abs(np.subtract(k_impacts, ref_impacts))) < bound, spp
        d_theta = abs(o[L.OUT_THETA_MAX] - ref["theta_max"]) / BODY3.alpha_cg
        assert d_theta < bound, spp
        if name in ("mode2", "cosine_mode1"):  # overturning right after a smooth stretch
            assert abs(o[L.OUT_T_OVERTURN] - ref["t_overturn"]) < bound, spp
