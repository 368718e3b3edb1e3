"""Impact laws: vertical (eq. 1), locked, constant, and e_factor.

Each law's e and energy loss are derived here with sympy from the impulse-momentum balance
(angular momentum about the impulse point, plus the law's rule for the top mass), written
from the masses' velocities; nothing is taken from rocksweep's code but parameter values.
"""

import math
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp
from bodies import FIG3_YAML
from helpers import one_line_error

from rocksweep.cli import main
from rocksweep.compute.driver import sweep_arrays
from rocksweep.compute.single import run_point
from rocksweep.errors import SceneError
from rocksweep.kernel import equations as eq
from rocksweep.kernel import layout as L
from rocksweep.numerics import Numerics
from rocksweep.physics import impact
from rocksweep.physics.bodies import FlexibleBody
from rocksweep.physics.ground_motion import pulse
from rocksweep.physics.points import Point, point_row
from rocksweep.scene.parse import load_scene, parse_scene

m, mA, IA, h, hA, b, lam = sp.symbols("m m_A I_A h h_A b lambda", positive=True)
uu, v_m, w_m, w_p, v_p, e_c = sp.symbols("uu v_m w_m w_p v_p e_c")
ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]


def _vel(w, v, corner):
    """Velocities of the top mass (at (uu, h), sliding at v) and of the base mass (at
    (0, hA)) at theta = 0, rotating clockwise at w about the corner (corner, 0)."""
    def rot(x, y):
        return sp.Matrix([w * y, -w * (x - corner)])
    return rot(uu, h) + sp.Matrix([v, 0]), rot(0, hA)


def _ang_mom(w, v, corner, x_q):
    def cross(r, vv):
        return r[0] * vv[1] - r[1] * vv[0]
    vP, vA = _vel(w, v, corner)
    return m * cross((uu - x_q, h), vP) + mA * cross((-x_q, hA), vA) - IA * w


def _kinetic(w, v, corner):
    vP, vA = _vel(w, v, corner)
    return (m * vP.dot(vP) + mA * vA.dot(vA) + IA * w**2) / 2


@pytest.fixture(scope="module")
def laws():
    """e and E_d per law for an impact ending rocking on the +b corner (the paper's upper
    sign; future corner -b, impulse at lam b from it)."""
    x_q = -b * (1 - lam)
    balance = _ang_mom(w_p, v_p, -b, x_q) - _ang_mom(w_m, v_m, b, x_q)
    top = {  # the law's rule for the top mass
        "vertical": m * (_vel(w_p, v_p, -b)[0][0] - _vel(w_m, v_m, b)[0][0]),  # momentum
        "locked": v_p - v_m,  # moves with the base: its rate relative to the base kept
    }
    out = {}
    for law, rule in top.items():
        sol = sp.solve([balance, rule], [w_p, v_p], dict=True)[0]
        e = sp.simplify(sol[w_p] / w_m)
        e_d = sp.simplify(_kinetic(w_m, v_m, b) - _kinetic(sol[w_p], sol[v_p], -b))
        out[law] = (e, e_d)
    # constant: w_p = e_c w_m given, the top mass keeps its momentum (as vertical)
    v_c = sp.solve(top["vertical"].subs(w_p, e_c * w_m), v_p)[0]
    out["constant"] = (e_c, sp.simplify(_kinetic(w_m, v_m, b)
                                        - _kinetic(e_c * w_m, v_c, -b)))
    return out


def _values(bd: FlexibleBody, lam_v: float, u_v: float) -> dict:
    return {m: bd.m, mA: bd.m_A, IA: bd.I_A, h: bd.h, hA: bd.h_A, b: bd.b, lam: lam_v,
            uu: u_v}


def _row(bd, law: str, lam_v: float, e: float = math.nan, factor: float = 1.0):
    return point_row(Point(bd, lam_v, "sine", 2.0, 3.0, law=law, e=e, e_factor=factor),
                     Numerics())


