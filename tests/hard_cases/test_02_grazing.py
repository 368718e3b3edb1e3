"""Hard case 2: grazing -- theta returns to 0 with theta' ~ 0 and leaves again."""

from dataclasses import replace

import pytest
from hardkit import (
    BASE,
    FINE,
    assert_sane,
    first_in,
    kernel_events,
    numerics,
    reference_events,
    run,
)
from hardkit import table3_body as body

from rocksweep.physics.points import Point

pytestmark = pytest.mark.hard

# The Figure 4 body (wn/p = 9.82) under a short sine pulse (w/p = 8, pulse end 0.785):
# the body uplifts, chatters, and its top mass then swings it back towards theta = 0 at
# t ~ 0.6 while the pulse still pushes it out. Depending on A the body touches down there
# (an impact) or turns back just above theta = 0; in between lies a grazing amplitude.
BODY = body(wn_over_p=9.82)
LAM, SHAPE, W = 0.2, "sine", 8.0
WINDOW = (0.59, 0.66)  # where the touch-down happens (p*t)
BRACKET = (1.06, 1.09)  # amplitudes with / without the touch-down


# the bisection's step: FINE's, without the certification's finer reruns (a run this near a
# graze is re-run finer, ``certify.graze_close``: its finest rerun's graze is its own)
GRAZE_NUM = numerics(steps_per_period=160, event_tol=1e-12)


def point(a_ratio: float) -> Point:
    return Point(BODY, LAM, SHAPE, W, a_ratio)


def touch(r):
    """The impact inside the window, or None."""
    return first_in(kernel_events(r), "impact", *WINDOW)


@pytest.fixture(scope="module")
def grazing_amplitude() -> float:
    """A_ratio of the graze, by bisection on runs at a fine step (touch-down or not)."""
    num = replace(GRAZE_NUM, horizon=0.1)
    lo, hi = BRACKET
    assert touch(run(point(lo), num)) is not None and touch(run(point(hi), num)) is None
    for _ in range(44):
        mid = 0.5 * (lo + hi)
        if touch(run(point(mid), num)) is not None:
            lo = mid
        else:
            hi = mid
    return hi


def test_grazing_is_a_graze(grazing_amplitude):
    """Guards against constructing something that is not a graze (a touch with theta' not ~0)."""
    a = grazing_amplitude
    below = touch(run(point(a * (1 - 1e-12)), GRAZE_NUM))
    assert below is not None and abs(below.theta_dot_before) < 1e-4  # touches at rest
    above = run(point(a * (1 + 1e-12)), GRAZE_NUM)
    assert touch(above) is None
    h = above.history
    m = (h["t"] > WINDOW[0]) & (h["t"] < WINDOW[1])
    s_theta = h["phase"][m] * h["theta"][m]
    assert (s_theta > 0).all() and s_theta.min() < 1e-6 * BODY.alpha_cg  # ... and leaves


@pytest.mark.parametrize("delta", [-1e-2, -1e-3, 1e-3, 1e-2])
def test_impact_or_not_next_to_the_graze_agrees_with_the_reference(grazing_amplitude, delta):
    """Guards against a touch-down near a graze being missed, or invented, at the default step."""
    p = point(grazing_amplitude * (1 + delta))
    r = run(p, BASE)
    assert_sane(r)
    res, ref = reference_events(p)
    mine, theirs = touch(r), first_in(ref, "impact", *WINDOW)
    assert (mine is None) == (theirs is None) == (delta > 0)
    if theirs is not None:
        assert mine.t == pytest.approx(theirs.t, abs=1e-3)
        assert mine.theta_dot_before == pytest.approx(theirs.theta_dot_before, rel=0.1)
    assert r.outcome == {0: "safe", 1: "mode1", 2: "mode2"}[res["outcome"]]


@pytest.mark.parametrize("delta", [-1e-4, 1e-4])
def test_closer_to_the_graze_a_finer_step_agrees(grazing_amplitude, delta):
    """Guards against non-convergence near the graze: a finer step resolves a shallower dip."""
    p = point(grazing_amplitude * (1 + delta))
    _, ref = reference_events(p)
    theirs = first_in(ref, "impact", *WINDOW)
    mine = touch(run(p, FINE))
    assert (mine is None) == (theirs is None) == (delta > 0)
    if theirs is not None:
        assert mine.t == pytest.approx(theirs.t, abs=1e-5)
        assert mine.theta_dot_before == pytest.approx(theirs.theta_dot_before, rel=1e-2)
    # this close, the touch-down is slow (the dip below zero, theta'^2 / 2 theta'', ~1e-7)
    assert delta > 0 or abs(theirs.theta_dot_before) < 1e-3
