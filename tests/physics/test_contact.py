"""Where the model holds: ground reactions, friction demand, lift-off, impulses.

The reactions are derived here independently with sympy from the masses' positions in the
ground frame (``test_derivations._positions``, the kinematics of the equations of motion):
H = sum m_i X_i'', N = sum m_i (Y_i'' + g), differentiated twice, with the kernel's
accelerations theta'', u'' substituted. Impulses from the masses' velocities (the same
positions differentiated once) before and after the kernel's impact map.
"""

import json
import math

import h5py
import numpy as np
import pytest
import sympy as sp
from bodies import FIG3_YAML, table3
from test_derivations import _positions

from rocksweep.cli.main import main
from rocksweep.compute.dispatch import history_capacity
from rocksweep.errors import SceneError
from rocksweep.kernel import chunk_kernel, contact, point_kernel
from rocksweep.kernel import equations as eq
from rocksweep.kernel import layout as L
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, FlexibleBody
from rocksweep.physics.points import Point, point_row
from rocksweep.scene.parse import parse_scene

t = sp.symbols("t")
m, mA, h, hA, b, g = sp.symbols("m m_A h h_A b g", positive=True)
TH, W, UU, V, THDD, UDD, XGDD, S = sp.symbols("th w uu v thdd udd xgdd s")


@pytest.fixture(scope="module")
def reactions_sympy():
    """(H, N) as functions of (th, w, uu, v, thdd, udd, xgdd, s, m, m_A, h, h_A, b, g)."""
    theta, u, xg = sp.Function("theta")(t), sp.Function("u")(t), sp.Function("x_g")(t)
    P, A = _positions(theta, u, xg, S * b)
    acc_P, acc_A = P.diff(t, 2), A.diff(t, 2)
    H = m * acc_P[0] + mA * acc_A[0]
    N = m * (acc_P[1] + g) + mA * (acc_A[1] + g)
    subs = [(theta.diff(t, 2), THDD), (u.diff(t, 2), UDD), (xg.diff(t, 2), XGDD),
            (theta.diff(t), W), (u.diff(t), V), (theta, TH), (u, UU)]
    H, N = H.subs(subs), N.subs(subs)
    assert not (H.has(xg) or N.has(xg))  # only the ground's acceleration enters
    args = (TH, W, UU, V, THDD, UDD, XGDD, S, m, mA, h, hA, b, g)
    return sp.lambdify(args, H, "math"), sp.lambdify(args, N, "math")


@pytest.fixture(scope="module")
def velocities_sympy():
    """Velocities (vP, vA) at theta = 0 as functions of (w, uu, v, s, h, h_A, b)."""
    theta, u = sp.Function("theta")(t), sp.Function("u")(t)
    P, A = _positions(theta, u, 0, S * b)
    subs = [(theta.diff(t), W), (u.diff(t), V), (theta, 0), (u, UU)]
    vP, vA = P.diff(t).subs(subs), A.diff(t).subs(subs)
    args = (W, UU, V, S, h, hA, b)
    return sp.lambdify(args, [vP[0], vP[1], vA[0], vA[1]], "math")


def _row(body, A=3.0, w=2.0, shape="sine", lam=0.2, mu=math.nan, numerics=None):
    return point_row(Point(body, lam, shape, w, A, mu=mu),
                     numerics or Numerics.preset("default"))


def _run(body, level=L.LEVEL_CONTACT, **kw):
    row = _row(body, **kw)
    out = np.empty((1, L.N_OUT))
    kind = (L.KIND_RIGID if body.rigid else
            L.KIND_FLEXIBLE if body.zeta > 0 else L.KIND_FLEXIBLE_UNDAMPED)
    chunk_kernel(kind, level)(row[None], out)
    return out[0]


def test_rocking_reactions_equal_sympy_derivation(body_fig3, reactions_sympy):
    """Both corners, random states: the kernel's H and N = Newton for the two masses."""
    f_H, f_N = reactions_sympy
    bd = body_fig3
    row = _row(bd)
    rng = np.random.default_rng(14)
    for _ in range(40):
        th, w = rng.uniform(-1.2, 1.2), rng.uniform(-2, 2)
        uu, v, xg = rng.uniform(-0.5, 0.5), rng.uniform(-2, 2), rng.uniform(-20, 20)
        for s in (1, -1):
            for damped in (True, False):
                got = contact.ground_reactions(th, w, uu, v, s, xg, 9.81, row, True, damped)
                thdd, udd, _, _ = eq.rocking_rhs(th, w, uu, v, s, xg, 9.81, row, damped)
                args = (th, w, uu, v, thdd, udd, xg, s, bd.m, bd.m_A, bd.h, bd.h_A, bd.b, 9.81)
                scale = bd.M * (9.81 + abs(xg))
                assert got[0] == pytest.approx(f_H(*args), abs=1e-11 * scale)
                assert got[1] == pytest.approx(f_N(*args), abs=1e-11 * scale)


