"""The impact with friction (``kernel.sliding.friction_impact``) against the free body's
impulse mechanics, derived here with sympy, and Routh's incremental process integrated by
brute force (docs/sliding.md, "Impacts with friction").

The free body at theta = 0: the velocity z = (v_x, v_y, w, u') of its base's point on the
ground line under the centre, its clockwise rotation, the top mass's rate (the laws
``vertical`` and ``constant``: the spring carries no impulse; ``locked``: u' is frozen, z
has three entries); a block is one mass M at h_cg with I_G. The ground gives a vertical
impulse J_y at the locus x_Q and a horizontal one J_x; then z^+ = z^- + M^-1 B^T J. The
new corner's normal velocity is v_y - w x_new, the slip velocity v_x.
"""

import math

import numpy as np
import pytest
import sympy as sp
from bodies import BODY2, BODY3

from rocksweep.kernel import contact, sliding
from rocksweep.kernel import equations as eq
from rocksweep.numerics import Numerics
from rocksweep.physics import sliding_reference as ref
from rocksweep.physics.bodies import BlockBody
from rocksweep.physics.points import Point, point_row
from rocksweep.vocab.laws import CONSTANT, EQ1, LOCKED

VX, VY, OM, UD, U = sp.symbols("v_x v_y w ud u")


def _free_body_mass(body, locked: bool):
    """The free body's mass matrix in z (numpy), from its kinetic energy (sympy)."""
    if body.rigid:
        i_g = body.I_O - body.M * (body.b**2 + body.h_cg**2)
        T = (body.M * ((VX + OM * body.h_cg) ** 2 + VY**2) + i_g * OM**2) / 2
        z = [VX, VY, OM]
    else:
        i_a = body.I_A
        vp = ((VX + OM * body.h + (0 if locked else UD)), VY - OM * U)
        T = (body.m_A * ((VX + OM * body.h_A) ** 2 + VY**2) + i_a * OM**2
             + body.m * (vp[0] ** 2 + vp[1] ** 2)) / 2
        z = [VX, VY, OM] + ([] if locked else [UD])
    return sp.lambdify(U, sp.hessian(T, z), "numpy"), len(z)


def _row(body, lam=0.0, law=EQ1, e=math.nan, e_factor=1.0):
    return point_row(Point(body, lam, "sine", 2.0, 3.0, law=law, e=e, e_factor=e_factor),
                     Numerics())


class FreeBody:
    def __init__(self, body, u, locked=False):
        f, self.n = _free_body_mass(body, locked)
        self.inv = np.linalg.inv(np.array(f(u), float))
        self.u = u

    def push(self, x_q):
        """(response to J_x, response to J_y at x_q): columns of dz."""
        ex, ey = np.zeros(self.n), np.zeros(self.n)
        ex[0] = 1.0
        ey[1], ey[2] = 1.0, -x_q
        return self.inv @ ex, self.inv @ ey

    def z(self, w, ud, xd, pivot):
        return np.array([xd, w * pivot, w, ud][: self.n])


def _post_check(body, fb, z0, out, x_q, s, keep_u=None):
    """The kernel's impulses, applied to the free body at x_q, give its post state, and
    the new corner's normal velocity ends at 0."""
    s_new, w_p, ud_p, xd_p, _, j_x, j_y, _, _ = out
    gx, gy = fb.push(x_q)
    z1 = z0 + gx * j_x + gy * j_y
    scale = max(1.0, abs(z0[2]) * body.b + abs(z0[0]))
    assert z1[0] == pytest.approx(xd_p, abs=1e-10 * scale)
    assert z1[2] == pytest.approx(w_p, abs=1e-10 * scale)
    if fb.n == 4:
        assert z1[3] == pytest.approx(ud_p, abs=1e-10 * scale)
    assert z1[1] - z1[2] * (-s * body.b) == pytest.approx(0.0, abs=1e-10 * scale)
    return z1


def _locus(body, row, s, u, law):
    """x_Q for the stuck impact, x' kept, to give the law's e: the free body's impulses
    at x_Q with v_t kept and the new corner's v_n = 0, the root in x_Q of w^+ = e w^-
    (scanned over +-50 b, refined by Brent's method)."""
    from scipy.optimize import brentq

    e = eq.restitution(s, u, row, not body.rigid)
    fb = FreeBody(body, u, law == LOCKED)
    z0 = fb.z(1.0, 0.0, 0.0, s * body.b)

    def gap(x_q):
        gx, gy = fb.push(x_q)
        a = np.array([[gx[0], gy[0]], [gx[1] + gx[2] * s * body.b, gy[1] + gy[2] * s * body.b]])
        jx, jy = np.linalg.solve(a, [0.0, -(z0[1] + z0[2] * s * body.b)])
        return (z0 + gx * jx + gy * jy)[2] - e

    xs = np.linspace(-50, 50, 2001) * body.b
    fs = np.array([gap(x) for x in xs])
    roots = [brentq(gap, xs[i], xs[i + 1], xtol=1e-14 * body.b)
             for i in np.flatnonzero(np.sign(fs[:-1]) != np.sign(fs[1:]))
             if abs(fs[i]) + abs(fs[i + 1]) < 1.0]  # a root, not a pole
    return min(roots, key=abs), e


