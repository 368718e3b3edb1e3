"""One fixed RK4 step on the state y = (theta, theta', u, u', W_in, D_damp) (jitted).

``derivatives`` assembles dy/dt for a phase from the equations (``equations``);
``rk4_step`` knows nothing of events, phases changing or the loop.

Compile-time flags (see ``variants``): FLEX (the top mass moves on its spring), DAMPED (the
spring has a damper), ENERGY (integrate the ground's work W_in and the damper's loss
D_damp along) and GROUND (the ground kind, ``ground.GROUNDS``). The functions are
inlined where they are called, by LLVM (``_cache.INLINE``: compiled once, then inlined;
numba's own ``inline="always"`` retyped them at every call site), so an RK4 step makes no
function call.
"""

from numba import njit

from rocksweep.kernel._cache import INLINE
from rocksweep.kernel.equations import contact_rhs, rigid_rhs, rocking_rhs, with_vertical_power
from rocksweep.kernel.ground import ground_acc, ground_gravity
from rocksweep.kernel.layout import Y_THETA, Y_THETA_DOT, Y_U, Y_U_DOT


@njit(cache=True, **INLINE)
def derivatives(t, y, s, on, prm, FLEX, DAMPED, ENERGY, GROUND):
    """dy/dt (a 6-tuple in the ``Y_*`` slot order) at (t, y) in phase s (0 full contact,
    +-1 rocking on that corner); ``on``: the ground moves (under GROUND's kind: with a
    vertical, its gravity g + a_v the rocking phases feel and its work W_in counts)."""
    theta, theta_dot, u, u_dot = y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT]
    xg = ground_acc(GROUND, t, on, prm)
    if s == 0:
        if not FLEX:
            return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        u_dd, p_in, p_damp = contact_rhs(u, u_dot, xg, prm, DAMPED)
        if ENERGY:
            return (0.0, 0.0, u_dot, u_dd, p_in, p_damp)
        return (0.0, 0.0, u_dot, u_dd, 0.0, 0.0)
    g = ground_gravity(GROUND, t, on, prm)
    if not FLEX:
        theta_dd, p_in = rigid_rhs(theta, theta_dot, s, xg, g, prm)
        if ENERGY:
            p_in = with_vertical_power(GROUND, p_in, theta, theta_dot, 0.0, 0.0, s, g, prm,
                                       FLEX)
            return (theta_dot, theta_dd, 0.0, 0.0, p_in, 0.0)
        return (theta_dot, theta_dd, 0.0, 0.0, 0.0, 0.0)
    theta_dd, u_dd, p_in, p_damp = rocking_rhs(theta, theta_dot, u, u_dot, s, xg, g, prm,
                                               DAMPED)
    if ENERGY:
        p_in = with_vertical_power(GROUND, p_in, theta, theta_dot, u, u_dot, s, g, prm, FLEX)
        return (theta_dot, theta_dd, u_dot, u_dd, p_in, p_damp)
    return (theta_dot, theta_dd, u_dot, u_dd, 0.0, 0.0)


@njit(cache=True, **INLINE)
def _axpy(y, a, k):
    """y + a k, slot by slot."""
    return (y[0] + a * k[0], y[1] + a * k[1], y[2] + a * k[2],
            y[3] + a * k[3], y[4] + a * k[4], y[5] + a * k[5])


@njit(cache=True, **INLINE)
def first_stage(t, y, s, on, prm, FLEX, DAMPED, ENERGY, GROUND):
    """k1 = dy/dt at (t, y): the first stage of every RK4 step from (t, y), whatever its
    length. A step and the trial steps that locate an event in it (``events``), or the
    shorter retries of the rotation limit (``loop``), all start from the same (t, y):
    they share one k1 (``rk4_from``), bit for bit what each computed (the same inputs:
    t + 0 and y + 0 k, as the other stages form theirs)."""
    zero = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    return derivatives(t + 0.0, _axpy(y, 0.0, zero), s, on, prm, FLEX, DAMPED, ENERGY,
                       GROUND)


@njit(cache=True, **INLINE)
def rk4_from(t, y, h, k1, s, on, prm, FLEX, DAMPED, ENERGY, GROUND):
    """One classical RK4 step of size h [s] from (t, y) in phase s whose first stage k1
    (``first_stage``) is known. Returns the new 6-tuple."""
    # The three stages share one call site of the inlined right-hand side (numba types and
    # lowers it once, LLVM unrolls the loop): fewer call sites, less compile time.
    k = k1
    k23 = k1
    for stage in range(1, 4):
        c = h if stage == 3 else 0.5 * h
        k = derivatives(t + c, _axpy(y, c, k), s, on, prm, FLEX, DAMPED, ENERGY, GROUND)
        if stage == 1:
            k23 = k
        elif stage == 2:
            k23 = _axpy(k23, 1.0, k)  # k2 + k3
    w = h / 6.0  # k is k4 now
    return (y[0] + w * (k1[0] + 2.0 * k23[0] + k[0]),
            y[1] + w * (k1[1] + 2.0 * k23[1] + k[1]),
            y[2] + w * (k1[2] + 2.0 * k23[2] + k[2]),
            y[3] + w * (k1[3] + 2.0 * k23[3] + k[3]),
            y[4] + w * (k1[4] + 2.0 * k23[4] + k[4]),
            y[5] + w * (k1[5] + 2.0 * k23[5] + k[5]))


@njit(cache=True, **INLINE)
def rk4_step(t, y, h, s, on, prm, FLEX, DAMPED, ENERGY, GROUND):
    """One classical RK4 step of size h [s] from (t, y) in phase s. Returns the new 6-tuple."""
    return rk4_from(t, y, h, first_stage(t, y, s, on, prm, FLEX, DAMPED, ENERGY, GROUND), s,
                    on, prm, FLEX, DAMPED, ENERGY, GROUND)
