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

from rocksweep.kernel._cache import INLINE, INTERNAL, PUBLIC
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


def pulse_acc(GROUND, t, on, prm):
    """Eq. (2): A sin(w t) or A cos(w t) (the paper's sine and cosine, n cycles); 0 when
    the ground is still."""
    if not on:
        return 0.0
    if prm[PAR_SHAPE] == SHAPE_COSINE:
        return prm[PAR_AMP] * math.cos(prm[PAR_OMEGA] * t)
    return prm[PAR_AMP] * math.sin(prm[PAR_OMEGA] * t)


def pulse_jerk(GROUND, t, on, prm):
    """d/dt of ``pulse_acc``."""
    if not on:
        return 0.0
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


def any_acc(GROUND, t, on, prm):
    """``ground_acc_any``: every shape; 0 when the ground is still."""
    if not on:
        return 0.0
    return ground_acc_any(t, prm)


def any_jerk(GROUND, t, on, prm):
    if not on:
        return 0.0
    return ground_jerk_any(t, prm)


def row_gravity(GROUND, t, on, prm):
    """The row's g [m/s^2]: no vertical component."""
    return prm[PAR_G]


def vertical_gravity(GROUND, t, on, prm):
    """g + a_v(t) [m/s^2] while the ground moves, g when it is still."""
    if not on:
        return prm[PAR_G]
    return prm[PAR_G] + vertical_acc_any(t, prm)


def no_gravity_rate(GROUND, t, on, prm):
    return 0.0


def vertical_gravity_rate(GROUND, t, on, prm):
    """d a_v/dt [m/s^3] while the ground moves."""
    if not on:
        return 0.0
    return vertical_jerk_any(t, prm)


# ----------------------------------------------------------------------------------------
# The table: one row per ground kind
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class GroundKind:
    """What a ground kind does to the equations, each a plain-Python
    ``f(GROUND, t, on, prm)`` (``on``: the ground moves; the variant's GROUND first, as
    ``_static.chosen``'s entries take it), and to the loop."""

    name: str  # its entry points' suffix (``variants``): "" for the paper's pulses
    acc: Callable  # xg''(t) [m/s^2]
    jerk: Callable  # d xg''/dt [m/s^3]
    gravity: Callable  # g + a_v(t) [m/s^2]: the gravity of the ground's frame
    gravity_rate: Callable  # d(g + a_v)/dt [m/s^3]
    records: bool  # a record's samples may drive it: the steps land on them (PAR_REC_H)
    vertical: bool  # a vertical acts: its work counts, the run stops at PAR_T_AIR


GROUNDS: dict[int, GroundKind] = {
    GROUND_PULSE: GroundKind("", pulse_acc, pulse_jerk, row_gravity, no_gravity_rate,
                             records=False, vertical=False),
    GROUND_ANY: GroundKind("_ground", any_acc, any_jerk, row_gravity, no_gravity_rate,
                           records=True, vertical=False),
    GROUND_VERTICAL: GroundKind("_vertical", any_acc, any_jerk, vertical_gravity,
                                vertical_gravity_rate, records=True, vertical=True),
}


def per_ground(pick: Callable[[GroundKind], Callable], name: str):
    """``_static.chosen`` over ``GROUNDS``: ``g(GROUND, *args)`` = ``pick(row)(GROUND,
    *args)`` of the variant's ground kind, picked while typing."""
    return chosen({code: pick(kind) for code, kind in GROUNDS.items()}, name)


#: (GROUND, t, on, prm) -> xg''(t) [m/s^2] (0 when the ground is still)
ground_acc = per_ground(lambda k: k.acc, "ground_acc")
#: (GROUND, t, on, prm) -> d xg''/dt [m/s^3], for locating an uplift inside a step
ground_jerk = per_ground(lambda k: k.jerk, "ground_jerk")
#: (GROUND, t, on, prm) -> g + a_v(t) [m/s^2] (the row's g without a vertical or when the
#: ground is still)
ground_gravity = per_ground(lambda k: k.gravity, "ground_gravity")
#: (GROUND, t, on, prm) -> d(g + a_v)/dt [m/s^3]
gravity_rate = per_ground(lambda k: k.gravity_rate, "gravity_rate")


def ground_flags(GROUND):
    """(records, vertical) of ground kind GROUND (``GroundKind``): constants of the variant
    (jitted: GROUND a literal)."""
    kind = GROUNDS[GROUND]
    return kind.records, kind.vertical


@overload(ground_flags, jit_options=INLINE, prefer_literal=True)
def _ground_flags(GROUND):
    kind = GROUNDS[GROUND.literal_value]
    records, vertical = kind.records, kind.vertical

    def constants(GROUND):
        return records, vertical
    return constants


# From Python (the reference path, tests): any shape (GROUND_ANY; the paper's sine and
# cosine are among them, the same arithmetic)
@njit(cache=True, **PUBLIC)
def any_ground_acc(t, on, prm):
    """xg''(t) [m/s^2] of the row's shape, 0 when ``on`` is false."""
    return ground_acc(GROUND_ANY, t, on, prm)


@njit(cache=True, **PUBLIC)
def any_ground_jerk(t, on, prm):
    """d xg''/dt [m/s^3] of the row's shape, 0 when ``on`` is false."""
    return ground_jerk(GROUND_ANY, t, on, prm)