def test_rigid_reactions_equal_sympy_derivation(reactions_sympy):
    """A block: one mass M at the centre of gravity (top mass welded, u = 0): the two-mass
    formula with m = M at height h_cg and m_A = 0."""
    f_H, f_N = reactions_sympy
    blk = BlockBody(alpha=0.2)
    row = _row(blk)
    rng = np.random.default_rng(3)
    for _ in range(30):
        th, w, xg = rng.uniform(-1.3, 1.3), rng.uniform(-2, 2), rng.uniform(-10, 10)
        for s in (1, -1):
            got = contact.ground_reactions(th, w, 0.0, 0.0, s, xg, 9.81, row, False, False)
            thdd = eq.rigid_rhs(th, w, s, xg, 9.81, row)[0]
            args = (th, w, 0.0, 0.0, thdd, 0.0, xg, s, blk.M, 0.0, blk.h_cg, 0.0, blk.b, 9.81)
            assert got[0] == pytest.approx(f_H(*args), rel=1e-11, abs=1e-11)
            assert got[1] == pytest.approx(f_N(*args), rel=1e-11, abs=1e-11)


def test_full_contact_reactions(body_fig4, reactions_sympy):
    """Full contact: N = M g exactly for any body, H = the sympy H at theta = theta' = 0."""
    f_H, _ = reactions_sympy
    bd = body_fig4
    row = _row(bd)
    for uu, v, xg in [(0.1, -0.3, 4.0), (-0.2, 0.5, -7.0), (0.0, 0.0, 2.5)]:
        H, N = contact.ground_reactions(0.0, 0.0, uu, v, 0, xg, 9.81, row, True, True)
        assert N == bd.M * 9.81
        udd = eq.contact_rhs(uu, v, xg, row, True)[0]
        want = f_H(0.0, 0.0, uu, v, 0.0, udd, xg, 1, bd.m, bd.m_A, bd.h, bd.h_A, bd.b, 9.81)
        assert H == pytest.approx(want, rel=1e-12)
        # the base follows the ground, the top mass feels the spring and damper
        assert H == pytest.approx(bd.m_A * xg - (bd.k * uu + bd.c * v), rel=1e-10)


@pytest.mark.parametrize("shape", ["sine", "cosine"])
@pytest.mark.parametrize("A", [0.3, 0.7, 0.95])
def test_rigid_body_without_uplift_needs_A_over_g(shape, A):
    """A rigid body that never uplifts (A_ratio < 1): mu_req = |A|/g = A_ratio tan(alpha),
    the peak of the pulse, located inside a step (the sine's peak falls between steps);
    N = M g throughout; no impact, no impulse."""
    for body in (BlockBody(alpha=0.2), FlexibleBody(**table3(wn_over_p=math.inf,
                                                                 zeta=0.0))):
        out = _run(body, A=A, w=1.7, shape=shape)
        assert out[L.OUT_UPLIFTS] == 0
        assert out[L.OUT_MU_REQ] == pytest.approx(A * math.tan(body.alpha_ref), rel=1e-9)
        assert out[L.OUT_N_MIN] == 1.0
        assert out[L.OUT_IMPULSE_MAX] == 0.0


def test_flexible_body_in_full_contact_keeps_N_equal_Mg(body_fig4):
    out = _run(body_fig4, A=0.3, w=3.0)
    assert out[L.OUT_UPLIFTS] == 0
    assert out[L.OUT_N_MIN] == 1.0
    assert out[L.OUT_MU_REQ] > 0.3 * math.tan(body_fig4.alpha_cg)  # the spring amplifies


def test_without_contact_the_slots_are_nan(body_fig3):
    out = _run(body_fig3, level=L.LEVEL_OUTCOME)
    for slot in (L.OUT_MU_REQ, L.OUT_N_MIN, L.OUT_IMPULSE_MAX):
        assert math.isnan(out[slot])


def test_contact_variant_leaves_the_run_unchanged(body_fig3):
    """The contact bookkeeping only reads the state: every other result is the same."""
    for A in (1.5, 3.0, 6.0):
        a = _run(body_fig3, level=L.LEVEL_ENERGY, A=A)
        c = _run(body_fig3, level=L.LEVEL_CONTACT, A=A)
        same = [s for s in range(L.N_OUT) if s not in (L.OUT_MU_REQ, L.OUT_N_MIN,
                                                       L.OUT_IMPULSE_MAX, L.OUT_STATUS)]
        np.testing.assert_array_equal(a[same], c[same])
        assert int(a[L.OUT_STATUS]) == int(c[L.OUT_STATUS]) & ~(L.STATUS_SLIDES
                                                                  | L.STATUS_LIFTS_OFF)


