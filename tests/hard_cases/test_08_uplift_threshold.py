"""Hard case 8: amplitudes a hair below and above the uplift threshold."""

import math

import numpy as np
import pytest
from hardkit import assert_sane, kernel_events, reference_events, run
from hardkit import table3_body as body

from rocksweep.physics.bodies import BlockBody
from rocksweep.physics.points import Point

pytestmark = pytest.mark.hard

# For a rigid body in full contact Q = -M h_cg xg'', so it lifts exactly when
# |xg''| >= g tan(alpha), i.e. A_ratio >= 1. At A_ratio = 1 + eps the threshold is only
# touched near the pulse's peaks: the uplift event function dips below zero for
# ~ sqrt(eps)/omega, far less than a step (a hidden crossing of the uplift function).
BODIES = {"welded": body(wn_over_p=math.inf), "block": BlockBody(alpha=0.2)}
EPS = [1e-3, 1e-6, 1e-9]


@pytest.mark.parametrize("eps", EPS)
@pytest.mark.parametrize("w", [0.7, 3.3])
@pytest.mark.parametrize("shape", ["sine", "cosine"])
@pytest.mark.parametrize("name", list(BODIES))
def test_a_hair_below_no_uplift_a_hair_above_uplift_without_spurious_rocking(name, shape, w,
                                                                            eps):
    """Guards against missing a barely reached uplift, inventing one, or spurious rocking."""
    b = BODIES[name]
    below = run(Point(b, 0.2, shape, w, 1.0 - eps))
    assert_sane(below)
    assert below.uplifts == 0 and below.impacts == 0 and below.outcome == "safe"
    assert not below.history["theta"].any() and not below.history["phase"].any()

    above = run(Point(b, 0.2, shape, w, 1.0 + eps))
    assert_sane(above)
    assert above.outcome == "safe"
    ups = [e for e in kernel_events(above) if e.kind == "uplift"]
    assert len(ups) >= 2  # near the pulse's positive peak and near its negative one
    # where A sin(w t) = g tan(alpha): sin(w t) = 1 / A_ratio (cosine: at t = 0)
    t_up = math.asin(1.0 / (1.0 + eps)) / w if shape == "sine" else 0.0
    assert ups[0].t == pytest.approx(t_up, abs=1e-7)
    assert ups[0].s_after == -1 and ups[1].s_after == 1
    # the body barely moves: the excess of xg'' lasts ~sqrt(eps)/w at ~eps g tan(alpha),
    # so |theta| ~ eps^2 (in alpha); anything like a real rocking motion is spurious
    assert above.theta_max_over_alpha <= eps
    assert np.abs(above.history["theta"]).max() <= eps * b.alpha_ref
    if eps == 1e-6:  # and the reference path sees the same uplifts
        res, ref = reference_events(above.point)
        assert res["uplifts"] == above.uplifts
        ref_ups = [e for e in ref if e.kind == "uplift"]
        for a, c in zip(ups, ref_ups, strict=True):
            assert (a.s_after, a.t) == (c.s_after, pytest.approx(c.t, abs=1e-6))
