"""The base may slide: Coulomb friction, the four contact phases and the impact with
friction (jitted; docs/sliding.md has the derivation, tests/physics/test_sliding_*.py its
checks).

A new degree of freedom, x [m]: how far the base has slipped along the ground (the base's
centre while flat, the pivot's displacement while rocking: the pivot is at x + s b, so
rocking without slip leaves x unchanged). The ground acts on the base with a normal force
N and a friction force F (horizontal, on the body). The phase is (s, sigma): s the corner
the body rocks on (0 flat), sigma the slip direction (sign of x'; 0 stuck). Codes:
``vocab.phases`` (rest, slide, rock, slide-rock = 2 (s != 0) + (sigma != 0)).

Every mass's position is the no-slip one shifted by x (``tests/test_derivations.py::
_positions`` with the pivot at x_g + x + s b), so x'' enters every equation exactly as the
ground's acceleration does: the accelerations of the rocking (``equations.rocking_rhs``,
``rigid_rhs``) and flat (``contact_rhs``) phases, and the reactions H, N
(``contact.ground_reactions``), are those of today's model under the base's absolute
acceleration a = xg'' + x''. Newton for the masses gives F = H(a) and N(a), both affine
in a:

    H(a) = H_0 + a H_a,     N(a) = N_0 + a N_a       (H_a > 0: the mass the base drags)

- stuck (rest, rock): x'' = 0, a = xg''; the contact holds while |H| <= mu_s N;
- slipping in direction sigma (slide, slide-rock): F = -mu sigma N, so
  H(a) = -mu sigma N(a) gives a = -(H_0 + mu sigma N_0) / (H_a + mu sigma N_a). Flat,
  N_a = 0 and N = M g. Rocking, H_a + mu sigma N_a <= 0 is Painleve's paradox (no
  consistent slip): the corner sticks by a tangential impulse (``jam_impulse``);
- gravity is g + a_v with a vertical (the ``g`` argument, ``ground.ground_gravity``).

The phase entered when the base does not slip (from rest, at an uplift, where a slip
stops, where a stuck contact's force leaves the cone) is the first consistent one of
rest, rock, slide, slide-rock (``choose_phase``): a stuck contact stays stuck while the
static cone holds. Within a step the phase is fixed; the changes are located events
(stick break mu_s N - |H| = 0, slip stop x' = 0, uplift, impact), so stick-slip cannot
chatter inside a step, and at a slip stop the contact sticks only where the stuck force
is inside the static cone, whose boundary is then crossed by a located event, not by
round-off.

The impact (``friction_impact``) at theta = 0 is the scene's law (e, the settling rule)
where the base does not slip; a slipping base, or a stuck one whose impact needs more
than mu_s times the normal impulse, slips through it by Routh's incremental process.
"""

import math

from numba import njit

from rocksweep.kernel._cache import INLINE, INLINE_PUBLIC, PUBLIC
from rocksweep.kernel.contact import ground_reactions
from rocksweep.kernel.equations import (
    contact_rhs,
    mechanical_energy,
    restitution,
    rigid_rhs,
    rocking_rhs,
    tip_moment,
    uplift_moment,
    with_vertical_power,
)
from rocksweep.kernel.ground import ground_acc, ground_gravity
from rocksweep.kernel.layout import (
    GROUND_ANY,
    LAW_LOCKED,
    PAR_B,
    PAR_C,
    PAR_H,
    PAR_HA,
    PAR_HCG,
    PAR_IA0,
    PAR_IAH,
    PAR_IO,
    PAR_LAW,
    PAR_M,
    PAR_MA,
    PAR_MTOT,
    PAR_RESTRATE,
    PHASE_REST,
    PHASE_ROCK,
    Y_X_DOT,
)

