"""The excitation: one value per distinct ground motion a body feels (no numba here).

An ``Excitation`` is what a point's ground motion is beside its two scalings, the time
scale (a pulse's w_over_p, or the body's p [rad/s] against a record's seconds) and the
amplitude (A_ratio):

- a pulse (``pulse``): its shape's kernel code and options (cycles, gamma, nu [deg]), and
  a harmonic vertical ground acceleration while it acts, if given (``pulse.vertical``,
  ``Harmonic``);
- samples (``recorded``): the record the body feels (a scene's ``ground.record``, a
  suite's record, or what the excitation path computes from them: an orientation, a
  building's floor, a pulse sampled for a building, ``physics.path``), and the ground's
  vertical component on its samples, if given (``ground.vertical``, a PEER folder's UP
  file; ``vertical_samples``).

The value is computed once: its samples are made with it, and a scene keeps every value
it made (``Excitations``, ``Scene.excitation``), so a sweep computes each distinct motion
once, whatever its chunks and workers, and its boundary searches, single runs and cost
checks ask the same values. The kernel's ground code (``kernel.layout.GROUND_*``) is the
value's (``ground_code``, the one rule); a batch of values runs on the most general of
theirs (``shared_ground``). ``Excitation.with_samples`` puts its samples after the
kernel's parameters (``layout.PAR_REC``, ``layout.PAR_V_REC``) and ``fill_gravity`` the
vertical's parameters into the rows (``physics.points.fill_rows`` builds the rest).

The vertical ground acceleration a_v (positive up; docs/vertical.md):

- a record's vertical component is taken on the horizontal's samples: as it is where DT
  and NPTS agree (``same_grid``), else its linear interpolant at the horizontal's sample
  times (0 after its last sample; what lies after the horizontal's last sample is
  dropped: the ground moves while the horizontal record does), and it reaches a floor
  unfiltered (no vertical mode is modelled). It scales with the horizontal's factor (one
  record's components scale together): a_v = |A| acc_v / PGA_h (A = A_ratio g
  tan(alpha_cg), the peak of the horizontal; a negative A_ratio turns the horizontal
  round, not the vertical); ``vertical_ims`` gives its intensity measures;
- a harmonic acts while the pulse acts: a_v = a g sin(w_v t + phase) for t < t_pulse (a
  [g], w_v/p, phase [deg]; kernel time p t).

While it acts gravity is g + a_v(t); where g + a_v <= 0 the ground falls faster than the
body would and the model no longer holds: ``air_time_*`` give the first such time, the
kernel's PAR_T_AIR (the run stops there, status ``airborne``).
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable, Iterable
from dataclasses import dataclass

import numpy as np

from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics, vertical_step
from rocksweep.physics.bodies import G
from rocksweep.physics.excitation import PulseShape, mp_peak
from rocksweep.physics.records import GroundRecord
from rocksweep.vocab.ground import (
    CYCLES,
    FREE,
    GAMMA,
    MP,
    NU_DEG,
    PAPER_SHAPES,
    RECORD,
    SHAPE_CODE,
    SINE,
)

# FREE runs as a sine of amplitude 0 that ends at t = 0 (its own code would be a new
# branch of the kernel for nothing)
_SHAPE_CODE = {**SHAPE_CODE, FREE: SHAPE_CODE[SINE]}
#: samples of the values a scene keeps [bytes] (``Excitations``)
CACHE_BYTES = 256 << 20
# Relative difference of two sample spacings below which a vertical's samples are the
# horizontal's as they are (a two-column file's DT is a mean of printed times).
SAME_DT = 1e-9


def ground_code(shape: str, vertical: bool) -> int:
    """The kernel variants' ground code (``layout.GROUND_*``) a motion needs: GROUND_VERTICAL
    with a vertical ground acceleration, GROUND_PULSE for the paper's sine and cosine (n
    cycles too) and free rocking, GROUND_ANY for the Ricker, MP and samples."""
    if vertical:
        return L.GROUND_VERTICAL
    return L.GROUND_PULSE if shape in (*PAPER_SHAPES, FREE) else L.GROUND_ANY


def shared_ground(codes: Iterable[int]) -> int:
    """The ground code of a batch of motions: the most general of theirs (the vertical
    variants run every motion, the GROUND_ANY variants every horizontal one)."""
    codes = set(codes)
    for code in (L.GROUND_VERTICAL, L.GROUND_ANY):
        if code in codes:
            return code
    return L.GROUND_PULSE


@dataclass(frozen=True)
class Harmonic:
    """``pulse.vertical``: a_v = amplitude g sin(w_over_p p t + phase) while the pulse acts.

    amplitude [g] (finite; negative: the opposite sign), w_over_p = w_v/p (>= 0), phase
    [deg] (finite)."""

    amplitude: float
    w_over_p: float
    phase: float = 0.0


@dataclass(frozen=True, eq=False)
class Excitation:
    """One distinct ground motion (module docstring); made by ``pulse`` or ``recorded``.

    shape: a pulse shape (``vocab.ground.SHAPES``), FREE, or RECORD for samples; cycles,
    gamma, nu [deg]: a pulse's options; harmonic: a pulse's vertical harmonic (None:
    none). record: the samples the body feels (RECORD; None for a pulse); vertical: the
    ground's vertical component as read (None: none), and vertical_acc [g] its samples
    on ``record``'s (float64[record.npts], read-only). ground_pga [g]: the peak of the
    ground motion A_ratio scales when ``record`` is computed from it (an excitation
    path: the ground record's H1 PGA, 1 for a pulse, whose A_ratio is its peak); None
    when A_ratio scales ``record`` itself.
    """

    shape: str
    cycles: int = CYCLES
    gamma: float = GAMMA
    nu: float = NU_DEG
    harmonic: Harmonic | None = None
    record: GroundRecord | None = None
    vertical: GroundRecord | None = None
    vertical_acc: np.ndarray | None = None
    ground_pga: float | None = None

    @property
    def code(self) -> float:
        """The kernel's shape code (PAR_SHAPE)."""
        return _SHAPE_CODE[self.shape]

    @property
    def ground(self) -> int:
        """The kernel variants' ground code this motion needs (``ground_code``)."""
        return ground_code(self.shape, self.harmonic is not None
                           or self.vertical_acc is not None)

    @property
    def pulse(self) -> PulseShape | None:
        """The pulse's reference definition (None for samples and free rocking)."""
        if self.shape in (RECORD, FREE):
            return None
        return PulseShape(self.shape, int(self.cycles), float(self.gamma), float(self.nu))

    @property
    def mp_norm(self) -> float:
        """1/r_max of an MP pulse (PAR_AMP_NORM: A is its peak), NaN for other shapes."""
        if self.shape != MP:
            return math.nan
        return 1.0 / mp_peak(float(self.gamma), float(self.nu))

    @property
    def nbytes(self) -> int:
        """Bytes of samples this value holds."""
        return sum(a.nbytes for a in (None if self.record is None else self.record.acc,
                                      self.vertical_acc) if a is not None)

    def with_samples(self, rows: np.ndarray) -> np.ndarray:
        """Rows float64[n, N_PAR] -> float64[n, N_PAR + npts] with the samples xg''/PGA after
        the parameters (``layout.PAR_REC``); ``rows`` itself for a pulse. With a vertical
        component the rows are float64[n, N_PAR + 2 npts + 1]: the last horizontal sample
        once more, then a_v/(g PGA) (``layout.PAR_V_REC``)."""
        rec = self.record
        if rec is None:
            return rows
        shape = rec.acc / rec.pga
        if self.vertical_acc is not None:
            shape = np.concatenate((shape, shape[-1:], self.vertical_acc / rec.pga))
        out = np.empty((rows.shape[0], L.N_PAR + shape.size))
        out[:, :L.N_PAR] = rows
        out[:, L.N_PAR:] = shape
        return out

    def step_on(self, dt_on: np.ndarray, numerics: Numerics) -> np.ndarray:
        """The RK4 step while the ground moves [p*t], float64[n]: ``dt_on`` (the
        horizontal's), shortened to resolve a harmonic vertical as the pulse is
        (``numerics.vertical_step``; a vertical record is on the horizontal's samples)."""
        if self.harmonic is None:
            return dt_on
        return vertical_step(dt_on, self.harmonic.w_over_p, numerics.steps_per_period,
                             numerics.pulse_steps)

    def fill_gravity(self, rows: np.ndarray, A: np.ndarray, t_pulse: np.ndarray) -> None:
        """The vertical's columns of parameter rows float64[n, N_PAR] (filled but these):
        PAR_V_AMP, PAR_V_OMEGA, PAR_V_PHASE, PAR_V_REC and PAR_T_AIR (inf: never airborne;
        all there is without a vertical). A: the horizontal's peak [m/s^2] float64[n]
        (the record's factor scales its vertical too); t_pulse: the ground motion's end
        [p*t] float64[n] (the harmonic acts until then)."""
        rows[:, L.PAR_T_AIR] = np.inf
        hv = self.harmonic
        if hv is not None:
            amp_v, w_v, phase_v = (np.asarray(v, float)
                                   for v in (hv.amplitude, hv.w_over_p, hv.phase))
            rows[:, L.PAR_V_AMP] = amp_v * G
            rows[:, L.PAR_V_OMEGA] = w_v
            rows[:, L.PAR_V_PHASE] = np.radians(phase_v)
            rows[:, L.PAR_T_AIR] = air_time_harmonic(amp_v, w_v, phase_v, t_pulse)
        elif self.vertical_acc is not None:
            # one factor for both components: a_v = |A| acc_v / PGA_h (A's sign turns the
            # horizontal round only)
            scale = np.abs(A)
            rows[:, L.PAR_V_AMP] = scale
            rows[:, L.PAR_V_REC] = L.PAR_REC + self.record.npts + 1
            rows[:, L.PAR_T_AIR] = air_time_record(self.vertical_acc / self.record.pga,
                                                   rows[:, L.PAR_REC_DT], scale / G)


def pulse(shape: str, cycles: int = CYCLES, gamma: float = GAMMA, nu: float = NU_DEG,
          harmonic: Harmonic | None = None) -> Excitation:
    """A pulse's excitation (shape one of ``vocab.ground.SHAPES`` or FREE; options as
    ``pulse.cycles``, ``.gamma``, ``.nu`` [deg]; a vertical harmonic or None)."""
    if shape not in _SHAPE_CODE or shape == RECORD:
        raise ValueError(f"shape = {shape!r}: not a pulse shape")
    return Excitation(shape, cycles, gamma, nu, harmonic)


def recorded(record: GroundRecord, vertical: GroundRecord | None = None,
             ground_pga: float | None = None) -> Excitation:
    """The excitation of samples the body feels (``record``), with the ground's vertical
    component as read (taken on ``record``'s samples here, once: ``vertical_samples``).
    ground_pga: see ``Excitation``."""
    acc = None
    if vertical is not None:
        acc = vertical_samples(vertical, record)
        acc.setflags(write=False)
    return Excitation(RECORD, record=record, vertical=vertical, vertical_acc=acc,
                      ground_pga=ground_pga)


class Excitations:
    """The excitations a scene made, by key (the values of the axes a motion depends
    on): each made when first asked for (``get``) and kept, most recently used first, up
    to CACHE_BYTES of samples (beyond, the least recently used is dropped and made again
    if asked again). Threads asking for one key at once wait for one making; a copy
    shipped to another process (dask) starts empty."""

    def __init__(self) -> None:
        self._kept: OrderedDict = OrderedDict()
        self._making: dict = {}
        self._bytes = 0
        self._lock = threading.Lock()

    def __reduce__(self) -> tuple:  # pickled (dask ships the scene) and copied: empty
        return (Excitations, ())

    def __len__(self) -> int:
        return len(self._kept)

    def get(self, key: Hashable, make: Callable[[], Excitation]) -> Excitation:
        """The excitation kept under ``key``, made by ``make()`` the first time."""
        with self._lock:
            hit = self._kept.get(key)
            if hit is not None:
                self._kept.move_to_end(key)
                return hit
            making = self._making.setdefault(key, threading.Lock())
        with making:
            with self._lock:
                hit = self._kept.get(key)
            if hit is not None:
                return hit
            value = make()
            with self._lock:
                self._kept[key] = value
                self._bytes += value.nbytes
                while self._bytes > CACHE_BYTES and len(self._kept) > 1:
                    _, old = self._kept.popitem(last=False)
                    self._bytes -= old.nbytes
                self._making.pop(key, None)
        return value


# ---------------------------------------------------------------------------------------
# the vertical component
# ---------------------------------------------------------------------------------------

def same_grid(vertical: GroundRecord, horizontal: GroundRecord) -> bool:
    """Whether the vertical has the horizontal's samples (NPTS equal, DT within SAME_DT)."""
    return (vertical.npts == horizontal.npts
            and abs(vertical.dt - horizontal.dt) <= SAME_DT * horizontal.dt)


def vertical_samples(vertical: GroundRecord, horizontal: GroundRecord) -> np.ndarray:
    """The vertical acceleration [g] (positive up) at the horizontal's sample times,
    float64[horizontal.npts]: the vertical's samples where the grids agree (``same_grid``),
    else its linear interpolant there (``GroundRecord.acc_at``: 0 after its last sample).
    Linear interpolation keeps what the piecewise-linear vertical does between the
    horizontal's samples only where its own samples fall on them: a vertical sampled finer
    than the horizontal loses the peaks between (a PEER record's components share DT and
    NPTS, where nothing is lost)."""
    if same_grid(vertical, horizontal):
        return np.array(vertical.acc, dtype=np.float64)
    return np.asarray(vertical.acc_at(horizontal.times()), dtype=np.float64)


def vertical_ims(vertical: GroundRecord, horizontal: GroundRecord) -> dict[str, float]:
    """The vertical component's intensity measures, as recorded (before any scaling: the
    components share one factor, so the ratio is that of the scaled motion too):
    PGA_v [g] = max |a_v| of the file's samples and VH_ratio = PGA_v / PGA of the
    horizontal."""
    return {"PGA_v": float(vertical.pga), "VH_ratio": float(vertical.pga / horizontal.pga)}


def air_time_harmonic(amplitude, w_over_p, phase_deg, t_pulse) -> np.ndarray:
    """First kernel time t in [0, t_pulse) with 1 + a sin(w t + phase) <= 0 (float64[n],
    inf: none; arguments broadcast, w = w_over_p with p = 1).

    With |a| >= 1 (a < 0 is |a| with phase + pi), sin x <= -1/|a| on the arcs
    [pi + asin(1/|a|), 2 pi - asin(1/|a|)] + 2 pi k: 0 if the phase is on one, else the
    time to the start of the next."""
    a = np.asarray(amplitude, float)
    w = np.asarray(w_over_p, float)
    x0 = np.radians(np.asarray(phase_deg, float)) + np.where(a < 0.0, math.pi, 0.0)
    x0 = np.mod(x0, 2 * math.pi)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.arcsin(np.minimum(1.0, 1.0 / np.abs(a)))  # nan-free where |a| >= 1
        lo, hi = math.pi + c, 2 * math.pi - c
        inside = (x0 >= lo) & (x0 <= hi)
        start = np.where(x0 <= lo, lo, lo + 2 * math.pi)
        t = np.where(inside, 0.0, (start - x0) / w)
        t = np.where((np.abs(a) >= 1.0) & (t < np.asarray(t_pulse, float)), t, np.inf)
    return np.asarray(t, float)


def air_time_record(shape_v: np.ndarray, dt_k, scale_g) -> np.ndarray:
    """First kernel time at which 1 + scale_g shape_v(t) <= 0 for the piecewise-linear
    vertical ``shape_v`` (float64[npts], on samples every dt_k [p t]), per point
    (scale_g: float64[n] >= 0, a_v/g per unit of shape_v; dt_k: float64[n] or a scalar).
    float64[n], inf: never; 0: at t = 0. O(n log npts): the first sample at or below
    -1/scale_g is found in the running minimum, the crossing inside the segment before it
    by linear interpolation."""
    shape_v = np.asarray(shape_v, float)
    scale = np.atleast_1d(np.asarray(scale_g, float))
    run_min = np.minimum.accumulate(shape_v)
    with np.errstate(divide="ignore"):
        level = np.where(scale > 0.0, -1.0 / scale, -np.inf)  # g + a_v <= 0 at shape <= level
    i = np.searchsorted(-run_min, -level, side="left")  # first i with run_min[i] <= level
    out = np.full(scale.shape, np.inf)
    hit = i < shape_v.size
    dt_k = np.broadcast_to(np.asarray(dt_k, float), scale.shape)
    at0 = hit & (i == 0)
    out[at0] = 0.0
    inner = hit & (i > 0)
    k = i[inner]
    a0, a1 = shape_v[k - 1], shape_v[k]
    frac = (level[inner] - a0) / (a1 - a0)  # a0 > level >= a1
    out[inner] = (k - 1 + frac) * dt_k[inner]
    return out
