"""Where the model holds: ground reactions, friction demand and impact impulses (jitted).

The model assumes the base neither slides nor leaves the ground (Housner's idealisations).
Newton's second law for the two masses gives the ground's reaction on the body: with
(X_i, Y_i) the positions of the top mass P (m) and the base's centre A (m_A) in the frame
of the ground (``tests/test_derivations.py::_positions``), rocking on corner s (a = u - s b):

    X_P = x_g + s b + a cos + h sin,       Y_P = -a sin + h cos
    X_A = x_g + s b - s b cos + h_A sin,   Y_A = s b sin + h_A cos

    H = m X_P'' + m_A X_A''                 (horizontal reaction [N])
    N = m (Y_P'' + g) + m_A (Y_A'' + g)     (vertical reaction [N])

with the accelerations theta'', u'' of the equations of motion (``equations``); the base's
own inertia I_A only rotates it about A and takes no force. Full contact (theta = 0):
H = M xg'' + m u'', N = M g. A rigid body (top mass welded, or a block) is one mass M at
its centre of gravity (-s b, h_cg) from the corner.

The friction demand is mu_req = max |H|/N over the run (+inf once N <= 0), the lift-off
margin min N/(M g). At an impact the ground's impulse is the jump of the two masses'
momentum (gravity and the spring carry none): J_x = m [(u' + h theta')^+ - (...)^-] +
m_A h_A (theta'^+ - theta'^-) (0 from the top mass: its momentum is kept, eq. 1's
derivation), J_y from the vertical velocities at theta = 0; no slip needs |J_x|/J_y <= mu.

The extremum of a sampled curve moves with the step: ``contact_sample`` takes the values at
every step end and event state of a phase (one "segment": same phase, pulse on or off);
where three consecutive samples bracket a maximum of |H|/N (or a minimum of N) that can
matter (within ``REFINE_BAND`` of the running extremum), it is located on the integrator's
own solution (fresh RK4 sub-steps from the start of the step it lies in, as events are) by
safeguarded successive parabolic interpolation.

The loop sees this bookkeeping as four calls at its sample points, ``reactions_begin``
(the outputs' starting values, the first sample: a ``Track``), ``reactions_sample``,
``reactions_impact`` and ``reactions_end`` (the run's STATUS_SLIDES / STATUS_LIFTS_OFF),
each picked while typing by the variant's REACTIONS literal: without it they are no-ops
(the outputs NaN, the tracker None) and none of this module's work is compiled.
"""

import math
from collections import namedtuple

import numpy as np
from numba import literally, njit

from rocksweep.kernel._cache import INLINE, INLINE_PUBLIC, INTERNAL
from rocksweep.kernel._static import chosen
from rocksweep.kernel.equations import contact_rhs, rigid_rhs, rocking_rhs
from rocksweep.kernel.ground import ground_acc, ground_gravity
from rocksweep.kernel.layout import (
    OUT_IMPULSE_MAX,
    OUT_MU_REQ,
    OUT_N_MIN,
    OUT_STATUS,
    PAR_B,
    PAR_G,
    PAR_H,
    PAR_HA,
    PAR_HCG,
    PAR_M,
    PAR_MA,
    PAR_MTOT,
    PAR_MU,
    STATUS_LIFTS_OFF,
    STATUS_SLIDES,
    Y_THETA,
    Y_THETA_DOT,
    Y_U,
    Y_U_DOT,
)
from rocksweep.kernel.stepping import rk4_step