# ``friction_impact``'s and ``choose_phase``'s flags (bits): no consistent slip (Painleve),
# the contact stuck by a tangential impulse; the impact needed no push from the ground;
# a slip slower than the rest speed after an impact, stopped (the settling rule for x')
JAM = 1
NO_PUSH = 2
SLIP_SETTLED = 4
LIFT_OFF = 8  # N <= 0 while rocking: the corner held as in the no-slip model (flagged)
# Relative round-off allowed where a sliding body's uplift moment equals M g b: a rigid
# body sliding at mu = tan(alpha_cg) exactly has Q = M g b for good (it slides, the normal
# force at its leading corner, theta'' = 0), which float64 may miss by an ulp or two
TIP_ROUNDOFF = 1e-12
# Slide-rock needs den = H_a + mu sigma N_a above JAM_DEN x M [kg], not only above 0:
# below it the contact jams (``choose_phase``, ``slide_loop._slipping``; ``slide_events``'
# Painleve slot fires there). Toward den = 0 the slip's acceleration and the reactions
# grow as 1/den, and the slip stops in a time that vanishes with den: the jam impulse
# (``jam_impulse``) is that stop's limit (its theta' jump is theta'' per unit a times the
# x' it removes). Stepped through to den = 0, fixed RK4 steps met the 1/den with no limit
# as the step shrank: the slip stop was located at den ~ 1e-6..1e-9 on a state with
# theta' of 1e2-1e5 alpha_ref (sliding threshold seed 60, mu 1.29: its deepest impact
# (theta'/alpha_ref)^2/2 5.7, 3e4, 5e3, 1e7, 8e5, 1e10 at 5 to 320 steps a period, its class
# flipping; seed 58, mu 1.41: lifted off and fell in mode 1 at 5 steps a period). With the
# jam at 1e-2 / 3e-3 / 1e-3 / 3e-4 M both converge at every step to the reference's class
# (seed 60's depth 5.96 / 5.83 / 5.77 / 5.75); at 1e-2 a slide-rock whose den dips to
# ~0.005 M and recovers (threshold seed 5, mu 0.62) jammed and fell 0.94 p t early. The
# impulse this early leaves |J_x|/J_y at mu (1 + ~1e-3 M/H_a): on the friction cone.
JAM_DEN = 1e-3


@njit(cache=True, **INLINE)
def jam_clearance(den, prm):
    """How far den [kg] (``slip_state``) lies above the jam band, JAM_DEN x M: > 0 where a
    slip on a corner is consistent (``choose_phase``, ``slide_loop._slipping``); the
    Painleve slot's event function (``slide_events``)."""
    return den - JAM_DEN * prm[PAR_MTOT]


@njit(cache=True, **INLINE_PUBLIC)
def phase_code(s, sigma):
    """The phase's code (``vocab.phases``) of corner s (0 flat) and slip direction sigma."""
    return (PHASE_ROCK if s != 0 else PHASE_REST) + (1 if sigma != 0 else 0)


# ----------------------------------------------------------------------------------------
# Forces and accelerations in each phase
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE)
def acceleration_rates(theta, u, s, prm, FLEX):
    """(d theta''/da [rad/m], d u''/da [1]): how the accelerations of phase s != 0 move
    with the base's absolute acceleration a (``equations.rocking_rhs``, ``rigid_rhs``:
    a enters F_theta as -a lever, F_u as -m a cos(theta); no velocity or gravity term)."""
    sb = s * prm[PAR_B]
    cth, sth = math.cos(theta), math.sin(theta)
    if not FLEX:
        return -prm[PAR_MTOT] * (prm[PAR_HCG] * cth + sb * sth) / prm[PAR_IO], 0.0
    m, h = prm[PAR_M], prm[PAR_H]
    arm = u - sb
    lever = m * (h * cth - arm * sth) + prm[PAR_MA] * (prm[PAR_HA] * cth + sb * sth)
    d_th = (h * m * cth - lever) / (prm[PAR_IA0] + m * arm * arm)
    return d_th, -cth - h * d_th


