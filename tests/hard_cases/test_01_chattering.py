"""Hard case 1: chattering (Zeno) -- free rocking dying out ends in full contact."""

import math

import numpy as np
import pytest
from hardkit import BASE, FINE, assert_sane, kernel_events, numerics, reference_events, run
from hardkit import table3_body as body

from rocksweep.physics.bodies import G
from rocksweep.physics.points import Point

pytestmark = pytest.mark.hard

# Table 3 body under a weak sine pulse: after the pulse the top mass re-lifts the body
# twice, and each of its three free-rocking episodes chatters down to full contact.
POINT = Point(body(), 0.2, "sine", 4.0, 1.05)


def _sequences(events):
    """Impact sequences: the impacts from an uplift to the return to full contact."""
    seqs, cur = [], []
    for e in events:
        if e.kind == "uplift":
            cur = []
            continue
        cur.append(e)
        if e.s_after == 0 or e.s_after == e.s_before:  # full contact (maybe lifted again)
            seqs.append(cur)
            cur = []
    return seqs


def _free_q_max(b, u0: float, v0: float, t_span: float) -> float:
    """Largest |Q| of the damped top mass in full contact, from (u0, u0') on, no pulse.

    Closed form of m u'' + c u' + k u = 0 (underdamped), sampled densely; Q = (h k + m g) u
    + h c u' is the moment that would lift the body (uplift at |Q| = M g b).
    """
    wn, z = b.omega_n, b.zeta
    wd = wn * math.sqrt(1 - z * z)
    t = np.linspace(0.0, t_span, 20001)
    env = np.exp(-z * wn * t)
    b_coef = (v0 + z * wn * u0) / wd
    u = env * (u0 * np.cos(wd * t) + b_coef * np.sin(wd * t))
    v = env * ((-z * wn) * (u0 * np.cos(wd * t) + b_coef * np.sin(wd * t))
               + (-u0 * wd * np.sin(wd * t) + b_coef * wd * np.cos(wd * t)))
    q = (b.h * b.k + b.m * G) * u + b.h * b.c * v
    return float(np.abs(q).max())


def test_chattering_ends_in_full_contact_after_finitely_many_impacts():
    """Guards against a Zeno sequence that never ends (hang, event cap) or ends wrongly."""
    r = run(POINT)
    assert_sane(r)
    assert r.outcome == "safe"
    # the rest-rate rule ended the sequences: the run says "settled" (a rule), never "rest"
    # (which would be a proof)
    assert "settled" in set(r.status) and "rest" not in set(r.status)
    seqs = _sequences(kernel_events(r))
    assert len(seqs) == 3  # three episodes, each chattering down to full contact
    for seq in seqs:
        assert seq[-1].s_after == 0 or seq[-1].theta_dot_after == 0.0
        assert len(seq) >= 20  # a real chattering sequence ...
        w = np.array([abs(e.theta_dot_before) for e in seq])
        t = np.array([e.t for e in seq])
        # ... whose impact rates decay geometrically (over a rocking cycle: two impacts,
        # one per corner) and whose flights shrink: Zeno accumulation
        assert (w[-10:][2:] < w[-10:][:-2]).all()
        assert w[-1] < 1e-2 * w[0]
        flights = np.diff(t)
        assert flights[-2:].sum() < 0.05 * flights[:2].sum()
        # the rest-rate rule stopped it: last rate below rest_rate * alpha_cg / e (e < 1)
        assert w[-1] < BASE.rest_rate * POINT.body.alpha_cg / 0.5

    # The rest state: full contact, theta = theta' = 0, and the damped top mass's free
    # vibration from there never lifts the body again (closed-form oscillator).
    h = r.history
    assert h["phase"][-1] == 0 and h["theta"][-1] == 0.0 and h["theta_dot"][-1] == 0.0
    b = POINT.body
    assert _free_q_max(b, h["u"][-1], h["u_dot"][-1], 20.0) < b.M * G * b.b
    e_spring = 0.5 * b.m * h["u_dot"][-1] ** 2 + 0.5 * b.k * h["u"][-1] ** 2
    assert h["E"][-1] == pytest.approx(e_spring, rel=1e-12)


def test_zeno_time_converges_as_the_rest_rate_and_the_step_shrink():
    """Guards against a settling time that depends on the Zeno cut-off or on the step."""
    base = run(POINT)
    tiny = run(POINT, numerics(rest_rate=BASE.rest_rate / 100))
    fine = run(POINT, FINE)
    res, ref = reference_events(POINT)

    def contacts(events):
        return np.array([e.t for e in events if e.kind == "impact" and e.s_after == 0])

    t_base, t_tiny, t_fine = (contacts(kernel_events(x)) for x in (base, tiny, fine))
    t_ref = contacts(ref)
    assert len(t_base) == len(t_tiny) == len(t_fine) == len(t_ref) == 3
    # 100x smaller rest rate: infinitely many impacts truncated later, same accumulation
    # time (the flights left are ~ rate / (p^2 alpha) each, a geometric series).
    np.testing.assert_allclose(t_tiny, t_base, atol=1e-3)
    # and only ~ln(100)/ln(1/e) more impacts per sequence (e ~ 0.8 here): bounded growth
    extra = tiny.impacts - base.impacts
    assert 0 < extra <= 3 * (math.log(100) / math.log(1 / 0.9) + 2)
    # converging as the step shrinks, and agreeing with the reference path
    np.testing.assert_allclose(t_base, t_ref, atol=2e-3)
    np.testing.assert_allclose(t_fine, t_ref, atol=1e-5)
    assert abs(base.impacts - res["impacts"]) <= 3
    assert fine.impacts == res["impacts"]