def test_locked_is_eq1_with_m_h2_added_and_rigid_at_u_0(laws):
    """The derived locked e is eq. (1) with m h^2 in numerator and denominator, and at
    u = 0 the rigid body's (I_O - (2 - lam) M b^2)/(I_O - lam M b^2) (Housner at lam = 0)."""
    e_v, e_l = laws["vertical"][0], laws["locked"][0]
    num, den = sp.fraction(sp.together(e_v))
    # eq. (1) as printed in the paper (upper sign), then m h^2 added to both
    n1 = IA + mA * hA**2 + m * uu * (-b + uu) + b * (1 - lam) * (-mA * b - m * b + m * uu)
    d1 = IA + mA * hA**2 + m * uu * (b + uu) + b * (1 - lam) * (mA * b + m * b + m * uu)
    assert sp.simplify(e_v - n1 / d1) == 0
    assert sp.simplify(e_l - (n1 + m * h**2) / (d1 + m * h**2)) == 0
    M = m + mA
    i_o = IA + mA * (hA**2 + b**2) + m * (h**2 + b**2)
    rigid = (i_o - (2 - lam) * M * b**2) / (i_o - lam * M * b**2)
    assert sp.simplify(e_l.subs(uu, 0) - rigid) == 0
    assert sp.simplify(rigid.subs(lam, 0) - (1 - 2 * M * b**2 / i_o)) == 0
    assert sp.simplify(e_v.subs(uu, 0) - rigid) != 0  # the laws do differ


@pytest.mark.parametrize("law", ["vertical", "locked", "constant"])
def test_coded_e_and_energy_loss_match_the_derivation(laws, body_fig2, law):
    """physics.impact and the kernel's restitution / impact_loss equal the derivation."""
    bd = body_fig2
    e_sym, ed_sym = laws[law]
    e_const = 0.83
    for lam_v in (0.0, 0.3, 1.0):
        for u_over in (-2.0, 0.0, 1.3):
            u_v = u_over * bd.u_cr
            vals = _values(bd, lam_v, u_v)
            e_ref = float(e_sym.subs({**vals, e_c: e_const}))
            factor = 1.1
            e_code = float(impact.restitution(bd, lam_v, u_v, True, law, e_const, factor))
            assert e_code == pytest.approx(factor * e_ref, rel=1e-12)
            row = _row(bd, law, lam_v, e_const if law == "constant" else math.nan, factor)
            assert eq.restitution(1, u_v, row, True) == pytest.approx(factor * e_ref,
                                                                     rel=1e-12)
            # the energy loss with the law's own e (e_factor 1), top mass rate v
            row1 = _row(bd, law, lam_v, e_const if law == "constant" else math.nan)
            w_v, vv = -0.3, 0.12
            ed_ref = float(ed_sym.subs({**vals, e_c: e_const, w_m: w_v, v_m: vv}))
            e1 = eq.restitution(1, u_v, row1, True)
            w_plus = e1 * w_v
            got = eq.impact_loss(1, -1, u_v, vv, w_v, w_plus, row1, True)
            assert got == pytest.approx(ed_ref, rel=1e-9, abs=1e-12)
            py = float(impact.energy_loss(bd, e1, u_v, w_v, True, law, vv))
            assert py == pytest.approx(ed_ref, rel=1e-9, abs=1e-12)


def test_locked_at_u_0_is_the_rigid_kernels_own_impacts(body_fig3):
    """The kernel's locked e at u = 0 equals the e the rigid kernel applies to the same
    body welded rigid, seen in a run's impacts (OUT_E_MAX: every impact has that e)."""
    rigid = replace(body_fig3, wn_over_p=math.inf)
    for lam_v in (0.0, 0.4):
        e_locked = eq.restitution(1, 0.0, _row(body_fig3, "locked", lam_v), True)
        run = run_point(Point(rigid, lam_v, pulse("sine", cycles=6), 6.0, 1.5, law="locked"),
                        Numerics(), history=False)
        assert run.impacts >= 5
        assert run.out[L.OUT_E_MAX] == pytest.approx(e_locked, rel=1e-13)
        i_o, mb2 = rigid.I_O, rigid.M * rigid.b**2
        assert e_locked == pytest.approx((i_o - (2 - lam_v) * mb2) / (i_o - lam_v * mb2),
                                         rel=1e-13)


def test_constant_e_1_conserves_a_rigid_bodys_energy(body_fig3):
    """A rigid body (wn/p = inf) under law constant with e = 1: no impact dissipates or
    gains energy, at each of many impacts (the history's cumulative impact loss does not
    move beyond the event location's overshoot, ~1e-8 E_ref)."""
    rigid = replace(body_fig3, wn_over_p=math.inf)
    p = Point(rigid, 0.0, pulse("sine", cycles=6), 6.0, 1.5, law="constant", e=1.0)
    run = run_point(p, Numerics.preset("fine"))
    assert run.impacts >= 10
    steps = np.abs(np.diff(run.history["E_impact"]))
    assert steps.max() < 1e-7 * rigid.E_ref
    assert run.out[L.OUT_N_GAINING] == 0
    # the same body under eq. (1)'s rigid e loses energy at its impacts
    lossy = run_point(replace(p, law="vertical", e=math.nan), Numerics.preset("fine"))
    assert lossy.out[L.OUT_E_IMPACT] > 1e-3 * rigid.E_ref


