"""Hard case 7: e = 0 and e < 0 (full contact follows) and e > 1 (energy gained at impact)."""

import math

import numpy as np
import pytest
from bodies import BODY2
from hardkit import assert_sane, kernel_events, reference_events, run

from rocksweep.kernel.equations import restitution as kernel_restitution
from rocksweep.kernel.layout import PAR_LAM
from rocksweep.physics.bodies import BlockBody, impact_energy_loss, restitution
from rocksweep.physics.points import Point, body_row

pytestmark = pytest.mark.hard

OUTCOME = {0: "safe", 1: "mode1", 2: "mode2"}
# A stocky block: I_O / (M b^2) = 4 / (3 sin^2 alpha) = 16/9, so e = 0 at lam_0 = 2/9
# (e = (I_O - M b^2 (2 - lam)) / (I_O - lam M b^2)) and e < 0 below it.
BLOCK = BlockBody(alpha=math.pi / 3)
LAM0_BLOCK = 2.0 - BLOCK.I_O / (BLOCK.M * BLOCK.b**2)
# Table 2's stocky flexible body (Figure 2); its lam_0 is < -0.2 for |u| <= 2 u_cr, so
# lam = -1 gives e < 0 at every impact; near lam = 1 and with large |u|, e > 1.
FIG2 = BODY2

NON_POSITIVE = {
    "block e = 0, uplift again at once": (BLOCK, LAM0_BLOCK, "sine", 2.0, 1.5),
    "block e = 0, uplift later": (BLOCK, LAM0_BLOCK, "cosine", 2.0, 1.5),
    "block e < 0": (BLOCK, 0.0, "cosine", 2.0, 1.5),
    "flexible e < 0": (FIG2, -1.0, "sine", 5.0, 6.0),
    "flexible e < 0, overturns": (FIG2, -1.0, "cosine", 3.0, 3.0),
}


def test_e_is_exactly_zero_at_the_blocks_lam_0():
    """Guards against the e = 0 case being tested with an e that is not exactly 0."""
    row = body_row(BLOCK)
    row[PAR_LAM] = LAM0_BLOCK
    assert kernel_restitution(1, 0.0, row, False) == 0.0
    assert float(restitution_block(LAM0_BLOCK)) == pytest.approx(0.0, abs=1e-15)
    row[PAR_LAM] = 0.0
    assert kernel_restitution(1, 0.0, row, False) == pytest.approx(restitution_block(0.0))
    assert restitution_block(0.0) < 0.0


def restitution_block(lam: float) -> float:
    """Angular momentum about the impulse point, uniform block (independent of the kernel)."""
    i_o, mb2 = 4.0 / 3.0 * BLOCK.R**2, BLOCK.b**2  # M = 1
    return (i_o - mb2 * (2.0 - lam)) / (i_o - lam * mb2)


@pytest.mark.parametrize("name", list(NON_POSITIVE))
def test_non_positive_e_ends_in_full_contact_and_rechecks_uplift(name):
    """Guards against rocking on after an impact with e <= 0, or a missed uplift right after it."""
    b, lam, shape, w, a_ratio = NON_POSITIVE[name]
    p = Point(b, lam, shape, w, a_ratio)
    r = run(p)
    assert_sane(r)
    s = r.summary()
    impacts = [e for e in kernel_events(r) if e.kind == "impact"]
    assert impacts
    assert all(e.theta_dot_after == 0.0 for e in impacts)  # no rocking goes on
    assert s["returns_to_contact"] == r.impacts and s["e_max"] == 0.0
    assert "settled" not in r.status  # the contact comes from e <= 0, not the rest rate
    h = r.history
    if b.rigid:  # the whole rocking energy is lost: the block is at rest after each impact
        for i in np.flatnonzero(np.diff(h["t"]) == 0.0):
            if h["phase"][i] != 0 and h["theta_dot"][i + 1] == 0.0:
                assert h["E"][i + 1] == 0.0
    # full contact, uplift checked at once and later: the same actions as the reference
    res, ref = reference_events(p)
    assert r.outcome == OUTCOME[res["outcome"]]
    assert [(e.kind, e.s_before, e.s_after) for e in kernel_events(r)] == [
        (e.kind, e.s_before, e.s_after) for e in ref]
    for a, c in zip(kernel_events(r), ref, strict=True):
        assert a.t == pytest.approx(c.t, abs=5e-3)


@pytest.mark.parametrize("lam, shape, w, a_ratio", [(0.95, "sine", 4.0, 3.0),
                                                    (0.98, "sine", 4.0, 2.0)])
def test_e_above_1_records_the_energy_gained_and_stays_finite(lam, shape, w, a_ratio):
    """Guards against energy gained at impact (e > 1) going unrecorded or blowing the run up."""
    p = Point(FIG2, lam, shape, w, a_ratio)
    r = run(p)
    assert_sane(r)
    assert {"e_above_1", "energy_gain"} <= set(r.status)
    h = r.history
    # every rocking-to-rocking impact, checked against eq. (1) and eq. (6) of the paper
    # (rocksweep.physics.bodies, written independently of the kernel): e, theta'^+ and the energy
    e_all, gained, n_gaining = [], 0.0, 0
    for i in np.flatnonzero(np.diff(h["t"]) == 0.0):
        s0, s1 = int(h["phase"][i]), int(h["phase"][i + 1])
        if s0 == 0 or s1 != -s0:
            continue
        u, w_minus = h["u"][i], h["theta_dot"][i]
        e = float(restitution(FIG2, lam, u, s0 == 1))
        assert h["theta_dot"][i + 1] == pytest.approx(e * w_minus, rel=1e-12, abs=1e-15)
        e_all.append(e)
        e_d = float(impact_energy_loss(FIG2, e, u, w_minus, s0 == 1))
        if e_d < 0.0:
            gained -= e_d
            n_gaining += 1
    s = r.summary()
    assert max(e_all) > 1.0 and s["e_max"] == pytest.approx(max(e_all), rel=1e-12)
    assert n_gaining >= 1 and s["energy_gaining_impacts"] == n_gaining
    assert s["impact_gain_over_Eref"] * FIG2.E_ref == pytest.approx(gained, rel=1e-9)
    res = reference_events(p)[0]
    assert r.outcome == OUTCOME[res["outcome"]]
    assert res["e_max"] == pytest.approx(s["e_max"], rel=1e-2)
