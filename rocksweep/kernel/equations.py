"""Equations of motion, uplift and impact of the flexible rocking oscillator (jitted).

Everything here is a pure function of scalars and the parameter row ``prm`` (see
``layout``). Conventions (``rocksweep.physics.bodies``): theta > 0 clockwise = rocking on the +b
corner (s = +1), u along the body's x axis, SI units with m = 1, g = 9.81, p = 1.

Derivation (section 2 of the paper; Lagrange's equations in the frame of the ground,
ground acceleration xg'' as d'Alembert loads -m_i xg'' on each mass, damper as the
generalised force -c u'). Rocking on corner s, with a = u - s b the top mass's lever arm:

    T = 1/2 m [(u' + h theta')^2 + a^2 theta'^2] + 1/2 (I_A + m_A R_A^2) theta'^2
    V = m g (h cos theta - a sin theta) + m_A g (h_A cos theta + s b sin theta) + 1/2 k u^2

which gives   [ I_O(u)  m h ] [theta'']   [F_theta]
              [  m h     m  ] [  u''  ] = [  F_u  ]

with I_O(u) = I_A + m_A R_A^2 + m (h^2 + a^2),

    F_theta = -2 m a u' theta' + m g (a cos + h sin) - m_A g (s b cos - h_A sin)
              - xg'' [m (h cos - a sin) + m_A (h_A cos + s b sin)]
    F_u     = m a theta'^2 + m g sin - k u - c u' - m xg'' cos

solved as theta'' = (F_theta - h F_u) / (I_A + m_A R_A^2 + m a^2), u'' = F_u/m - h theta''.
Full contact (theta = 0):  m u'' + c u' + k u = -m xg''.

A vertical ground acceleration a_v(t) (positive up) adds the d'Alembert loads -m_i a_v
along y: in the ground's frame gravity is g + a_v(t) in every term above (V, so F_theta,
F_u, Q and the tipping moment M g b). The functions take that gravity as their argument
``g`` (``ground.ground_gravity``: the row's PAR_G itself without a vertical); the impact
map has no g (a finite a_v gives no impulse). docs/vertical.md.
"""

import math

from numba import njit

from rocksweep.kernel import eq1, ridge, spring
from rocksweep.kernel._cache import INLINE, INLINE_PUBLIC, PUBLIC
from rocksweep.kernel.ground import gravity_rate, per_ground
from rocksweep.kernel.layout import (
    LAW_CONSTANT,
    LAW_LOCKED,
    PAR_B,
    PAR_C,
    PAR_E,
    PAR_E_FACTOR,
    PAR_G,
    PAR_H,
    PAR_HA,
    PAR_HCG,
    PAR_IA0,
    PAR_IAH,
    PAR_IO,
    PAR_K,
    PAR_LAM,
    PAR_LAW,
    PAR_M,
    PAR_MA,
    PAR_MTOT,
)

# Eq. (1) and its rigid limit, written once in ``eq1`` (plain Python: the physics evaluates
# the same functions on arrays); inlined into ``restitution``, their one call site, by numba
# (not compiled on their own)
_e_eq1 = njit(inline="always")(eq1.restitution)
_e_rigid = njit(inline="always")(eq1.restitution_rigid)
# the ridge of the potential energy (``ridge``), inlined into ``ridge_energy``
_ridge = njit(inline="always")(ridge.ridge_energy)

# ----------------------------------------------------------------------------------------
# The vertical ground acceleration's power (the ground motions themselves: ``ground``)
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE_PUBLIC)
def vertical_power(p_in, theta, theta_dot, u, u_dot, s, g, prm, FLEX):
    """p_in plus the power [W] of the vertical d'Alembert loads -m_i a_v on the masses'
    heights Y_i (a_v = g - PAR_G): -a_v sum m_i Y_i' (full contact: 0). The work of a_v
    is counted with the ground's (W_in), the energy E keeps the constant g: E(t) - E(0) =
    W_in - D_damp - E_impact holds with a vertical too (docs/vertical.md)."""
    if s == 0:
        return p_in
    a_v = g - prm[PAR_G]
    cth, sth = math.cos(theta), math.sin(theta)
    sb = s * prm[PAR_B]
    if not FLEX:
        return p_in - a_v * prm[PAR_MTOT] * (sb * cth - prm[PAR_HCG] * sth) * theta_dot
    a, h = u - sb, prm[PAR_H]
    y_p = -u_dot * sth - (a * cth + h * sth) * theta_dot  # Y_P = -a sin + h cos
    y_a = (sb * cth - prm[PAR_HA] * sth) * theta_dot  # Y_A = s b sin + h_A cos
    return p_in - a_v * (prm[PAR_M] * y_p + prm[PAR_MA] * y_a)