def test_e_factor_1_and_law_vertical_are_bit_identical(tmp_path):
    """Naming the default law and factor changes no bit of any result."""
    base = load_scene(ROOT / "configs" / "ci-small.yaml", ["outputs.energy=true"])
    named = load_scene(ROOT / "configs" / "ci-small.yaml",
                       ["outputs.energy=true", "impact.law=vertical", "impact.e_factor=1"])
    assert [a.name for a in named.swept] == [a.name for a in base.swept]
    a, b_ = sweep_arrays(base, jobs=1)[0], sweep_arrays(named, jobs=1)[0]
    for k in a:
        assert a[k].tobytes() == b_[k].tobytes(), k
    # and a factor that is not 1 changes the outcomes
    scaled = load_scene(ROOT / "configs" / "ci-small.yaml", ["impact.e_factor=1.3"])
    assert (sweep_arrays(scaled, jobs=1)[0]["outcome"] != a["outcome"]).any()


def test_energy_admissible_lam(laws, body_fig2):
    """lam_energy_limit is where the derived E_d changes sign (u' = 0); at u = 0 it is 1
    for both vertical and locked (e = 1 there: the impulse at the body's middle)."""
    bd = body_fig2
    for law in ("vertical", "locked"):
        e_sym, ed_sym = laws[law]
        u_v = np.array([-2.0, -1.0, 0.0, 1.0]) * bd.u_cr
        lim = impact.lam_energy_limit(bd, u_v, True, law)
        assert lim[2] == pytest.approx(1.0, abs=1e-12)
        for lv, uv in zip(lim, u_v, strict=True):
            def ed(x, uv=uv, ed_sym=ed_sym):
                return float(ed_sym.subs({**_values(bd, x, uv), w_m: -1.0, v_m: 0.0}))
            assert ed(lv - 1e-6) > 0 > ed(lv + 1e-6)
    # constant: lam plays no part; at u = 0 an e <= 1 never gains energy
    assert impact.lam_energy_limit(bd, np.zeros(1), True, "constant", 0.9)[0] == 2.0


def test_reference_follows_each_law(body_fig3):
    """The reference integrator implements each law: same outcome and impacts' e as the
    kernel at a point where the laws differ."""
    from rocksweep.physics.reference import reference_run

    seen = set()
    for law, e in (("vertical", math.nan), ("locked", math.nan), ("constant", 0.77)):
        p = Point(body_fig3, 0.4, "sine", 5.0, 4.0, law=law, e=e)
        ref = reference_run(p, Numerics.preset("fine"))
        run = run_point(p, Numerics.preset("fine"), history=False)
        assert ref["outcome"] == int(run.out[L.OUT_OUTCOME])
        assert ref["e_max"] == pytest.approx(run.out[L.OUT_E_MAX], rel=1e-3)
        seen.add(round(ref["e_max"], 3))
    assert len(seen) == 3


BAD = [
    ("impact.e=0", "impact.e = 0.0: must be in (0, 1]"),
    ("impact.e=1.5", "impact.e = 1.5: must be in (0, 1]"),
    ("impact.law=elastic", "impact.law = 'elastic': must be vertical, locked, constant"),
    ("impact.e_factor=0", "impact.e_factor = 0.0: must be in (0, 10]"),
]


@pytest.mark.parametrize("setting,needle", BAD)
def test_bad_values_are_one_line_errors(cli, setting, needle):
    scene = ROOT / "configs" / "impact-laws.yaml"
    msg = one_line_error(cli.invoke(main, ["simulate", str(scene), "--set", setting]))
    assert needle in msg, msg


def test_e_needs_law_constant_and_constant_needs_e(cli):
    scene = ROOT / "configs" / "fig3a.yaml"
    msg = one_line_error(cli.invoke(main, ["simulate", str(scene), "--set", "impact.e=0.8"]))
    assert "impact.e = 0.8: only law constant uses e" in msg, msg
    msg = one_line_error(cli.invoke(main, ["simulate", str(scene), "--set",
                                           "impact.law=constant"]))
    assert msg.endswith("impact.e: missing; law constant needs its coefficient of "
                        "restitution e: a number in (0, 1], a list or a range"), msg
    with pytest.raises(SceneError, match=r"impact.law = \['vertical', 'vertical'\]: a law is"):
        parse_scene(FIG3_YAML + "impact: {lam: 0, law: [vertical, "
                    "vertical]}\npulse: {shape: sine, w_over_p: 1, A_ratio: 1}")


SMALL = ["--set", "pulse.w_over_p={start: 1, stop: 6, num: 6}",
         "--set", "pulse.A_ratio={start: 1, stop: 8, num: 5}"]


