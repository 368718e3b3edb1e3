"""The rules that change the phase or end a run early (jitted).

- ``uplift_side``: full contact -> rocking on a corner, when s Q >= M g b;
- ``impact_map``: rocking -> rocking on the other corner or full contact, at theta = 0
  (eq. 1 or the row's impact law, and the settling rule);
- ``rest_proven``: after the pulse, full contact for good (flexible body);
- ``rigid_bounded``: after the pulse, a rigid body that can no longer overturn;
- ``flexible_bounded``: after the pulse, a flexible body that can neither overturn nor
  tilt past its theta_max again.

The formulas come from ``equations``; the reference path (``rocksweep.physics.reference``) calls
the same ones (``tip_moment``, ``rest_margin``, ``rigid_peak``, ``ridge_energy``).
"""

import math

from numba import literally, njit

from rocksweep.kernel._cache import INTERNAL
from rocksweep.kernel._static import skipped_when
from rocksweep.kernel.equations import (
    BOUND_ENERGY_MARGIN,
    impact_loss,
    mechanical_energy,
    rest_margin,
    restitution,
    ridge_energy,
    rigid_peak,
    tip_moment,
    top_mass_rate,
    uplift_moment,
)
from rocksweep.kernel.ground import ground_acc, ground_gravity
from rocksweep.kernel.layout import (
    PAR_RESTRATE,
    PAR_RIDGE,
    Y_D_DAMP,
    Y_THETA,
    Y_THETA_DOT,
    Y_U,
    Y_U_DOT,
    Y_W_IN,
)


@njit(cache=True, **INTERNAL)
def uplift_side(t, y, on, prm, FLEX, DAMPED, GROUND):
    """Corner (+1 / -1) the body uplifts on from full contact at (t, y), or 0 (with a
    vertical: under g + a_v(t), in Q and in M g b alike)."""
    g = ground_gravity(GROUND, t, on, prm)
    q = uplift_moment(y[Y_U], y[Y_U_DOT], ground_acc(GROUND, t, on, prm), g, prm, FLEX, DAMPED)
    mgb = tip_moment(g, prm)
    if q >= mgb:
        return 1
    if q <= -mgb:
        return -1
    return 0


@njit(cache=True, **INTERNAL)
def rest_proven(y, prm, FLEX):
    """After the pulse, in full contact: can the oscillator never uplift the body again?

    True when the largest Q over the oscillator's energy ellipse is below M g b
    (``rest_margin`` < 0); always for a rigid body (nothing moves in full contact).
    """
    if not FLEX:
        return True
    return rest_margin(y[Y_U], y[Y_U_DOT], prm) < 0.0


# the flexible variants never test the rigid bound, the outcome-only ones never account
# energy: neither compiles them (``_static``)
_rigid_peak = skipped_when(True, rigid_peak, -1.0)  # -1: not proven (FLEX)
_energy = skipped_when(False, mechanical_energy, 0.0)  # (not ENERGY)
_impact_loss = skipped_when(False, impact_loss, 0.0)  # (not ENERGY)


@njit(cache=True, **INTERNAL)
def rigid_bounded(y, s, prm, FLEX):
    """After the pulse, a rigid body rocking on corner s: the largest |theta| still to come
    if it can never overturn (its outcome is decided: safe), else -1 (``rigid_peak``;
    always -1 for a flexible body, FLEX)."""
    literally(FLEX)
    return _rigid_peak(FLEX, y[Y_THETA], y[Y_THETA_DOT], s, prm)