@njit(cache=True, **INLINE)
def reaction_rates(theta, u, s, prm, FLEX):
    """(H_a [kg], N_a [kg]): the rates dH/da, dN/da of ``contact.ground_reactions`` in the
    base's absolute acceleration a (the a-terms of its formulas, with
    ``acceleration_rates``): the mass the base drags along and how it loads the ground.
    Flat: H_a = m_A (flexible: the top mass rides on its spring) or M, N_a = 0."""
    M = prm[PAR_MTOT]
    if s == 0:
        return (M - prm[PAR_M] if FLEX else M), 0.0
    d_th, d_u = acceleration_rates(theta, u, s, prm, FLEX)
    sb = s * prm[PAR_B]
    cth, sth = math.cos(theta), math.sin(theta)
    if not FLEX:
        hcg = prm[PAR_HCG]
        return M * (1.0 + d_th * (hcg * cth + sb * sth)), M * d_th * (sb * cth - hcg * sth)
    m, m_A, h, h_A = prm[PAR_M], prm[PAR_MA], prm[PAR_H], prm[PAR_HA]
    arm = u - sb
    d_xp = 1.0 + d_u * cth + d_th * (h * cth - arm * sth)
    d_yp = -d_u * sth - d_th * (arm * cth + h * sth)
    d_xa = 1.0 + d_th * (sb * sth + h_A * cth)
    d_ya = d_th * (sb * cth - h_A * sth)
    return m * d_xp + m_A * d_xa, m * d_yp + m_A * d_ya


@njit(cache=True, **INLINE)
def reactions_affine(theta, theta_dot, u, u_dot, s, g, prm, FLEX, DAMPED):
    """(H_0, N_0, H_a, N_a) [N, N, kg, kg]: the ground's reactions in phase s as affine
    functions of the base's absolute horizontal acceleration a [m/s^2]: H = H_0 + a H_a,
    N = N_0 + a N_a (``contact.ground_reactions`` at a = 0, ``reaction_rates``)."""
    h0, n0 = ground_reactions(theta, theta_dot, u, u_dot, s, 0.0, g, prm, FLEX, DAMPED)
    h_a, n_a = reaction_rates(theta, u, s, prm, FLEX)
    return h0, n0, h_a, n_a


@njit(cache=True, **INLINE_PUBLIC)
def slip_state(theta, theta_dot, u, u_dot, s, sigma, xg, g, mu, prm, FLEX, DAMPED):
    """While the base slips in direction sigma (+1 / -1) in phase s (0 flat), under ground
    acceleration xg and gravity g: (x'' [m/s^2], N [N], den [kg]). F = -mu sigma N;
    den = H_a + mu sigma N_a must be > 0 (Painleve: no consistent slip otherwise)."""
    h0, n0, h_a, n_a = reactions_affine(theta, theta_dot, u, u_dot, s, g, prm, FLEX, DAMPED)
    den = h_a + mu * sigma * n_a
    a = -(h0 + mu * sigma * n0) / den
    return a - xg, n0 + a * n_a, den


@njit(cache=True, **INLINE)
def _phase_accelerations(theta, theta_dot, u, u_dot, s, a, g, prm, FLEX, DAMPED):
    """(theta'', u'') in phase s under the base's absolute acceleration a."""
    if s == 0:
        if not FLEX:
            return 0.0, 0.0
        return 0.0, contact_rhs(u, u_dot, a, prm, DAMPED)[0]
    if not FLEX:
        return rigid_rhs(theta, theta_dot, s, a, g, prm)[0], 0.0
    th_dd, u_dd, _, _ = rocking_rhs(theta, theta_dot, u, u_dot, s, a, g, prm, DAMPED)
    return th_dd, u_dd


@njit(cache=True, **INLINE_PUBLIC)
def accelerations(theta, theta_dot, u, u_dot, s, sigma, xg, g, mu, prm, FLEX, DAMPED):
    """(theta'' [rad/s^2], u'' [m/s^2], x'' [m/s^2], F [N]) in phase (s, sigma): stuck
    (sigma = 0: x'' = 0; F = 0 is returned, the stuck force is ``ground_reactions``' H) or
    slipping (F = -mu sigma N)."""
    x_dd = 0.0
    f = 0.0
    if sigma != 0:
        x_dd, n, _ = slip_state(theta, theta_dot, u, u_dot, s, sigma, xg, g, mu, prm, FLEX,
                                DAMPED)
        f = -mu * sigma * n
    th_dd, u_dd = _phase_accelerations(theta, theta_dot, u, u_dot, s, xg + x_dd, g, prm,
                                       FLEX, DAMPED)
    return th_dd, u_dd, x_dd, f