def test_law_axis_sweeps_resumes_compares_and_refuses_a_changed_law(cli, tmp_path):
    from rocksweep.store.reader import read_result
    from rocksweep.store.writer import SweepFile

    scene = ROOT / "configs" / "impact-laws.yaml"
    full = tmp_path / "full.h5"
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(full), "-j", "1", *SMALL])
    assert res.exit_code == 0, res.output
    assert "shape  law       lam" in res.output
    r = read_result(full, ["outcome"])
    assert r.dims == ("lam", "law", "A_ratio", "w_over_p")
    assert list(r.coords["law"]) == ["vertical", "locked", "constant"]
    # a file created, nothing computed yet, then resumed: the same results
    part = tmp_path / "part.h5"
    sc = load_scene(scene, [s for s in SMALL if s != "--set"])
    SweepFile.create(part, sc, tuple(s for s in SMALL if s != "--set")).close()
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(part), "--resume", "-j", "1",
                            *SMALL])
    assert res.exit_code == 0, res.output
    assert (read_result(part, ["outcome"]).arrays["outcome"] == r.arrays["outcome"]).all()
    msg = one_line_error(cli.invoke(main, ["sweep", str(scene), "-o", str(part), "--resume",
                                           *SMALL, "--set", "impact.law=[vertical, locked]",
                                           "--set", "impact.e=null"]))
    assert "cannot resume" in msg and "impact.law: file [" in msg, msg
    # the comparison figure, and a key that cannot be compared
    png = tmp_path / "laws.png"
    res = cli.invoke(main, ["plot", str(full), "--compare", "impact.law", "--curves",
                            "-o", str(png)])
    assert res.exit_code == 0, res.output
    assert png.stat().st_size > 10_000
    msg = one_line_error(cli.invoke(main, ["plot", str(full), "--compare", "zeta", "-o",
                                           str(tmp_path / "x.png")]))
    assert "--compare zeta: not swept" in msg, msg


def test_compare_categories():
    from rocksweep.figures.compare import compare_categories

    S, M1, M2, NR = L.OUTCOME_SAFE, L.OUTCOME_MODE1, L.OUTCOME_MODE2, L.OUTCOME_NOT_RUN
    o = np.array([[S, M1, S, M1, M2, NR], [S, S, M1, M1, M2, M1]])
    # safe under both, only the first, only the second, both, mode 2 under both, missing
    assert compare_categories(o).tolist() == [1, 2 + 1, 2 + 2, 2 + 3, 2, 0]


@pytest.mark.parametrize("law", ["vertical", "locked"])
def test_energy_lost_at_each_impact_is_eq6_of_the_law(law):
    """simulate reports the energy each impact dissipated; each rocking-to-rocking one is
    eq. (6) of the law (physics.impact.energy_loss, numpy) at the impact's own state, and
    they sum to the run's total."""
    import numpy as np

    import rocksweep
    from rocksweep.physics.impact import energy_loss

    # at `fine` (event_tol 1e-8): the located impact's overshoot of theta = 0, whose
    # potential energy the kernel's loss includes, is then below the 1e-6 compared here
    # (3e-5 at `default`, event_tol 1e-6)
    sim = rocksweep.simulate(ROOT / "configs" / "fig5.yaml",
                             {"impact.lam": 0.4, "impact.law": law,
                              "numerics.accuracy": "fine"})
    losses = np.array(sim.summary["impact_losses_over_Eref"])
    assert losses.size == sim.summary["impacts"] > 0
    assert losses.sum() == pytest.approx(sim.summary["impact_loss_over_Eref"], rel=1e-12)
    h, body = sim.run.history, sim.run.point.body
    t, ph = np.asarray(h["t"]), np.asarray(h["phase"])
    at = np.flatnonzero((t[1:] == t[:-1]) & (ph[:-1] != 0))
    checked = 0
    for k, i in enumerate(at):
        if ph[i + 1] != -ph[i]:
            continue  # an impact that ends in full contact: not eq. (6)
        w_minus, w_plus = h["theta_dot"][i], h["theta_dot"][i + 1]
        want = energy_loss(body, w_plus / w_minus, h["u"][i], w_minus, upper=ph[i] > 0,
                           law=law, u_dot=h["u_dot"][i])
        # the kernel takes a difference of kinetic energies, eq. (6) is its closed form:
        # equal to rounding, amplified by the cancellation (an O(1) error if a law's
        # formula were wrong)
        assert losses[k] * body.E_ref == pytest.approx(float(want), rel=1e-6)
        checked += 1
    assert checked >= 2