# A sampled peak of |H|/N is refined when it is within this fraction of the running
# maximum (a minimum of N/(M g) within this much of the running minimum): peaks far below
# cannot become the maximum (at 5 steps a period a sampled peak is within ~20% of the
# curve's), and refining only those keeps the cost to a few peaks per run.
REFINE_BAND = 0.25
# Refinement stops when the bracket is below this fraction of the step (the value's error
# goes with the square of the location's: ~1e-6 relative) or after REFINE_MAX_ITER trials.
REFINE_XTOL = 1e-3
REFINE_MAX_ITER = 12
_GOLD = 0.3819660112501051  # 2 - golden ratio
# contact_sample's modes and _refine's two curves: numpy ints, not Python ints, so that
# numba types them int64, not as literals (a literal argument is a specialisation of its
# own: contact_sample compiled three times, _refine twice)
SAMPLE_STEP = np.int64(0)
SAMPLE_START = np.int64(1)
SAMPLE_EVENT = np.int64(2)
PEAK_RATIO = np.int64(0)  # |H|/N
PEAK_NORMAL = np.int64(1)  # -N/(M g)

# The tracker of a segment's samples (``contact_sample``): how many it has had, and the two
# before the current one (time, state, |H|/N, N/(M g)); a tuple to numba
Track = namedtuple("Track", ["samples", "t_a", "y_a", "ratio_a", "normal_a",
                             "t_b", "y_b", "ratio_b", "normal_b"])


@njit(cache=True, **INLINE_PUBLIC)
def ground_reactions(theta, theta_dot, u, u_dot, s, xg, g, prm, FLEX, DAMPED):
    """(H [N], N [N]): the ground's horizontal and vertical reaction on the body in phase
    s (0 full contact) at the state (theta, theta', u, u'), ground acceleration xg and
    gravity g (``ground.ground_gravity``: g + a_v with a vertical)."""
    M = prm[PAR_MTOT]
    if s == 0:
        if FLEX:
            u_dd = contact_rhs(u, u_dot, xg, prm, DAMPED)[0]
            return M * xg + prm[PAR_M] * u_dd, M * g
        return M * xg, M * g
    sb = s * prm[PAR_B]
    cth, sth = math.cos(theta), math.sin(theta)
    w2 = theta_dot * theta_dot
    if not FLEX:
        hcg = prm[PAR_HCG]
        th_dd = rigid_rhs(theta, theta_dot, s, xg, g, prm)[0]
        h_ = M * (xg + th_dd * (hcg * cth + sb * sth) + w2 * (sb * cth - hcg * sth))
        n_ = M * (g + th_dd * (sb * cth - hcg * sth) - w2 * (sb * sth + hcg * cth))
        return h_, n_
    m, m_A, h, h_A = prm[PAR_M], prm[PAR_MA], prm[PAR_H], prm[PAR_HA]
    th_dd, u_dd, _, _ = rocking_rhs(theta, theta_dot, u, u_dot, s, xg, g, prm, DAMPED)
    a = u - sb
    xp = (xg + u_dd * cth - 2.0 * u_dot * sth * theta_dot + th_dd * (h * cth - a * sth)
          - w2 * (a * cth + h * sth))
    yp = (-u_dd * sth - 2.0 * u_dot * cth * theta_dot - th_dd * (a * cth + h * sth)
          + w2 * (a * sth - h * cth))
    xa = xg + th_dd * (sb * sth + h_A * cth) + w2 * (sb * cth - h_A * sth)
    ya = th_dd * (sb * cth - h_A * sth) - w2 * (sb * sth + h_A * cth)
    return m * xp + m_A * xa, m * (yp + g) + m_A * (ya + g)


@njit(cache=True, **INLINE_PUBLIC)
def impact_impulses(s, u, u_dot_minus, w_minus, s_new, u_dot_plus, w_plus, prm, FLEX):
    """(J_x, J_y) [N s]: the ground's impulse on the body at an impact at theta = 0 that
    ends rocking on corner s (rate w_minus, top mass rate u_dot_minus) and leaves it in
    phase s_new with rates (w_plus, u_dot_plus): the jump of the masses' momentum."""
    b = prm[PAR_B]
    if not FLEX:
        M = prm[PAR_MTOT]
        return M * prm[PAR_HCG] * (w_plus - w_minus), M * b * (s_new * w_plus - s * w_minus)
    m, m_A, h = prm[PAR_M], prm[PAR_MA], prm[PAR_H]
    j_x = m * ((u_dot_plus + h * w_plus) - (u_dot_minus + h * w_minus)) + \
        m_A * prm[PAR_HA] * (w_plus - w_minus)
    # vertical velocity at theta = 0 about corner c: top mass -(u - c) w, base c w
    j_y = ((-m * (u - s_new * b) + m_A * s_new * b) * w_plus
           - (-m * (u - s * b) + m_A * s * b) * w_minus)
    return j_x, j_y


