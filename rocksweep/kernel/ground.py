"""The ground's motion as the body feels it, one row per ground kind (jitted).

What a point's ground does to the equations: the horizontal acceleration xg''(t) (eq. 2,
the other pulse shapes, records) and the gravity of the ground's frame, g + a_v(t) with a
vertical component (docs/vertical.md). ``on`` (a bool) is decided per step by the loop (the
step that ends exactly at the pulse's end still sees the pulse, the next one does not), so
a jump at the end (the cosine's) is never smeared across a step.

A variant's GROUND (``layout.GROUND_*``, an integer literal of the entry point) picks its
row of ``GROUNDS`` while typing (``_static.chosen``); the other rows' code is not typed or
compiled:

- GROUND_PULSE: the paper's sine and cosine only (eq. 2), the code the paper's scenes
  always ran (a run-time branch to the other shapes cost them 5% inlined to 60% as a call,
  measured);
- GROUND_ANY: every shape, Ricker, MP and records too, chosen by PAR_SHAPE at run time
  (``ground_acc_any``); a record's samples set the steps while it acts (PAR_REC_H);
- GROUND_VERTICAL: the same with a vertical component a_v (PAR_V_*): gravity g + a_v while
  the ground moves, its work counted, the run stopped where g + a_v reaches 0 (PAR_T_AIR).

A new ground kind: its functions here, one row of ``GROUNDS`` and its code in ``layout``
(the entry points, ``variants``, follow from the table).
"""

import math
from collections.abc import Callable
from dataclasses import dataclass

from numba import njit
from numba.extending import overload

from rocksweep.kernel._cache import INLINE, INTERNAL
from rocksweep.kernel._static import chosen
from rocksweep.kernel.layout import (
    GROUND_ANY,
    GROUND_PULSE,
    GROUND_VERTICAL,
    PAR_AMP,
    PAR_AMP_NORM,
    PAR_G,
    PAR_GAMMA,
    PAR_NU,
    PAR_OMEGA,
    PAR_REC,
    PAR_REC_DT,
    PAR_SHAPE,
    PAR_V_AMP,
    PAR_V_OMEGA,
    PAR_V_PHASE,
    PAR_V_REC,
    SHAPE_COSINE,
    SHAPE_RECORD,
    SHAPE_RICKER,
    SHAPE_SINE,
)
from rocksweep.vocab import ground as _ground

# The Ricker and MP formulas, written once in ``rocksweep.vocab.ground`` (the physics
# module evaluates the same functions per sample); compiled here, inlined by LLVM.
_ricker_tau = njit(**INLINE)(_ground.ricker_tau)
_ricker = njit(**INLINE)(_ground.ricker)
_ricker_rate = njit(**INLINE)(_ground.ricker_rate)
_mp_raw = njit(**INLINE)(_ground.mp_raw)
_mp_raw_rate = njit(**INLINE)(_ground.mp_raw_rate)


# ----------------------------------------------------------------------------------------
# The horizontal acceleration xg''(t) while the ground moves
# ----------------------------------------------------------------------------------------


@njit(**INLINE)
def pulse_acc(t, prm):
    """Eq. (2): A sin(w t) or A cos(w t) (the paper's sine and cosine, n cycles)."""
    if prm[PAR_SHAPE] == SHAPE_COSINE:
        return prm[PAR_AMP] * math.cos(prm[PAR_OMEGA] * t)
    return prm[PAR_AMP] * math.sin(prm[PAR_OMEGA] * t)


@njit(**INLINE)
def pulse_jerk(t, prm):
    """d/dt of ``pulse_acc``."""
    w = prm[PAR_OMEGA]
    if prm[PAR_SHAPE] == SHAPE_COSINE:
        return -prm[PAR_AMP] * w * math.sin(w * t)
    return prm[PAR_AMP] * w * math.cos(w * t)


@njit(cache=True, **INLINE)
def _samples_segment(t, prm, first, last):
    """(a_k, x - k, a_k+1 - a_k), x = t / PAR_REC_DT: the first sample of the linear
    segment [t_k, t_k+1] that holds t of the samples prm[first:], the fraction of it at t,
    and the samples' difference; k <= last (the last segment at the end). At a sample
    time either neighbour gives the same value (the interpolant is continuous), so the
    loop's steps, which land on sample times, always see one segment's straight line."""
    x = t / prm[PAR_REC_DT]
    k = min(max(int(x), 0), last)
    a0 = prm[first + k]
    return a0, x - k, prm[first + k + 1] - a0