def _power_plain(GROUND, p_in, theta, theta_dot, u, u_dot, s, g, prm, FLEX):
    return p_in


def _power_vertical(GROUND, p_in, theta, theta_dot, u, u_dot, s, g, prm, FLEX):
    return vertical_power(p_in, theta, theta_dot, u, u_dot, s, g, prm, FLEX)


#: (GROUND, p_in, theta, theta', u, u', s, g, prm, FLEX) -> ``vertical_power`` under a
#: ground kind with a vertical (``ground.GROUNDS``), else p_in itself (the other variants
#: compile nothing of it)
with_vertical_power = per_ground(lambda k: _power_vertical if k.vertical else _power_plain,
                                 "with_vertical_power")


# ----------------------------------------------------------------------------------------
# Rocking phases
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE_PUBLIC)
def rocking_rhs(theta, theta_dot, u, u_dot, s, xg, g, prm, DAMPED):
    """Accelerations while rocking on corner s (+1 / -1), and the input and damper powers,
    under ground acceleration xg [m/s^2] and gravity g [m/s^2] (``ground_gravity``).

    Returns (theta'' [rad/s^2], u'' [m/s^2], horizontal ground power [W], damper power [W]).
    """
    m, m_A, h, h_A = prm[PAR_M], prm[PAR_MA], prm[PAR_H], prm[PAR_HA]
    k, sb = prm[PAR_K], s * prm[PAR_B]
    cth, sth = math.cos(theta), math.sin(theta)
    a = u - sb
    f_damp = prm[PAR_C] * u_dot if DAMPED else 0.0
    lever = m * (h * cth - a * sth) + m_A * (h_A * cth + sb * sth)  # d(X_i)/d theta, summed
    f_theta = (-2.0 * m * a * u_dot * theta_dot + m * g * (a * cth + h * sth)
               - m_A * g * (sb * cth - h_A * sth) - xg * lever)
    f_u = m * a * theta_dot * theta_dot + m * g * sth - k * u - f_damp - m * xg * cth
    theta_dd = (f_theta - h * f_u) / (prm[PAR_IA0] + m * a * a)
    u_dd = f_u / m - h * theta_dd
    power_in = -xg * (lever * theta_dot + m * cth * u_dot)
    return theta_dd, u_dd, power_in, f_damp * u_dot


@njit(cache=True, **INLINE_PUBLIC)
def rigid_rhs(theta, theta_dot, s, xg, g, prm):
    """Rigid body (top mass welded, or a block): I_O theta'' = moment about corner s.

    I_O theta'' = -M g (s b cos - h_cg sin) - M xg'' (h_cg cos + s b sin); this is
    ``rocking_rhs`` with u = u' = 0 and no u equation (g: ``ground_gravity``). Returns
    (theta'', horizontal ground power).
    """
    M, sb, hcg = prm[PAR_MTOT], s * prm[PAR_B], prm[PAR_HCG]
    cth, sth = math.cos(theta), math.sin(theta)
    lever = M * (hcg * cth + sb * sth)
    theta_dd = (-M * g * (sb * cth - hcg * sth) - xg * lever) / prm[PAR_IO]
    return theta_dd, -xg * lever * theta_dot


# ----------------------------------------------------------------------------------------
# Full contact and uplift
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE_PUBLIC)
def contact_rhs(u, u_dot, xg, prm, DAMPED):
    """Full contact: m u'' + c u' + k u = -m xg''. Returns (u'', ground power, damper power)."""
    f_damp = prm[PAR_C] * u_dot if DAMPED else 0.0
    u_dd = -(prm[PAR_K] * u + f_damp) / prm[PAR_M] - xg
    return u_dd, -prm[PAR_M] * xg * u_dot, f_damp * u_dot