@njit(cache=True, **INLINE)
def relative_momentum(theta, theta_dot, u, u_dot, s, prm, FLEX):
    """sum m_i X_i' [kg m/s] of the masses relative to the slipping base (x' = 0): the
    body's horizontal momentum is this plus M x'."""
    if s == 0:
        return prm[PAR_M] * u_dot if FLEX else 0.0
    sb = s * prm[PAR_B]
    cth, sth = math.cos(theta), math.sin(theta)
    if not FLEX:
        return prm[PAR_MTOT] * (prm[PAR_HCG] * cth + sb * sth) * theta_dot
    m = prm[PAR_M]
    lever = m * (prm[PAR_H] * cth - (u - sb) * sth) + prm[PAR_MA] * (prm[PAR_HA] * cth
                                                                    + sb * sth)
    return lever * theta_dot + m * cth * u_dot


@njit(cache=True, **INLINE_PUBLIC)
def sliding_energy(theta, theta_dot, u, u_dot, x_dot, s, prm, FLEX):
    """T + V - V_rest [J] in the ground's frame with the base slipping at x' [m/s]:
    ``equations.mechanical_energy`` plus x' sum m_i X_i' + 1/2 M x'^2."""
    return (mechanical_energy(theta, theta_dot, u, u_dot, s, prm, FLEX)
            + x_dot * relative_momentum(theta, theta_dot, u, u_dot, s, prm, FLEX)
            + 0.5 * prm[PAR_MTOT] * x_dot * x_dot)


@njit(cache=True, **INLINE)
def sliding_derivatives(t, y, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND):
    """dy/dt, a 9-tuple, of y = (theta, theta', u, u', W_in, D_damp, x, x', D_fric) in
    phase (s, sigma) under ground kind GROUND (``ground.GROUNDS``): the ground's power
    -xg'' (sum m_i X_i' + M x') (a vertical's own, ``equations.vertical_power``, added
    under a ground kind with one: x moves no mass up or down), the damper's c u'^2,
    friction's loss -F x' = mu N |x'| >= 0 (ENERGY; else 0)."""
    theta, theta_dot, u, u_dot, x_dot = y[0], y[1], y[2], y[3], y[Y_X_DOT]
    xg = ground_acc(GROUND, t, on, prm)
    g = ground_gravity(GROUND, t, on, prm)
    th_dd, u_dd, x_dd, f = accelerations(theta, theta_dot, u, u_dot, s, sigma, xg, g, mu,
                                         prm, FLEX, DAMPED)
    if s == 0:
        theta_dot = 0.0
    if not FLEX:
        u_dot = 0.0
    p_in = p_damp = p_fric = 0.0
    if ENERGY:
        p_in = -xg * (relative_momentum(theta, theta_dot, u, u_dot, s, prm, FLEX)
                      + prm[PAR_MTOT] * x_dot)
        p_in = with_vertical_power(GROUND, p_in, theta, theta_dot, u, u_dot, s, g, prm, FLEX)
        p_damp = prm[PAR_C] * u_dot * u_dot if (FLEX and DAMPED) else 0.0
        p_fric = -f * x_dot
    return (theta_dot, th_dd, u_dot, u_dd, p_in, p_damp, x_dot, x_dd, p_fric)


@njit(cache=True, **PUBLIC)
def any_sliding_derivatives(t, y, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY):
    """``sliding_derivatives`` of any ground shape without a vertical (GROUND_ANY), from
    Python (tests)."""
    return sliding_derivatives(t, y, s, sigma, on, mu, prm, FLEX, DAMPED, ENERGY, GROUND_ANY)


# ----------------------------------------------------------------------------------------
# Events and the phase a non-slipping base enters
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE_PUBLIC)
def stick_margin(theta, theta_dot, u, u_dot, s, xg, g, mu_s, prm, FLEX, DAMPED):
    """mu_s N - |H| [N] of a stuck contact in phase s (rest or rock): the stick-break
    event's function (the contact slips once it is < 0)."""
    h, n = ground_reactions(theta, theta_dot, u, u_dot, s, xg, g, prm, FLEX, DAMPED)
    return mu_s * n - abs(h)


