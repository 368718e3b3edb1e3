"""Impact laws: the coefficient of restitution and the energy an impact dissipates.

The paper (section 2) derives eq. (1) from two balances over the instant of impact: the
angular momentum of the whole body about the locus of the vertical impulse (at lam*b from
the future rocking corner; a horizontal impulse at the ground has no moment about it) and,
since "the spring and damper cannot transmit impulsive forces", the horizontal momentum of
the top mass. It names the other assumptions in use: Housner's rigid body, coefficients of
restitution calibrated to experiments, and coefficients scaled from the analytical one
(Acikgoz et al.). rocksweep offers them as laws (scene keys ``impact.law``, ``impact.e``,
``impact.e_factor``), read by the kernel at each impact (``rocksweep.kernel.equations``):

- ``vertical`` (eq. 1): the top mass keeps its horizontal momentum m (u' + h theta').
- ``locked``: the top mass moves with the base through the impact, its velocity relative to
  the base u' is kept (the spring acts as if rigid for the instant of impact). The angular
  momentum balance then gives eq. (1) with m h^2 added to its numerator and denominator;
  at u = 0 it is the rigid body's e = (I_O - (2 - lam) M b^2) / (I_O - lam M b^2),
  Housner's 1 - 2 M b^2 / I_O at lam = 0.
- ``constant``: e given (a calibrated value, 0 < e <= 1); the top mass keeps its
  horizontal momentum as in ``vertical``.
- ``e_factor`` (> 0) multiplies any law's e (the "modified coefficient" practice).

After an impact with e <= 0, or whose rate falls below the rest rate, full contact
follows with the law's rule for the top mass. A rigid body (wn_over_p = inf, a block) has
its top mass welded: ``vertical`` and ``locked`` are then one law, the rigid body's.

Energy, eq. (6) generalised: at theta = 0 the potential energy is the same before and
after the impact, so the energy it dissipates is the drop of the kinetic energy
T = 1/2 m (u' + h w)^2 + 1/2 (I_A + m_A R_A^2 + m a^2) w^2, a = u - s b:

- ``vertical``, ``constant``: u' + h w is kept, E_d = 1/2 (I_0A + m a^2) w^-^2
  - 1/2 (I_0A + m a'^2) w^+^2, which is eq. (6) with w^+ = e w^-;
- ``locked``: u' is kept, which adds m h u' w^- (1 - e) + 1/2 m h^2 w^-^2 (1 - e^2); the
  first term is the work of the impulse that locks the top mass to the base, so whether a
  locked impact gains energy depends on u' too. ``lam_energy_limit`` uses u' = 0 for it
  (the top mass at rest relative to the base).

Conventions as in ``rocksweep.physics.bodies``: ``upper`` is the paper's upper sign (rocking
on the +b corner ends, the future corner is -b, u positive toward +b).
"""

from __future__ import annotations

import math

import numpy as np

from rocksweep.kernel import eq1 as _eq1
from rocksweep.physics.bodies import Body, FlexibleBody, impact_energy_loss, restitution_rigid
from rocksweep.vocab.laws import CONSTANT, DEFAULT_LAW, EQ1, LAWS, LOCKED

# The u/u_cr range over which a body's energy-admissible lam is taken (Figure 2's range)
U_RANGE = 2.0


def _flexible(body: Body) -> bool:
    return isinstance(body, FlexibleBody) and not body.rigid


