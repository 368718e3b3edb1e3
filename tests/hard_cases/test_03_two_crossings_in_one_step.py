"""Hard case 3: a dip of theta through 0 and back inside one (coarse) step is registered."""

import numpy as np
import pytest
from hardkit import kernel_events, numerics, reference_events, run
from numba import njit
from test_02_grazing import WINDOW, point, touch

from rocksweep.kernel.layout import GROUND_PULSE, PAR_DT, PAR_TPULSE
from rocksweep.kernel.stepping import rk4_step
from rocksweep.physics.points import point_row

pytestmark = pytest.mark.hard

# Next to the graze of case 2 (A* ~ 1.0781) the body dips below theta = 0 for a short
# while (~ sqrt(delta)). At a coarse step the dip fits inside one step: both ends of the
# step have s*theta > 0, and only the Hermite check (and the search for the minimum of the
# integrator's own solution) can see it.
A_GRAZE = 1.0781151847
DELTAS = [-3e-3, -2e-3, -1.5e-3, -1e-3]
STEPS = [8, 10, 12]
STATE = ("theta", "theta_dot", "u", "u_dot", "W_in", "D_damp")


def _step_in_question(r, t_event):
    """The step the kernel took from the last row before t_event (rows are step ends)."""
    h = r.history
    t = h["t"]
    i = int(np.searchsorted(t, t_event)) - 1
    while t[i] == t[i + 1]:  # an action's pair of rows: the step starts after it
        i -= 1
    row = point_row(r.point, r.numerics)
    dt = min(row[PAR_DT], row[PAR_TPULSE] - t[i]) if t[i] < row[PAR_TPULSE] else row[PAR_DT]
    y0 = tuple(float(h[k][i]) for k in STATE)
    return float(t[i]), y0, float(dt), int(h["phase"][i]), row


@njit
def _fresh_steps(t0, y0, taus, s, row):
    out = np.empty(taus.size)
    for i in range(taus.size):
        out[i] = s * rk4_step(t0, y0, taus[i], s, True, row, True, True, True,
                                  GROUND_PULSE)[0]
    return out


def _own_solution(t0, y0, dt, s, row, n=400):
    """s*theta along the kernel's own RK4 solution in the step: fresh steps of length tau
    from the step's start (the continuous solution the kernel's event location uses)."""
    taus = np.linspace(0.0, dt, n + 1)
    return taus, _fresh_steps(t0, y0, taus, s, row)


def test_dip_through_zero_and_back_inside_one_step_is_registered():
    """Guards against missing an impact whose two crossings of theta = 0 fall in one step."""
    hidden = 0
    for spp in STEPS:
        num = numerics(steps_per_period=spp, horizon=0.1)
        for delta in DELTAS:
            p = point(A_GRAZE * (1 + delta))
            r = run(p, num)
            ev = touch(r)
            # the step that holds the dip: the one the event is in, or (if none was
            # registered) the one where the reference path's touch-down lies
            t_ref = ev.t if ev else first_in_ref(p)
            t0, y0, dt, s, row = _step_in_question(r, t_ref)
            assert s == 1 and t0 < t_ref < t0 + dt
            taus, st = _own_solution(t0, y0, dt, s, row)
            dips = st.min() < 0.0
            # registered if and only if the integrator's own solution crosses zero
            assert (ev is not None) == dips, (spp, delta, st.min())
            if dips and st[0] > 0.0 and st[-1] > 0.0:
                hidden += 1  # both ends above zero: the two crossings are inside the step
                # the event lies inside the dip of the own solution
                inside = taus[st < 0.0]
                assert inside.min() - dt / 400 <= ev.t - t0 <= inside.max() + dt / 400
    assert hidden >= 3  # the configurations really put both crossings inside one step


def first_in_ref(p):
    _, ref = reference_events(p)
    return next(e.t for e in ref if e.kind == "impact" and WINDOW[0] <= e.t < WINDOW[1])


def test_hidden_dip_at_a_coarse_step_matches_the_reference():
    """Guards against a hidden crossing located at the wrong time or with the wrong outcome."""
    p = point(A_GRAZE * (1 - 3e-3))
    r = run(p, numerics(steps_per_period=10))
    res, ref = reference_events(p)
    mine = touch(r)
    theirs = next(e for e in ref if e.kind == "impact" and WINDOW[0] <= e.t < WINDOW[1])
    assert mine is not None
    assert mine.t == pytest.approx(theirs.t, abs=2e-3)
    assert len([e for e in kernel_events(r) if e.t < WINDOW[1]]) == len(
        [e for e in ref if e.t < WINDOW[1]])