@njit(cache=True, **INLINE_PUBLIC)
def slide_uplift_moment(u, u_dot, sigma, xg, g, mu, prm, FLEX, DAMPED):
    """Q [N m] of the sliding body (flat, slipping in direction sigma): the uplift
    moment ``equations.uplift_moment`` under the base's acceleration a = xg'' + x''
    (friction acts at the ground, on the line of both corners: no moment about either).
    The body uplifts on corner s' when s' Q >= M g b (``tip_moment``); for a rigid body
    Q = -h_cg F = mu sigma M g h_cg: a slipping rigid body tips onto its leading corner
    exactly when mu >= tan(alpha_cg)."""
    x_dd, _, _ = slip_state(0.0, 0.0, u, u_dot, 0, sigma, xg, g, mu, prm, FLEX, DAMPED)
    return uplift_moment(u, u_dot, xg + x_dd, g, prm, FLEX, DAMPED)


@njit(cache=True, **PUBLIC)
def choose_phase(theta, theta_dot, u, u_dot, s, xg, g, mu, mu_s, prm, FLEX, DAMPED):
    """The phase (s, sigma, flag) a base that does not slip (x' = 0) enters at this state.

    s = 0 (flat, theta = theta' = 0): the first consistent of
      rest        |H| <= mu_s N and s' Q < M g b for both corners s' (today's uplift rule);
      rock s'     s' Q >= M g b (the body tips onto s'), N > 0, |H| <= mu_s N on s';
      slide sg    sg x'' > 0 (friction mu N cannot hold it), no uplift while sliding
                  (|Q| <= M g b under the slip's acceleration, ``slide_uplift_moment``:
                  at equality it slides with theta'' = 0, TIP_ROUNDOFF);
      slide-rock  (s', sg): sg x'' > 0, s' Q >= M g b under the slip's acceleration,
                  N > 0, den > JAM_DEN M (``slip_state``).
    s != 0 (rocking on s): rock if |H| <= mu_s N, else slide-rock in the direction
    sg = -sign(H) where den > JAM_DEN M and N > 0 (its x'' then has the sign sg).
    flag: 0, or JAM where no phase is consistent (Painleve: the contact is stuck by a
    tangential impulse: rock on the corner the body tips to, or stays on), or LIFT_OFF
    where N <= 0 while rocking (the ground would have to pull: outside the model; the
    corner is held as the no-slip model holds it, and flagged as it is). The stuck
    phases come first: static friction holds while it can (with mu_s > mu a base at rest
    may be consistent both stuck and slipping; it stays stuck).
    """
    if s != 0:
        h, n = ground_reactions(theta, theta_dot, u, u_dot, s, xg, g, prm, FLEX, DAMPED)
        if abs(h) <= mu_s * n:
            return s, 0, 0
        if not n > 0.0:  # the ground would have to pull: outside the model, held
            return s, 0, LIFT_OFF
        # friction cannot hold H: the slip goes against it. With den > 0 its x'' =
        # -(H + mu sg N)/den has the sign sg exactly (|H| > mu_s N >= mu N), so only den
        # and N are tested: on the far side of a stick break (|H| - mu_s N ~ 1e-16 N at a
        # tight event_tol) x'' is round-off, and testing its sign jammed the corner stuck
        # with |H| > mu_s N for the rest of the run
        sg = -1 if h > 0.0 else 1
        x_dd, n2, den = slip_state(theta, theta_dot, u, u_dot, s, sg, xg, g, mu, prm,
                                   FLEX, DAMPED)
        if jam_clearance(den, prm) > 0.0 and n2 > 0.0:
            return s, sg, 0
        return s, 0, JAM
    mgb = tip_moment(g, prm)
    q = uplift_moment(u, u_dot, xg, g, prm, FLEX, DAMPED)
    h, n = ground_reactions(0.0, 0.0, u, u_dot, 0, xg, g, prm, FLEX, DAMPED)
    if abs(q) < mgb and abs(h) <= mu_s * n:
        return 0, 0, 0
    tip = 1 if q >= mgb else (-1 if q <= -mgb else 0)
    if tip != 0:
        h, n = ground_reactions(0.0, 0.0, u, u_dot, tip, xg, g, prm, FLEX, DAMPED)
        if n > 0.0 and abs(h) <= mu_s * n:
            return tip, 0, 0
    for sg in (1, -1):
        x_dd, n, den = slip_state(0.0, 0.0, u, u_dot, 0, sg, xg, g, mu, prm, FLEX, DAMPED)
        if sg * x_dd > 0.0 and abs(uplift_moment(u, u_dot, xg + x_dd, g, prm, FLEX,
                                                 DAMPED)) <= mgb * (1.0 + TIP_ROUNDOFF):
            return 0, sg, 0
    for sc in (1, -1):
        for sg in (1, -1):
            x_dd, n, den = slip_state(0.0, 0.0, u, u_dot, sc, sg, xg, g, mu, prm, FLEX,
                                      DAMPED)
            if (jam_clearance(den, prm) > 0.0 and n > 0.0 and sg * x_dd > 0.0
                    and sc * uplift_moment(u, u_dot, xg + x_dd, g, prm, FLEX, DAMPED) >= mgb):
                return sc, sg, 0
    return tip, 0, JAM