@pytest.mark.parametrize("body,law", [(bd, law) for bd in (BODY3, BODY2) for law in
                                      (EQ1, LOCKED, CONSTANT)]
                         + [(BlockBody(alpha=0.2), EQ1), (BlockBody(alpha=0.2), CONSTANT)],
                         ids=[f"{b}-{law}" for b in ("fig3", "fig2") for law in
                              (EQ1, LOCKED, CONSTANT)] + ["block-eq1",
                                                               "block-constant"])
def test_impact_is_the_free_body_with_the_laws_locus(body, law):
    """Every law, random states, slipping or stuck before: the kernel's impulses at the
    locus its e implies (x_Q = -s b (1 - lam) for eq. 1) carry the free body from its
    state before to the kernel's after, with the new corner's normal velocity 0; a stuck
    body with ample friction gets today's impact (eq. 1's e, contact.py's impulses). Where
    friction turns the rotation back the base lands flat: the impulses are then the jump
    of the free body's momentum into its flat state. (A rigid body has one law: vertical
    and locked coincide.)"""
    lam = 0.3
    row = _row(body, lam, law, e=0.8 if law == CONSTANT else math.nan)
    flex = not body.rigid
    rng = np.random.default_rng(5)
    for _ in range(4):
        s = int(rng.choice([1, -1]))
        u = rng.uniform(-0.3, 0.3) * body.u_cr if flex else 0.0
        w, ud = -s * rng.uniform(0.05, 0.5), rng.uniform(-0.3, 0.3) if flex else 0.0
        x_q, e = _locus(body, row, s, u, law)
        if law == EQ1:
            assert x_q == pytest.approx(-s * body.b * (1 - lam), rel=1e-9)
        fb = FreeBody(body, u, law == LOCKED)
        for xd, mu in [(0.0, 10.0), (0.0, 0.05), (rng.uniform(-0.3, 0.3), 0.3),
                       (rng.uniform(-0.01, 0.01), 0.6)]:
            out = sliding.friction_impact(w, u, ud, xd, s, mu, mu, row, flex)
            j_x, j_y = out[5], out[6]
            z0 = fb.z(w, ud, xd, s * body.b)
            if out[0] == 0:  # landed flat: the momentum's jump
                assert out[1] == 0.0
                mass = np.linalg.inv(fb.inv)
                dz = fb.z(0.0, out[2], out[3], 0.0) - z0
                assert (j_x, j_y) == pytest.approx(tuple((mass @ dz)[:2]), rel=1e-10)
                continue
            assert out[0] == -s  # rocking goes on on the other corner
            _post_check(body, fb, z0, out, x_q, s)
            assert j_y > 0
            assert abs(j_x) <= mu * j_y * (1 + 1e-12)  # Coulomb's cone
            assert out[7] <= 0.0  # friction's work
            if mu == 10.0:  # stuck throughout: today's impact
                assert out[3] == 0.0 and out[1] == pytest.approx(e * w, rel=1e-12)
                want = contact.impact_impulses(s, u, ud, w, -s, out[2], out[1], row, flex)
                assert (j_x, j_y) == pytest.approx(want, rel=1e-11, abs=1e-13)


def _brute_routh(z0, gx, gy, x_new, mu, mu_s, n=40000):
    """Routh's process by brute force: J_y in small steps, the slip's friction -mu sgn(v)
    or, once v_t is 0 and the ratio that keeps it there is within mu_s, that ratio; until
    the new corner's normal velocity reaches 0. Returns x'^+."""
    def vel(z):
        return z[0], z[1] - z[2] * x_new

    vt0, vn0 = vel(z0)
    # an upper bound of J_y: the stuck impulse's, twice over
    a = np.array([[gx[0], gy[0]], [gx[1] - gx[2] * x_new, gy[1] - gy[2] * x_new]])
    jy_max = 2 * abs(np.linalg.solve(a, [-vt0, -vn0])[1]) + 1e-12
    d = jy_max / n
    z, stuck = z0.copy(), vt0 == 0.0
    r = -(gy[0]) / gx[0]  # dJ_x/dJ_y that keeps v_t
    for _ in range(2 * n):
        vt, vn = vel(z)
        if vn >= 0:
            break
        if stuck and abs(r) <= mu_s:
            djx = r * d
        else:
            sg = np.sign(vt) if vt != 0 else -np.sign(r)
            djx = -mu * sg * d
        z_new = z + gx * djx + gy * d
        if vt != 0 and np.sign(z_new[0]) != np.sign(vt):  # crossed: stuck from here
            stuck = True
            z_new[0] = 0.0 if abs(r) <= mu_s else z_new[0]
        z = z_new
    return z[0]


@pytest.mark.parametrize("case", ["slips_throughout", "slip_then_stick", "slips_from_stuck",
                                  "reverses"])
