"""The sliding kernel's functions (``kernel.sliding``) driven as a loop would drive them:
a small RK4 driver in Python (no compiled variant: each function compiles once per
signature, about 10 s for the module the first time, then loads from numba's cache)
with the stick-break and slip-stop events located by bisection on fresh steps. Against
the closed-form rigid-plastic sliding block and the energy balance of the kernel's own
rates (docs/sliding.md)."""

import math

import pytest

from rocksweep.kernel import sliding
from rocksweep.kernel.ground import any_ground_acc as ground_acc
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, G
from rocksweep.physics.friction import sliding_block
from rocksweep.physics.points import Point, point_row

Y0 = (0.0,) * 9


def _rk4(t, y, h, s, sigma, on, mu, row):
    def f(tt, yy):
        return sliding.any_sliding_derivatives(tt, yy, s, sigma, on, mu, row, False, False, True)

    def ax(yy, a, k):
        return tuple(yi + a * ki for yi, ki in zip(yy, k, strict=True))

    k1 = f(t, y)
    k2 = f(t + h / 2, ax(y, h / 2, k1))
    k3 = f(t + h / 2, ax(y, h / 2, k2))
    k4 = f(t + h, ax(y, h, k3))
    return tuple(yi + h / 6 * (a + 2 * b + 2 * c + d)
                 for yi, a, b, c, d in zip(y, k1, k2, k3, k4, strict=True))


def _locate(t, y, h, s, sigma, on, mu, row, event):
    """The first time in (t, t + h] where event(t, y) < 0, by bisection on fresh steps:
    on the event's far side (a stick break located where |H| = mu_s N exactly would find
    the contact still stuck: the static cone holds on its boundary)."""
    lo, hi = 0.0, h
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if event(t + mid, _rk4(t, y, mid, s, sigma, on, mu, row)) < 0.0:
            hi = mid
        else:
            lo = mid
    return t + hi, _rk4(t, y, hi, s, sigma, on, mu, row)


def _slide(row, mu, mu_s, t_pulse, n=800):
    """Run a rigid block from rest through the pulse until it sticks after it."""
    h_max = t_pulse / n
    t, y, s, sigma = 0.0, Y0, 0, 0
    slide_max, phases = 0.0, []

    def stick(tt, yy):
        on = tt < t_pulse
        xg = ground_acc(tt, on, row)
        return sliding.stick_margin(0.0, 0.0, 0.0, 0.0, 0, xg, G, mu_s, row, False, False)

    while t < 100 * t_pulse:  # (after the pulse the slip decelerates by mu g: it stops)
        on = t < t_pulse
        if sigma == 0 and not on:
            break
        h = min(h_max, t_pulse - t) if on else h_max  # no step straddles the pulse's end
        y1 = _rk4(t, y, h, s, sigma, on, mu, row)
        if sigma == 0 and stick(t + h, y1) < 0:  # (strictly: the cone holds on its edge)
            t, y = _locate(t, y, h, s, sigma, on, mu, row, stick)
            s, sigma, flag = sliding.choose_phase(0.0, 0.0, 0.0, 0.0, 0, ground_acc(
                t, on, row), G, mu, mu_s, row, False, False)
            assert s == 0 and flag == 0
            phases.append(sigma)
            continue
        if sigma != 0 and sigma * y1[7] < 0:
            t, y = _locate(t, y, h, s, sigma, on, mu, row,
                           lambda tt, yy, sg=sigma: sg * yy[7])
            y = (*y[:7], 0.0, y[8])
            s, sigma, flag = sliding.choose_phase(0.0, 0.0, 0.0, 0.0, 0, ground_acc(
                t, on, row), G, mu, mu_s, row, False, False)
            phases.append(sigma)
            slide_max = max(slide_max, abs(y[6]))
            continue
        t, y = t + h, y1
        slide_max = max(slide_max, abs(y[6]))
    return y, slide_max, phases


@pytest.mark.parametrize("shape,A_ratio,mu_s", [("sine", 1.5, 0.2), ("cosine", 3.0, 0.2),
                                                 ("sine", 2.5, 0.27)])
def test_kernel_functions_slide_the_rigid_plastic_block(shape, A_ratio, mu_s):
    """slide_max within 0.1% of the closed form at 800 RK4 steps a pulse; the kernel's
    rates close the energy balance W_in - D_fric = E_end (a block at rest stores none)."""
    blk = BlockBody(alpha=0.3)
    pt = Point(blk, 0.0, shape, 2.0, A_ratio, mu=0.2)
    row = point_row(pt, Numerics())
    t_pulse = 2 * math.pi / pt.omega
    y, slide_max, phases = _slide(row, 0.2, mu_s, t_pulse)
    cf = sliding_block(pt.A, pt.omega, 0.2, mu_s, shape)
    assert slide_max == pytest.approx(cf["slide_max"], rel=1e-3)
    assert abs(y[6]) == pytest.approx(cf["slide_final"], rel=1e-3, abs=1e-3 * cf["slide_max"])
    assert len([p for p in phases if p != 0]) == len(cf["segments"])
    e_end = sliding.sliding_energy(0.0, 0.0, 0.0, 0.0, y[7], 0, row, False)
    assert y[4] - y[8] - e_end == pytest.approx(0.0, abs=1e-6 * blk.E_ref)
    assert y[8] > 0


def test_slip_from_rest_accelerates_against_friction():
    """The kernel's x'' while the block slides flat is -xg'' - mu g sigma, and its
    friction F = -mu sigma M g (Newton for one mass)."""
    blk = BlockBody(alpha=0.3)
    row = point_row(Point(blk, 0.0, "sine", 2.0, 1.0, mu=0.2), Numerics())
    for xg, sigma in ((3.0, -1), (-4.0, 1)):
        _, _, x_dd, f = sliding.accelerations(0.0, 0.0, 0.0, 0.0, 0, sigma, xg, G, 0.2, row,
                                              False, False)
        assert x_dd == pytest.approx(-xg - 0.2 * G * sigma, rel=1e-14)
        assert f == pytest.approx(-0.2 * sigma * blk.M * G, rel=1e-14)