@njit(cache=True, **PUBLIC)
def jam_impulse(theta, theta_dot, u, u_dot, x_dot, s, g, prm, FLEX, DAMPED):
    """Painleve's jam (den = H_a + mu sigma N_a <= 0 while the corner s slips): the
    tangential impulse that sticks it. A horizontal impulse J_x at the pivot changes the
    base's velocity by J_x / H_a and the rest as the ground's acceleration would
    (theta'' and u'' per unit a); the normal impulse is N_a x'-change. Returns
    (theta'^+, u'^+, J_x [N s], J_y [N s], work of J_x [J] (<= 0)); x'^+ = 0. Inside the
    cone where den <= 0: |J_x| / J_y = H_a / |N_a| <= mu."""
    h0, n0, h_a, n_a = reactions_affine(theta, theta_dot, u, u_dot, s, g, prm, FLEX, DAMPED)
    t0, u0 = _phase_accelerations(theta, theta_dot, u, u_dot, s, 0.0, g, prm, FLEX, DAMPED)
    t1, u1 = _phase_accelerations(theta, theta_dot, u, u_dot, s, 1.0, g, prm, FLEX, DAMPED)
    dv = -x_dot
    return (theta_dot + (t1 - t0) * dv, u_dot + (u1 - u0) * dv, h_a * dv, n_a * dv,
            0.5 * h_a * dv * x_dot)


# ----------------------------------------------------------------------------------------
# The impact with friction
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE)
def impact_momenta(w, u, u_dot, x_dot, p, prm, FLEX):
    """(P_x, P_y) [N s]: the body's momentum at theta = 0 rocking at rate w about the
    pivot at p (body frame, p = s b; p = 0 with w = 0 flat), the base slipping at x'."""
    M = prm[PAR_MTOT]
    if not FLEX:
        return M * (x_dot + prm[PAR_HCG] * w), M * p * w
    m, m_A = prm[PAR_M], prm[PAR_MA]
    return (m_A * (x_dot + prm[PAR_HA] * w) + m * (x_dot + prm[PAR_H] * w + u_dot),
            (M * p - m * u) * w)


@njit(cache=True, **INLINE)
def _lever_terms(u, p, prm, FLEX, locked):
    """(D_0, D_1): the angular momentum about the impulse's locus x_Q (on the ground) of
    the body rocking about the pivot p at theta = 0, per unit rate, is D_0 + x_Q D_1 (the
    top mass's kept momentum left out, ``friction_impact``)."""
    M = prm[PAR_MTOT]
    if not FLEX:
        return prm[PAR_IO] - M * prm[PAR_B] * prm[PAR_B], M * p
    m = prm[PAR_M]
    d0 = prm[PAR_IAH] + m * u * (u - p)
    if locked:
        d0 += m * prm[PAR_H] * prm[PAR_H]
    return d0, M * p - m * u