@njit(cache=True, **INLINE_PUBLIC)
def uplift_moment(u, u_dot, xg, g, prm, FLEX, DAMPED):
    """Q [N m]: the moment that tips the body in full contact (g: ``ground_gravity``).

    In full contact the ground reaction N = M g acts at x_R in [-b, b]; holding theta'' = 0
    in the theta equation about corner s (theta = theta' = 0, u'' from full contact) gives
    N (b - s x_R) = M g b - s Q with

        Q = h (k u + c u') + m g u - m_A h_A xg''.

    The reaction reaches corner s, and the body uplifts on it, when s Q >= M g b.
    (The top mass's d'Alembert load cancels against m h u''; only the spring force reaches
    the frame.) Rigid body: Q = -M h_cg xg'', i.e. uplift at |xg''| = g tan(alpha_cg).
    """
    if not FLEX:
        return -prm[PAR_MTOT] * prm[PAR_HCG] * xg
    f = prm[PAR_K] * u + (prm[PAR_C] * u_dot if DAMPED else 0.0)
    return prm[PAR_H] * f + prm[PAR_M] * g * u - prm[PAR_MA] * prm[PAR_HA] * xg


@njit(cache=True, **INLINE_PUBLIC)
def uplift_moment_rate(u, u_dot, xg, jerk, g, prm, FLEX, DAMPED):
    """dQ/dt [N m/s] in full contact, at constant g (a vertical's rate: ``uplift_rates``)."""
    if not FLEX:
        return -prm[PAR_MTOT] * prm[PAR_HCG] * jerk
    u_dd = contact_rhs(u, u_dot, xg, prm, DAMPED)[0]
    df = prm[PAR_K] * u_dot + (prm[PAR_C] * u_dd if DAMPED else 0.0)
    return prm[PAR_H] * df + prm[PAR_M] * g * u_dot - prm[PAR_MA] * prm[PAR_HA] * jerk


@njit(cache=True, **INLINE_PUBLIC)
def tip_moment(g, prm):
    """M g b [N m]: the moment about a corner that the body's weight resists uplift with
    (g: ``ground_gravity``, or the row's PAR_G)."""
    return prm[PAR_MTOT] * g * prm[PAR_B]


def _rates_plain(GROUND, dq, t, u, on, prm, FLEX):
    return -dq, dq


def _rates_vertical(GROUND, dq, t, u, on, prm, FLEX):
    dg = gravity_rate(GROUND, t, on, prm)
    dq_all = dq + prm[PAR_M] * dg * u if FLEX else dq  # Q's m g u
    d_mgb = prm[PAR_MTOT] * dg * prm[PAR_B]
    return d_mgb - dq_all, d_mgb + dq_all


#: (GROUND, dq, t, u, on, prm, FLEX) -> (d/dt (M g b - Q), d/dt (M g b + Q)): the uplift
#: events' rates from dQ/dt at constant g (``uplift_moment_rate``), plus, under a ground
#: kind with a vertical, those of g + a_v in Q and M g b (``ground.gravity_rate``)
uplift_rates = per_ground(lambda k: _rates_vertical if k.vertical else _rates_plain,
                          "uplift_rates")


@njit(cache=True, **INLINE_PUBLIC)
def rest_margin(u, u_dot, prm):
    """Q_max^2 - (M g b)^2 [N^2 m^2] after the pulse, in full contact (< 0: rest for good).

    Q = (h k + m g) u + h c u' is linear in (u, u'); over the energy ellipse
    1/2 m u'^2 + 1/2 k u^2 <= E (which c >= 0 never lets grow) its largest value Q_max
    has Q_max^2 = 2 E (L_u^2/k + L_v^2/m). Below M g b the body stays in contact for good.
    Flexible bodies only (a rigid body in full contact after the pulse is at rest).
    """
    m, k, h = prm[PAR_M], prm[PAR_K], prm[PAR_H]
    l_u = h * k + m * prm[PAR_G]
    l_v = h * prm[PAR_C]
    e2 = m * u_dot * u_dot + k * u * u  # 2 E
    q_max2 = e2 * (l_u * l_u / k + l_v * l_v / m)
    mgb = tip_moment(prm[PAR_G], prm)
    return q_max2 - mgb * mgb


# ----------------------------------------------------------------------------------------
# Impact (eq. 1 and the other impact laws)
# ----------------------------------------------------------------------------------------