def _history_run(body, theta0=0.0, **kw):
    row = _row(body, numerics=Numerics.preset("fine"), **kw)
    row[L.PAR_THETA0] = theta0
    out = np.empty(L.N_OUT)
    hist = np.empty((history_capacity(row), L.N_HIST))
    kind = L.KIND_RIGID if body.rigid else L.KIND_FLEXIBLE
    point_kernel(kind)(row, out, hist)
    return row, out, hist[:int(out[L.OUT_HIST_ROWS])]


def _impulses_from_history(body, hist, velocities):
    """|J_x|/J_y of every impact in a history: rows at the same time where rocking on s
    ends (before) and the next phase starts (after); J = sum m_i (v_i^+ - v_i^-)."""
    rigid = body.rigid
    M = body.M
    ratios = []
    for i in range(len(hist) - 1):
        r0, r1 = hist[i], hist[i + 1]
        s0, s1 = int(r0[L.HIST_PHASE]), int(r1[L.HIST_PHASE])
        if r0[L.HIST_T] != r1[L.HIST_T] or s0 == 0:
            continue
        if rigid:  # one mass M at (-s b, h_cg) from the corner: the base formula
            v0 = velocities(r0[L.HIST_THETA_DOT], 0.0, 0.0, s0, 0.0, body.h_cg, body.b)
            v1 = velocities(r1[L.HIST_THETA_DOT], 0.0, 0.0, s1 or 1, 0.0, body.h_cg, body.b)
            jx, jy = M * (v1[2] - v0[2]), M * (v1[3] - v0[3])
        else:
            u = r0[L.HIST_U]
            v0 = velocities(r0[L.HIST_THETA_DOT], u, r0[L.HIST_U_DOT], s0, body.h, body.h_A,
                            body.b)
            v1 = velocities(r1[L.HIST_THETA_DOT], u, r1[L.HIST_U_DOT], s1 or 1, body.h,
                            body.h_A, body.b)
            jx = body.m * (v1[0] - v0[0]) + body.m_A * (v1[2] - v0[2])
            jy = body.m * (v1[1] - v0[1]) + body.m_A * (v1[3] - v0[3])
        assert jy > 0.0  # the ground pushes
        ratios.append(abs(jx) / jy)
    return ratios


@pytest.mark.parametrize("which", ["flexible", "block"])
def test_impulse_ratio_is_the_momentum_jump(which, body_fig3, velocities_sympy):
    """impulse_ratio_max = the largest |J_x|/J_y of the impacts of a run, J the jump of the
    two masses' momentum computed from the history's states before and after each impact."""
    if which == "flexible":
        body = body_fig3
        _, out, hist = _history_run(body, A=2.0, w=3.0, lam=0.2)
    else:  # free rocking from theta = alpha/2 under a long, weak pulse: many impacts
        body = BlockBody(alpha=0.2)
        _, out, hist = _history_run(body, theta0=0.1, A=0.01, w=0.05, lam=0.2)
    assert out[L.OUT_IMPACTS] >= 2
    ratios = _impulses_from_history(body, hist, velocities_sympy)
    assert len(ratios) == out[L.OUT_IMPACTS]
    assert out[L.OUT_IMPULSE_MAX] == pytest.approx(max(ratios), rel=1e-9)
    if which == "block":  # closed forms: (1 - e)/(1 + e) h_cg/b rocking on, h_cg/b settling
        e = eq.restitution(1, 0.0, _row(body, lam=0.2), False)
        on, settle = (1 - e) / (1 + e) / math.tan(0.2), 1 / math.tan(0.2)
        for r in ratios:
            assert r == pytest.approx(on, rel=1e-9) or r == pytest.approx(settle, rel=1e-9)
        assert out[L.OUT_CONTACTS] >= 1 and max(ratios) == pytest.approx(settle, rel=1e-9)


def test_mu_required_is_located_between_steps(body_fig3):
    """The demand at the `default` step (5 a period) agrees with the one at `fine` (20 a
    period), within 1%: the maximum is located, not sampled (sampling alone misses ~5-20%)."""
    for A, w in [(1.5, 2.0), (3.0, 4.0), (0.8, 1.0)]:
        coarse = _run(body_fig3, A=A, w=w)
        fine = _run(body_fig3, A=A, w=w, numerics=Numerics.preset("fine"))
        if coarse[L.OUT_OUTCOME] != fine[L.OUT_OUTCOME] or not math.isfinite(
                fine[L.OUT_MU_REQ]):
            continue
        assert coarse[L.OUT_MU_REQ] == pytest.approx(fine[L.OUT_MU_REQ], rel=0.01)
        assert coarse[L.OUT_N_MIN] == pytest.approx(fine[L.OUT_N_MIN], rel=0.01, abs=0.01)


