"""The sliding base's reference runs (``physics.sliding_reference``) against independent
results: the closed-form rigid-plastic sliding block (``physics.friction.sliding_block``),
the no-slip reference (``physics.reference``) where friction is ample, and the energy
balance. Few points: the reference is slow (0.2-3 s a run)."""

import math

import numpy as np
import pytest
from bodies import BODY3

from rocksweep.kernel import layout as L
from rocksweep.physics.bodies import BlockBody
from rocksweep.physics.friction import sliding_block
from rocksweep.physics.points import Point
from rocksweep.physics.reference import reference_run
from rocksweep.physics.sliding_reference import sliding_reference


@pytest.mark.parametrize("shape,A_ratio,mu_s", [("sine", 1.5, None), ("cosine", 3.0, None),
                                                 ("sine", 2.5, 0.27), ("cosine", 1.2, 0.25)])
def test_pure_sliding_equals_the_rigid_plastic_block(shape, A_ratio, mu_s):
    """mu = 0.2 < tan(alpha) = 0.309 (and mu_s < tan alpha): friction bounds the block's
    acceleration below g tan(alpha), so it never rocks; slide_max and slide_final are the
    closed form's (to 1e-6: the reference integrates to 1e-10)."""
    blk = BlockBody(alpha=0.3)
    pt = Point(blk, 0.0, shape, 2.0, A_ratio, mu=0.2)
    r = sliding_reference(pt, mu_static=mu_s)
    cf = sliding_block(pt.A, pt.omega, 0.2, mu_s, shape)
    assert set(r["phases"]) <= {"rest", "slide"} and "slide" in r["phases"]
    assert r["uplifts"] == 0 and r["impacts"] == 0 and r["theta_max"] == 0.0
    assert r["slide_max"] == pytest.approx(cf["slide_max"], rel=1e-6)
    assert r["slide_final"] == pytest.approx(cf["slide_final"], rel=1e-6, abs=1e-9)
    assert abs(r["closure"]) < 1e-6 * r["E_ref"]


def test_static_friction_holds_longer():
    """mu_s > mu: the block starts to slip later and slips less far than with mu_s = mu
    (the closed form with its own mu_s, and the reference agree on both)."""
    blk = BlockBody(alpha=0.3)
    pt = Point(blk, 0.0, "sine", 2.0, 1.5, mu=0.2)
    far = sliding_block(pt.A, pt.omega, 0.2)
    near = sliding_block(pt.A, pt.omega, 0.2, 0.28)
    assert near["segments"][0][0] > far["segments"][0][0]
    assert near["slide_max"] < far["slide_max"]


@pytest.mark.parametrize("body,lam,shape,w,A", [
    (BlockBody(alpha=0.2), 0.0, "sine", 2.0, 1.5),
    (BlockBody(alpha=0.2), 0.0, "cosine", 3.0, 3.0),
    (BODY3, 0.2, "sine", 5.3, 5.0),
], ids=["block-mode1", "block-cosine", "fig5-safe"])
def test_mu_10_is_the_no_slip_model(body, lam, shape, w, A):
    """mu = 10: outcome, impacts and max|theta| of the no-slip reference (to 1e-4). (Near
    overturning N falls to 0 and the base slips past the barrier: the outcome is
    decided.)"""
    pt = Point(body, lam, shape, w, A, mu=10.0)
    r = sliding_reference(pt)
    q = reference_run(pt, early_exit=False)
    assert r["outcome"] == q["outcome"]
    assert r["impacts"] == q["impacts"]
    assert r["theta_max"] == pytest.approx(q["theta_max"], rel=1e-4)
    if q["outcome"] == L.OUTCOME_SAFE:
        assert r["slide_max"] == 0.0 and set(r["phases"]) <= {"rest", "rock"}


@pytest.mark.parametrize("body,lam,shape,w,A,mu", [
    (BlockBody(alpha=0.2), 0.0, "sine", 6.0, 2.5, 0.22),
    (BlockBody(alpha=0.2), 0.0, "cosine", 5.0, 1.5, 0.22),
    (BODY3, 0.0, "sine", 2.0, 2.0, 0.3),
], ids=["block-sine", "block-cosine", "fig3-mode2"])
def test_energy_closes_with_friction(body, lam, shape, w, A, mu):
    """Work in = final energy + damper + impacts + friction, to 1e-4 of E_ref, in runs that
    slide-rock (the friction loss a real share of it)."""
    r = sliding_reference(Point(body, lam, shape, w, A, mu=mu))
    assert "slide-rock" in r["phases"]
    assert r["D_fric"] > 1e-3 * r["E_ref"] and r["slide_max"] > 0
    assert abs(r["closure"]) < 1e-4 * r["E_ref"]
    terms = (r["W_in"], r["D_damp"], r["D_fric"], r["E_impact"], r["E_end"])
    assert all(math.isfinite(v) for v in terms)


def test_a_run_past_its_evaluation_budget_stops_flagged(monkeypatch):
    """Every reference run ends: past MAX_EVALUATIONS right-hand-side calls it stops with
    status step_cap (a flagged status of the kernel's result row), its outcome undecided
    (safe), instead of crawling on (a body lifting off a slipping corner near the Painleve
    point ran for more than an hour). Here the budget is cut to 200 on an ordinary run
    that needs more."""
    from rocksweep.physics import sliding_reference as sr

    pt = Point(BlockBody(alpha=0.3), 0.0, "sine", 2.0, 1.5, mu=0.2)
    assert "step_cap" not in sliding_reference(pt)["status"]
    monkeypatch.setattr(sr, "MAX_EVALUATIONS", 200)
    r = sliding_reference(pt)
    assert "step_cap" in r["status"] and r["outcome"] == L.OUTCOME_SAFE
    assert int(sr.result_row(r)[L.OUT_STATUS]) & L.STATUS_FLAGGED


def test_a_stage_exactly_at_a_painleve_point_is_rejected_not_raised(monkeypatch):
    """A DOP853 stage that lands exactly on a Painleve point (den = 0: the slip's system
    singular) gives NaN accelerations, which DOP853 rejects and retries shorter, instead of
    numpy's LinAlgError ending the reference with a traceback (threshold seed 13 at mu
    1.19, ``scripts/threshold_sample.py --mu``). Here one solve of a pure sliding run is
    made singular: the run ends as without it."""
    from rocksweep.physics import sliding_reference as sr

    pt = Point(BlockBody(alpha=0.3), 0.0, "sine", 2.0, 1.5, mu=0.2)
    plain = sliding_reference(pt)
    solve, calls = np.linalg.solve, [0]

    def singular_once(a, b):
        calls[0] += 1
        if calls[0] == 60:
            raise np.linalg.LinAlgError("Singular matrix")
        return solve(a, b)

    monkeypatch.setattr(sr.np.linalg, "solve", singular_once)
    r = sliding_reference(pt)
    assert calls[0] > 60
    assert r["outcome"] == plain["outcome"] and r["status"] == plain["status"]
    assert r["slide_max"] == pytest.approx(plain["slide_max"], rel=1e-6)
