"""The ridge of a flexible body's potential energy, over which it overturns (plain Python).

``ridge_energy`` is evaluated on arrays by the rows' builder (``rocksweep.physics.points``:
where the ridge peaks, once per body) and compiled by ``equations`` for the kernel, which
ends a run once its energy is below the ridge (``transitions.flexible_bounded``). Plain
numpy arithmetic on floats or arrays (they broadcast), importable without numba.
Conventions of ``equations``: SI units with m = 1, g = 9.81, p = 1.
"""

import numpy as np

# golden-section iterations of ``ridge_theta``: the bracket shrinks by 0.618 per step,
# from pi/2 to < 1e-15 rad after 75
_GOLDEN_STEPS = 80


def ridge_energy(theta, m, m_A, h, h_A, b, k, g):
    """W(theta) [J]: the least potential energy V - V_rest of the flexible body tilted by
    |theta| [rad] on either corner, over the top mass's u.

    Rocking on corner s (s theta = |theta|), V - V_rest = m g (h (cos - 1) - (u - s b) sin
    theta) + m_A g (h_A (cos - 1) + s b sin theta) + 1/2 k u^2 (``equations``) is
    1/2 k u^2 - m g u sin|theta| plus terms free of u: least at u = m g sin|theta| / k,

        W = m g (h (cos - 1) + b sin) + m_A g (h_A (cos - 1) + b sin) - (m g sin)^2 / (2 k)

    (of |theta|). W(0) = 0, and on [0, pi/2] W has one peak, theta_r (``ridge_theta``): its
    derivative cos (M g b - (m g)^2 sin / k) - M g h_cg sin falls while it is positive.
    W(theta_r) is the overturning saddle's energy, and T + V >= V >= W(theta): a body
    whose energy is below W(theta) <= W(theta_r) cannot tilt to theta.
    """
    sth = np.sin(np.abs(theta))
    cm1 = np.cos(theta) - 1.0
    return (m * g * (h * cm1 + b * sth) + m_A * g * (h_A * cm1 + b * sth)
            - (m * g * sth) ** 2 / (2.0 * k))


def ridge_theta(m, m_A, h, h_A, b, k, g):
    """theta_r [rad]: where ``ridge_energy`` peaks on [0, pi/2] (float64 like the inputs,
    broadcast; k > 0), by golden sections (W is unimodal there)."""
    inv = (np.sqrt(5.0) - 1.0) / 2.0
    shape = np.broadcast(m, m_A, h, h_A, b, k, g).shape
    lo, hi = np.zeros(shape), np.full(shape, np.pi / 2)
    for _ in range(_GOLDEN_STEPS):
        x1 = hi - inv * (hi - lo)
        x2 = lo + inv * (hi - lo)
        left = (ridge_energy(x1, m, m_A, h, h_A, b, k, g)
                >= ridge_energy(x2, m, m_A, h, h_A, b, k, g))
        hi = np.where(left, x2, hi)
        lo = np.where(left, lo, x1)
    return 0.5 * (lo + hi)