def test_status_bits_follow_mu(body_fig3):
    for A, w in [(1.5, 2.0), (1.2, 4.0), (2.0, 8.0), (1.1, 1.0)]:  # a rocking, safe point
        base = _run(body_fig3, A=A, w=w)
        if (base[L.OUT_OUTCOME] == L.OUTCOME_SAFE and base[L.OUT_UPLIFTS] > 0
                and base[L.OUT_N_MIN] > 0.0):
            break
    mu_req = base[L.OUT_MU_REQ]
    assert base[L.OUT_UPLIFTS] > 0 and 0.0 < mu_req < 10.0 and base[L.OUT_N_MIN] > 0.0
    assert not int(base[L.OUT_STATUS]) & (L.STATUS_SLIDES | L.STATUS_LIFTS_OFF)  # mu NaN
    low = _run(body_fig3, A=A, w=w, mu=0.9 * mu_req)
    high = _run(body_fig3, A=A, w=w, mu=1.1 * mu_req)
    assert int(low[L.OUT_STATUS]) & L.STATUS_SLIDES
    assert not int(high[L.OUT_STATUS]) & L.STATUS_SLIDES
    over = _run(body_fig3, A=8.0, w=2.0, mu=0.6)  # overturns: N < 0 on the way down
    assert over[L.OUT_N_MIN] < 0.0 and math.isinf(over[L.OUT_MU_REQ])
    assert int(over[L.OUT_STATUS]) & L.STATUS_LIFTS_OFF
    assert int(over[L.OUT_STATUS]) & L.STATUS_SLIDES


SCENE = """
""" + FIG3_YAML + """impact: {lam: [0.0, 0.4]}
pulse: {shape: sine, w_over_p: {start: 0.5, stop: 6, num: 5}, A_ratio: {start: 0.5, stop: 8,
        num: 5}}
"""


def test_scene_keys():
    assert not parse_scene(SCENE).contact
    # body.mu makes the base slide (docs/sliding.md): the no-slip demand is not computed
    slides = parse_scene(SCENE, overrides=["body.mu=0.6"])
    assert not slides.contact and slides.slides
    assert parse_scene(SCENE, overrides=["outputs.contact=true"]).contact
    with pytest.raises(SceneError, match="outputs.contact = true: the friction demand is "
                                         "the no-slip model's, and body.mu = 0.6"):
        parse_scene(SCENE, overrides=["body.mu=0.6", "outputs.contact=true"])
    with pytest.raises(SceneError, match=r"body.mu = 0.0: must be in \(0, 10\]"):
        parse_scene(SCENE, overrides=["body.mu=0"])
    with pytest.raises(SceneError, match="outputs.contact = 'yes'"):
        parse_scene(SCENE, overrides=["outputs.contact='yes'"])


def test_cli_end_to_end(cli, tmp_path):
    scene = tmp_path / "s.yaml"
    scene.write_text(SCENE)
    # without body.mu: the no-slip model's demand, and the contour map of mu_required
    f2 = tmp_path / "g.h5"
    r = cli.invoke(main, ["sweep", str(scene), "--contact", "-o", str(f2), "-q", "-j", "1"])
    assert r.exit_code == 0, r.output
    with h5py.File(f2) as h:
        mu_req = h["mu_required"][()]
        status = h["status"][()]
        n_min = h["normal_min_over_Mg"][()]
        assert h["impulse_ratio_max"].shape == mu_req.shape == (2, 5, 5)
        assert "work_in_over_Eref" not in h  # energy not asked
        assert "slide_max" not in h  # a scene pays for no output it did not ask for
    assert np.isfinite(mu_req).any() and (mu_req > 0).all()
    np.testing.assert_array_equal((status & L.STATUS_LIFTS_OFF) != 0, n_min < 0)
    r = cli.invoke(main, ["plot", str(f2), "--mu", "-o", str(tmp_path / "g.png")])
    assert r.exit_code == 0, r.output
    # the single-run path reports the same numbers
    one = tmp_path / "one.yaml"
    one.write_text(SCENE.replace("{lam: [0.0, 0.4]}", "{lam: 0.4}").replace(
        "{start: 0.5, stop: 6, num: 5}", "2.0").replace("{start: 0.5, stop: 8,\n        num: 5}",
                                                         "0.3"))
    r = cli.invoke(main, ["simulate", str(one), "--contact", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert d["mu_required"] > 0 and d["normal_min_over_Mg"] <= 1.0
    assert "impulse_ratio_max" in d
    r = cli.invoke(main, ["simulate", str(one), "--json"])
    assert "mu_required" not in json.loads(r.output)  # only when asked