def restitution(body: Body, lam, u, upper: bool = True, law: str = DEFAULT_LAW,
                e: float = math.nan, e_factor: float = 1.0) -> np.ndarray:
    """e = theta'^+ / theta'^- of a rocking-to-rocking impact under ``law``, times
    ``e_factor``. lam, u [m]: arrays broadcast (u is not used by a rigid body)."""
    lam = np.asarray(lam, float)
    u = np.asarray(u, float)
    if law == CONSTANT:
        return np.broadcast_to(np.float64(e * e_factor), np.broadcast(lam, u).shape).copy()
    if law not in (EQ1, LOCKED):
        raise ValueError(f"impact law {law!r}: must be one of {', '.join(LAWS)}")
    if not _flexible(body):  # top mass welded: the rigid body's e
        return np.asarray(restitution_rigid(body, lam), float) * e_factor + 0.0 * u
    # eq. (1), one definition (the kernel's, ``rocksweep.kernel.eq1``); locked: + m h^2
    mh2 = body.m * body.h * body.h if law == LOCKED else 0.0
    return _eq1.restitution(1.0 if upper else -1.0, u, lam, body.m, body.m_A, body.b,
                            body.I_A + body.m_A * body.h_A**2, mh2) * e_factor


def energy_loss(body: Body, e, u, theta_dot_minus, upper: bool = True,
                law: str = DEFAULT_LAW, u_dot=0.0) -> np.ndarray:
    """E_d [J], the energy a rocking-to-rocking impact with restitution e dissipates
    (eq. 6 under ``law``; < 0: the impact gains energy). u [m], theta_dot_minus [rad/s]
    and (``locked`` only) u_dot [m/s], the top mass's rate relative to the base."""
    e = np.asarray(e, float)
    w2 = np.asarray(theta_dot_minus, float) ** 2
    if not _flexible(body):
        return 0.5 * body.I_O * (1 - e**2) * w2
    loss = impact_energy_loss(body, e, u, theta_dot_minus, upper)
    if law == LOCKED:
        mh = body.m * body.h
        loss = loss + (mh * np.asarray(u_dot, float) * np.asarray(theta_dot_minus, float)
                       * (1 - e) + 0.5 * mh * body.h * (1 - e**2) * w2)
    return loss


def lam_energy_limit(body: Body, u, upper: bool = True, law: str = DEFAULT_LAW,
                     e: float = math.nan, e_factor: float = 1.0, iters: int = 60
                     ) -> np.ndarray:
    """The largest lam in [0, 2] at which a rocking-to-rocking impact at lateral u [m]
    cannot gain energy under ``law`` (``locked``: with u' = 0), float64 like u.

    E_d falls as lam grows (eq. 7: dE_d/de < 0 for e > 0, and e grows with lam, eq. 5),
    so the limit is the root of E_d(lam) = 0, found by bisection; 2 where no lam in
    [0, 2] gains energy, NaN where even lam = 0 does (the ``constant`` law's e does not
    depend on lam: 2 or NaN). Impacts with e <= 0 end in full contact and only dissipate.
    """
    u = np.asarray(u, float)

    def gains(lam):
        ev = restitution(body, lam, u, upper, law, e, e_factor)
        ed = energy_loss(body, ev, u, 1.0, upper, law, 0.0)
        return (ev > 0) & (ed < 0)

    lo = np.zeros(u.shape)
    hi = np.full(u.shape, 2.0)
    none = ~gains(hi)
    every = gains(lo)
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        g = gains(mid)
        hi = np.where(g, mid, hi)
        lo = np.where(g, lo, mid)
    out = np.where(none, 2.0, lo)
    return np.where(every & ~none, np.nan, out)


def body_lam_limit(body: Body, law: str = DEFAULT_LAW, e: float = math.nan,
                   e_factor: float = 1.0, n_u: int = 161) -> float:
    """The body's energy-admissible lam: the least ``lam_energy_limit`` over u/u_cr in
    [-U_RANGE, U_RANGE] (both transition directions: the lower sign is the upper's mirror
    u -> -u); NaN when some impact there gains energy at every lam."""
    if not _flexible(body):
        u = np.zeros(1)
    else:
        u = np.linspace(-U_RANGE, U_RANGE, n_u) * body.u_cr
    lim = lam_energy_limit(body, u, True, law, e, e_factor)
    return float(np.nan if np.isnan(lim).any() else lim.min())
