"""The sliding base's loop (``kernel.slide_loop``, the contact model CONTACT_SLIDE) against
independent answers: the no-slip model where friction is ample, the closed-form
rigid-plastic block (``physics.friction.sliding_block``), the closed-form onset criteria
(``physics.friction.onset``), the reference integrator (``physics.sliding_reference``:
scipy's DOP853 phase by phase, its own equations, events and impacts) and the energy
balance. (Its hard cases: tests/hard_cases/test_13_sliding.py.)

Cost: the history variants of the rigid and the flexible kind on the paper's pulses (two
variants of the slide loop, compiled cold once per kernel source: measured in
docs/sliding.md, "Cost"), and the reference's runs (~1 s each); every case is a few
points.
"""

import math
from dataclasses import replace
from pathlib import Path

import pytest

from rocksweep.compute.single import run_point
from rocksweep.kernel import layout as L
from rocksweep.numerics import Numerics
from rocksweep.physics import friction
from rocksweep.physics.bodies import BlockBody, FlexibleBody
from rocksweep.physics.ground_motion import Harmonic, pulse
from rocksweep.physics.points import Point
from rocksweep.physics.sliding_reference import sliding_reference
from rocksweep.scene.parse import load_scene
from rocksweep.vocab.outcomes import OUTCOME_CODE, SLID
from rocksweep.vocab.phases import PHASE_CODE, ROCK, SLIDE, SLIDE_ROCK

CONFIGS = Path(__file__).resolve().parents[2] / "configs"

FINE = Numerics.preset("fine")
DEFAULT = Numerics.preset("default")
DRAFT = Numerics.preset("draft")


def _closure(s: dict) -> float:
    """W_in - D_damp - E_impact - D_fric - E_end, over E_ref (the summary's energies)."""
    return (s["work_in_over_Eref"] - s["damper_loss_over_Eref"] - s["impact_loss_over_Eref"]
            - s["friction_loss_over_Eref"] - s["energy_end_over_Eref"])


def _fig5(*sets: str) -> Point:
    sc = load_scene(CONFIGS / "fig5.yaml", ["impact.lam=0.4", *sets])
    return sc.single_point()


def _uncertified_and_reference(pt: Point) -> tuple[dict, dict]:
    """(the uncertified `default` run's summary, the sliding reference's result) of a
    threshold sample's point, the reference decided (no cap, no lift-off)."""
    ref = sliding_reference(pt)
    assert not ref["status"]
    return run_point(pt, replace(DEFAULT, refine=0)).summary(), ref


@pytest.mark.parametrize("body", ["flexible", "block"])
def test_ample_friction_is_the_no_slip_model(body):
    """mu = 10 on a point whose base never needs it: the no-slip model's outcome, impacts
    and max|theta| (to 1e-4), and the base never slips (regime: rest and rock)."""
    if body == "flexible":
        pt = _fig5("pulse.A_ratio=3.0")
    else:  # free rocking from a tilt: the no-slip run goes on to rest too (PAR_TO_REST)
        pt = load_scene(CONFIGS / "free-rocking.yaml").single_point()
    a, b = run_point(pt, FINE), run_point(replace(pt, mu=10.0), FINE)
    assert b.outcome == a.outcome
    assert b.impacts == a.impacts > 0
    assert b.theta_max_over_alpha == pytest.approx(a.theta_max_over_alpha, rel=1e-4)
    s = b.summary()
    assert SLID not in s["status"] and s["slide_max"] == 0.0
    assert s["regime"] & ((1 << PHASE_CODE[SLIDE]) | (1 << PHASE_CODE[SLIDE_ROCK])) == 0
    assert s["regime"] & (1 << PHASE_CODE[ROCK])


@pytest.mark.parametrize("shape,A_ratio,mu_s", [("sine", 1.5, 0.2), ("cosine", 3.0, 0.2),
                                                 ("sine", 2.5, 0.27)])
