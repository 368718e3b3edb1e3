"""Hard case 10: degenerate bodies -- zeta = 0, tiny and large m_A/m, very slender, h -> 0."""

import math

import numpy as np
import pytest
from bodies import FIG3
from hardkit import assert_sane, numerics, reference_events, run
from hardkit import table3_body as body

from rocksweep.kernel.layout import KIND_FLEXIBLE_UNDAMPED
from rocksweep.physics.bodies import G
from rocksweep.physics.points import Point, kernel_kind

pytestmark = pytest.mark.hard

OUTCOME = {0: "safe", 1: "mode1", 2: "mode2"}
# The top mass sits above the base while h > 0, i.e. tan(alpha_cg) < (1 + mu)/mu tan(alpha_A)
# (mu = m_A/m): for Table 3 (mu = 0.47, alpha_A = 0.28) alpha_cg < 0.7325. 0.999 of that
# puts the top mass at h = 0.0024 b: u_cr ~ 1/h is huge, the lever arm tiny.
ALPHA_MAX = math.atan((1 + FIG3["mA_over_m"]) / FIG3["mA_over_m"] * math.tan(FIG3["alpha_A"]))
CASES = {
    "zeta = 0": (dict(zeta=0.0), [("sine", 5.3, 5.0), ("cosine", 2.0, 1.5)]),
    "m_A/m = 1e-4": (dict(mA_over_m=1e-4), [("cosine", 4.0, 2.0), ("sine", 5.3, 5.0)]),
    "m_A/m = 100": (dict(mA_over_m=100.0), [("cosine", 4.0, 2.0), ("sine", 5.3, 5.0)]),
    "alpha_cg = 0.01": (dict(alpha_cg=0.01, alpha_A=0.02), [("sine", 5.3, 5.0),
                                                           ("cosine", 2.0, 1.5)]),
    "alpha_cg -> upper bound": (dict(alpha_cg=0.999 * ALPHA_MAX), [("cosine", 4.0, 2.0),
                                                                   ("sine", 4.0, 1.05)]),
}


@pytest.mark.parametrize("k", [0, 1])
@pytest.mark.parametrize("name", list(CASES))
def test_degenerate_body_runs_cleanly_and_agrees_with_the_reference(name, k):
    """Guards against tiny masses or lever arms, or the undamped variant, breaking a run."""
    changes, pulses = CASES[name]
    p = Point(body(**changes), 0.2, *pulses[k])
    r = run(p)
    assert_sane(r)
    if name == "zeta = 0":
        assert kernel_kind(p.body) == KIND_FLEXIBLE_UNDAMPED
        assert not r.history["D_damp"].any()  # no damper anywhere in the undamped variant
    res = reference_events(p)[0]
    assert r.outcome == OUTCOME[res["outcome"]] and r.uplifts == res["uplifts"]
    assert abs(r.impacts - res["impacts"]) <= 0.05 * res["impacts"] + 3
    if r.t_overturn is None:
        assert r.theta_max_over_alpha * p.body.alpha_cg == pytest.approx(res["theta_max"],
                                                                         rel=1e-3)
    else:
        assert r.t_overturn == pytest.approx(res["t_overturn"], rel=1e-3)


def test_undamped_top_mass_keeps_the_body_at_the_edge_of_uplift_without_hanging():
    """Guards against a hang when zeta = 0 leaves the spring ringing at the uplift threshold."""
    # With no damper the top mass loses energy only through the impacts its own uplifts
    # cause, and ever less of it as its swing nears the threshold: the energy tends to the
    # threshold from above, so rest can never be proven. The run must stop at the horizon,
    # flagged 'horizon' (the honest answer), in bounded work, with the body barely moving.
    b = body(zeta=0.0)
    p = Point(b, 0.2, "cosine", 4.0, 2.0)
    r = run(p, numerics(horizon=30.0))
    assert_sane(r, allow=("horizon",))
    assert r.outcome == "safe" and "horizon" in r.status
    h = r.history
    assert not h["D_damp"].any()
    # after the pulse the energy only drops, at impacts (none gains energy here)
    after = h["t"] >= p.t_pulse
    assert (np.diff(h["E_impact"][after]) >= -1e-15 * b.E_ref).all()
    # the oscillator's energy 1/2 m u'^2 + 1/2 k u^2 stays just above the threshold energy
    # at which its largest uplift moment (h k + m g) sqrt(2 E / k) equals M g b
    e_thr = (b.M * G * b.b) ** 2 * b.k / (2 * (b.h * b.k + b.m * G) ** 2)
    last = h["phase"] == 0
    e_osc = 0.5 * b.m * h["u_dot"][last][-1] ** 2 + 0.5 * b.k * h["u"][last][-1] ** 2
    assert e_thr <= e_osc < 1.05 * e_thr
    late = h["t"] > p.t_pulse + 20.0
    # a hair of rocking only: a hundredth of the rocking the pulse caused
    assert np.abs(h["theta"][late]).max() < 0.01 * np.abs(h["theta"]).max()