@njit(cache=True, **PUBLIC)
def restitution(s, u, prm, FLEX):
    """e = theta'^+ / theta'^- for an impact that ends rocking on corner s, under the row's
    impact law (PAR_LAW, ``rocksweep.physics.impact``), times PAR_E_FACTOR.

    LAW_EQ1: eq. (1) (``eq1.restitution``, the one definition). LAW_LOCKED: the top mass
    keeps u' (moves with the base), which adds m h^2 to eq. (1)'s numerator and
    denominator. LAW_CONSTANT: e = PAR_E. Rigid body (eq. 1 and locked are one law: the
    top mass is welded): ``eq1.restitution_rigid``.
    """
    law = prm[PAR_LAW]
    if law == LAW_CONSTANT:
        return prm[PAR_E] * prm[PAR_E_FACTOR]
    b, lam = prm[PAR_B], prm[PAR_LAM]
    if not FLEX:
        return _e_rigid(prm[PAR_IO], prm[PAR_MTOT] * b * b, lam) * prm[PAR_E_FACTOR]
    m = prm[PAR_M]
    mh2 = m * prm[PAR_H] * prm[PAR_H] if law == LAW_LOCKED else 0.0
    return _e_eq1(s, u, lam, m, prm[PAR_MA], b, prm[PAR_IAH], mh2) * prm[PAR_E_FACTOR]


@njit(cache=True, **INLINE)
def top_mass_rate(u_dot, w_minus, w_plus, prm):
    """u'^+ [m/s] after an impact (any phase after): LAW_LOCKED keeps u' (the top mass
    moves with the base); the other laws keep the top mass's horizontal momentum
    m (u' + h theta') (no impulse reaches it through the spring)."""
    if prm[PAR_LAW] == LAW_LOCKED:
        return u_dot
    return u_dot + prm[PAR_H] * (w_minus - w_plus)


# ----------------------------------------------------------------------------------------
# Energy (relative to rest, in the frame of the ground)
# ----------------------------------------------------------------------------------------


@njit(cache=True, **PUBLIC)
def mechanical_energy(theta, theta_dot, u, u_dot, s, prm, FLEX):
    """T + V - V_rest [J] in phase s (0: full contact)."""
    if not FLEX:
        if s == 0:
            return 0.0
        sth, cth = math.sin(theta), math.cos(theta)
        pot = prm[PAR_MTOT] * prm[PAR_G] * (s * prm[PAR_B] * sth + prm[PAR_HCG] * (cth - 1.0))
        return 0.5 * prm[PAR_IO] * theta_dot * theta_dot + pot
    m, k = prm[PAR_M], prm[PAR_K]
    if s == 0:
        return 0.5 * m * u_dot * u_dot + 0.5 * k * u * u
    h, h_A, sb, g = prm[PAR_H], prm[PAR_HA], s * prm[PAR_B], prm[PAR_G]
    sth, cth = math.sin(theta), math.cos(theta)
    a = u - sb
    v_x = u_dot + h * theta_dot
    kin = 0.5 * m * (v_x * v_x + a * a * theta_dot * theta_dot) + 0.5 * prm[PAR_IA0] * theta_dot**2
    pot = (m * g * (h * (cth - 1.0) - a * sth) + prm[PAR_MA] * g * (h_A * (cth - 1.0) + sb * sth)
           + 0.5 * k * u * u)
    return kin + pot