def test_pure_sliding_is_the_rigid_plastic_block(shape, A_ratio, mu_s):
    """mu = 0.2 < tan(alpha) = 0.309: slide_max and slide_final equal the closed-form
    rigid-plastic block's to 0.1%, and the block never rocks (regime: rest and slide, no
    uplift). At `draft` too: where the sine's first step holds both the stick break
    (|xg''| = mu g) and the later uplift threshold (g tan alpha), the slip starts at the
    stick break (it started at the uplift's time, 1.5% short, the stick break's bracket
    skipped because it reached past the uplift's)."""
    blk = BlockBody(alpha=0.3)
    pt = Point(blk, 0.0, shape, 2.0, A_ratio, mu=0.2, mu_static=mu_s)
    cf = friction.sliding_block(pt.A, pt.omega, 0.2, mu_s, shape)
    for numerics in (DRAFT, DEFAULT):
        s = run_point(pt, numerics).summary()
        assert s["slide_max"] * blk.b == pytest.approx(cf["slide_max"], rel=1e-3)
        assert s["slide_final"] * blk.b == pytest.approx(cf["slide_final"], rel=1e-3,
                                                         abs=1e-3 * cf["slide_max"])
    assert s["uplifts"] == 0 and s["theta_max_over_alpha"] == 0.0
    assert s["regime"] & ((1 << PHASE_CODE[ROCK]) | (1 << PHASE_CODE[SLIDE_ROCK])) == 0
    assert SLID in s["status"] and "rest" in s["status"]


@pytest.mark.parametrize("mu,A_over_g", [(0.2, 0.1), (0.2, 0.5), (0.8, 0.45), (0.8, 1.5),
                                         (0.5, 1.2), (0.9, 0.9)])
def test_onset_phase_equals_the_closed_form(mu, A_over_g):
    """A cosine pulse is a step of A at t = 0: the first phase the run enters is the
    closed form's (Shenton's criteria for the rigid block, mu_s = mu), all four met."""
    blk = BlockBody(alpha=0.35)
    A_ratio = A_over_g / math.tan(0.35)
    pt = Point(blk, 0.0, "cosine", 1.0, A_ratio, mu=mu)
    word = friction.onset(blk, pt.A, mu)[0]
    assert run_point(pt, DEFAULT).phases()[0] == word


# Rigid blocks across the regimes: (mu, alpha, shape, w_over_p, A_ratio) slide, slide-rock
# then overturn, rock from a cosine's step, slide-rock without impact, a long chattering
# slide-rock, a slender block overturning after an impact
BLOCKS = [(0.1, 0.3, "sine", 2.0, 1.5), (0.5, 0.2, "sine", 3.0, 3.0),
          (0.9, 0.2, "cosine", 3.0, 2.0), (0.3, 0.25, "sine", 2.0, 4.0),
          (0.6, 0.35, "cosine", 4.0, 5.0), (0.4, 0.1, "sine", 6.0, 8.0)]


@pytest.mark.parametrize("mu,alpha,shape,w,A", BLOCKS)
def test_rigid_blocks_equal_the_reference(mu, alpha, shape, w, A):
    """At the default preset: the reference's outcome and impacts, its phases (in order),
    slide_max and slide_final within 2%."""
    pt = Point(BlockBody(alpha=alpha), 0.0, shape, w, A, mu=mu)
    r = run_point(pt, DEFAULT)
    ref = sliding_reference(pt, numerics=DEFAULT)
    s, b = r.summary(), pt.body.b
    assert OUTCOME_CODE[s["outcome"]] == ref["outcome"]
    assert s["impacts"] == ref["impacts"]
    assert s["phases"][:6] == ref["phases"][:6]
    assert s["slide_max"] * b == pytest.approx(ref["slide_max"], rel=0.02)
    assert s["slide_final"] * b == pytest.approx(ref["slide_final"], rel=0.02,
                                                 abs=0.02 * ref["slide_max"])


def test_a_slip_that_turns_in_its_first_step_stops():
    """Far outside the paper's region (w/p 12, A_ratio 12): the base starts to slip in
    slide-rock from x' = 0 and turns back inside the first step. The slip stop must fire
    there; it did not, and friction pushed the base on (11 b, mode 2 at `default`, where
    the reference and `fine` rock it to rest with 5e-5 m of slip)."""
    pt = Point(BlockBody(alpha=0.15), 0.0, "sine", 12.0, 12.0, mu=0.5)
    s, ref = run_point(pt, DEFAULT).summary(), sliding_reference(pt, numerics=DEFAULT)
    assert OUTCOME_CODE[s["outcome"]] == ref["outcome"] == 0
    assert s["slide_max"] * pt.body.b == pytest.approx(ref["slide_max"], rel=0.02)


