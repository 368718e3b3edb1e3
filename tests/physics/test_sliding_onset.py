"""The phase a body at rest enters under a ground acceleration: the closed forms
(``physics.friction.onset``; Shenton 1996 for the rigid block, with mu_s >= mu) against
the kernel (``kernel.sliding.choose_phase``, which solves each candidate phase with the
equations of motion and keeps the first consistent one) and the reference
(``physics.sliding_reference.choose``: its own equations), on grids of (mu, A, alpha)."""

import math

import numpy as np
import pytest
from bodies import BODY2, BODY3, BODY4

from rocksweep.kernel import sliding
from rocksweep.numerics import Numerics
from rocksweep.physics import friction
from rocksweep.physics import sliding_reference as ref
from rocksweep.physics.bodies import BlockBody, G
from rocksweep.physics.points import Point, point_row
from rocksweep.vocab.phases import PHASES

MUS = np.linspace(0.05, 1.2, 24)
A_OVER_G = np.linspace(-1.6, 1.6, 33)


def _kernel_word(body, row, A, mu, mu_s, u=0.0, u_dot=0.0):
    s, sigma, flag = sliding.choose_phase(0.0, 0.0, u, u_dot, 0, A, G, mu, mu_s, row,
                                          not body.rigid, not body.rigid and body.zeta > 0)
    if flag & sliding.JAM:
        return friction.JAM, 0, 0
    return PHASES[sliding.phase_code(s, sigma)], s, sigma


def _row(body):
    return point_row(Point(body, 0.0, "sine", 2.0, 1.0), Numerics())


@pytest.mark.parametrize("alpha", [0.1, 0.2, 0.35])
@pytest.mark.parametrize("static", [1.0, 1.5])
def test_rigid_block_onset_equals_the_closed_form(alpha, static):
    """Every (mu, A) of the grid: the kernel enters the closed form's phase, on the closed
    form's corner and slip direction; the grid meets all four phases."""
    blk = BlockBody(alpha=alpha)
    row = _row(blk)
    seen = set()
    for mu in MUS:
        for a in A_OVER_G:
            want = friction.onset(blk, a * G, mu, static * mu)
            assert _kernel_word(blk, row, a * G, mu, static * mu) == want, (mu, a)
            seen.add(want[0])
    assert seen == set(PHASES)


def test_shenton_regions_of_the_block():
    """mu_s = mu: rest below min(mu, tan alpha) g; mu < tan alpha slides above mu g and
    never rocks; mu > tan alpha rocks from tan alpha g to A_r(mu) and slide-rocks above."""
    blk = BlockBody(alpha=0.2)
    t = math.tan(0.2)
    for mu in (0.1, 0.5):
        a_r, _ = friction.rock_threshold(blk, mu)
        for a in np.linspace(0.01, 2.0, 200) * G:
            word = friction.onset(blk, a, mu)[0]
            if a <= min(mu, t) * G:
                assert word == "rest"
            elif mu < t:
                assert word == "slide"
            else:
                assert word == ("rock" if a <= a_r else "slide-rock")
        if mu > t:
            assert t * G < a_r  # a rocking region exists


@pytest.mark.parametrize("body", [BODY3, BODY2, BODY4], ids=["fig3", "fig2", "fig4"])
def test_flexible_onset_equals_the_closed_form(body):
    """The flexible body at rest in full contact with its top mass displaced (the spring
    pushes the base with k u + c u'): kernel and closed form agree on a grid of mu and A
    at random (u, u') (A up to 30 g tan(alpha_cg): the flexible body slide-rocks from
    rest only under a large step, the base alone carrying it at first)."""
    row = _row(body)
    rng = np.random.default_rng(2)
    seen = set()
    for _ in range(6):
        u, ud = rng.uniform(-0.8, 0.8) * body.u_cr, rng.uniform(-0.5, 0.5) * body.u_cr
        for mu in MUS[::2]:
            for a in np.linspace(-30, 30, 41) * math.tan(body.alpha_cg):
                want = friction.onset(body, a * G, mu, 1.2 * mu, u, ud)
                got = _kernel_word(body, row, a * G, mu, 1.2 * mu, u, ud)
                assert got == want, (u, ud, mu, a)
                seen.add(want[0])
    assert seen == set(PHASES)


@pytest.mark.parametrize("body", [BlockBody(alpha=0.2), BODY3], ids=["block", "fig3"])
def test_reference_enters_the_same_phase(body):
    """The reference's own choice (its equations, its candidates) on a coarser grid."""
    row = _row(body)
    flex = not body.rigid
    rb = ref._Body(row, flex, flex and body.zeta > 0)
    y = np.zeros(9)
    for mu in MUS[::4]:
        for a in A_OVER_G[::4] * (1 if body.rigid else 4 * math.tan(body.alpha_cg)):
            s, sigma, jam = ref.choose(rb, 0.0, y, 0, a * G, G, mu, mu)
            word = friction.JAM if jam else PHASES[(2 if s else 0) + (1 if sigma else 0)]
            assert (word, s, sigma) == friction.onset(body, a * G, mu), (mu, a)


@pytest.mark.parametrize("alpha", [0.15, 0.3])
def test_mu_exactly_tan_alpha_slides(alpha):
    """mu = tan(alpha) exactly: a sliding rigid body's uplift moment is M g b for good
    (the normal force at its leading corner, theta'' = 0): it slides, in the closed form
    and in the kernel (float64's ulp at the equality allowed for)."""
    blk = BlockBody(alpha=alpha)
    row = _row(blk)
    mu = math.tan(alpha)
    for a in (1.2, 2.0, -1.5):
        want = friction.onset(blk, a * mu * G, mu)
        assert want == ("slide", 0, -1 if a > 0 else 1)
        assert _kernel_word(blk, row, a * mu * G, mu, mu) == want


def test_a_rocking_body_the_ground_would_have_to_pull_is_held():
    """N <= 0 while rocking (spun fast enough): no friction can act; the corner is held as
    the no-slip model holds it, flagged LIFT_OFF (outside the model, as lifts_off)."""
    blk = BlockBody(alpha=0.2)
    row = _row(blk)
    s, sigma, flag = sliding.choose_phase(0.1, 4.0, 0.0, 0.0, 1, 0.0, G, 0.3, 0.3, row,
                                          False, False)
    from rocksweep.kernel import contact

    assert contact.ground_reactions(0.1, 4.0, 0.0, 0.0, 1, 0.0, G, row, False, False)[1] < 0
    assert (s, sigma, flag) == (1, 0, sliding.LIFT_OFF)
