"""Hard case 5: the cosine pulse's jump at its end -- the step lands on it."""

import math

import numpy as np
import pytest
from hardkit import assert_sane, kernel_events, numerics, reference_events, run
from hardkit import table3_body as body

from rocksweep.kernel.layout import PAR_DT, PAR_DT_ON, PAR_TPULSE
from rocksweep.physics.points import Point, body_omega_rock, point_row

pytestmark = pytest.mark.hard

BODY = body()
OUTCOME = {0: "safe", 1: "mode1", 2: "mode2"}


def _after(events, t_pulse):
    return [e for e in events if e.t >= t_pulse]


def test_jump_at_the_pulse_end_lifts_the_body_at_once():
    """Guards against missing the uplift caused by a cosine pulse's end (a kernel bug, fixed)."""
    # The body stays in full contact through the pulse; at its end xg'' jumps from A to 0
    # and the uplift moment Q with it by m_A h_A A, past M g b, while Q is falling: no
    # crossing happens after the jump, so only a check at the pulse end can see the uplift.
    p = Point(BODY, 0.2, "cosine", 4.25, 1.3)
    r = run(p)
    assert_sane(r)
    t_pulse = point_row(p, r.numerics)[PAR_TPULSE]
    ev = kernel_events(r)
    assert ev[0].kind == "uplift" and ev[0].t == t_pulse  # exactly at the end, not later
    res, ref = reference_events(p)
    assert ref[0].kind == "uplift" and ref[0].t == pytest.approx(t_pulse, abs=1e-12)
    assert ev[0].s_after == ref[0].s_after
    assert r.impacts == res["impacts"] and r.outcome == OUTCOME[res["outcome"]]
    assert ev[1].t == pytest.approx(ref[1].t, abs=1e-3)


@pytest.mark.parametrize("w0, a_ratio", [(4.25, 1.3), (4.5, 1.5)])
def test_results_do_not_depend_on_where_the_step_grid_meets_the_pulse_end(w0, a_ratio):
    """Guards against results that change when a step boundary falls on or near the jump."""
    # BASE's step (the spring sets it here: 20 steps per period, x (27.5/omega_rock)^(2/5)
    # for a spring softer than Figure 4's), the same while the pulse acts and after it
    w_rock = body_omega_rock(BODY)
    dt = 2 * math.pi / (w_rock * 20 * (27.5 / w_rock) ** 0.4)
    n = round(2 * math.pi / w0 / dt)
    runs = {}
    # the pulse ends on the step grid, 1e-12 / 1e-9 after a grid point (a tiny landing
    # step), 1e-9 before one (a landing step a hair short), and half a step off
    for label, t_pulse in (("on", n * dt), ("+1e-12", n * dt + 1e-12), ("+1e-9", n * dt + 1e-9),
                           ("-1e-9", n * dt - 1e-9), ("half", (n - 0.5) * dt)):
        p = Point(BODY, 0.2, "cosine", 2 * math.pi / t_pulse, a_ratio)
        row = point_row(p, numerics())
        assert row[PAR_DT] == pytest.approx(dt, rel=1e-14)
        assert row[PAR_DT_ON] == row[PAR_DT]
        r = run(p)
        assert_sane(r)
        h = r.history
        t_end = row[PAR_TPULSE]
        # in full contact through the pulse: the step grid is k*dt up to the pulse's end
        before = h["t"][h["t"] < t_end]
        np.testing.assert_allclose(before, dt * np.arange(before.size), rtol=0, atol=1e-12)
        if label.startswith("+"):
            assert t_end - before[-1] < 2e-9  # a tiny landing step was taken
        runs[label] = (p, r)

    ref_ev = {}
    for label, (p, r) in runs.items():
        res, ref = reference_events(p)
        ref_ev[label] = ref
        assert r.outcome == OUTCOME[res["outcome"]] and r.impacts == res["impacts"]
        mine, theirs = kernel_events(r), ref
        assert [(e.kind, e.s_after) for e in mine[:4]] == [(e.kind, e.s_after) for e in theirs[:4]]
        for a, b in zip(mine[:4], theirs[:4], strict=True):
            assert a.t == pytest.approx(b.t, abs=1e-3)
    # the four near-aligned variants are one physical point (w differs by < 1e-8; the
    # chattering after the pulse magnifies that to ~5e-7 in the last impact times):
    # the kernel must give them the same history to round-off, whatever the grid does
    ev_on = kernel_events(runs["on"][1])
    for label in ("+1e-12", "+1e-9", "-1e-9"):
        ev = kernel_events(runs[label][1])
        assert [(e.kind, e.s_after) for e in ev] == [(e.kind, e.s_after) for e in ev_on]
        np.testing.assert_allclose([e.t for e in ev], [e.t for e in ev_on], atol=1e-5)


@pytest.mark.parametrize("spp", [17, 19, 20, 23])
def test_rocking_through_the_pulse_end_at_any_grid_alignment(spp):
    """Guards against the jump being smeared across a step while the body rocks."""
    p = Point(BODY, 0.2, "cosine", 3.0, 2.0)  # rocking on the +b corner when the pulse ends
    r = run(p, numerics(steps_per_period=spp))
    assert_sane(r)
    row = point_row(p, r.numerics)
    h = r.history
    k = int(np.searchsorted(h["t"], row[PAR_TPULSE]))
    assert h["t"][k] == row[PAR_TPULSE] and h["phase"][k] == 1  # a step ends on the jump
    res, ref = reference_events(p)
    assert r.outcome == OUTCOME[res["outcome"]]
    mine, theirs = _after(kernel_events(r), row[PAR_TPULSE]), _after(ref, row[PAR_TPULSE])
    for a, b in zip(mine[:3], theirs[:3], strict=True):
        assert (a.kind, a.s_after) == (b.kind, b.s_after)
        assert a.t == pytest.approx(b.t, abs=2e-3)