@njit(cache=True, **PUBLIC)
def impact_loss(s, s_new, u, u_dot, w_minus, w_plus, prm, FLEX):
    """Energy [J] the impact itself dissipates (eq. 6 under the row's law; < 0: the
    impact gains energy). u_dot: u' before the impact.

    At theta = 0 the potential energy is the same before and after. With a = u - s b the
    top mass's lever arm about corner s, the kinetic energy at theta = 0 is
    1/2 m (u' + h w)^2 + 1/2 (I_A + m_A R_A^2 + m a^2) w^2. Under LAW_EQ1 and
    LAW_CONSTANT the top mass keeps its horizontal velocity u' + h w (no impulse reaches
    it), so only the rest changes:

        E_d = 1/2 (I_A + m_A R_A^2 + m a^2) w^-^2 - 1/2 (I_A + m_A R_A^2 + m a'^2) w^+^2,

    a' = u - s_new b (w^+ = 0 when s_new = 0, full contact). With s_new = -s and
    w^+ = e w^- this is eq. (6). LAW_LOCKED keeps u' instead, which adds
    1/2 m [(u' + h w^-)^2 - (u' + h w^+)^2]. Rigid body: 1/2 I_O (w^-^2 - w^+^2). Written
    as this difference, not as a difference of total energies, so that round-off in the
    spring's energy cannot make a dissipating impact look like one that gains energy.
    """
    if not FLEX:
        return 0.5 * prm[PAR_IO] * (w_minus * w_minus - w_plus * w_plus)
    m, b = prm[PAR_M], prm[PAR_B]
    a_minus = u - s * b
    loss = 0.5 * (prm[PAR_IA0] + m * a_minus * a_minus) * w_minus * w_minus
    if s_new != 0:
        a_plus = u - s_new * b
        loss -= 0.5 * (prm[PAR_IA0] + m * a_plus * a_plus) * w_plus * w_plus
    if prm[PAR_LAW] == LAW_LOCKED:
        v_minus = u_dot + prm[PAR_H] * w_minus
        v_plus = u_dot + prm[PAR_H] * w_plus
        loss += 0.5 * m * (v_minus * v_minus - v_plus * v_plus)
    return loss


# ----------------------------------------------------------------------------------------
# After the pulse: a flexible body whose energy is below its ridge
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INLINE_PUBLIC)
def ridge_energy(theta, prm):
    """W(theta) [J]: the least potential energy V - V_rest of the flexible body tilted by
    |theta| [rad], over the top mass's u (``ridge.ridge_energy``, the one definition: V
    above is 1/2 k u^2 - m g u sin|theta| plus terms free of u, least at u = m g sin|theta|
    / k). Its peak, at PAR_RIDGE, is the overturning saddle's energy."""
    return _ridge(theta, prm[PAR_M], prm[PAR_MA], prm[PAR_H], prm[PAR_HA], prm[PAR_B],
                  prm[PAR_K], prm[PAR_G])


# ----------------------------------------------------------------------------------------
# After the pulse: a rigid body that can no longer overturn
# ----------------------------------------------------------------------------------------


# Relative margin on a body's energy below its barrier (``rigid_peak``) or its ridge
# (``transitions.flexible_bounded``): covers the integrator's energy error (RK4 at the
# presets drifts far less), so round-off cannot prove a body safe.
BOUND_ENERGY_MARGIN = 1e-6


@njit(cache=True, **INLINE_PUBLIC)
def rigid_peak(theta, theta_dot, s, prm):
    """After the pulse, a rigid body rocking on corner s: the largest |theta| [rad] still to
    come if it can never overturn, else -1 (not proven).

    With no ground motion its energy E is constant while it rocks and is multiplied by
    e^2 <= 1 at every impact when |e| <= 1 (lam <= 1; e is the same at every impact).
    The potential V = M g (R cos(a - s theta) - h_cg), a = atan(b/h_cg), peaks at
    s theta = a; a body inside the barrier (s theta < a) with E below that peak (less
    BOUND_ENERGY_MARGIN) never overturns. The next peak has V = E if moving away from
    theta = 0, else V = e^2 E (after the next impact).
    """
    e = restitution(s, 0.0, prm, False)
    if abs(e) > 1.0:
        return -1.0
    mg, b, hcg = prm[PAR_MTOT] * prm[PAR_G], prm[PAR_B], prm[PAR_HCG]
    r = math.hypot(b, hcg)
    a = math.atan2(b, hcg)
    e_now = mechanical_energy(theta, theta_dot, 0.0, 0.0, s, prm, False)
    if not (s * theta < a and e_now < (1.0 - BOUND_ENERGY_MARGIN) * mg * (r - hcg)):
        return -1.0
    if s * theta_dot < 0.0:
        e_now *= e * e
    return a - math.acos(min((e_now / mg + hcg) / r, 1.0))


# ----------------------------------------------------------------------------------------
# The top mass's spring while the base rocks (what the step size must resolve): plain
# Python, in ``spring`` (called from Python only; importable without numba)
# ----------------------------------------------------------------------------------------

rocking_spring_omega = spring.rocking_spring_omega
