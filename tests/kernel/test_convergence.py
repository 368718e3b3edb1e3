"""The kernel converges to the reference at RK4's order, and its event times converge as
the event tolerance shrinks."""

import math

import numpy as np
import pytest
from bodies import BODY3, BODY4

from rocksweep.compute.single import run_point
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics
from rocksweep.physics.points import Point
from rocksweep.physics.reference import reference_run

# Smooth stretches: uplift -> first impact (stiff body), uplift -> overturning (mode 2).
SMOOTH = {
    "first_impact": (Point(BODY4, 0.2, "sine", 4.0, 3.0), L.OUT_T_FIRST_IMPACT,
                     "t_first_impact"),
    "overturn": (Point(BODY3, 0.2, "sine", 2.0, 3.0), L.OUT_T_OVERTURN, "t_overturn"),
}


@pytest.mark.parametrize("name", list(SMOOTH))
def test_error_falls_sixteenfold_per_halving_of_the_step(name):
    point, index, key = SMOOTH[name]
    truth = reference_run(point)[key]
    errors = []
    for spp in (10, 20, 40, 80):
        out = run_point(point, Numerics(steps_per_period=spp, event_tol=1e-13),
                        history=False).out
        errors.append(abs(out[index] - truth))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(ratios > 1), errors  # monotone over the ladder
    assert np.all((ratios > 2**3.7) & (ratios < 2**4.3)), ratios  # order 4 (16 per halving)


def _event_times(run) -> list[float]:
    t, ph = run.history["t"], run.history["phase"]
    return [float(t[i]) for i in range(len(t) - 1) if t[i] == t[i + 1] and ph[i] != ph[i + 1]]


@pytest.mark.parametrize("root", ["bisection", "illinois", "hermite"])
def test_event_times_converge_to_the_reference_as_the_tolerance_shrinks(root):
    """At a fine step (error ~1e-9) the event times are off by at most about event_tol.

    Events are located on their far side, so the uplift (the first event, from a state
    the kernel has exactly) is late by 0..event_tol; the first impact inherits that.
    """
    point = SMOOTH["first_impact"][0]
    ref = reference_run(point, events=True)
    t_uplift, t_impact = ref["events"][0]["t"], ref["t_first_impact"]
    floor = 1e-8
    errors = []
    for tol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-8):
        run = run_point(point, Numerics(steps_per_period=160, event_tol=tol, root=root))
        times = _event_times(run)
        d_uplift = times[0] - t_uplift
        d_impact = run.out[L.OUT_T_FIRST_IMPACT] - t_impact
        assert -floor <= d_uplift <= tol + floor, (tol, d_uplift)
        assert abs(d_impact) <= 3 * tol + floor, (tol, d_impact)
        errors.append(max(abs(d_uplift), abs(d_impact)))
    assert errors[-1] < 3e-8  # at 1e-8 only the step's own error is left
    assert errors[0] > 30 * errors[-1]
    assert math.isfinite(sum(errors))