@njit(cache=True, **INTERNAL)
def flexible_bounded(y, s, theta_max, prm):
    """After the pulse, a flexible body in phase s at y whose |theta| has not exceeded
    theta_max [rad]: its energy margin sqrt((W_r - E) / W_r) if it can neither overturn nor
    tilt past theta_max again, else -1 (not proven).

    With the ground still, T + V only falls: the damper takes c u'^2, and every impact
    loses energy where the row's law cannot gain any (PAR_RIDGE is NaN otherwise,
    ``physics.points.impacts_lose``; the rest-rate rule and full contact only lose). V >= W(theta)
    (``ridge_energy``) and W rises to its peak W_r at theta_r = PAR_RIDGE, the overturning
    saddle's energy: a body now inside the ridge (|theta| < theta_r) with an energy below
    W(min(theta_max, theta_r)) (less BOUND_ENERGY_MARGIN) can reach neither theta_r nor
    theta_max again (a flexible body may have tilted past theta_r and come back: its u
    was off the ridge's). Its outcome (safe) and its theta_max are both decided: what is
    left of the run is the rocking to rest, which the class does not need
    (docs/accuracy.md, "Decided by its energy"). The margin, in the units of a rigid
    body's (``rigid_peak``, ``loop._energy_margin``), says how far the decision was from
    the step's error in E (``compute.certify``).
    """
    theta_r = prm[PAR_RIDGE]
    if not abs(y[Y_THETA]) < theta_r:  # past the ridge's peak now (falling?), or NaN
        return -1.0
    e_now = mechanical_energy(y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT], s, prm, True)
    w_r = ridge_energy(theta_r, prm)
    # W at min(theta_max, theta_r): the peak itself once theta_max has reached it
    w_cap = w_r if theta_max >= theta_r else ridge_energy(theta_max, prm)
    if not e_now < (1.0 - BOUND_ENERGY_MARGIN) * w_cap:
        return -1.0
    return math.sqrt((w_r - e_now) / w_r)


@njit(cache=True, **INTERNAL)
def impact_map(y, s, prm, FLEX, ENERGY):
    """Impact map at theta = 0 ending rocking on corner s (eq. 1 and the settling rule).

    Returns (state after, new phase, e, energy lost E_d [J], impact loss [J]) (energies 0
    unless ENERGY). E_d = E(before) - E(after) closes the energy balance; it includes the
    potential energy of the located state's overshoot of theta = 0 (within the event
    tolerance). The impact loss (``impact_loss``, eq. 6) is the impact's own share; only it
    decides whether an impact gained energy, so the overshoot cannot flag a spurious gain.
    e > 0 with |e theta'^-| >= PAR_RESTRATE: rocking continues on -s, theta'^+ = e theta'^-.
    Otherwise full contact: e <= 0 is inadmissible as rocking, and a post-impact rate
    below the rest rate ends a chattering (Zeno) sequence after finitely many impacts.
    Either way the top mass follows the law's rule (``top_mass_rate``): it keeps its
    horizontal momentum m (u' + h theta') (vertical, constant) or its rate u' (locked).
    e is the law's (``restitution``, PAR_LAW and PAR_E_FACTOR read here, at run time).
    """
    literally(FLEX)
    literally(ENERGY)
    theta, w_minus, u, u_dot = y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT]
    e = restitution(s, u, prm, FLEX)
    if e > 0.0 and abs(e * w_minus) >= prm[PAR_RESTRATE]:
        s_new = -s
        w_plus = e * w_minus
    else:
        s_new = 0
        w_plus = 0.0
    u_dot_plus = top_mass_rate(u_dot, w_minus, w_plus, prm) if FLEX else 0.0
    y_new = (0.0, w_plus, u, u_dot_plus, y[Y_W_IN], y[Y_D_DAMP])
    e_d = 0.0
    loss = 0.0
    if ENERGY:
        e_d = (_energy(ENERGY, theta, w_minus, u, u_dot, s, prm, FLEX)
               - _energy(ENERGY, 0.0, w_plus, u, u_dot_plus, s_new, prm, FLEX))
        loss = _impact_loss(ENERGY, s, s_new, u, u_dot, w_minus, w_plus, prm, FLEX)
    return y_new, s_new, e, e_d, loss