@njit(cache=True, **INLINE)
def _record_segment(t, prm):
    """``_samples_segment`` of the horizontal record (its samples from PAR_REC on)."""
    return _samples_segment(t, prm, PAR_REC, prm.shape[0] - PAR_REC - 2)


@njit(cache=True, **INTERNAL)
def ground_acc_any(t, prm):
    """xg''(t) [m/s^2] while on, of any shape (``rocksweep.physics.excitation`` defines
    each as a function of phi = w t); one call (inlining it into every right-hand side
    inlines it again in each of the variant's call sites: numba's IR inliner warns).

    Sine, cosine: A sin(phi), A cos(phi). Ricker: A (1 - 2 tau^2) exp(-tau^2), tau =
    phi/2 - 3 pi/2 (t0 = 1.5/f, f = w/(2 pi)). MP: A/r_max [sin(phi/gamma) cos(psi) -
    gamma (1 - cos(phi/gamma)) sin(psi)], psi = phi - pi gamma + nu (OpenSees' MPAcc;
    PAR_AMP_NORM = 1/r_max). Record: A times the samples xg''/PGA interpolated linearly,
    samples every PAR_REC_DT.
    """
    shape = prm[PAR_SHAPE]
    amp = prm[PAR_AMP]
    if shape == SHAPE_RECORD:
        a0, frac, da = _record_segment(t, prm)
        return amp * (a0 + frac * da)
    phi = prm[PAR_OMEGA] * t
    if shape == SHAPE_SINE:
        return amp * math.sin(phi)
    if shape == SHAPE_COSINE:
        return amp * math.cos(phi)
    if shape == SHAPE_RICKER:
        return _ricker(_ricker_tau(phi), amp)
    return amp * prm[PAR_AMP_NORM] * _mp_raw(phi, prm[PAR_GAMMA], prm[PAR_NU])


@njit(cache=True, **INTERNAL)
def ground_jerk_any(t, prm):
    """d xg''/dt [m/s^3] of ``ground_acc_any`` (a record: its segment's constant slope)."""
    shape = prm[PAR_SHAPE]
    amp = prm[PAR_AMP]
    if shape == SHAPE_RECORD:
        _, _, da = _record_segment(t, prm)
        return amp * da / prm[PAR_REC_DT]
    w = prm[PAR_OMEGA]
    phi = w * t
    if shape == SHAPE_SINE:
        return amp * w * math.cos(phi)
    if shape == SHAPE_COSINE:
        return -amp * w * math.sin(phi)
    if shape == SHAPE_RICKER:
        return _ricker_rate(_ricker_tau(phi), amp * w)
    return amp * prm[PAR_AMP_NORM] * w * _mp_raw_rate(phi, prm[PAR_GAMMA], prm[PAR_NU])


# ----------------------------------------------------------------------------------------
# The vertical ground acceleration a_v (positive up): gravity g + a_v while the ground
# moves
# ----------------------------------------------------------------------------------------


@njit(cache=True, **INTERNAL)
def vertical_acc_any(t, prm):
    """a_v(t) [m/s^2] while the ground moves: PAR_V_AMP sin(PAR_V_OMEGA t + PAR_V_PHASE)
    (a harmonic), or PAR_V_AMP times the vertical record's samples (PAR_V_REC > 0: on the
    horizontal's times, interpolated linearly)."""
    first = prm[PAR_V_REC]
    if first > 0.0:
        i = int(first)
        a0, frac, da = _samples_segment(t, prm, i, prm.shape[0] - i - 2)
        return prm[PAR_V_AMP] * (a0 + frac * da)
    return prm[PAR_V_AMP] * math.sin(prm[PAR_V_OMEGA] * t + prm[PAR_V_PHASE])


@njit(cache=True, **INTERNAL)
def vertical_jerk_any(t, prm):
    """d a_v/dt [m/s^3] of ``vertical_acc_any`` (a record: its segment's slope)."""
    first = prm[PAR_V_REC]
    if first > 0.0:
        i = int(first)
        _, _, da = _samples_segment(t, prm, i, prm.shape[0] - i - 2)
        return prm[PAR_V_AMP] * da / prm[PAR_REC_DT]
    w = prm[PAR_V_OMEGA]
    return prm[PAR_V_AMP] * w * math.cos(w * t + prm[PAR_V_PHASE])