@njit(cache=True, **INLINE_PUBLIC)
def impulse_ratio(j_x, j_y):
    """|J_x| / J_y (+inf when the ground would have to pull: J_y <= 0)."""
    if j_y <= 0.0:
        return math.inf
    return abs(j_x) / j_y


@njit(cache=True, **INLINE)
def _values(t, y, s, on, prm, FLEX, DAMPED, GROUND):
    """(|H|/N or +inf when N <= 0, N/(M g)) at (t, y) in phase s."""
    h_, n_ = ground_reactions(y[Y_THETA], y[Y_THETA_DOT], y[Y_U], y[Y_U_DOT], s,
                              ground_acc(GROUND, t, on, prm), ground_gravity(GROUND, t, on, prm),
                              prm, FLEX, DAMPED)
    ratio = abs(h_) / n_ if n_ > 0.0 else math.inf
    return ratio, n_ / (prm[PAR_MTOT] * prm[PAR_G])


@njit(cache=True, **INLINE)
def _vertex(x0, f0, x1, f1, x2, f2):
    """Vertex of the parabola through three points (x0 < x1 < x2); NaN if it has none
    (collinear)."""
    d01 = (f1 - f0) / (x1 - x0)
    d12 = (f2 - f1) / (x2 - x1)
    c2 = (d12 - d01) / (x2 - x0)
    if c2 == 0.0:
        return math.nan
    return 0.5 * (x0 + x1) - d01 / (2.0 * c2)


@njit(cache=True, **INTERNAL)
def _refine(which, t_a, y_a, f_a, t_b, y_b, f_b, t_c, f_c, s, on, prm, FLEX, DAMPED,
            ENERGY, GROUND):
    """Largest value of f (which PEAK_RATIO: |H|/N; PEAK_NORMAL: -N/(M g)) on [t_a, t_c]
    around the sampled peak at t_b, on the integrator's own solution: a trial at tau in
    [t_a, t_b] is a fresh RK4 step from (t_a, y_a), one in [t_b, t_c] from (t_b, y_b).
    Safeguarded successive parabolic interpolation on the bracket (x0, x1, x2),
    f(x1) >= f(x0), f(x2). ENERGY: the variant's (the energy slots ride along unused: one
    compiled RK4 step for both)."""
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    x0, f0, x1, f1, x2, f2 = t_a, f_a, t_b, f_b, t_c, f_c
    best = f_b
    xtol = REFINE_XTOL * (t_c - t_a)
    for _ in range(REFINE_MAX_ITER):
        if x2 - x0 <= xtol:
            break
        x = _vertex(x0, f0, x1, f1, x2, f2)
        eps = 0.25 * xtol
        if not (x0 + eps < x < x2 - eps):
            # no usable vertex: golden section of the larger side
            x = x1 + _GOLD * (x2 - x1) if x2 - x1 > x1 - x0 else x1 - _GOLD * (x1 - x0)
        if abs(x - x1) < eps:
            x = x1 + eps if x2 - x1 > x1 - x0 else x1 - eps
        if x <= t_b:
            y_x = rk4_step(t_a, y_a, x - t_a, s, on, prm, FLEX, DAMPED, ENERGY, GROUND)
        else:
            y_x = rk4_step(t_b, y_b, x - t_b, s, on, prm, FLEX, DAMPED, ENERGY, GROUND)
        r, n = _values(x, y_x, s, on, prm, FLEX, DAMPED, GROUND)
        f = r if which == PEAK_RATIO else -n
        if not math.isfinite(f):
            return f
        if f > best:
            best = f
        if f >= f1:
            if x < x1:
                x2, f2 = x1, f1
            else:
                x0, f0 = x1, f1
            x1, f1 = x, f
        elif x < x1:
            x0, f0 = x, f
        else:
            x2, f2 = x, f
    return best


