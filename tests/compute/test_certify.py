"""The step rule that resolves what acts, the certification of close calls and the one
default, against the independent reference path (``physics.reference``:
scipy's DOP853 at rtol 1e-10 with located events).

- two cases the old step rule got wrong: a uniform block (alpha = 0.25, lam = 0, sine,
  omega/p = 8) overturns in mode 1 for A/(g tan alpha) in [10.86, 11.41] (at 5 steps per
  pulse period its work on the block was ~2% off and `default` called the band safe);
  Figure 3(b)'s body under a cosine at omega/p = 4, A = 5.47-5.66 chatters to rest
  (`default` overturned it after one impact);
- a run near its threshold (it came within PAR_CLOSE of the saddle) is re-run or, a safe
  one between the close-call margin and the band, probed, and says so in its status; a
  clear one is not; an outcome that keeps changing is flagged uncertified;
- both sides of a threshold: a flexible body that `default` overturned after 3 impacts
  where the reference survives ~140, and one that `default` rocked to rest with a margin
  of 3.3 x the close-call margin where the reference overturns after one impact;
- ``simulate`` and a sweep give one point one answer.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from bodies import BODY3, BODY4

from rocksweep.compute.certify import certify, lifted_off
from rocksweep.compute.driver import sweep_arrays
from rocksweep.compute.single import run_point
from rocksweep.fields import check_rows, refined_rows
from rocksweep.kernel import chunk_kernel, warm_up
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import (
    CLEARANCE,
    CLOSE_AFTER,
    CLOSE_BAND,
    ENERGY_ORDER,
    GRAZE_BAND,
    GRAZE_MARGIN,
    IMPACT_AGREE,
    LIFT_BAND,
    LIFT_PAST,
    MIN_EVENT_TOL,
    MODE_BAND,
    OVERTURN_BAND,
    PATH_REACH,
    RICHARDSON_SAFETY,
    RINGING_BAND,
    RINGING_MEMORY,
    SAME_FALL,
    UNSPLIT_SHARE,
    Numerics,
    close_band,
)
from rocksweep.physics.bodies import BlockBody, FlexibleBody
from rocksweep.physics.points import Point, kernel_contact, kernel_kind, point_row
from rocksweep.physics.reference import reference_run
from rocksweep.physics.sliding_reference import sliding_reference
from rocksweep.scene.parse import parse_scene
from rocksweep.vocab.phases import PHASE_CODE, REST, ROCK, SLIDE, SLIDE_ROCK

BLOCK = BlockBody(alpha=0.25, inertia=4.0 / 3.0)


def _stand_in(n: int) -> np.ndarray:
    """Result rows float64[n, N_OUT] of a stand-in kernel: zeros, and no graze (inf, as a
    run whose rocking never neared an impact it did not make while the ground moved), mode
    graze (inf: never neared theta = 0 before its first impact), lift graze (inf: never
    near an uplift it did not make), shallow impact (inf: none while the ground moved) nor
    lift-off (inf: its corner's N never neared zero)."""
    out = np.zeros((n, L.N_OUT))
    out[:, [L.OUT_GRAZE, L.OUT_MODE_GRAZE, L.OUT_LIFT_GRAZE, L.OUT_SHALLOW,
            L.OUT_LIFT_ANGLE]] = np.inf
    return out


# threshold seed 116's body and pulse (CASES, ``test_a_phase_no_step_split_...``)
CHATTER_116 = Point(FlexibleBody(wn_over_p=2.2884208799658987, zeta=0.07749233964307982,
                                 alpha_cg=0.10536760629882237, alpha_A=0.4257780382044154,
                                 mA_over_m=2.6949288737431365, IA_ratio=0.8313050697778259),
                    0.4112574981187938, "cosine", 3.603490843936676, 3.967538642746966)

CASES = [
    # (point, what the issue found the reference does)
    (Point(BLOCK, 0.0, "sine", 8.0, 10.9), L.OUTCOME_MODE1),
    (Point(BLOCK, 0.0, "sine", 8.0, 11.35), L.OUTCOME_MODE1),
    (Point(BODY3, 0.0, "cosine", 4.0, 5.47), L.OUTCOME_SAFE),
    (Point(BODY3, 0.0, "cosine", 4.0, 5.66), L.OUTCOME_SAFE),
    # near its mode-1 threshold (3.122 at `fine`): the bare default run commits to falling
    # after 3 impacts with a margin of 1.6 PAR_CLOSE; the reference rocks to rest
    (Point(FlexibleBody(wn_over_p=2.9574, zeta=0.0968, alpha_cg=0.1243, alpha_A=0.4078,
                        mA_over_m=1.4056, IA_ratio=0.6851), 0.3216, "sine", 4.6059, 3.1123),
     L.OUTCOME_SAFE),
    # near its mode-1 threshold: the bare default run rocks to rest with a margin of 3.3 x
    # the close-call margin; the reference overturns after 1 impact
    (Point(FlexibleBody(wn_over_p=2.52, zeta=0.046, alpha_cg=0.173, alpha_A=0.213,
                        mA_over_m=0.82, IA_ratio=0.96), 0.229, "sine", 3.71, 3.8515),
     L.OUTCOME_MODE1),
    # a held-out threshold sample's point (seed 3): `default` overturns in mode 1 at 5 and
    # 10 steps a period (at 12.15 and 17.7 p t, margins 5.7 and 4.3 x the steps' close-call
    # margins); 20 and 40 steps and the reference rock to rest after ~90 impacts. Its
    # margins have not converged (the finer squared margin is 0.55 x Richardson's estimate
    # of its error even at order 5), nor did it fall on the same approach twice
    (Point(FlexibleBody(wn_over_p=4.2221, zeta=0.02553, alpha_cg=0.29953, alpha_A=0.19599,
                        mA_over_m=0.31736, IA_ratio=0.84879), 0.36736, "cosine", 4.2632,
           8.7676),
     L.OUTCOME_SAFE),
    # held-out threshold samples' points (seeds 6-7): a near-miss (bare default safe, margin
    # 0.0134) whose probe at 10 steps a period stays safe but passes the saddle within 3e-4
    # alpha_ref, below its own close-call margin; 20 steps and the reference overturn in
    # mode 1 after 7 impacts
    (Point(FlexibleBody(wn_over_p=3.191621303630217, zeta=0.029138857586427994,
                        alpha_cg=0.15374705081836282, alpha_A=0.42524544057792923,
                        mA_over_m=0.6651808336725784, IA_ratio=0.665727144451087),
           0.05887685771070211, "sine", 6.501315649740741, 7.270368980515457),
     L.OUTCOME_MODE1),
    # ... and an overturn without impact at 5 and 10 steps a period, its margin
    # 0.051 then 0.029 alpha_ref (the second clear of its step's band, but the squared
    # margin fell by two thirds: not settled); 20 steps and the reference rock to rest
    # after 41 impacts
    (Point(FlexibleBody(wn_over_p=2.0366252178143402, zeta=0.08137178855398537,
                        alpha_cg=0.34805529221107046, alpha_A=0.25755176968669025,
                        mA_over_m=0.5270192388463457, IA_ratio=0.5025951314687973),
           0.17216879085380637, "cosine", 3.4290422082106495, 10.783290405871984),
     L.OUTCOME_SAFE),
    # a held-out threshold sample's point (seed 9): `default` at 5 steps a period rocks
    # to rest after 36 impacts with a margin of 5.1 x its close-call margin (a near-miss,
    # probed, only since CLOSE_BAND 8); 10 steps and the reference overturn in mode 1
    # after 10 impacts
    (Point(FlexibleBody(wn_over_p=5.897660048190691, zeta=0.12286561896478687,
                        alpha_cg=0.2306352643333695, alpha_A=0.4492947536651719,
                        mA_over_m=0.5870911136601574, IA_ratio=0.5304677117738952),
           0.04798491908524943, "sine", 1.5599727774432728, 1.0689059504580425),
     L.OUTCOME_MODE1),
    # springs that ring long (seeds 1 and 13; 1/(zeta' omega_rock) = 11.9 and 24.2 p t):
    # `default` rocks to rest after ~145 impacts with margins of 0.099 and 0.101 alpha_ref,
    # 7.9 and 8.1 x the close-call margin; 20 steps a period and the reference overturn in
    # mode 1 after 6 and 3 impacts, at 19.5 and 18.3 p t. The first one's probe at 10 steps
    # stopped at 14.3 p t, before the fall, its margin 0.008 (moved by more than itself);
    # the second one lies beyond the band: not probed before RINGING_BAND
    (Point(FlexibleBody(wn_over_p=4.5995206050253845, zeta=0.01216059849378684,
                        alpha_cg=0.23548630894464534, alpha_A=0.1846912670297746,
                        mA_over_m=0.4497075382856386, IA_ratio=0.9795358578478384),
           0.40432158738642565, "cosine", 7.341356655748948, 10.140268114250159),
     L.OUTCOME_MODE1),
    (Point(FlexibleBody(wn_over_p=1.8056627155637202, zeta=0.017385192977056818,
                        alpha_cg=0.2384100271815635, alpha_A=0.25787897660818015,
                        mA_over_m=2.8278779999915957, IA_ratio=0.8249220518496778),
           0.360617709279215, "sine", 2.1547173634520327, 1.273314669996943),
     L.OUTCOME_MODE1),
    # a graze (seed 19): just above the pulse's uplift threshold, `default` at 5 and 10
    # steps a period rocks to rest through ~190 impacts (margins 0.012 and 0.009), its arcs
    # grazing theta = 0 at 7.3e-4 then 1.3e-4 alpha_ref without an impact; 20 steps and the
    # reference make that impact (at 1.80 p t) and overturn in mode 1 after 7
    (Point(FlexibleBody(wn_over_p=3.685875454041754, zeta=0.0970436258544244,
                        alpha_cg=0.08472585297979551, alpha_A=0.24588356376249662,
                        mA_over_m=2.906150601512549, IA_ratio=0.36398053129159574),
           0.1508474214840334, "sine", 2.589274983284195, 1.1223682677246714),
     L.OUTCOME_MODE1),
    # clear by twice the margin (seeds 10 and 18): `default` at 5 and 10 steps a period
    # overturns after 3 impacts (margins 0.0036 and 0.0042 alpha_ref, converged, the second
    # 1.9 x its step's close-call margin); 20 steps and the reference rock to rest. And
    # one that rocks to rest at 5 and 10 steps (margins 0.0034 and 0.0041, 1.9 x) where 20
    # steps and the reference overturn after 15 impacts
    (Point(FlexibleBody(wn_over_p=3.839128118005102, zeta=0.04836142719624848,
                        alpha_cg=0.08226364888458781, alpha_A=0.28483523130561605,
                        mA_over_m=2.466746728263963, IA_ratio=0.8438206825733008),
           0.008303049307849586, "sine", 8.550640729956466, 12.044341170783627),
     L.OUTCOME_SAFE),
    (Point(FlexibleBody(wn_over_p=3.244384436080784, zeta=0.1241331001565131,
                        alpha_cg=0.10430558839545015, alpha_A=0.3825673588512779,
                        mA_over_m=2.7502004413457013, IA_ratio=0.8790279046190526),
           0.38111342415709554, "sine", 2.60235692855235, 1.1135754061905543),
     L.OUTCOME_MODE1),
    # events located finer (seed 36): a lightly damped spring whose runs at 20-80 steps a
    # period all overturn after 5 impacts at event_tol 1e-6; at 1e-7 and below each rocks
    # to rest, as the reference does after ~100 impacts
    (Point(FlexibleBody(wn_over_p=4.647534481033071, zeta=0.005360295426164207,
                        alpha_cg=0.2608468305885651, alpha_A=0.2401621490149733,
                        mA_over_m=2.1164155659054247, IA_ratio=0.6289562775924202),
           0.045452296669503345, "cosine", 4.494057754758692, 8.396486280261689),
     L.OUTCOME_SAFE),
    # falls that moved (seed 37): `default` at 5 and 10 steps overturns after a chatter of 7
    # impacts and a 10 p t creep to the saddle, falling 0.86 p t apart (margins 0.016,
    # 0.018); 20 steps and the reference rock to rest
    (Point(FlexibleBody(wn_over_p=2.7130457923670743, zeta=0.05408015458343131,
                        alpha_cg=0.09410451933184985, alpha_A=0.41232774836102537,
                        mA_over_m=1.3031095121007714, IA_ratio=0.8118827777636031),
           0.4653911688089458, "sine", 4.788063776208234, 3.1461616999062776),
     L.OUTCOME_SAFE),
    # probes that must clear twice their margin (seeds 39 and 44, drawn after the rules
    # above; before the finer event tolerance, their probes were close calls):
    # near-misses (margins 1.04 and 1.3 x the close-call margin) whose probes at 10 steps
    # stay safe 1.1-1.2 x their own step's margin away; 20 steps and the reference
    # overturn after 1 impact
    (Point(FlexibleBody(wn_over_p=3.0800381649449644, zeta=0.09052809882064987,
                        alpha_cg=0.22264291317829377, alpha_A=0.23133862564106367,
                        mA_over_m=0.3943392577779223, IA_ratio=0.972440396327676),
           0.2869093448570578, "cosine", 3.7543599616085386, 2.663931193052373),
     L.OUTCOME_MODE1),
    (Point(FlexibleBody(wn_over_p=3.772668007617098, zeta=0.04535670898537445,
                        alpha_cg=0.26259796074669167, alpha_A=0.3297679672564091,
                        mA_over_m=1.1163266672244812, IA_ratio=0.7017887641230507),
           0.27312513876994055, "sine", 5.289383516384128, 5.187507434762409),
     L.OUTCOME_MODE1),
    # nearly uplifted (seed 63): at 5 steps a period the uplift moment turns back 3.5e-5
    # M g b short of uplifting and the body falls later without an impact (mode 2); finer
    # runs and the reference uplift there by a hair, impact once and fall in mode 1
    (Point(FlexibleBody(wn_over_p=1.7957502692358451, zeta=0.08062461560373882,
                        alpha_cg=0.18801316374715496, alpha_A=0.22816281603351407,
                        mA_over_m=2.6435877119708886, IA_ratio=0.3667814134254739),
           0.2524961519237265, "cosine", 1.3323570528284048, 1.4121684954916087),
     L.OUTCOME_MODE1),
    # two paths, one class (seeds 64 and 66, springs that ring long): `default` at 5 and
    # 10 steps a period rocks to rest after 82 and 36 impacts, margins 0.032 and 0.033;
    # 20 steps and finer fall in mode 1 after 12, as the reference does. And an overturn
    # after 5 impacts at 1.06 x the overturn band where finer runs and the reference rock
    # to rest after 8
    (Point(FlexibleBody(wn_over_p=7.037649694070546, zeta=0.0023540019192680116,
                        alpha_cg=0.2294307100554438, alpha_A=0.1948138215409945,
                        mA_over_m=2.1745212409788, IA_ratio=0.977377538803013),
           0.33332330202872895, "cosine", 6.421472704841054, 11.571988404376356),
     L.OUTCOME_MODE1),
    (Point(FlexibleBody(wn_over_p=3.075709081322864, zeta=0.030134590120287907,
                        alpha_cg=0.2694365211138179, alpha_A=0.19254937652001652,
                        mA_over_m=1.0962236801345875, IA_ratio=0.8953117873169059),
           0.25831097900721167, "cosine", 4.713245726626207, 10.697457631199324),
     L.OUTCOME_SAFE),
    # a probe whose margin fell past its error (seed 73): a near-miss at 0.091 alpha_ref
    # whose probe at 10 steps passes at 0.0068 (clear of twice its margin); 20 steps and
    # the reference overturn in mode 1 after 3 impacts
    (Point(FlexibleBody(wn_over_p=2.4690161419528724, zeta=0.0686134070587241,
                        alpha_cg=0.11032806691211333, alpha_A=0.18697876631211824,
                        mA_over_m=2.4517520795207446, IA_ratio=0.5664574421239543),
           0.35996189697155917, "cosine", 3.8059568165695747, 13.449372852900005),
     L.OUTCOME_MODE1),
    # ... and one whose margin's error fell as the step^1.8 (seed 91): a near-miss at
    # 0.0369 alpha_ref, its probe at 10 steps safe at 0.0068 on the same approach (after 2
    # impacts both): above an eighth of the coarse margin (kept at order 3), its square
    # below Richardson's estimate of its error; 20 steps and the reference overturn in
    # mode 1 after 2 impacts
    (Point(FlexibleBody(wn_over_p=3.921693151038834, zeta=0.04685791416296161,
                        alpha_cg=0.24501445506105962, alpha_A=0.1921075786309662,
                        mA_over_m=0.6957075438595095, IA_ratio=0.6439474412600221),
           0.3921048784532814, "cosine", 5.623570097921776, 12.107635581056998),
     L.OUTCOME_MODE1),
    # ... and one whose probe kept a quarter of the coarse margin (seed 108): 0.0214 ->
    # 0.0059 alpha_ref (kept by a margin falling as the step^2), its square below twice
    # Richardson's estimate of its error; 20 steps and the reference overturn in mode 1
    # after 3 impacts
    (Point(FlexibleBody(wn_over_p=2.3525895708138695, zeta=0.05318234470632472,
                        alpha_cg=0.1271048357583636, alpha_A=0.1748262277044242,
                        mA_over_m=0.4525297464932731, IA_ratio=0.4499597382431248),
           0.11343676581875684, "sine", 3.3780099563350623, 2.1434725405584727),
     L.OUTCOME_MODE1),
    # ... and a point of Figure 3(a) at 1000 x 1000 x 3 lam (lam 0.4): a near-miss at
    # 0.0393 alpha_ref whose probe passed at 0.0103 (above a quarter); 20 steps, `fine`
    # and the reference overturn in mode 1 after 5 impacts
    (Point(BODY3, 0.4, "sine", 2.4533033033033034, 0.9777777777777779), L.OUTCOME_MODE1),
    # a safe run far from the saddle (margin 0.20 alpha_ref) that turned back 2e-4 alpha_ref
    # short of an impact during the pulse (seed 123): 10 steps a period and finer, `fine`
    # and the reference make the impact and fall in mode 1 after 6 impacts
    (Point(FlexibleBody(wn_over_p=6.218136792383917, zeta=0.14781416683518317,
                        alpha_cg=0.09124220466571292, alpha_A=0.1737986144034394,
                        mA_over_m=0.30571760553678246, IA_ratio=0.8152897221194817),
           0.47940659424735316, "cosine", 1.30534476443025, 1.0446585255087506),
     L.OUTCOME_MODE1),
    # a spring of 4.16 p t (seed 143), safe at 5 steps a period 1.04 x the band from the
    # saddle after 7 impacts; 10 steps and finer, `fine` and the reference fall in mode 1
    # after 6 (rings long at RINGING_MEMORY 3, not at 5)
    (Point(FlexibleBody(wn_over_p=3.409622614885268, zeta=0.015643268654519874,
                        alpha_cg=0.2622210858957979, alpha_A=0.5071949366534465,
                        mA_over_m=1.862923374039951, IA_ratio=0.9316619683201901),
           0.16010470152810913, "cosine", 5.160447353459797, 15.997318617223787),
     L.OUTCOME_MODE1),
    # a chatter through the pulse (seed 116): a phase of 0.0363 p t is one step at 5 and at
    # 10 steps a period, both runs fall after 7 impacts with margins that converged; 20
    # steps a period and finer, and the reference, rock to rest (``unsplit``)
    (CHATTER_116, L.OUTCOME_SAFE),
    # a chatter after the pulse (seed 37), then a creep toward the saddle: safe at 5 and 10
    # steps a period (margins 0.0055, 0.0047 alpha_ref, settled and clear), where 20 steps
    # and the reference fall in mode 1 after 9 impacts; and one of a fresh sample (seed 168)
    (Point(FlexibleBody(wn_over_p=2.7130457923670743, zeta=0.05408015458343131,
                        alpha_cg=0.09410451933184985, alpha_A=0.41232774836102537,
                        mA_over_m=1.3031095121007714, IA_ratio=0.8118827777636031),
           0.4653911688089458, "sine", 4.788063776208234, 5.428812302383947), L.OUTCOME_MODE1),
    (Point(FlexibleBody(wn_over_p=2.8881816686926944, zeta=0.02804039237289362,
                        alpha_cg=0.13151163727485587, alpha_A=0.40900155264766413,
                        mA_over_m=1.9815800204068397, IA_ratio=0.5792516804898262),
           0.47784499636566097, "sine", 8.472913494896671, 13.255574397855478),
     L.OUTCOME_MODE1),
    # just outside the near-miss band of 8 x the close-call margin (fresh seed 208): safe
    # at 5 steps a period with margin 0.1032 alpha_ref (8.26 x), at 10 with 0.011; 20 steps
    # and finer, and the reference, fall in mode 1 (a knife-edge overturn)
    (Point(FlexibleBody(wn_over_p=2.8371270000994024, zeta=0.047357018196036556,
                        alpha_cg=0.19996446254270336, alpha_A=0.3090525518678418,
                        mA_over_m=2.81824933627754, IA_ratio=0.4035747943050826),
           0.0002890750586505564, "cosine", 3.3879898935437556, 9.170677551207886),
     L.OUTCOME_MODE1),
    # an impact made by a hair while the ground moves, which finer runs make later and
    # deeper: seed 36's body (on a base without sliding), safe at 5 steps a period with
    # margin 0.21 alpha_ref after 7 impacts (the shallowest 3.6e-4 alpha_ref deep, 0.019 p t
    # late); and a Figure 4(b) point at 1000 x 1000 (lam 0.2), safe with margin 0.37 after
    # 15 (2.2e-4 deep). 10 steps a period and finer, `fine` and the reference fall in mode 1
    # after 6 and 14
    (Point(FlexibleBody(wn_over_p=6.39578552800787, zeta=0.13122225893448825,
                        alpha_cg=0.2857983365637249, alpha_A=0.16199849037018302,
                        mA_over_m=0.4325411830436524, IA_ratio=0.3324034469049034),
           0.21839509262713191, "cosine", 1.2607246731818131, 1.1187845670129442),
     L.OUTCOME_MODE1),
    (Point(BODY4, 0.2, "cosine", 0.7926426426426425, 1.0344094094094094), L.OUTCOME_MODE1),
]


@pytest.mark.parametrize("point,expected", CASES,
                         ids=["block-10.9", "block-11.35", "fig3b-5.47", "fig3b-5.66",
                              "flexible-overturn-side", "flexible-safe-side",
                              "flexible-overturn-unconverged",
                              "flexible-probe-close", "flexible-margin-unsettled",
                              "flexible-near-miss-wide", "ringing-probe-moved",
                              "ringing-beyond-band", "graze", "clear-overturn",
                              "clear-safe", "event-tol", "fall-moved", "probe-clear-1",
                              "probe-clear-2", "nearly-uplifted", "two-paths-safe",
                              "two-paths-overturn", "probe-kept", "probe-kept-91", "probe-kept-108",
                              "fig3a-probe-kept", "graze-safe-123", "ringing-4-143",
                              "chatter-116", "chatter-37", "chatter-168",
                              "band-edge-208", "shallow-36", "shallow-fig4b"])
def test_default_classifies_the_reproduced_cases_like_the_reference(point, expected):
    """The reference's outcome is the one written here; `default` (sweep kernel and simulate) gives
    the same. Before the step rule, `default` gave safe / mode 1 here."""
    ref = reference_run(point)
    assert ref["outcome"] == expected
    run = run_point(point, Numerics.preset("default"), history=False)
    assert run.out[L.OUT_OUTCOME] == expected
    if expected == L.OUTCOME_MODE1:  # and overturns after the same impacts
        assert run.impacts == ref["impacts"]


def _bare(point: Point, numerics: Numerics) -> np.ndarray:
    """One kernel run without certification: the result row (the kernel's own status, as
    the certification sees it)."""
    row = point_row(point, numerics)
    kind, contact = kernel_kind(point.body), kernel_contact(point.mu)
    warm_up(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE, contact)
    out = np.empty((1, L.N_OUT))
    chunk_kernel(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE, contact)(row[None, :], out)
    return out[0]


def _sliding_runs(point: Point) -> tuple[dict, np.ndarray, np.ndarray]:
    """(the sliding reference's run, the `default` run without certification, the
    certified one) of a point on a base that may slide: result rows float64[N_OUT]."""
    default = Numerics.preset("default")
    return (sliding_reference(point), run_point(point, replace(default, refine=0)).out,
            run_point(point, default).out)


def test_close_calls_are_refined_and_clear_ones_are_not():
    """Over a scan of A across the block's mode-1 band and clear of it on both sides (margins
    up to ~14 x the close-call margin): a run is refined exactly when its
    bare run came within PAR_CLOSE of the saddle (OVERTURN_BAND / CLOSE_BAND x PAR_CLOSE
    if it overturned); the scan holds overturns and near-misses
    (safe, between PAR_CLOSE / CLOSE_BAND and PAR_CLOSE: probed, their own result kept
    but for the steps) and clear runs, whose result is the bare run's, bit for bit."""
    n = Numerics.preset("default")
    refined = clear = probed = 0
    for A in np.linspace(9.0, 13.0, 41):
        point = Point(BLOCK, 0.0, "sine", 8.0, float(A))
        bare = _bare(point, n)
        band = point_row(point, n)[L.PAR_CLOSE]
        fell = bare[L.OUT_OUTCOME] != L.OUTCOME_SAFE
        close = bare[L.OUT_MARGIN] < band * (OVERTURN_BAND / CLOSE_BAND if fell else 1.0)
        run = run_point(point, n, history=False)
        is_refined = bool(int(run.out[L.OUT_STATUS]) & L.STATUS_REFINED)
        assert is_refined == close, A
        assert ("refined" in run.status) == close
        near_miss = close and not fell and bare[L.OUT_MARGIN] >= band / CLOSE_BAND
        if near_miss and run.out[L.OUT_OUTCOME] == L.OUTCOME_SAFE:
            probed += 1
            for slot in (L.OUT_T_END, L.OUT_THETA_MAX, L.OUT_IMPACTS, L.OUT_MARGIN):
                assert run.out[slot] == bare[slot], A
            # the shorter check's history is not the point's: its own runs to its end
            t = run_point(point, n, history=True).history["t"]
            assert t[-1] == bare[L.OUT_T_END], A
        if close:
            refined += 1
            assert run.out[L.OUT_STEPS] > bare[L.OUT_STEPS]  # every run's steps counted
        else:
            clear += 1
            assert np.array_equal(run.out, bare, equal_nan=True)
    assert refined >= 2 and clear >= 10 and probed >= 1


def test_a_near_miss_is_probed_to_its_last_approach():
    """certify's rule on a stand-in kernel: a safe run between PAR_CLOSE / CLOSE_BAND and
    PAR_CLOSE is run once at half the step, up to CLOSE_AFTER past its last approach
    (OUT_T_CLOSE), without keeping a history; one whose probe stays safe keeps its own
    result (steps added, refined); one whose probe overturns is re-run in full from the
    first refinement on, as a close call."""
    rows = np.zeros((3, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.04
    rows[:, L.PAR_DT] = 1.0
    rows[:, L.PAR_TEND] = 100.0
    outs = _stand_in(3)
    outs[:, L.OUT_MARGIN] = [0.02, 0.03, 0.5]  # two near-misses, one clear
    outs[:, L.OUT_T_CLOSE] = [5.0, 7.0, np.nan]
    outs[:, L.OUT_T_END] = 40.0
    outs[:, L.OUT_STEPS] = 100
    calls = []

    def run(sub, idx, keep=True):
        calls.append((idx.tolist(), sub[:, L.PAR_DT].tolist(), sub[:, L.PAR_TEND].tolist(),
                      keep))
        res = _stand_in(len(idx))
        res[:, L.OUT_OUTCOME] = np.where(idx == 1, L.OUTCOME_MODE1, L.OUTCOME_SAFE)
        res[:, L.OUT_STEPS] = 10
        res[:, L.OUT_MARGIN] = 1.0
        return res

    certify(rows, outs, run, 3)
    assert calls[0] == ([0, 1], [0.5, 0.5], [5.0 + CLOSE_AFTER, 7.0 + CLOSE_AFTER], False)
    # the flipped one: full runs at levels 1 and 2 (stable there), kept
    assert calls[1:] == [([1], [0.5], [100.0], True), ([1], [0.25], [100.0], True)]
    st = outs[:, L.OUT_STATUS].astype(int)
    assert st[0] & L.STATUS_REFINED and not st[0] & L.STATUS_FLAGGED
    assert outs[0, L.OUT_OUTCOME] == L.OUTCOME_SAFE and outs[0, L.OUT_T_END] == 40.0
    assert outs[0, L.OUT_STEPS] == 110
    assert outs[1, L.OUT_OUTCOME] == L.OUTCOME_MODE1 and outs[1, L.OUT_STEPS] == 130
    assert st[1] & L.STATUS_REFINED and not st[1] & L.STATUS_UNCERTIFIED
    assert st[2] == 0 and outs[2, L.OUT_STEPS] == 100


def _probed_near_misses(band: float, margin: float, probe: tuple[float, float]):
    """Two near-misses (safe, ``margin``, last close at 5 p t; rows with PAR_CLOSE ``band``)
    certified on a stand-in kernel whose probes (keep=False) pass at ``probe[i]`` and whose
    full runs clear everything (0.5). Returns ({point: [(level, keep), ...]}, outs)."""
    rows = np.zeros((2, L.N_PAR))
    rows[:, L.PAR_CLOSE] = band
    rows[:, L.PAR_DT] = 1.0
    rows[:, L.PAR_TEND] = 100.0
    outs = _stand_in(2)
    outs[:, L.OUT_MARGIN] = margin
    outs[:, L.OUT_T_CLOSE] = 5.0
    levels_run = {0: [], 1: []}

    def run(sub, idx, keep=True):
        res = _stand_in(len(idx))
        level = round(-np.log2(sub[0, L.PAR_DT]))
        for j, i in enumerate(idx):
            levels_run[int(i)].append((level, keep))
            res[j, L.OUT_MARGIN] = probe[int(i)] if not keep else 0.5
        return res

    certify(rows, outs, run, 3)
    return levels_run, outs


def test_a_near_miss_whose_probe_does_not_clear_twice_its_margin_is_a_close_call():
    """certify's rule on a stand-in kernel: a near-miss whose probe stays safe but within
    CLEARANCE x its own step's close-call margin is re-run in full from level 1; one whose
    probe clears it keeps its own result."""
    # near-misses at 1.3 x the close-call margin (0.01; level 1's: 0.00177), probed at 1.2
    # and 2.8 x level 1's margin (the second's square clear of twice Richardson's estimate
    # of its error too: ``energy_clear``)
    levels_run, outs = _probed_near_misses(0.01 * CLOSE_BAND, 0.013, (0.0021, 0.005))
    assert levels_run == {0: [(1, False), (1, True)], 1: [(1, False)]}
    assert not (outs[:, L.OUT_STATUS].astype(int) & L.STATUS_UNCERTIFIED).any()
    assert outs[1, L.OUT_MARGIN] == 0.013  # its own result kept


def test_a_near_miss_whose_probe_margin_fell_past_its_error_is_a_close_call():
    """certify's rule on a stand-in kernel: a near-miss whose probe stays safe and clear of
    CLEARANCE x its own step's close-call margin, but with a squared margin below
    RICHARDSON_SAFETY x Richardson's estimate of its error at ENERGY_ORDER
    ((m_c^2 - m_f^2) / (2^4 - 1)), is re-run in full from level 1; one whose probe margin
    fell less keeps its own result."""
    # near-misses at 0.09 (close-call margin 0.0125; level 1's 0.00221), probed at 0.0068
    # (threshold seed 73's) and 0.04, both clear of 2 x 0.00221
    probe = (0.0068, 0.04)
    assert min(probe) > CLEARANCE * 0.1 / CLOSE_BAND * 2.0 ** -2.5

    def err(m_f: float) -> float:
        return RICHARDSON_SAFETY * (0.09 ** 2 - m_f ** 2) / (2 ** ENERGY_ORDER - 1)

    assert probe[0] ** 2 < err(probe[0]) and probe[1] ** 2 >= err(probe[1])
    levels_run, outs = _probed_near_misses(0.1, 0.09, probe)
    assert levels_run == {0: [(1, False), (1, True)], 1: [(1, False)]}
    assert outs[1, L.OUT_MARGIN] == 0.09  # its own result kept


def test_a_ringing_spring_is_a_close_call_wider_and_must_keep_its_path():
    """certify's rule on a stand-in kernel, for a spring that rings long (PAR_MEMORY above
    RINGING_MEMORY): its safe runs up to RINGING_BAND x PAR_CLOSE and its overturns up to
    RINGING_BAND x OVERTURN_BAND x the close-call margin are re-run in full (not probed),
    and a repeated safe outcome below the last level counts only where both runs made as
    many impacts, within IMPACT_AGREE (a repeated overturn needs the same fall, not the
    same impacts), and from two refined runs (levels 1 and 2), not from the first one's
    agreement with the coarse run; the finer runs answer to the plain bands; a body that
    does not ring is not re-run at those margins."""
    rows = np.zeros((4, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.04  # close-call margin 0.005
    rows[:, L.PAR_DT] = 1.0
    rows[:, L.PAR_TEND] = 100.0
    rows[:, L.PAR_MEMORY] = [2.0 * RINGING_MEMORY, 0.5 * RINGING_MEMORY] * 2
    # rows 0-1 safe, 2-3 overturned, all at 0.06: beyond the band and beyond OVERTURN_BAND
    # x the close-call margin (0.04), within RINGING_BAND x both (0.08)
    assert OVERTURN_BAND * 0.005 < 0.06 < RINGING_BAND * min(0.04, OVERTURN_BAND * 0.005)
    outs = _stand_in(4)
    outs[:, L.OUT_OUTCOME] = [L.OUTCOME_SAFE] * 2 + [L.OUTCOME_MODE1] * 2
    outs[:, L.OUT_MARGIN] = 0.06
    outs[:, L.OUT_T_OVERTURN] = [np.nan, np.nan, 5.0, 5.0]
    outs[:, L.OUT_IMPACTS] = 20
    # level -> impacts: row 0's second run parts from its first (30 against 20, beyond
    # IMPACT_AGREE), its third keeps to the second's path (31); row 2's falls on the same
    # approach after other impacts
    impacts = {1: {0: 30, 2: 40}, 2: {0: 31, 2: 40}}
    assert abs(31 - 30) <= IMPACT_AGREE * 31 < abs(30 - 20)
    # row 0's margins at levels 1 and 2: settled, clear, and at level 2 inside RINGING_BAND
    # x its band (0.04 x 2^-5 = 0.00125): the finer runs answer to the plain bands
    margins = {1: {0: 0.003, 2: 0.5}, 2: {0: 0.0024, 2: 0.5}}
    assert 0.0024 < RINGING_BAND * 0.04 * 2.0 ** -5
    calls = []

    def run(sub, idx, keep=True):
        level = round(-np.log2(sub[0, L.PAR_DT]))
        calls.append((idx.tolist(), level, keep))
        res = _stand_in(len(idx))
        res[:, L.OUT_OUTCOME] = outs[idx, L.OUT_OUTCOME]
        res[:, L.OUT_T_OVERTURN] = outs[idx, L.OUT_T_OVERTURN]
        res[:, L.OUT_MARGIN] = [margins[level][int(i)] for i in idx]
        res[:, L.OUT_IMPACTS] = [impacts[level][int(i)] for i in idx]
        return res

    certify(rows, outs, run, 3)
    # row 2's repeated overturn at level 1 is not trusted yet: a ringing body's class
    # comes from two refined runs
    assert calls == [([0, 2], 1, True), ([0, 2], 2, True)]
    st = outs[:, L.OUT_STATUS].astype(int)
    assert st[0] & L.STATUS_REFINED and st[2] & L.STATUS_REFINED
    assert not (st[0] | st[2]) & L.STATUS_FLAGGED
    assert st[1] == 0 and st[3] == 0  # not ringing: not re-run
    assert outs[0, L.OUT_IMPACTS] == 31 and outs[2, L.OUT_IMPACTS] == 40  # finest kept


def test_an_outcome_that_keeps_changing_is_uncertified():
    """certify's rule on a stand-in kernel: outcomes that flip at every refinement end
    flagged uncertified after `levels` reruns; stable ones are refined once, unflagged;
    runs outside the margin are not touched."""
    rows = np.zeros((3, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.01
    rows[:, L.PAR_DT] = 1.0
    outs = _stand_in(3)
    inside = 0.5 * 0.01 / CLOSE_BAND  # half the close-call margin
    outs[:, L.OUT_MARGIN] = [inside, inside, 0.5]
    outs[:, L.OUT_OUTCOME] = [0, 0, 0]
    calls = []

    def run(sub, idx, keep=True):
        calls.append((idx.tolist(), sub[:, L.PAR_DT].tolist()))
        res = _stand_in(len(idx))
        level = round(-np.log2(sub[0, L.PAR_DT]))
        res[:, L.OUT_OUTCOME] = np.where(idx == 0, level % 2, 0)  # point 0 flips
        res[:, L.OUT_STEPS] = 10
        res[:, L.OUT_MARGIN] = 1.0  # the finer runs are clear of the saddle
        return res

    certify(rows, outs, run, 3)
    assert calls == [([0, 1], [0.5, 0.5]), ([0], [0.25]), ([0], [0.125])]
    st = outs[:, L.OUT_STATUS].astype(int)
    assert st[0] & L.STATUS_UNCERTIFIED and st[0] & L.STATUS_REFINED
    assert st[0] & L.STATUS_FLAGGED
    assert st[1] & L.STATUS_REFINED and not st[1] & L.STATUS_UNCERTIFIED
    assert st[2] == 0
    assert outs[0, L.OUT_STEPS] == 30 and outs[1, L.OUT_STEPS] == 10


def test_a_knife_edge_is_refined_until_clear_or_flagged():
    """certify's rule on a stand-in kernel: an outcome the finer run repeats is certified
    only where that run is itself clear of the saddle by its own step's margin (PAR_CLOSE
    scales with the step): a run whose margin stays below it at every refinement is
    refined to the last level and flagged uncertified though its outcome never changed;
    one whose finer run clears it stops there."""
    rows = np.zeros((2, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.04  # close-call margin 0.01 at level 0
    rows[:, L.PAR_DT] = 1.0
    outs = _stand_in(2)
    outs[:, L.OUT_MARGIN] = 0.001
    levels_run = {0: [], 1: []}

    def run(sub, idx, keep=True):
        res = _stand_in(len(idx))
        level = round(-np.log2(sub[0, L.PAR_DT]))
        for i in idx:
            levels_run[int(i)].append(level)
        # point 0: a knife edge (margin 1e-5 at every step); point 1 clears the level-1
        # close-call margin (0.01 x 2^-2.5 = 0.0018) at 0.005
        res[:, L.OUT_MARGIN] = np.where(idx == 0, 1e-5, 0.005)
        return res

    certify(rows, outs, run, 3)
    assert levels_run == {0: [1, 2, 3], 1: [1]}
    st = outs[:, L.OUT_STATUS].astype(int)
    assert st[0] & L.STATUS_UNCERTIFIED and st[0] & L.STATUS_FLAGGED
    assert st[1] & L.STATUS_REFINED and not st[1] & L.STATUS_UNCERTIFIED
    assert (outs[:, L.OUT_OUTCOME] == L.OUTCOME_SAFE).all()


def test_a_graze_that_moved_is_refined_further():
    """certify's rule on a stand-in kernel: a repeated outcome clear of the saddle whose
    finer run grazed an impact it did not make by less than GRAZE_MARGIN (OUT_GRAZE), with
    a graze that shrank by more than itself (a coming impact), goes on to the next level;
    one whose graze settled, stayed above GRAZE_MARGIN or never was, stops at level 1."""
    rows = np.zeros((4, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.04
    rows[:, L.PAR_DT] = 1.0
    g = GRAZE_MARGIN
    grazes = {0: [0.8 * g, 0.2 * g, 0.19 * g], 1: [0.8 * g, 0.7 * g],
              2: [80 * g, 10 * g], 3: [np.inf, np.inf]}
    outs = _stand_in(4)
    outs[:, L.OUT_MARGIN] = 0.001  # close calls
    outs[:, L.OUT_GRAZE] = [grazes[i][0] for i in range(4)]
    levels_run = {i: [] for i in range(4)}

    def run(sub, idx, keep=True):
        res = _stand_in(len(idx))
        level = round(-np.log2(sub[0, L.PAR_DT]))
        res[:, L.OUT_MARGIN] = 0.5  # clear and settled
        for j, i in enumerate(idx):
            levels_run[int(i)].append(level)
            res[j, L.OUT_GRAZE] = grazes[int(i)][level]
        return res

    certify(rows, outs, run, 3)
    assert levels_run == {0: [1, 2], 1: [1], 2: [1], 3: [1]}
    assert not (outs[:, L.OUT_STATUS].astype(int) & L.STATUS_FLAGGED).any()


LADDER_SLOTS = [L.OUT_OUTCOME, L.OUT_MARGIN, L.OUT_T_OVERTURN]


def _run_ladder(rows: np.ndarray, ladder: dict, levels: int, slots: list[int] = LADDER_SLOTS
                ) -> tuple[np.ndarray, dict]:
    """certify on a stand-in kernel: ladder[i][level] is point i's (outcome, margin,
    overturning time) at that refinement level (level 0: its own run), or the values of
    ``slots`` in their order. Returns the certified result rows and the levels each point
    was run at."""
    outs = _stand_in(len(ladder))
    for i, steps in ladder.items():
        outs[i, slots] = steps[0]
    levels_run = {i: [] for i in ladder}

    def run(sub, idx, keep=True):
        res = _stand_in(len(idx))
        level = round(-np.log2(sub[0, L.PAR_DT]))
        for j, i in enumerate(idx):
            levels_run[int(i)].append(level)
            res[j, slots] = ladder[int(i)][level]
        return res

    return certify(rows, outs, run, levels), levels_run


def test_a_repeated_overturn_whose_margin_converged_stops_there():
    """certify's rule on a stand-in kernel: a repeated overturn still inside the overturn
    band at its own step is certified where its margins converged between the two runs
    (the same fall, within SAME_FALL; the finer squared margin at least RICHARDSON_SAFETY
    times |m_f^2 - m_c^2| / (2^ENERGY_ORDER - 1); the finer margin clear of its own step's
    close-call margin) and a finer run would follow, not otherwise; a safe run's converged
    margin certifies nothing."""
    # close-call margin b_L = 0.01 x 2^(-2.5 L): 0.01, 0.00177, 0.000313, 5.5e-5
    rows = np.zeros((6, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.01 * CLOSE_BAND
    rows[:, L.PAR_DT] = 1.0
    fell, safe = L.OUTCOME_MODE1, L.OUTCOME_SAFE
    # per point and level 0..3: (outcome, margin, overturning time)
    ladder = {
        # converged at level 1: 0.0105^2 = 1.1e-4 >= 2 x |1.1e-4 - 4e-4| / 15 = 3.9e-5
        0: [(fell, 0.02, 10.0), (fell, 0.0105, 10.01)],
        # the same margins, but the finer run fell 2 p t later: another approach
        1: [(fell, 0.02, 10.0), (fell, 0.0105, 12.0), (fell, 0.0104, 12.0)],
        # level 1's margin is mostly the coarse step's error (it fell by 10x): one more
        2: [(fell, 0.05, 10.0), (fell, 0.005, 10.0), (fell, 0.0049, 10.0)],
        # converged, but below the finer step's own close-call margin (0.00177)
        3: [(fell, 0.0012, 10.0), (fell, 0.0012, 10.0), (fell, 0.0012, 10.0)],
        # safe with converged margins below its close-call margin: the rule as before
        4: [(safe, 0.0016, np.nan), (safe, 0.0015, np.nan), (safe, 0.0015, np.nan)],
        # converged only at the last level, still inside the band there (8 x 5.5e-5):
        # it would spare no run, and the verdict stays as before: uncertified
        5: [(fell, 0.05, 10.0), (fell, 0.005, 10.0), (fell, 3e-4, 10.0), (fell, 3e-4, 10.0)],
    }
    outs, levels_run = _run_ladder(rows, ladder, 3)
    assert levels_run == {0: [1], 1: [1, 2], 2: [1, 2], 3: [1, 2], 4: [1, 2], 5: [1, 2, 3]}
    st = outs[:, L.OUT_STATUS].astype(int)
    assert (st & L.STATUS_REFINED).all() and not (st[:5] & L.STATUS_UNCERTIFIED).any()
    assert st[5] & L.STATUS_UNCERTIFIED


def test_below_the_last_level_a_repeated_outcome_clears_twice_its_margin():
    """certify's rule on a stand-in kernel: below the last level, a repeated outcome, safe
    or a converged overturn, is trusted only where the finer margin is at least CLEARANCE
    times its own step's close-call margin (the coarse step's scaled as the step^(3/2));
    at the last level once is enough, as before."""
    # close-call margin b_L = 0.01 x 2^(-2.5 L): b_1 = 0.00177, CLEARANCE x b_1 = 0.00354
    rows = np.zeros((4, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.01 * CLOSE_BAND
    rows[:, L.PAR_DT] = 1.0
    fell, safe = L.OUTCOME_MODE1, L.OUTCOME_SAFE
    ladder = {
        # settled, 1.7 x b_1: one more level
        0: [(safe, 0.004, np.nan), (safe, 0.003, np.nan), (safe, 0.003, np.nan)],
        # settled, 2.04 x b_1: stops at level 1
        1: [(safe, 0.004, np.nan), (safe, 0.0036, np.nan)],
        # converged overturns (the same fall, Richardson's estimate far below m_f^2) at
        # 1.7 x and 2.04 x b_1
        2: [(fell, 0.0032, 10.0), (fell, 0.003, 10.0), (fell, 0.003, 10.0)],
        3: [(fell, 0.0038, 10.0), (fell, 0.0036, 10.0)],
    }
    assert CLEARANCE == 2.0
    outs, levels_run = _run_ladder(rows, ladder, 3)
    assert levels_run == {0: [1, 2], 1: [1], 2: [1, 2], 3: [1]}
    assert not (outs[:, L.OUT_STATUS].astype(int) & L.STATUS_UNCERTIFIED).any()
    # at the last level (refine 1) the 1.7 x run is certified there
    outs, levels_run = _run_ladder(rows[:1], {0: ladder[0]}, 1)
    assert levels_run == {0: [1]}
    assert not int(outs[0, L.OUT_STATUS]) & L.STATUS_UNCERTIFIED


def test_a_refinement_locates_events_finer():
    """refined_rows (and Numerics.refined, which the admission's cost check runs) take the
    event tolerance to a 16th per halving of the step, no lower than MIN_EVENT_TOL;
    outputs.check's rerun is level 1."""
    point = Point(BLOCK, 0.0, "sine", 8.0, 10.9)
    n = Numerics.preset("default")
    row = point_row(point, n)[None, :]
    for level in (1, 2, 3):
        tol = refined_rows(row, level)[0, L.PAR_TOL]
        assert tol == n.event_tol / 16 ** level
        assert point_row(point, n.refined(level))[L.PAR_TOL] == tol
    assert check_rows(row)[0, L.PAR_TOL] == n.event_tol / 16
    tight = Numerics.preset("default", event_tol=4 * MIN_EVENT_TOL)
    assert tight.refined(3).event_tol == MIN_EVENT_TOL
    assert refined_rows(point_row(point, tight)[None, :], 3)[0, L.PAR_TOL] == MIN_EVENT_TOL


def test_a_repeated_overturn_on_another_approach_is_not_trusted():
    """certify's rule on a stand-in kernel: two runs that both overturn clear of the band
    but SAME_FALL or more apart in time fell on different approaches (trajectories that
    parted): the point goes on to the next level, and one still apart at the last level is
    flagged; falls within SAME_FALL stop at level 1 as before."""
    rows = np.zeros((3, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.01 * CLOSE_BAND
    rows[:, L.PAR_DT] = 1.0
    fell = L.OUTCOME_MODE1
    # per point and level 0..2: (outcome, margin, overturning time); level 0 inside the
    # overturn band (a close call), every finer margin far outside it and settled
    ladder = {
        0: [(fell, 0.02, 10.0), (fell, 0.3, 10.0 + SAME_FALL)],
        1: [(fell, 0.02, 79.0), (fell, 0.3, 195.0), (fell, 0.3, 195.2)],
        2: [(fell, 0.02, 79.0), (fell, 0.3, 195.0), (fell, 0.3, 102.0)],
        # a fall that moved by 0.86 p t (seed 37's, a creep to the saddle)
        3: [(fell, 0.02, 12.59), (fell, 0.3, 13.45), (fell, 0.3, 13.46)],
    }
    assert SAME_FALL == 0.5
    outs, levels_run = _run_ladder(np.vstack([rows, rows[:1]]), ladder, 2)
    assert levels_run == {0: [1], 1: [1, 2], 2: [1, 2], 3: [1, 2]}
    st = outs[:, L.OUT_STATUS].astype(int)
    assert not st[0] & L.STATUS_UNCERTIFIED and not st[1] & L.STATUS_UNCERTIFIED
    assert st[2] & L.STATUS_UNCERTIFIED and not st[3] & L.STATUS_UNCERTIFIED


SCENE = """
name: one point
body: {kind: block, alpha: 0.25}
impact: {lam: 0.0}
pulse: {shape: sine, w_over_p: 8.0, A_ratio: [10.9, 11.1, 14.0]}
"""


def test_simulate_and_sweep_give_one_point_one_answer():
    """No preset named: simulate runs what the sweep runs (one default), certification
    included: the same outcome, status, impacts and times, bit for bit."""
    scene = parse_scene(SCENE)
    assert scene.single_numerics == scene.numerics
    assert scene.numerics.accuracy == "default"
    swept = {k: np.ravel(v) for k, v in sweep_arrays(scene)[0].items()}
    fixed = {a.name: a.values[0] for a in scene.axes}
    for i, A in enumerate((10.9, 11.1, 14.0)):
        run = run_point(scene.point({**fixed, "A_ratio": A}), scene.single_numerics)
        for k in ("outcome", "status", "impacts", "t_overturn", "theta_max_over_alpha",
                  "steps", "event_steps"):
            assert np.array_equal(np.asarray(run.get(k) if run.get(k) is not None
                                             else np.nan, float),
                                  np.asarray(swept[k][i], float), equal_nan=True), (A, k)
    assert (swept["status"] & L.STATUS_REFINED).any()


ADAPTIVE = """
name: the block's mode-1 band, adaptive
body: {kind: block, alpha: 0.25}
impact: {lam: 0.0}
pulse: {shape: sine, w_over_p: {start: 6, stop: 10, num: 9},
        A_ratio: {start: 9.0, stop: 13.0, num: 41}}
"""


def test_adaptive_sweeps_certify_as_the_full_sweep_does():
    """An adaptive sweep computes its points through the sweep's chunks: every computed
    point has the full sweep's result, status bits (refined) included, and some of them
    were close calls."""
    import rocksweep.compute.adaptive as ad
    from rocksweep.compute.dispatch import run_variant
    from rocksweep.scene.grid import Grid

    sc = parse_scene(ADAPTIVE)
    full = sweep_arrays(sc)[0]
    arr, rep = sweep_arrays(sc, jobs=2, chunk_size=3, adaptive=ad.Options())
    c = arr["computed"] > 0
    for k in ("outcome", "status", "steps", "t_overturn"):
        np.testing.assert_array_equal(arr[k][c], full[k][c], err_msg=k)
    assert ((arr["status"][c] & L.STATUS_REFINED) != 0).any()
    np.testing.assert_array_equal(arr["outcome"], full["outcome"])
    # its count of the certification's evaluations: those of its computed points, each
    # once (spare workers compute some early, in chunks split between batches)
    cr = Grid(sc).rows_at(np.flatnonzero(c.ravel()))
    own = run_variant(cr.rows, int(cr.kinds[0]), L.LEVEL_OUTCOME, sc.ground,
                      sc.numerics.refine)
    assert rep.refine_evaluations == own[:, L.OUT_REFINE_EVALS].sum() > 0


def test_a_file_states_what_its_certification_cost(tmp_path):
    """A sweep file's attribute refine_evaluations is the RK4 evaluations its certification
    took: the file's steps + event_steps less those of the same sweep without
    certification (numerics.refine = 0); a near-miss or close call's own
    OUT_REFINE_EVALS is its certified run's evaluations less its bare run's.
    ``rocksweep info`` says it; a file from before the count (no attribute), and one
    resumed from such a file, say it was not recorded."""
    import h5py

    from rocksweep.analysis.summary import format_info, info_dict, read_info
    from rocksweep.compute.session import sweep_file

    scene = parse_scene(SCENE)
    out = sweep_file(scene, tmp_path / "a.h5")
    bare = sweep_file(parse_scene(SCENE, overrides=["numerics.refine=0"]), tmp_path / "b.h5")
    spent = {k: int(r.attrs["steps_total"]) + int(r.attrs["event_steps_total"])
             for k, r in (("cert", out), ("bare", bare))}
    assert out.attrs["refine_evaluations"] == spent["cert"] - spent["bare"] > 0
    assert bare.attrs["refine_evaluations"] == 0
    d = info_dict(read_info(tmp_path / "a.h5"))
    assert d["certification"]["refine_evaluations"] == spent["cert"] - spent["bare"]
    assert d["certification"]["points_refined"] >= 1
    text = "\n".join(format_info(d))
    assert f"certification of close calls: {spent['cert'] - spent['bare']} of them" in text
    n = Numerics.preset("default")
    for A in (10.9, 11.1, 14.0):
        point = Point(BLOCK, 0.0, "sine", 8.0, A)
        bare_out = _bare(point, n)
        run = run_point(point, n, history=False)
        own = bare_out[L.OUT_STEPS] + bare_out[L.OUT_EVENT_STEPS]
        assert run.out[L.OUT_REFINE_EVALS] == (run.out[L.OUT_STEPS]
                                               + run.out[L.OUT_EVENT_STEPS] - own), A
    # a file from before the count: none recorded; a resume of it keeps "not recorded"
    old = tmp_path / "old.h5"
    two = parse_scene(SCENE, overrides=["pulse.A_ratio=[10.9, 11.1]"])
    sweep_file(two, old)
    with h5py.File(old, "r+") as f:
        del f.attrs["refine_evaluations"]
        for name in ("outcome",):  # one point left to compute
            a = f[name][()]
            a.flat[-1] = L.OUTCOME_NOT_RUN
            f[name][...] = a
    d = info_dict(read_info(old))
    assert d["certification"]["refine_evaluations"] is None
    assert "not recorded" in "\n".join(format_info(d))
    again = sweep_file(two, old, resume=True)
    assert again.computed == 1 and again.attrs["refine_evaluations"] == -1
    assert info_dict(read_info(old))["certification"]["refine_evaluations"] is None


def _certify_ladder(ladder: dict, slot: int, levels: int = 3
                    ) -> tuple[np.ndarray, dict[int, list[int]]]:
    """certify on a stand-in kernel whose row i gives ``ladder[i][level]`` = (outcome, the
    result's ``slot``) at each level (5 steps a period at level 0: PAR_CLOSE close_band(5)),
    every run clear of the saddle (margin 0.5 alpha_ref), an overturn at 5 p t. Returns the
    certified result rows and the levels each row was re-run at."""
    n = len(ladder)
    rows = np.zeros((n, L.N_PAR))
    rows[:, L.PAR_CLOSE] = close_band(5)
    rows[:, L.PAR_DT] = 1.0

    def fill(res: np.ndarray, j: int, step: tuple) -> None:
        res[j, [L.OUT_OUTCOME, slot]] = step
        res[j, L.OUT_T_OVERTURN] = 5.0 if step[0] != L.OUTCOME_SAFE else np.nan

    outs = _stand_in(n)
    outs[:, L.OUT_MARGIN] = 0.5
    for i, steps in ladder.items():
        fill(outs, i, steps[0])
    levels_run = {i: [] for i in ladder}

    def run(sub, idx, keep=True):
        res = _stand_in(len(idx))
        res[:, L.OUT_MARGIN] = 0.5
        level = round(-np.log2(sub[0, L.PAR_DT]))
        for j, i in enumerate(idx):
            levels_run[int(i)].append(level)
            fill(res, j, ladder[int(i)][level])
        return res

    certify(rows, outs, run, levels)
    return outs, levels_run


def test_an_overturn_whose_mode_hangs_on_a_graze_is_a_close_call():
    """certify's rule on a stand-in kernel: an overturn clear of the saddle whose rocking
    came within MODE_BAND x PAR_CLOSE of theta = 0 before its first impact (OUT_MODE_GRAZE)
    is re-run finer, and trusted once two runs agree and the finer one's graze is clear of
    its own step's band (which shrinks with the step); one still that close at the last
    level is flagged; a safe run's mode graze, or a wide one, buys no rerun."""
    band = MODE_BAND * close_band(5)  # 5 steps a period: 0.02 alpha_ref
    assert band == pytest.approx(0.02)
    # row -> (outcome, mode graze) at each level; the band at level k is band x 2^(-2.5 k)
    mode2, mode1, safe = L.OUTCOME_MODE2, L.OUTCOME_MODE1, L.OUTCOME_SAFE
    ladder = {0: [(mode2, 0.05 * band), (mode1, 0.3 * band), (mode1, 0.3 * band)],
              1: [(mode1, 0.01 * band)] + [(mode1, 1e-6 * band)] * 3,
              2: [(safe, 0.01 * band)],
              3: [(mode2, 2.0 * band)]}
    outs, levels_run = _certify_ladder(ladder, L.OUT_MODE_GRAZE)
    # 0: mode 2 at its own step, mode 1 at 1 and 2 with a graze clear of level 2's band
    # (0.3 band > band x 2^-5): certified mode 1 there
    assert levels_run == {0: [1, 2], 1: [1, 2, 3], 2: [], 3: []}
    st = outs[:, L.OUT_STATUS].astype(int)
    assert outs[0, L.OUT_OUTCOME] == mode1 and not st[0] & L.STATUS_FLAGGED
    assert st[1] & L.STATUS_UNCERTIFIED  # a knife edge of the mode at every level
    assert not st[2] & L.STATUS_REFINED and not st[3] & L.STATUS_REFINED


def test_a_run_that_grazed_an_impact_while_the_ground_moved_is_a_close_call():
    """certify's rule on a stand-in kernel: a run clear of the saddle, safe or overturned,
    that came within GRAZE_BAND x PAR_CLOSE of an impact it did not make while the ground
    moved (OUT_GRAZE) is re-run finer, and trusted once two runs agree and the finer one's
    graze clears its own step's band (band x 2^-2.5 a level) or converged (``grazed``: it
    moved by less than itself between the two runs: the true path's graze, whose touch-down
    at theta' ~ 0, or none, leaves nearly one state); a graze wider than the band buys
    nothing."""
    band = GRAZE_BAND * close_band(5)  # 5 steps a period: GRAZE_MARGIN
    assert band == pytest.approx(GRAZE_MARGIN)
    safe, mode1 = L.OUTCOME_SAFE, L.OUTCOME_MODE1
    # row -> (outcome, graze) at each level; level k's band is band x 2^(-2.5 k)
    ladder = {0: [(safe, 0.01 * band), (mode1, 0.5 * band), (mode1, 0.5 * band)],
              1: [(mode1, 0.9 * band), (mode1, 0.9 * band), (mode1, np.inf)],
              2: [(safe, 0.01 * band)] + [(safe, 1e-4 * band)] * 3,
              3: [(safe, 1.01 * band)],
              4: [(mode1, 2.0 * band)]}
    outs, levels_run = _certify_ladder(ladder, L.OUT_GRAZE)
    # 0: safe grazing at its own step, mode 1 at levels 1 and 2 (graze 0.5 band, clear of
    # level 2's band, 2^-5 band): certified mode 1 at level 2
    # 1: mode 1 grazing at its own step, mode 1 at level 1 with a graze (0.9 band) clear of
    # level 1's band (2^-2.5 band): certified there
    # 2: safe at every level, grazing within each level's band: 1e-4 band at level 1 (it
    # moved by more than itself from 0.01 band), again at level 2 (converged): certified
    # 3, 4: grazes at or past the band: no rerun
    assert levels_run == {0: [1, 2], 1: [1], 2: [1, 2], 3: [], 4: []}
    st = outs[:, L.OUT_STATUS].astype(int)
    assert outs[0, L.OUT_OUTCOME] == mode1 and not st[0] & L.STATUS_FLAGGED
    assert outs[1, L.OUT_OUTCOME] == mode1 and not st[1] & L.STATUS_FLAGGED
    assert outs[2, L.OUT_OUTCOME] == safe and st[2] & L.STATUS_REFINED
    assert not st[2] & L.STATUS_FLAGGED
    assert not st[3] & L.STATUS_REFINED and not st[4] & L.STATUS_REFINED


@pytest.mark.parametrize("mu", [math.nan, 5.0])
def test_the_first_impacts_depth_is_its_speed_squared(mu):
    """The kernel's OUT_MODE_GRAZE of a rigid block released at rest from theta0 with no
    ground motion: its first impact comes at the speed energy conservation gives,
    theta'^2 / 2 = cos(alpha - theta0) - cos(alpha) (p t units), so the mode graze, (theta' /
    alpha)^2 / 2, is (cos(alpha - theta0) - cos(alpha)) / alpha^2 (before it the rocking
    only falls toward theta = 0: no dip). At 80 steps a period (four refinements) the run
    gives it to 1e-6; at 5, within 3%. The same on a base that may slide, where friction
    (mu 5) holds the corner: the sliding base's loop keeps the mode graze too."""
    alpha = 0.2
    body = BlockBody(alpha=alpha, inertia=4.0 / 3.0)
    pt = Point(body, 0.0, "sine", 1.0, 1.0, mu=mu)
    row = point_row(pt, Numerics.preset("default"))[None, :]
    row = row.copy()
    row[0, L.PAR_TPULSE] = 0.0  # no ground motion
    row[0, L.PAR_TO_REST] = 1.0  # on to the impact (a still block is decided at once)
    kind, contact = kernel_kind(body), kernel_contact(mu)
    warm_up(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE, contact)
    for theta0 in (0.02, 0.1, 0.15):
        row[0, L.PAR_THETA0] = theta0
        want = (np.cos(alpha - theta0) - np.cos(alpha)) / alpha**2
        for level, rel in ((0, 0.03), (4, 1e-6)):
            out = np.empty((1, L.N_OUT))
            r = np.ascontiguousarray(refined_rows(row, level) if level else row)
            chunk_kernel(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE, contact)(r, out)
            assert out[0, L.OUT_IMPACTS] >= 1
            assert out[0, L.OUT_MODE_GRAZE] == pytest.approx(want, rel=rel)


@pytest.mark.parametrize("mu", [math.nan, 5.0])
def test_the_shallowest_impact_while_the_ground_moves_is_kept(mu):
    """The kernel's OUT_SHALLOW of a rigid block (alpha 0.2) released at rest from theta0 =
    alpha/2 while a ground of zero amplitude 'moves' up to t_pulse. Linearized (theta(t) =
    alpha - (alpha - theta0) cosh t, p t units) the first impact comes at arccosh(2) = 1.32
    p t, the second at ~3.6 and the third at ~5.6 (restitution ~0.94). A ground still from
    1 p t on: no impact while it moves (inf). Moving to 2.5 p t: the first impact's depth,
    (cos(alpha - theta0) - cos alpha) / alpha^2 by energy conservation (the mode graze's).
    To 5 p t: the second's, shallower than the first (the shallowest, not the deepest).
    The same on a base that may slide, friction (mu 5) holding the corner."""
    alpha, theta0 = 0.2, 0.1
    body = BlockBody(alpha=alpha, inertia=4.0 / 3.0)
    row = point_row(Point(body, 0.0, "sine", 1.0, 1.0, mu=mu), Numerics.preset("default"))
    row = refined_rows(row[None, :], 4)  # 80 steps a period
    row[0, L.PAR_AMP] = 0.0
    row[0, L.PAR_TO_REST] = 1.0  # on to the impact (a still block is decided at once)
    row[0, L.PAR_THETA0] = theta0
    kind, contact = kernel_kind(body), kernel_contact(mu)
    warm_up(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE, contact)
    depth = {}
    for t_pulse in (1.0, 2.5, 5.0):
        row[0, L.PAR_TPULSE] = t_pulse
        out = np.empty((1, L.N_OUT))
        chunk_kernel(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE, contact)(row, out)
        assert out[0, L.OUT_IMPACTS] >= 3
        depth[t_pulse] = out[0, L.OUT_SHALLOW]
        first = out[0, L.OUT_MODE_GRAZE]
    want = (np.cos(alpha - theta0) - np.cos(alpha)) / alpha**2
    assert first == pytest.approx(want, rel=1e-6)
    assert depth[1.0] == np.inf
    assert depth[2.5] == pytest.approx(want, rel=1e-6)
    assert 0.5 * want < depth[5.0] < 0.95 * want


def test_a_shallow_impact_near_the_saddle_is_a_close_call():
    """certify's rule on a stand-in kernel: a run that made an impact shallower than
    GRAZE_BAND x PAR_CLOSE while the ground moved (OUT_SHALLOW) is re-run finer where it
    came within PATH_REACH of the saddle, safe or overturned; farther from it, or with
    every impact deeper than the band, it is not."""
    band = GRAZE_BAND * close_band(5)
    safe, mode1 = L.OUTCOME_SAFE, L.OUTCOME_MODE1
    # (outcome, margin, shallowest impact) of each first run; its finer runs all mode 1
    first = [(safe, 0.5 * PATH_REACH, 0.5 * band), (mode1, 0.5 * PATH_REACH, 0.5 * band),
             (safe, 1.5 * PATH_REACH, 0.5 * band), (safe, 0.5 * PATH_REACH, 2.0 * band)]
    rows = np.zeros((4, L.N_PAR))
    rows[:, L.PAR_CLOSE] = close_band(5)
    rows[:, L.PAR_DT] = 1.0
    outs = _stand_in(4)
    outs[:, L.OUT_OUTCOME], outs[:, L.OUT_MARGIN], outs[:, L.OUT_SHALLOW] = np.array(first).T
    outs[:, L.OUT_T_OVERTURN] = np.where(outs[:, L.OUT_OUTCOME] == mode1, 5.0, np.nan)
    seen = []

    def run(sub, idx, keep=True):
        seen.append(idx.tolist())
        res = _stand_in(len(idx))
        res[:, L.OUT_OUTCOME] = mode1
        res[:, L.OUT_MARGIN] = 0.5
        res[:, L.OUT_T_OVERTURN] = 5.0
        return res

    certify(rows, outs, run, 3)
    assert seen[0] == [0, 1]
    assert outs[0, L.OUT_OUTCOME] == mode1  # the finer runs' class
    assert outs[2, L.OUT_OUTCOME] == safe and outs[3, L.OUT_OUTCOME] == safe
    assert not int(outs[2, L.OUT_STATUS]) & L.STATUS_REFINED


def test_a_slide_rock_run_near_the_saddle_is_a_close_call():
    """certify's rule on a stand-in kernel: a run of a base that may slide which rocked on
    a slipping corner (OUT_REGIME's slide-rock bit) is re-run finer where it came within
    PATH_REACH of the saddle; one that only rested, slid flat and rocked on a stuck corner,
    one farther from the saddle, and a base without sliding (OUT_REGIME NaN) are not."""
    bit = {w: 1 << c for w, c in PHASE_CODE.items()}
    slide_rock = bit[REST] | bit[ROCK] | bit[SLIDE_ROCK]
    first = [(slide_rock, 0.5 * PATH_REACH), (bit[REST] | bit[SLIDE] | bit[ROCK], 0.5 * PATH_REACH),
             (slide_rock, 1.5 * PATH_REACH), (np.nan, 0.5 * PATH_REACH)]
    rows = np.zeros((4, L.N_PAR))
    rows[:, L.PAR_CLOSE] = close_band(5)
    rows[:, L.PAR_DT] = 1.0
    outs = _stand_in(4)
    outs[:, L.OUT_REGIME], outs[:, L.OUT_MARGIN] = np.array(first).T
    seen = []

    def run(sub, idx, keep=True):
        seen.append(idx.tolist())
        res = _stand_in(len(idx))
        res[:, L.OUT_MARGIN] = 0.5
        return res

    certify(rows, outs, run, 3)
    assert seen[0] == [0]
    assert int(outs[0, L.OUT_STATUS]) & L.STATUS_REFINED
    assert not any(int(outs[i, L.OUT_STATUS]) & L.STATUS_REFINED for i in (1, 2, 3))


def test_a_slide_rock_path_the_coarse_step_misses_is_certified():
    """Threshold seed 39 at mu 0.38 (``scripts/threshold_sample.py --mu 0.15 1.5``): under a
    cosine of A 14.9 the base slide-rocks; at 5 steps a period the body falls in mode 1
    after 1 impact with margin 0.114 alpha_ref (outside the overturn band), where 10 steps
    a period and finer, and the sliding reference, rock to rest after 34-36 impacts. As a
    slide-rock run near the saddle (``certify.slide_rock_close``) it is re-run, and the
    certified run takes the reference's class."""
    body = FlexibleBody(wn_over_p=7.313953952175054, zeta=0.0578493875902795,
                        alpha_cg=0.24101584287064365, alpha_A=0.575281851740087,
                        mA_over_m=0.9388866932687785, IA_ratio=0.4920433916277761)
    pt = Point(body, 0.41744305178839125, "cosine", 5.156788109035284, 14.92266972835969,
               mu=0.37755136239301296)
    ref, bare, certified = _sliding_runs(pt)
    assert not ref["status"] and ref["outcome"] == L.OUTCOME_SAFE
    assert bare[L.OUT_OUTCOME] == L.OUTCOME_MODE1
    assert certified[L.OUT_OUTCOME] == ref["outcome"]


def test_a_run_that_lifted_off_takes_its_class_from_two_refined_runs():
    """certify's rule on a stand-in kernel: a run whose rocking corner's normal force fell
    to zero (STATUS_LIFTS_OFF), far from every band (margin inf or 0.3 alpha_ref), is re-run
    finer; within PATH_REACH of the saddle its class comes from two refined runs (levels
    1 and 2), not from level 1's agreement with it; the same ladder without the lift-off
    is not re-run."""
    rows = np.zeros((4, L.N_PAR))
    rows[:, L.PAR_CLOSE] = close_band(5)
    rows[:, L.PAR_DT] = 1.0
    m1, m2, safe = L.OUTCOME_MODE1, L.OUTCOME_MODE2, L.OUTCOME_SAFE
    off, none = (L.STATUS_LIFTS_OFF, 0.0), (0, np.inf)  # (status, OUT_LIFT_ANGLE)
    ladder = {  # per point and level 0..3: (outcome, margin, overturning time, status,
        # angle), a lift-off while the ground moves (angle 0) or none
        # as sliding threshold seed 58's body under a cosine of A 15.3: mode 2 at 5 and 10
        # steps a period, mode 1 after 2 impacts from 20 on
        0: [(m2, 0.31, 5.68, *off), (m2, 0.28, 5.69, *off), (m1, 0.017, 9.07, *off),
            (m1, 0.015, 9.07, *off)],
        # safe with no approach at 5 steps a period, mode 1 from 10 on
        1: [(safe, np.inf, np.nan, *off), (m1, 0.5, 7.62, *off), (m1, 0.5, 7.62, *off)],
        2: [(m2, 0.31, 5.68, *none), (m2, 0.28, 5.69, *none), (m1, 0.017, 9.07, *none)],
        # beyond PATH_REACH (no approach): level 1's agreement is enough
        3: [(m2, np.inf, 1.87, *off), (m2, np.inf, 1.87, *off), (m1, np.inf, 1.2, *off)],
    }
    outs, levels_run = _run_ladder(rows, ladder, 3,
                                   [L.OUT_OUTCOME, L.OUT_MARGIN, L.OUT_T_OVERTURN,
                                    L.OUT_STATUS, L.OUT_LIFT_ANGLE])
    assert levels_run == {0: [1, 2, 3], 1: [1, 2], 2: [], 3: [1]}
    assert outs[:, L.OUT_OUTCOME].tolist() == [m1, m1, m2, m2]
    st = outs[:, L.OUT_STATUS].astype(int)
    assert (st[[0, 1, 3]] & L.STATUS_REFINED).all() and not st[2] & L.STATUS_REFINED
    assert not (st & L.STATUS_UNCERTIFIED).any()
    # the no-slip model's lift-off (its contact outputs; OUT_REGIME NaN) is not the rule's,
    # nor a falling body's: after the ground stopped, LIFT_PAST alpha_ref or more past
    # theta = 0 (OUT_LIFT_ANGLE; 0: one while the ground moved)
    lifts = _stand_in(4)
    lifts[:, L.OUT_STATUS] = L.STATUS_LIFTS_OFF
    lifts[1, L.OUT_REGIME] = np.nan
    lifts[:, L.OUT_LIFT_ANGLE] = [0.0, 0.0, 0.999 * LIFT_PAST, LIFT_PAST]
    assert lifted_off(lifts).tolist() == [True, False, True, False]


FIG3A_BODY = FlexibleBody(wn_over_p=2.43, zeta=0.05, alpha_cg=0.15, alpha_A=0.28,
                          mA_over_m=0.47, IA_ratio=0.56)


@pytest.mark.parametrize(("a_ratio", "during"), [(0.8181818181818182, False),
                                                 (1.5363636363636366, True)])
def test_a_lift_off_s_angle_is_kept(a_ratio, during):
    """The kernel's OUT_LIFT_ANGLE: Figure 3(a)'s body on a base at mu 0.3, lam 0, a sine
    at w/p 1.152 (its pulse lasts 5.45 p t). At A 0.82 it falls in mode 1 after the pulse
    (7.54 p t) and its corner lifts off on the way over, after the ground stopped: the
    angle is |theta| / alpha_cg there, past LIFT_PAST and at most pi / 2 / alpha_cg (the
    run ends on its side), and the certification leaves the run alone. At A 1.54 it falls
    in mode 2 during the pulse (4.50 p t): a lift-off while the ground moves, 0, which the
    certification re-runs."""
    pt = Point(FIG3A_BODY, 0.0, "sine", 1.1522727272727271, a_ratio, mu=0.3)
    bare = _bare(pt, Numerics.preset("default"))
    assert int(bare[L.OUT_STATUS]) & L.STATUS_LIFTS_OFF
    fell_after = bare[L.OUT_T_OVERTURN] > 2 * math.pi / 1.1522727272727271
    assert fell_after != during
    angle = bare[L.OUT_LIFT_ANGLE]
    if during:
        assert angle == 0.0
    else:
        assert LIFT_PAST < angle <= (math.pi / 2) / 0.15 + 1e-9
    assert lifted_off(bare[None]).tolist() == [during]


def test_a_lift_off_missed_by_a_hair_is_certified():
    """Sliding threshold seed 55 (``scripts/threshold_sample.py --mu 0.15 1.5``): under a
    cosine of A 15.4 on a base at mu 0.66, at 5 steps a period the slipping corner's normal
    force comes within 0.0087 M g of zero (below ``slide_loop.LIFT_NEAR``) and the body
    falls in mode 1 after 2 impacts, where 10 steps a period and finer, and the sliding
    reference, lift off and are flung over in mode 2. The near lift-off is kept (OUT_LIFT_
    ANGLE 0: while the ground moves, not flagged ``lifts_off``), and the certified run
    takes the reference's class."""
    body = FlexibleBody(wn_over_p=5.739779894600782, zeta=0.009244754900421282,
                        alpha_cg=0.2444371655176647, alpha_A=0.19856112740667958,
                        mA_over_m=0.47599883287641626, IA_ratio=0.8240761237198564)
    pt = Point(body, 0.4550727763510952, "cosine", 2.9105671717123416, 15.418119666858884,
               mu=0.663152819894955)
    bare = _bare(pt, Numerics.preset("default"))
    assert bare[L.OUT_OUTCOME] == L.OUTCOME_MODE1
    assert not int(bare[L.OUT_STATUS]) & L.STATUS_LIFTS_OFF
    assert bare[L.OUT_LIFT_ANGLE] == 0.0
    ref, _, certified = _sliding_runs(pt)
    assert ref["outcome"] == L.OUTCOME_MODE2
    assert certified[L.OUT_OUTCOME] == ref["outcome"]


def test_a_mode_2_that_nearly_uplifted_before_is_a_close_call():
    """certify's rule on a stand-in kernel: a mode 2 whose body came within LIFT_BAND x
    PAR_CLOSE of an uplift it did not make (OUT_LIFT_GRAZE, before its first uplift) is
    re-run finer; once its finer run (mode 1 after an uplift by a hair, whose impact is
    as shallow: OUT_MODE_GRAZE ~ 0) agrees with none, the point is flagged; a mode 2
    whose dip clears the band, and a safe run or a mode 1 with the same dip, buy no
    rerun."""
    rows = np.zeros((4, L.N_PAR))
    rows[:, L.PAR_CLOSE] = close_band(5)
    rows[:, L.PAR_DT] = 1.0
    band = LIFT_BAND * close_band(5)  # 5 steps a period: 2e-3 of M g b
    assert band == pytest.approx(2e-3)
    mode2, mode1, safe = L.OUTCOME_MODE2, L.OUTCOME_MODE1, L.OUTCOME_SAFE
    outs = _stand_in(4)
    outs[:, L.OUT_MARGIN] = 0.5
    outs[:, L.OUT_T_OVERTURN] = 5.0
    outs[:, L.OUT_OUTCOME] = (mode2, mode2, safe, mode1)
    outs[:, L.OUT_LIFT_GRAZE] = (0.02 * band, 2.0 * band, 0.02 * band, 0.02 * band)
    outs[3, L.OUT_MODE_GRAZE] = 1.0  # a mode 1 with deep impacts
    seen = []

    def run(sub, idx, keep=True):
        seen.extend(int(i) for i in idx)
        res = _stand_in(len(idx))
        res[:, L.OUT_MARGIN] = 0.5
        res[:, L.OUT_T_OVERTURN] = 5.0
        res[:, L.OUT_OUTCOME] = mode1
        res[:, L.OUT_MODE_GRAZE] = 1e-9  # the hair's impact
        return res

    certify(rows, outs, run, 3)
    assert set(seen) == {0}
    st = outs[:, L.OUT_STATUS].astype(int)
    assert st[0] & L.STATUS_UNCERTIFIED
    assert not (st[1:] & L.STATUS_REFINED).any()


@pytest.mark.parametrize("mu", [math.nan, 5.0])
def test_a_blocks_least_uplift_gap_is_one_less_its_amplitude_ratio(mu):
    """The kernel's OUT_LIFT_GRAZE of a rigid block on the ground under a sine pulse too
    weak to uplift it (A_ratio < 1): in full contact the uplift function is M g b - s M
    a_g h_cg, so its least value over the pulse, over M g b, is 1 - A_ratio (A = A_ratio
    g tan alpha, tan alpha = b / h_cg), reached at the pulse's peaks, inside steps. At 5
    steps a period the step's cubic gives it to 1e-3 of M g b, at 80 to 1e-8. With
    A_ratio > 1 the block uplifts and no dip is kept (inf). The same on a base that may
    slide where friction (mu 5) holds it: its loop screens the rest phase's uplift
    functions inside a step as the no-slip loop does (``slide_events._lift_dip``)."""
    body = BlockBody(alpha=0.2, inertia=4.0 / 3.0)
    kind, contact = kernel_kind(body), kernel_contact(mu)
    warm_up(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE, contact)
    for a_ratio in (0.3, 0.9, 0.999):
        row = point_row(Point(body, 0.0, "sine", 3.0, a_ratio, mu=mu),
                        Numerics.preset("default"))
        for level, tol in ((0, 1e-3), (4, 1e-8)):
            out = np.empty((1, L.N_OUT))
            r = np.ascontiguousarray(refined_rows(row[None, :], level))
            chunk_kernel(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE, contact)(r, out)
            assert out[0, L.OUT_UPLIFTS] == 0
            assert abs(out[0, L.OUT_LIFT_GRAZE] - (1.0 - a_ratio)) < tol
    row = point_row(Point(body, 0.0, "sine", 3.0, 1.5, mu=mu), Numerics.preset("default"))
    out = np.empty((1, L.N_OUT))
    chunk_kernel(kind, L.LEVEL_OUTCOME, L.GROUND_PULSE, contact)(row[None, :].copy(), out)
    assert out[0, L.OUT_UPLIFTS] >= 1 and out[0, L.OUT_LIFT_GRAZE] == np.inf


def test_a_phase_no_step_split_is_the_longest_single_step_phase_of_the_history():
    """OUT_UNSPLIT of an overturn against the run's own history: the longest phase (event
    to event: the history's phase changes) before the fall that is shorter than the step
    in effect at its start (dt_on while the pulse acts, dt after: the first step after its
    start ended it), over that step. Seed 116's chatter: the phase of 0.0363 p t is one
    step at 5 and at 10 steps a period (0.995 of the step at 10)."""
    from rocksweep.compute.dispatch import run_variant

    row = point_row(CHATTER_116, Numerics.preset("default"))[None, :]
    found = []
    for level in (0, 1):
        rows = np.ascontiguousarray(refined_rows(row, level) if level else row)
        hist = [None]
        out = run_variant(rows, kernel_kind(CHATTER_116.body), L.LEVEL_OUTCOME,
                          L.GROUND_PULSE, 0, histories=hist)[0]
        assert out[L.OUT_OUTCOME] == L.OUTCOME_MODE1  # both fall: every phase counts
        h = hist[0][:int(out[L.OUT_HIST_ROWS])]
        t, s = h[:, L.HIST_T], h[:, L.HIST_PHASE]
        change = t[np.flatnonzero(np.diff(s) != 0) + 1]
        starts = np.concatenate(([0.0], change[:-1]))
        tau = change - starts
        step = np.where(starts < rows[0, L.PAR_TPULSE], rows[0, L.PAR_DT_ON], rows[0, L.PAR_DT])
        short = tau < step
        expected = (tau[short] / step[short]).max() if short.any() else 0.0
        assert out[L.OUT_UNSPLIT] == pytest.approx(expected, rel=1e-12)
        found.append(out[L.OUT_UNSPLIT])
    assert found[0] > UNSPLIT_SHARE and found[1] > 0.99


UNSPLIT_SLOTS = [L.OUT_OUTCOME, L.OUT_T_OVERTURN, L.OUT_MARGIN, L.OUT_UNSPLIT]


def test_a_safe_run_s_agreement_over_a_phase_no_step_split_certifies_nothing():
    """certify on a stand-in kernel: safe runs clear of the saddle at levels 0 and 1
    (margins 0.0055 and 0.0047 alpha_ref at PAR_CLOSE 0.1, settled and clear, as seed 37's):
    one whose level-1 run took a phase of 0.9 of its step in one step before its approach
    goes on to level 2 (where its steps split it), one whose longest such phase was 0.4 of
    its step is kept at level 1, and so is one that took such a phase but passed the
    saddle beyond its band (0.05 alpha_ref, PAR_CLOSE 0.0177 at level 1)."""
    safe = L.OUTCOME_SAFE, np.nan
    # (outcome, overturning time, margin, OUT_UNSPLIT) of each row at levels 0, 1, 2
    ladder = {0: [(*safe, 0.0055, 0.7), (*safe, 0.0047, 0.9), (*safe, 0.0047, 0.3)],
              1: [(*safe, 0.0055, 0.7), (*safe, 0.0047, 0.4), (*safe, 0.0047, 0.4)],
              2: [(*safe, 0.0100, 0.7), (*safe, 0.0500, 0.9), (*safe, 0.0500, 0.9)]}
    rows = np.zeros((3, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.1
    rows[:, L.PAR_DT] = 1.0
    outs, levels_run = _run_ladder(rows, ladder, 3, UNSPLIT_SLOTS)
    assert levels_run == {0: [1, 2], 1: [1], 2: [1]}
    assert (outs[:, L.OUT_OUTCOME] == L.OUTCOME_SAFE).all()


def test_converged_margins_do_not_certify_a_run_with_a_phase_no_step_split():
    """certify on a stand-in kernel: two overturns whose margins converged between levels 0
    and 1 inside the finer run's band (0.0150 -> 0.0152 alpha_ref at PAR_CLOSE 0.1, as
    seed 116's): one whose level-1 run took a phase of 0.99 of its step in one step goes on
    to level 2 (where its steps split it), one whose longest such phase was 0.3 of its step
    is certified at level 1."""
    rows = np.zeros((2, L.N_PAR))
    rows[:, L.PAR_CLOSE] = 0.1
    rows[:, L.PAR_DT] = 1.0
    fell = L.OUTCOME_MODE1, 5.0
    # (outcome, overturning time, margin, OUT_UNSPLIT) of each row at levels 0, 1, 2
    ladder = {0: [(*fell, 0.0150, 0.6), (*fell, 0.0152, 0.99), (*fell, 0.0152, 0.3)],
              1: [(*fell, 0.0150, 0.6), (*fell, 0.0152, 0.3), (*fell, 0.0152, 0.3)]}
    outs, levels_run = _run_ladder(rows, ladder, 3, UNSPLIT_SLOTS)
    assert levels_run == {0: [1, 2], 1: [1]}
    status = outs[:, L.OUT_STATUS].astype(np.int64)
    assert not (status & L.STATUS_UNCERTIFIED).any()
