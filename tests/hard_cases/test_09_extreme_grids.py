"""Hard case 9: extreme grid values -- a very long pulse, tiny and huge amplitudes."""

import math

import numpy as np
import pytest
from hardkit import BASE, assert_sane, kernel_events, reference_events, run
from hardkit import table3_body as body

from rocksweep.kernel.layout import PAR_DT, PAR_DT_ON, PAR_ROT_STEP, PAR_TPULSE
from rocksweep.physics.bodies import G
from rocksweep.physics.points import Point, point_row

pytestmark = pytest.mark.hard

FLEX = body()
WELDED = body(wn_over_p=math.inf)
BODIES = {"flexible": FLEX, "welded": WELDED}
OUTCOME = {0: "safe", 1: "mode1", 2: "mode2"}


@pytest.mark.parametrize("name, shape, a_ratio", [
    ("flexible", "sine", 0.3),  # stays in full contact through the 628-long pulse
    ("flexible", "cosine", 0.5),
    ("flexible", "sine", 0.9),  # quasi-static: the deflected spring lifts it below A = g tan
    ("welded", "sine", 1.2),
])
def test_very_long_pulse_finishes_in_bounded_work(name, shape, a_ratio):
    """Guards against a w/p = 0.01 pulse (628 p*t long) running away in steps or time."""
    p = Point(BODIES[name], 0.2, shape, 0.01, a_ratio)
    r = run(p)
    assert_sane(r)
    row = point_row(p, BASE)
    assert row[PAR_TPULSE] == pytest.approx(200 * math.pi)
    s = r.summary()
    # one regular step per dt_on of the pulse's time and per dt after it, plus one cut short
    # per event at most, plus
    # the rotation limit's (PAR_ROT_STEP) shorter steps: about one per rot of turning, the
    # fall's pi/2 counted twice
    rot = row[PAR_ROT_STEP]
    extra = 2 * (math.pi / 2) / rot if rot > 0 else 0.0
    on = min(r.t_end, row[PAR_TPULSE])
    regular = on / row[PAR_DT_ON] + (r.t_end - on) / row[PAR_DT]
    assert s["steps"] <= regular + 2 + r.impacts + r.uplifts + extra
    assert s["event_steps"] <= 100 * (r.impacts + r.uplifts + 1)
    res = reference_events(p)[0]
    assert r.outcome == OUTCOME[res["outcome"]]
    if r.t_overturn is not None:
        assert r.t_overturn == pytest.approx(res["t_overturn"], rel=1e-5)


@pytest.mark.parametrize("a_ratio", [0.0, 1e-9])
@pytest.mark.parametrize("shape", ["sine", "cosine"])
@pytest.mark.parametrize("name", list(BODIES))
def test_tiny_amplitude_is_safe_without_uplift_or_impact(name, shape, a_ratio):
    """Guards against a body that rocks, or a run that does not stop, when nothing can lift it."""
    r = run(Point(BODIES[name], 0.2, shape, 2.0, a_ratio))
    assert_sane(r)
    assert r.outcome == "safe" and r.uplifts == 0 and r.impacts == 0
    assert "rest" in r.status and r.t_end == pytest.approx(math.pi)  # stops at the pulse end
    h = r.history
    assert not h["theta"].any() and not h["phase"].any()
    # the top mass follows the pulse linearly: |u| <= A / omega_n^2 x a resonance factor
    if not BODIES[name].rigid:
        assert np.abs(h["u"]).max() <= 10 * a_ratio * G * math.tan(FLEX.alpha_cg) / FLEX.omega_n**2


@pytest.mark.parametrize("a_ratio", [1e3, 1e6])
@pytest.mark.parametrize("shape", ["sine", "cosine"])
@pytest.mark.parametrize("name", list(BODIES))
def test_huge_amplitude_overturns_at_once_without_impact(name, shape, a_ratio):
    """Guards against a huge pulse stepped over (a kernel bug, fixed: cosine 1e5 gave mode 1)."""
    p = Point(BODIES[name], 0.2, shape, 2.0, a_ratio)
    r = run(p)
    assert_sane(r)
    assert r.outcome == "mode2" and r.impacts == 0 and r.uplifts == 1
    ev = kernel_events(r)
    res, ref = reference_events(p)
    if BODIES[name].rigid:  # Q = -M h_cg xg'' = M g b where sin(w t) = 1 / A_ratio
        t_up = math.asin(1.0 / a_ratio) / 2.0 if shape == "sine" else 0.0
    else:
        t_up = ref[0].t
    assert ev[0].kind == "uplift" and ev[0].t == pytest.approx(t_up, abs=2e-8)
    # the step follows the pulse's own time scale 1/(p sqrt(A/g)) while it acts, not only
    # 2 pi/p
    dt = point_row(p, BASE)[PAR_DT_ON]
    assert dt <= 2 * math.pi / (BASE.steps_per_period * math.sqrt(abs(p.A) / G)) * (1 + 1e-12)
    assert OUTCOME[res["outcome"]] == "mode2"
    assert r.t_overturn == pytest.approx(res["t_overturn"], rel=1e-3)
    assert r.t_overturn < 0.5  # "at once": within a tenth of the pulse (pi long)