@njit(cache=True, **INLINE)
def _take(out, r, n):
    if r > out[OUT_MU_REQ] or r != r:
        out[OUT_MU_REQ] = r
    if n < out[OUT_N_MIN]:
        out[OUT_N_MIN] = n


@njit(cache=True, **INTERNAL)
def contact_sample(track, t, y, s, on, mode, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    """Take the sample (t, y) of phase s into the contact bookkeeping; returns the new
    ``Track`` (the two samples before this one of the segment, r = |H|/N, n = N/(M g)).

    mode: SAMPLE_STEP (a step's end), SAMPLE_START (the sample starts a new segment: after
    an action, the pulse's end) or SAMPLE_EVENT (an event state, which ends the segment).
    Updates out[OUT_MU_REQ] (running max of r) and out[OUT_N_MIN] (running min of n),
    refining a peak bracketed by the last three samples of a segment (``_refine``). A
    segment that an event ends after less than one step (chattering: rocking arcs shorter
    than a step) gets a midpoint sample (a fresh RK4 half step), so that a peak inside it
    is bracketed too. ENERGY: the variant's flag, for its RK4 steps (the energy slots are
    not used here; the other slots are the same).
    """
    literally(FLEX)
    literally(DAMPED)
    literally(ENERGY)
    r, n = _values(t, y, s, on, prm, FLEX, DAMPED, GROUND)
    _take(out, r, n)
    cnt, t_a, y_a, r_a, n_a, t_b, y_b, r_b, n_b = track
    if mode == SAMPLE_START:
        return Track(1.0, t_b, y_b, r_b, n_b, t, y, r, n)
    if mode == SAMPLE_EVENT and cnt == 1.0 and t_b < t:
        t_a, y_a, r_a, n_a = t_b, y_b, r_b, n_b
        t_b = 0.5 * (t_a + t)
        y_b = rk4_step(t_a, y_a, t_b - t_a, s, on, prm, FLEX, DAMPED, ENERGY, GROUND)
        r_b, n_b = _values(t_b, y_b, s, on, prm, FLEX, DAMPED, GROUND)
        _take(out, r_b, n_b)
        cnt = 2.0
    if cnt >= 2.0 and t_a < t_b < t:
        mu = out[OUT_MU_REQ]
        if (r_b >= r_a and r_b >= r and (r_b > r_a or r_b > r) and math.isfinite(mu)
                and r_b >= (1.0 - REFINE_BAND) * mu):
            f = _refine(PEAK_RATIO, t_a, y_a, r_a, t_b, y_b, r_b, t, r, s, on, prm, FLEX,
                        DAMPED, ENERGY, GROUND)
            if f > out[OUT_MU_REQ]:
                out[OUT_MU_REQ] = f
        if (n_b <= n_a and n_b <= n and (n_b < n_a or n_b < n)
                and n_b <= out[OUT_N_MIN] + REFINE_BAND):
            f = _refine(PEAK_NORMAL, t_a, y_a, -n_a, t_b, y_b, -n_b, t, -n, s, on, prm, FLEX,
                        DAMPED, ENERGY, GROUND)
            if -f < out[OUT_N_MIN]:
                out[OUT_N_MIN] = -f
    return Track(cnt + 1.0, t_b, y_b, r_b, n_b, t, y, r, n)


@njit(cache=True, **INTERNAL)
def contact_impact(y_minus, s, y_plus, s_new, prm, out, FLEX):
    """Impact from (y_minus, corner s) to (y_plus, phase s_new): update the largest
    impulse ratio out[OUT_IMPULSE_MAX]."""
    literally(FLEX)
    j_x, j_y = impact_impulses(s, y_minus[Y_U], y_minus[Y_U_DOT], y_minus[Y_THETA_DOT], s_new,
                               y_plus[Y_U_DOT], y_plus[Y_THETA_DOT], prm, FLEX)
    q = impulse_ratio(j_x, j_y)
    if q > out[OUT_IMPULSE_MAX]:
        out[OUT_IMPULSE_MAX] = q


# ----------------------------------------------------------------------------------------
# The bookkeeping as the loop sees it: four calls at its sample points, each a no-op (its
# work not even typed) in a variant without REACTIONS (``variants``: outputs.contact and
# the single runs), so the loop holds no test of the flag and no tracker's insides. The
# entries take REACTIONS first (``_static.chosen``).
# ----------------------------------------------------------------------------------------


def _begin(REACTIONS, t, y, s, on, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    """The contact outputs' starting values (no demand yet, N never seen) and the first
    sample, at the run's start (t, y): its ``Track``."""
    out[OUT_MU_REQ] = 0.0
    out[OUT_N_MIN] = np.inf
    out[OUT_IMPULSE_MAX] = 0.0
    before = Track(0.0, 0.0, y, 0.0, 0.0, 0.0, y, 0.0, 0.0)  # no sample yet
    return contact_sample(before, t, y, s, on, SAMPLE_START, prm, out, FLEX, DAMPED, ENERGY,
                          GROUND)


def _no_begin(REACTIONS, t, y, s, on, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    """The contact outputs are NaN (not tracked); no tracker."""
    out[OUT_MU_REQ] = np.nan
    out[OUT_N_MIN] = np.nan
    out[OUT_IMPULSE_MAX] = np.nan
    return None


def _sample(REACTIONS, track, t, y, s, on, mode, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    return contact_sample(track, t, y, s, on, mode, prm, out, FLEX, DAMPED, ENERGY, GROUND)


def _no_sample(REACTIONS, track, t, y, s, on, mode, prm, out, FLEX, DAMPED, ENERGY, GROUND):
    return track


def _impact(REACTIONS, y_minus, s, y_plus, s_new, prm, out, FLEX):
    contact_impact(y_minus, s, y_plus, s_new, prm, out, FLEX)


def _no_impact(REACTIONS, y_minus, s, y_plus, s_new, prm, out, FLEX):
    return None


def _end(REACTIONS, prm, out):
    """STATUS_SLIDES when the friction demand exceeds PAR_MU (never when PAR_MU is NaN),
    STATUS_LIFTS_OFF when the normal reaction went below zero."""
    if out[OUT_MU_REQ] > prm[PAR_MU]:
        out[OUT_STATUS] = int(out[OUT_STATUS]) | STATUS_SLIDES
    if out[OUT_N_MIN] < 0.0:
        out[OUT_STATUS] = int(out[OUT_STATUS]) | STATUS_LIFTS_OFF


def _no_end(REACTIONS, prm, out):
    return None


#: (REACTIONS, t, y, s, on, prm, out, FLEX, DAMPED, ENERGY, GROUND) -> tracker
reactions_begin = chosen({True: _begin, False: _no_begin}, "reactions_begin")
#: (REACTIONS, tracker, t, y, s, on, mode, prm, out, FLEX, DAMPED, ENERGY, GROUND) -> tracker
reactions_sample = chosen({True: _sample, False: _no_sample}, "reactions_sample")
#: (REACTIONS, y_minus, s, y_plus, s_new, prm, out, FLEX): an impact's impulse ratio
reactions_impact = chosen({True: _impact, False: _no_impact}, "reactions_impact")
#: (REACTIONS, prm, out): the run's verdicts (STATUS_SLIDES, STATUS_LIFTS_OFF)
reactions_end = chosen({True: _end, False: _no_end}, "reactions_end")