def test_routh_process_against_brute_force(case):
    """The kernel's exact, piecewise process and a brute-force one agree on x'^+."""
    body, s, lam = BlockBody(alpha=0.25), 1, 0.0
    row = _row(body, lam)
    w = -0.4
    xd, mu, mu_s = {"slips_throughout": (0.5, 0.1, 0.1), "slip_then_stick": (0.005, 0.3, 0.3),
                    "slips_from_stuck": (0.0, 0.05, 0.05),
                    "reverses": (0.003, 0.1, 0.1)}[case]
    out = sliding.friction_impact(w, 0.0, 0.0, xd, s, mu, mu_s, row, False)
    fb = FreeBody(body, 0.0)
    gx, gy = fb.push(-s * body.b * (1 - lam))
    got = _brute_routh(fb.z(w, 0.0, xd, s * body.b), gx, gy, -s * body.b, mu, mu_s)
    scale = abs(w) * body.h_cg
    assert out[3] == pytest.approx(got, abs=2e-3 * scale)
    if case == "slip_then_stick":
        assert out[3] == 0.0 and got == 0.0
    if case == "slips_from_stuck":
        assert out[3] != 0.0 and abs(out[5]) == pytest.approx(mu * out[6], rel=1e-12)
    if case == "reverses":  # friction one way, then the other: inside the cone
        assert out[3] * xd < 0.0 and abs(out[5]) < mu * out[6]


@pytest.mark.parametrize("alpha", [0.1, 0.2, 0.35, 0.6])
def test_housner_impact_sticks(alpha):
    """Housner's block (lam = 0, e = 1 - 1.5 sin^2 alpha) needs a tangential impulse of
    3 tan(alpha) / (4 + tan^2 alpha) times the normal one, less than tan(alpha): with mu
    = tan(alpha) (the least a rocking block's stuck corner needs at uplift) it sticks; with
    less than the ratio it slips, on Coulomb's cone, and the new corner ends at rest."""
    blk = BlockBody(alpha=alpha)
    row = _row(blk)
    tan = math.tan(alpha)
    ratio = 3 * tan / (4 + tan**2)
    assert ratio < tan
    w = -0.3
    out = sliding.friction_impact(w, 0.0, 0.0, 0.0, 1, tan, tan, row, False)
    assert eq.restitution(1, 0.0, row, False) == pytest.approx(1 - 1.5 * math.sin(alpha)**2,
                                                               rel=1e-12)
    assert out[0] == -1 and out[3] == 0.0 and out[8] == 0
    assert abs(out[5]) / out[6] == pytest.approx(ratio, rel=1e-12)
    mu = 0.5 * ratio
    out = sliding.friction_impact(w, 0.0, 0.0, 0.0, 1, mu, mu, row, False)
    assert out[3] != 0.0 and abs(out[5]) == pytest.approx(mu * out[6], rel=1e-12)
    fb = FreeBody(blk, 0.0)
    _post_check(blk, fb, fb.z(w, 0.0, 0.0, blk.b), out, -blk.b, 1)


@pytest.mark.parametrize("body", [BODY3, BlockBody(alpha=0.2)], ids=["fig3", "block"])
@pytest.mark.parametrize("law,e_factor", [(EQ1, 1.0), (EQ1, 0.8), (LOCKED, 1.0),
                                          (CONSTANT, 1.0)])
def test_kernel_impact_equals_the_reference_impact(body, law, e_factor):
    """The kernel's family-and-Routh impact and the reference's free-body Routh process
    (``physics.sliding_reference.impact``) agree, landing flat included (e below the
    rest rate)."""
    flex = not body.rigid
    rng = np.random.default_rng(9)
    for lam in (0.0, 0.4):
        row = _row(body, lam, law, e=0.7 if law == CONSTANT else math.nan, e_factor=e_factor)
        rb = ref._Body(row, flex, flex and body.zeta > 0)
        for _ in range(6):
            s = int(rng.choice([1, -1]))
            u = rng.uniform(-0.5, 0.5) * body.u_cr if flex else 0.0
            ud = rng.uniform(-0.3, 0.3) if flex else 0.0
            w = -s * (rng.uniform(0.02, 0.4) if rng.uniform() < 0.8 else 1e-6)
            xd = rng.choice([0.0, rng.uniform(-0.2, 0.2)])
            mu = rng.uniform(0.05, 0.8)
            out = sliding.friction_impact(w, u, ud, xd, s, mu, mu, row, flex)
            y = np.zeros(9)
            y[1], y[2], y[3], y[5] = w, u, ud, xd
            y_r, s_r, _, e_r, wf_r, _ = ref.impact(rb, row, y, s, mu, mu)
            assert out[0] == s_r
            scale = abs(w) * body.R + abs(xd)
            assert out[1] == pytest.approx(y_r[1], abs=1e-9 * scale)
            assert out[3] == pytest.approx(y_r[5], abs=1e-9 * scale)
            if flex:
                assert out[2] == pytest.approx(y_r[3], abs=1e-9 * scale)
            assert out[7] == pytest.approx(wf_r, abs=1e-9 * scale**2)
