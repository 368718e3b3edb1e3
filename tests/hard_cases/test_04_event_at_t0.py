"""Hard case 4: a cosine pulse above the uplift threshold lifts the body at t = 0."""

import math

import pytest
from hardkit import assert_sane, kernel_events, reference_events, run
from hardkit import table3_body as body

from rocksweep.physics.points import Point

pytestmark = pytest.mark.hard

FLEX = body()
RIGID = body(wn_over_p=math.inf)
# In full contact at t = 0 (u = u' = 0) the uplift moment is Q = -m_A h_A xg'': the flexible
# body lifts at once when m_A h_A A >= M g b, i.e. A_ratio >= M b / (m_A h_A tan alpha_cg).
A0_FLEX = FLEX.M * FLEX.b / (FLEX.m_A * FLEX.h_A * math.tan(FLEX.alpha_cg))

CASES = {
    "rigid, +A": (RIGID, 2.0, 1.5, -1),  # xg'' > 0 tips the body onto the -b corner
    "rigid, -A": (RIGID, 2.0, -1.5, 1),
    "rigid, a hair above": (RIGID, 2.0, 1.0 + 1e-9, -1),  # lifts, and lands 5e-5 later
    "flexible, above": (FLEX, 6.0, 1.01 * A0_FLEX, -1),
    "flexible, just below": (FLEX, 2.0, 0.99 * A0_FLEX, 0),  # lifts a moment later
}


@pytest.mark.parametrize("name", list(CASES))
def test_uplift_at_t0_fires_once_and_agrees_with_the_reference(name):
    """Guards against a missed uplift at t = 0, or one that fires twice."""
    b, w, a_ratio, corner = CASES[name]
    p = Point(b, 0.2, "cosine", w, a_ratio)
    r = run(p)
    assert_sane(r)
    ev = kernel_events(r)
    at_0 = [e for e in ev if e.t == 0.0]
    if corner:
        assert len(at_0) == 1 and at_0[0].kind == "uplift" and at_0[0].s_after == corner
        h = r.history
        # the first step rocks it outwards (or lands it again, after a hair above)
        assert corner * h["theta"][1] > 0.0 or h["t"][1] == ev[1].t
        assert ev[1].t > 0.0 and ev[1].kind == "impact"  # nothing else fires at t = 0
    else:
        assert not at_0 and ev[0].kind == "uplift" and 0.0 < ev[0].t < 0.05
    res, ref = reference_events(p)
    assert r.outcome == {0: "safe", 1: "mode1", 2: "mode2"}[res["outcome"]]
    n = min(len(ref), 4)
    assert len(ev) >= n
    for mine, theirs in zip(ev[:n], ref[:n], strict=True):
        assert (mine.kind, mine.s_before, mine.s_after) == (
            theirs.kind, theirs.s_before, theirs.s_after)
        assert mine.t == pytest.approx(theirs.t, abs=1e-4)