@njit(cache=True, **PUBLIC)
def friction_impact(w_minus, u, u_dot, x_dot, s, mu, mu_s, prm, FLEX):
    """The impact at theta = 0 that ends rocking on corner s, with Coulomb friction.

    w_minus, u, u_dot, x_dot: theta'^-, u, u'^-, x'^- (the base's slip velocity).
    The scene's law gives e (``equations.restitution``, e_factor included) and the
    settling rule the new phase s_new (-s, or 0 flat) as today. Every law is a vertical
    impulse at a locus x_Q and a horizontal one at the ground (no moment about x_Q), the
    top mass keeping its horizontal velocity (vertical, constant) or its rate u'
    (locked); x_Q is where e puts it: x_Q = (D0^- - e D0^+) / (e D1^+ - D1^-)
    (``_lever_terms``; lam's own locus for vertical and locked with e_factor 1). So the
    post-impact state is a family in the slip change delta = x'^+ - x'^-:

        w^+ = e w^- - kappa delta,   kappa = c_x / D^+(x_Q),

    c_x = m_A h_A (top mass kept) or M h_cg (locked, rigid), and its impulses are affine
    in delta: J = J^n + delta (alpha, beta), J^n the law's own (x' kept). Routh's
    incremental process along the impulse picks delta: the base slips (dJ_x = -mu sigma
    dJ_y) while it slips, sticks where its slip velocity reaches 0 if the law's ratio
    |J_x^n| / J_y^n <= mu_s (a stuck start keeps the law's result: delta = 0), else slips
    on the other way; the impact ends when the new corner's normal velocity is 0.

    Where friction turns the rotation back (w^+ / w^- <= 0) or below the rest rate, the
    base lands flat instead (s_new = 0, the settling rule's impact).

    Returns (s_new, w^+, u'^+, x'^+, e, J_x, J_y, W_f, flag): W_f <= 0 the work of the
    friction impulse on the slip [J]; flag JAM (impulsive Painleve: stuck by a tangential
    impulse), NO_PUSH (J_y^n <= 0: the law's impact needs no push, no friction impulse),
    else 0. x'^+ is exactly 0 where the contact ends stuck. A slip after it (x'^+ != 0)
    goes on in slide-rock only where ``slip_state``'s den > 0 (else ``jam_impulse``), and
    a flat one tips at once where ``slide_uplift_moment`` says so.
    """
    e = restitution(s, u, prm, FLEX)
    rocks = e > 0.0 and abs(e * w_minus) >= prm[PAR_RESTRATE]
    out = _impact_into(-s if rocks else 0, e, w_minus, u, u_dot, x_dot, s, mu, mu_s, prm,
                       FLEX)
    w = out[1]
    if out[0] != 0 and not (w / w_minus > 0.0 and abs(w) >= prm[PAR_RESTRATE]):
        # friction turned the rotation back (or below the rest rate): it lands flat
        out = _impact_into(0, e, w_minus, u, u_dot, x_dot, s, mu, mu_s, prm, FLEX)
    return out


@njit(cache=True, **INLINE)
def _impact_into(s_new, e, w_minus, u, u_dot, x_dot, s, mu, mu_s, prm, FLEX):
    """``friction_impact`` into phase s_new (-s rocking on, with rate e w^- when x' is
    kept; 0 flat)."""
    w_n = e * w_minus if s_new != 0 else 0.0
    locked = FLEX and prm[PAR_LAW] == LAW_LOCKED
    keep = FLEX and not locked
    b = prm[PAR_B]
    kappa = 0.0
    if s_new != 0:
        d0m, d1m = _lever_terms(u, s * b, prm, FLEX, locked)
        d0p, d1p = _lever_terms(u, -s * b, prm, FLEX, locked)
        c_x = prm[PAR_MA] * prm[PAR_HA] if keep else prm[PAR_MTOT] * prm[PAR_HCG]
        kappa = c_x * (e * d1p - d1m) / (d0m * d1p - d0p * d1m)
    pxm, pym = impact_momenta(w_minus, u, u_dot, x_dot, s * b, prm, FLEX)
    jn = _jumps(w_minus, u, u_dot, x_dot, w_n, kappa, 0.0, s_new * b, pxm, pym, prm, FLEX,
                keep)
    j1 = _jumps(w_minus, u, u_dot, x_dot, w_n, kappa, 1.0, s_new * b, pxm, pym, prm, FLEX,
                keep)
    jxn, jyn = jn[3], jn[4]
    # the rest speed: the settling rule's rest rate at the centre of gravity's height
    v_rest = prm[PAR_RESTRATE] * prm[PAR_HCG]
    delta, flag, w_f = routh(x_dot, jxn, jyn, j1[3] - jxn, j1[4] - jyn, mu, mu_s, v_rest)
    w, ud, xd, j_x, j_y = _jumps(w_minus, u, u_dot, x_dot, w_n, kappa, delta, s_new * b,
                                 pxm, pym, prm, FLEX, keep)
    return s_new, w, ud, xd, e, j_x, j_y, w_f, flag


