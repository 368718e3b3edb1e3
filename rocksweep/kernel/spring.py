"""The top mass's spring while the base rocks: what the step size must resolve (plain Python).

Called from Python only (the step-size rule, ``rocksweep.physics.points``; the model; the
reference), never from the jitted loop: no numba, so that importing it costs nothing (the
jitted ``equations`` imports numba, ~0.1-0.2 s of a command's start-up).
``equations.rocking_spring_omega`` is this function.
"""

import math


def rocking_spring_omega(omega_n, zeta, m, h, i_a0, a):
    """Fastest rate [rad/s] of the top mass on its spring while the base rocks, with the
    top mass's lever arm a = u - s b [m] about the corner.

    Linearising ``equations.rocking_rhs`` in u: u'' = -Gamma (k u + c u') / m + ...,
    Gamma = 1 + m h^2 / (I_A + m_A R_A^2 + m a^2) (i_a0 = I_A + m_A R_A^2 [kg m^2]): a
    spring of frequency omega_n sqrt(Gamma) and damping ratio zeta sqrt(Gamma). Gamma is
    largest at a = 0. Above a damping ratio of 1 the mode is overdamped and its fast root,
    omega (zeta' + sqrt(zeta'^2 - 1)), is what an explicit step must resolve.
    """
    gamma = 1.0 + m * (h * h) / (i_a0 + m * (a * a))
    omega, zeta_r = omega_n * math.sqrt(gamma), zeta * math.sqrt(gamma)
    if zeta_r > 1.0:
        omega *= zeta_r + math.sqrt(zeta_r * zeta_r - 1.0)
    return float(omega)