def test_a_stick_break_located_tightly_slips():
    """Housner's block (alpha 0.2618, mu 0.4) rocking on a stuck corner under a sine: its
    friction demand |H|/N crosses mu at p t = 0.168 and goes on to 0.42. Located to
    1e-12, the far side of the stick break holds |H| - mu N ~ 1e-16 N, where the slip's
    x'' is round-off: the kernel and the reference tested its sign, found no direction
    consistent and stuck the corner (the reference called it a Painleve jam, impossible
    for a uniform block below mu = 4/3) with |H| > mu N to the end (no slip, max|theta|
    1.2% off). Both now slide-rock, alike, with no jam. (Found by `rocksweep accuracy`.)"""
    pt = Point(BlockBody(alpha=0.2618), 0.0, "sine", 6.0, 3.8, mu=0.4)
    tight = replace(FINE, event_tol=1e-12)
    s, ref = run_point(pt, tight).summary(), sliding_reference(pt, numerics=tight)
    assert "jam" not in ref["status"]
    assert s["phases"] == ref["phases"] == ["rest", "rock", "slide-rock", "rock", "rest"]
    assert s["slide_max"] * pt.body.b == pytest.approx(ref["slide_max"], rel=1e-4)
    assert s["theta_max_over_alpha"] * pt.body.alpha_ref == pytest.approx(ref["theta_max"],
                                                                          rel=1e-6)


@pytest.mark.parametrize("mu", [0.5, 0.2])
def test_energy_closes_with_friction(mu):
    """Figure 5's point at `fine`: work in = final energy + damper + impacts + friction to
    1e-4 E_ref, with friction and slide-rock impacts (at mu 0.2 the base slides, tips,
    slips through impacts)."""
    s = run_point(_fig5(f"body.mu={mu}"), FINE).summary()
    assert s["friction_loss_over_Eref"] > 0.0
    assert abs(_closure(s)) < 1e-4
    assert {SLIDE_ROCK} <= set(s["phases"])


@pytest.mark.parametrize("c", [0.4, -0.3])
def test_a_constant_vertical_slides_the_block_as_gravity_times_one_plus_c(c):
    """Under a_v = c g (a vertical harmonic at frequency 0, phase 90 deg) the friction
    bound is mu g (1 + c): the block that never rocks (mu 0.2 < tan alpha) slides as the
    closed-form rigid-plastic block with mu and mu_s times 1 + c, to 0.1% at `default`.
    The one test of the sliding loop's vertical variant (one compile, ~10-18 s)."""
    blk = BlockBody(alpha=0.3)
    exc = pulse("sine", harmonic=Harmonic(c, 0.0, 90.0))
    pt = Point(blk, 0.0, exc, 2.0, 1.5, mu=0.2)
    cf = friction.sliding_block(pt.A, pt.omega, 0.2 * (1 + c), 0.2 * (1 + c), "sine")
    s = run_point(pt, DEFAULT).summary()
    assert s["slide_max"] * blk.b == pytest.approx(cf["slide_max"], rel=1e-3)
    assert s["uplifts"] == 0 and SLID in s["status"]
    # and not the block under g alone: the vertical is felt
    assert cf["slide_max"] != pytest.approx(
        friction.sliding_block(pt.A, pt.omega, 0.2, 0.2, "sine")["slide_max"], rel=0.05)