@njit(cache=True, **INLINE)
def _jumps(w_minus, u, u_dot, x_dot, w_n, kappa, delta, p_new, pxm, pym, prm, FLEX, keep):
    """(w^+, u'^+, x'^+, J_x, J_y) of the member delta of the impact's family."""
    w = w_n - kappa * delta
    if not FLEX:
        ud = 0.0
    elif keep:  # the top mass keeps its horizontal velocity x' + u' + h w
        ud = u_dot + prm[PAR_H] * (w_minus - w) - delta
    else:
        ud = u_dot
    xd = x_dot + delta
    pxp, pyp = impact_momenta(w, u, ud, xd, p_new, prm, FLEX)
    return w, ud, xd, pxp - pxm, pyp - pym


@njit(cache=True, **PUBLIC)
def routh(v0, jxn, jyn, alpha, beta, mu, mu_s, v_rest):
    """Routh's incremental process of an impact whose end states are the family
    J = J^n + delta (alpha, beta) (x'^+ = x'^- + delta): (delta, flag, W_f).

    Along the impulse the slip velocity and the progress to the end (the new corner's
    normal velocity reaching 0) are linear in (J_x, J_y), fixed by the family:
    v = v0 + (J_y^n J_x - J_x^n J_y) / D, progress = (alpha J_y - beta J_x) / D,
    D = alpha J_y^n - beta J_x^n. Slipping in direction sg: dJ_x = -mu sg dJ_y; stuck:
    dJ_x = (J_x^n / J_y^n) dJ_y (v stays 0), allowed while |J_x^n| <= mu_s J_y^n. A slip
    whose progress would run backwards (alpha + mu sg beta <= 0: Painleve in impulse form)
    is stopped by a tangential impulse (progress kept: dJ = -v (alpha, beta)): JAM.
    W_f: the work of J_x on the slip (<= 0), exact (v is linear in J along each piece).
    A slip left slower than v_rest [m/s] is stopped the same way (SLIP_SETTLED): the
    settling rule of x', which ends a Zeno sequence of ever smaller slips between impacts
    as the rest rate ends one of ever smaller rotations.
    """
    mu_s = max(mu_s, mu)  # (a scene's mu_s >= mu; kept so whatever the caller passes)
    d = alpha * jyn - beta * jxn
    if not (jyn > 0.0 and d > 0.0):  # the law needs no push from the ground: frictionless
        return -jxn / alpha, NO_PUSH, 0.0
    v = v0
    prog = 0.0
    w_f = 0.0
    flag = 0
    for _ in range(6):
        if prog >= 1.0:
            break
        if v == 0.0:
            if abs(jxn) <= mu_s * jyn:  # sticks to the end
                break
            sg = -1.0 if jxn > 0.0 else 1.0  # friction as needed, as far as it goes
        else:
            sg = 1.0 if v > 0.0 else -1.0
        kp = (alpha + mu * sg * beta) / d
        if kp <= 0.0:  # no consistent slip: stuck by a tangential impulse, to the end
            w_f -= 0.5 * alpha * v * v
            v = 0.0
            flag |= JAM
            break
        kv = -(jxn + mu * sg * jyn) / d
        dj_end = (1.0 - prog) / kp
        dj_stop = -v / kv if (v != 0.0 and sg * kv < 0.0) else math.inf
        if dj_end <= dj_stop:
            v_end = v + kv * dj_end
            w_f -= mu * sg * dj_end * 0.5 * (v + v_end)
            v = v_end
            prog = 1.0
        else:
            w_f -= mu * sg * dj_stop * 0.5 * v
            prog += kp * dj_stop
            v = 0.0
    if v != 0.0 and abs(v) < v_rest:
        w_f -= 0.5 * alpha * v * v
        v = 0.0
        flag |= SLIP_SETTLED
    return v - v0, flag, w_f