@njit(**INLINE)
def row_gravity(t, prm):
    """The row's g [m/s^2]: no vertical component."""
    return prm[PAR_G]


@njit(**INLINE)
def vertical_gravity(t, prm):
    """g + a_v(t) [m/s^2] while the ground moves."""
    return prm[PAR_G] + vertical_acc_any(t, prm)


@njit(**INLINE)
def no_gravity_rate(t, prm):
    return 0.0


# ----------------------------------------------------------------------------------------
# The table: one row per ground kind
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class GroundKind:
    """What a ground kind does to the equations while the ground moves (each a jitted
    ``f(t, prm)``) and to the loop."""

    name: str  # its entry points' suffix (``variants``): "" for the paper's pulses
    acc: Callable  # xg''(t) [m/s^2]
    jerk: Callable  # d xg''/dt [m/s^3]
    gravity: Callable  # g + a_v(t) [m/s^2]
    gravity_rate: Callable  # d(g + a_v)/dt [m/s^3]
    records: bool  # a record's samples may drive it: the steps land on them (PAR_REC_H)
    vertical: bool  # a vertical acts: its work counts, the run stops at PAR_T_AIR


GROUNDS: dict[int, GroundKind] = {
    GROUND_PULSE: GroundKind("", pulse_acc, pulse_jerk, row_gravity, no_gravity_rate,
                             records=False, vertical=False),
    GROUND_ANY: GroundKind("_ground", ground_acc_any, ground_jerk_any, row_gravity,
                           no_gravity_rate, records=True, vertical=False),
    GROUND_VERTICAL: GroundKind("_vertical", ground_acc_any, ground_jerk_any,
                                vertical_gravity, vertical_jerk_any, records=True,
                                vertical=True),
}


def per_ground(pick: Callable[[GroundKind], Callable], name: str, general=None):
    """``_static.chosen`` over ``GROUNDS``: ``g(GROUND, *args)`` = ``pick(row)(*args)`` of
    the variant's ground kind, picked while typing."""
    return chosen({code: pick(kind) for code, kind in GROUNDS.items()}, name, general)


@njit(**INLINE)
def _any_acc(ground, t, prm):
    return ground_acc_any(t, prm)


@njit(**INLINE)
def _any_jerk(ground, t, prm):
    return ground_jerk_any(t, prm)


# a call from Python (GROUND a plain int: the reference path, tests) computes any shape
# (the pulses' sine and cosine are among them, the same arithmetic)
_acc = per_ground(lambda k: k.acc, "ground_acc_of", general=_any_acc)
_jerk = per_ground(lambda k: k.jerk, "ground_jerk_of", general=_any_jerk)
_gravity = per_ground(lambda k: k.gravity, "ground_gravity_of")
_gravity_rate = per_ground(lambda k: k.gravity_rate, "gravity_rate_of")


@njit(cache=True, **INLINE)
def ground_acc(t, on, prm, GROUND):
    """xg''(t) [m/s^2] of the row's shape under ground kind GROUND; 0 when ``on`` is
    false (Python callers: any GROUND_* as a plain int computes every shape)."""
    if not on:
        return 0.0
    return _acc(GROUND, t, prm)


@njit(cache=True, **INLINE)
def ground_jerk(t, on, prm, GROUND):
    """d xg''/dt [m/s^3], for locating an uplift inside a step."""
    if not on:
        return 0.0
    return _jerk(GROUND, t, prm)


@njit(cache=True, **INLINE)
def ground_gravity(t, on, prm, GROUND):
    """g + a_v(t) [m/s^2]: the gravity of the ground's frame (the row's g without a
    vertical, or when the ground is still)."""
    if not on:
        return prm[PAR_G]
    return _gravity(GROUND, t, prm)


@njit(cache=True, **INLINE)
def gravity_rate(t, on, prm, GROUND):
    """d(g + a_v)/dt [m/s^3] (0 without a vertical, or when the ground is still)."""
    if not on:
        return 0.0
    return _gravity_rate(GROUND, t, prm)


def ground_is(GROUND, what):
    """Whether ground kind GROUND has the property ``what`` ("records", "vertical"): a
    constant of the variant (jitted: GROUND and ``what`` literals)."""
    return getattr(GROUNDS[GROUND], what)


@overload(ground_is, jit_options=INLINE, prefer_literal=True)
def _ground_is(GROUND, what):
    value = getattr(GROUNDS[GROUND.literal_value], what.literal_value)

    def constant(GROUND, what):
        return value
    return constant
