"""Eq. (1): the coefficient of restitution of an impact, written once (plain Python).

Pure arithmetic on floats or numpy arrays (they broadcast), importable without numba:
``equations.restitution`` compiles these for the kernel (the row's law and body),
``rocksweep.physics.bodies`` and ``rocksweep.physics.impact`` evaluate them on arrays of lam
and u (Figure 2, the energy-admissible lam). Conventions of ``rocksweep.physics.bodies``.

An impact ends rocking on corner s (+1 / -1); the vertical impulse acts at
x_Q = s' b (1 - lam), lam*b from the future corner s' = -s. The angular momentum of the
whole body about x_Q is conserved (a horizontal impulse at the ground has no moment about
it), and so is the top mass's horizontal momentum m (u' + h theta') (the spring and damper
carry no impulse); eliminating u'^+ gives

    e = [I_A + m_A (h_A^2 + x_Q s b)  + m (u - x_Q)(u - s b)]
      / [I_A + m_A (h_A^2 + x_Q s' b) + m (u - x_Q)(u - s' b)],

which is eq. (1) (its upper sign: s = +1). I_A + m_A h_A^2 is the base's inertia about the
base's mid point (``layout.PAR_IAH``). A top mass locked to the base through the impact
(law ``locked``) keeps u' instead, which adds m h^2 to numerator and denominator
(``mh2``; 0 for eq. (1) itself).

The rigid body (top mass welded, or a block: one mass M, inertia I_O about a corner) has
e = (I_O - M b^2 (2 - lam)) / (I_O - lam M b^2) by the same balance (Housner's
1 - 2 M b^2 / I_O at lam = 0).
"""


def restitution(s, u, lam, m, m_A, b, i_ah, mh2):
    """Eq. (1): e = theta'^+ / theta'^- of an impact that ends rocking on corner s (float
    +-1), top mass at u [m], impulse at lam*b from the future corner; m, m_A [kg], b [m],
    i_ah = I_A + m_A h_A^2 [kg m^2], mh2: m h^2 [kg m^2] for a locked top mass, else 0.
    (The kernel's arithmetic, in its order: the kernel's e bit for bit.)"""
    x_q = -s * b * (1.0 - lam)
    num = i_ah + m_A * x_q * s * b + m * (u - x_q) * (u - s * b) + mh2
    den = i_ah - m_A * x_q * s * b + m * (u - x_q) * (u + s * b) + mh2
    return num / den


def restitution_rigid(i_o, mb2, lam):
    """The rigid body's e for an impulse at lam*b from the future corner: i_o = I_O [kg m^2]
    about a corner, mb2 = M b^2 [kg m^2]."""
    return (i_o - mb2 * (2.0 - lam)) / (i_o - lam * mb2)