def test_an_impact_before_a_slip_stop_in_the_same_step_is_taken_first():
    """A lightly lifted flexible body at mu 0.73 chatters to rest after 33 impacts. After
    one impact (theta = 0) it rises on a slipping corner, falls back through theta = 0 and
    rises again within a `default` step, so the impact slot does not fire at the step's
    end, while the slip stops after the fall. Taken alone, the slip stop left the body
    rocking on the wrong side of its corner, through the ground: 3.5 b of slip, |theta|
    to 18 alpha, the horizon. The impact comes first; the run ends as the reference's."""
    body = FlexibleBody(wn_over_p=7.569540961646859, zeta=0.13976984193496939,
                        alpha_cg=0.2242938746337304, alpha_A=0.49636278738555506,
                        mA_over_m=0.484567597803758, IA_ratio=0.33132218797415197)
    pt = Point(body, 0.33662511892692226, "sine", 11.390641968431677, 9.47971905400548,
               mu=0.7290385729203283)
    ref = sliding_reference(pt)
    s = run_point(pt, DEFAULT).summary()
    assert OUTCOME_CODE[s["outcome"]] == ref["outcome"]
    assert "horizon" not in s["status"] and s["impacts"] == ref["impacts"]
    assert s["theta_max_over_alpha"] * body.alpha_cg == pytest.approx(ref["theta_max"],
                                                                    rel=1e-3)
    assert s["slide_max"] * body.b < 1e-4  # the reference's slip: 1.9e-5 m


def test_a_slide_rock_step_past_a_painleve_point_is_taken_again_shorter():
    """Threshold seed 5 at mu 0.62 (``scripts/threshold_sample.py --mu 0.15 1.5``): during
    the pulse the body slide-rocks near a Painleve point (den -> 0, the slip's
    accelerations ~ 1/den). One `default` step took den from 0.0135 to 0.0050 and N from
    0.85 to -710 M g: the corner was held (`lifts_off`) and the body fell in mode 2 at 1.5
    p t, at 5 and 10 steps a period alike. Retaken shorter where N jumps (``slide_loop.
    _shorter``), the uncertified run at `default` rocks on as the reference does and falls
    in mode 1 after one impact at 11.4 p t."""
    body = FlexibleBody(wn_over_p=7.2810467651018245, zeta=0.0755017452978083,
                        alpha_cg=0.2934390141263994, alpha_A=0.1591144161454679,
                        mA_over_m=0.5188305568649272, IA_ratio=0.304432527370192)
    pt = Point(body, 0.2913956357360759, "sine", 3.1138079302773445, 3.73904849352834,
               mu=0.6183334894742714)
    s, ref = _uncertified_and_reference(pt)
    assert OUTCOME_CODE[s["outcome"]] == ref["outcome"] == OUTCOME_CODE["mode1"]
    assert s["impacts"] == ref["impacts"] and "lifts_off" not in s["status"]
    # on the same approach (the fall near the saddle: the coarse step's least accurate
    # output, 0.13 p t off at `default`, 0.002 at 10 steps a period), not at 1.5 p t
    assert s["t_overturn"] == pytest.approx(ref["t_overturn"], abs=0.2)


@pytest.mark.parametrize("A_ratio,expected", [(10.881503463809514, "mode2"),
                                              (10.676504153845608, "safe")])
def test_a_block_slipping_near_its_tipping_point_takes_half_steps(A_ratio, expected):
    """Threshold seed 9 at mu 0.26 ~ tan alpha (0.25): under a slow cosine of 2.7 g the
    block slide-rocks for 2.4 p t near its tipping point, where a step's error grows like
    e^(p t). At 5 steps a period it took the other class on both sides of its threshold
    (safe with margin 0.78 alpha_ref where the reference falls in mode 2; mode 1 where the
    reference rocks to rest after 184 impacts). While the base slips the step is at most
    half the step then in effect (``slide_loop.SLIP_STEP``): the uncertified run at
    `default` takes the reference's class, with its impacts."""
    pt = Point(BlockBody(alpha=0.24848521746135252, inertia=4.0 / 3.0), 0.48693205265718686,
               "cosine", 1.3883556364126837, A_ratio, mu=0.26438999715309713)
    s, ref = _uncertified_and_reference(pt)
    assert ref["outcome"] == OUTCOME_CODE[expected] and s["outcome"] == expected
    assert abs(s["impacts"] - ref["impacts"]) <= 2


def test_an_uplift_inside_a_step_at_rest_is_found():
    """Threshold seed 28 at mu 0.30 (``scripts/threshold_sample.py --mu 0.15 1.5``): at rest
    during a cosine, the body's uplift moment crosses M g b inside one `default` step and
    turns back before its end. Finer runs and the reference uplift there by a hair, make 6
    impacts, settle, uplift again and fall in mode 1 at 6.04 p t; the run that saw only
    the step's ends fell in mode 2 at the same time. The rest phase's uplift functions are
    now screened inside the step with their cubic Hermite interpolant (``slide_events.
    _lift_dip``, the no-slip model's ``events._crossing``): the uncertified run at
    `default` takes the reference's class and impacts."""
    body = FlexibleBody(wn_over_p=1.6913321929354148, zeta=0.1443916261018191,
                        alpha_cg=0.22951701006243408, alpha_A=0.4377970517320052,
                        mA_over_m=1.5123255436071759, IA_ratio=0.5981090617798844)
    pt = Point(body, 0.3176354063133086, "cosine", 1.7000503872414043, 1.4560670531549458,
               mu=0.3011832404399563)
    s, ref = _uncertified_and_reference(pt)
    assert ref["outcome"] == OUTCOME_CODE["mode1"] and s["outcome"] == "mode1"
    assert s["impacts"] == ref["impacts"] == 6
    assert s["t_overturn"] == pytest.approx(ref["t_overturn"], abs=0.01)


# Sliding threshold seeds 58 and 60 (``scripts/threshold_sample.py --mu 0.15 1.5``): a
# slide-rock whose den = H_a + mu sigma N_a falls through zero inside one step
PAINLEVE_POINTS = {
    58: Point(FlexibleBody(wn_over_p=3.3722378857946786, zeta=0.1224068555290883,
                           alpha_cg=0.2109865729030082, alpha_A=0.5335889012185802,
                           mA_over_m=2.2114254931342257, IA_ratio=0.3985674791314566),
              0.38981991628991713, "sine", 4.1184429356192265, 13.302344358319083,
              mu=1.4103002721120335),
    60: Point(FlexibleBody(wn_over_p=7.817045861122146, zeta=0.13475997850773416,
                           alpha_cg=0.2652356462792552, alpha_A=0.18595209432962762,
                           mA_over_m=0.3762826832083047, IA_ratio=0.706262482032598),
              0.15306589315024344, "cosine", 5.339530649562527, 12.867805017509495,
              mu=1.2856029950234569),
}


@pytest.mark.parametrize("seed", sorted(PAINLEVE_POINTS))
def test_a_slip_toward_a_painleve_point_jams_at_every_step(seed):
    """Toward den = 0 the slip's accelerations grow as 1/den and the slip stops in a
    vanishing time, whose limit is the jam impulse; the loop jams at den = JAM_DEN M
    (``sliding.JAM_DEN``). Stepped through to den = 0 instead, the slip stop was located
    on a state with theta' of 1e2-1e5 alpha_ref, different at every step: seed 58 lifted
    off and fell in mode 1 after an impact at 5 steps a period, seed 60 (deepest impact
    (theta'/alpha_ref)^2/2 5.7, 3e4, 5e3 at 5, 10, 20 steps a period) flipped between safe
    and mode 1. Now, uncertified, at 5 and 10 steps a period: the reference's class (which
    jams too), seed 58's fall at its time, seed 60's impacts as deep at both steps (a
    path that converges) and as many as the reference's."""
    pt = PAINLEVE_POINTS[seed]
    ref = sliding_reference(pt)
    assert "jam" in ref["status"]
    runs = [run_point(pt, DEFAULT.refined(level)) for level in (0, 1)]
    for r in runs:
        assert OUTCOME_CODE[r.outcome] == ref["outcome"]
        if seed == 58:
            assert ref["outcome"] == OUTCOME_CODE["mode2"]
            assert r.summary()["t_overturn"] == pytest.approx(ref["t_overturn"], abs=1e-2)
        else:
            assert ref["outcome"] == OUTCOME_CODE["safe"]
            assert abs(r.summary()["impacts"] - ref["impacts"]) <= 1
    if seed == 60:
        depth = [r.out[L.OUT_MODE_GRAZE] for r in runs]
        assert depth[1] == pytest.approx(depth[0], rel=0.02) and depth[0] < 10.0
