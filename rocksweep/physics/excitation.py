"""Reference definitions of the ground-acceleration pulses (pure numpy, no numba).

This module is the pulses' reference in physics units and the source of the plot of
the shapes in docs/excitations.md (``figures.pulses``). The Ricker and MP formulas are
written once, in ``rocksweep.vocab.ground``, and evaluated here per sample and compiled
into the kernel; tests/physics/test_excitation.py checks them against independent closed
forms (the Ricker's roots and side lobes, the Lambert-W uplift, OpenSees' MPAcc and its
velocity, finite differences).

Every shape is a function of the phase ``phi = w t`` (w = w_over_p * p [rad/s], t [s];
in kernel time p = 1, so phi = w_over_p * (p t)) and is normalised so that its peak |xg''| is A:

    xg''(t) = A * shape(w t),        d xg''/dt = A * w * shape'(w t).

Shapes (all are 0 before phi = 0 and after the pulse duration D; the end point phi = D is
still "on", as in the kernel, where the step ending exactly at D still sees the pulse):

- ``sine``, ``cosine`` with ``cycles`` = n >= 1 (eq. (2) of the paper for n = 1):
  shape = sin(phi) or cos(phi) for 0 <= phi <= D = 2 pi n. The sine has zero net velocity
  (its integral over the pulse is 0); the cosine does too, but jumps from A to 0 at D.
- ``ricker``: shape = (1 - 2 tau^2) exp(-tau^2), tau = pi f (t - t0), f = w / (2 pi) the
  wavelet's peak frequency, t0 = 1.5 / f; in phase, tau = phi/2 - 3 pi/2 and D = 2 w t0 =
  6 pi. Peak 1 at tau = 0 (phi = 3 pi), zero crossings at tau = +-1/sqrt(2), side lobes
  -2 exp(-3/2) = -0.446 at tau = +-sqrt(3/2). Off by 1e-8 at the ends (truncation).
- ``mp``: the Mavroeidis-Papageorgiou (2003) near-fault pulse, as OpenSees' ``MPAcc``
  time series defines it. Its velocity, with f_p = w / (2 pi), gamma >= 1, nu [deg],

      v(t) = A_MP/2 [1 + cos(2 pi f_p (t - t0)/gamma)] cos(2 pi f_p (t - t0) + nu)

  for |t - t0| <= gamma / (2 f_p), else 0, is anchored (as ``MPAcc`` anchors it at its
  pseudo-time 0) so that it starts at t = 0: t0 = gamma / (2 f_p), D = 2 pi gamma. Its
  derivative is, with psi = phi - pi gamma + nu,

      a(t) = A_MP w / (2 gamma) * r(phi),
      r(phi) = sin(phi/gamma) cos(psi) - gamma (1 - cos(phi/gamma)) sin(psi),

  which is OpenSees' ``MPAccSeries::getFactor`` (A_MP = its ``-AFactor``, period T =
  1/f_p) term for term. OpenSees' A_MP is a *velocity* amplitude; rocksweep normalises
  r by its largest magnitude over the pulse, r_max (found numerically, ``mp_peak``), so
  that A (and A_ratio = A / (g tan alpha_cg)) is the pulse's peak ground *acceleration*
  like for every other shape: shape = r / r_max, and the equivalent OpenSees amplitude is
  A_MP = 2 gamma A / (w r_max) (``mp_velocity_amplitude``). The sign follows OpenSees: A
  > 0 is A_MP > 0, so for nu = 90 deg the largest lobe (at the pulse centre) is negative.
  v and r vanish at both ends, so the pulse has zero net velocity and no jump.

``PulseShape`` bundles a shape with its parameters; ``uplift_phase`` is the rigid block's
uplift under it (|A_ratio * shape(phi)| first reaches 1, the block's g tan(alpha));
``rocksweep.figures.pulses.shapes_figure`` draws every shape.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from rocksweep.vocab.ground import (
    PAPER_SHAPES,
    RICKER,
    RICKER_TAU0,
    SHAPE_TITLE,
    SHAPES,
    mp_raw,
    mp_raw_rate,
    pulse_duration,
    ricker,
    ricker_rate,
)

# uplift_phase samples this many points per pulse before refining with brentq
_UPLIFT_SAMPLES = 20_001


def _phase(phi) -> np.ndarray:
    return np.asarray(phi, dtype=np.float64)


# The formulas are ``rocksweep.vocab.ground``'s (the kernel compiles the same functions),
# evaluated here per sample: float64 arrays of any shape in and out.
_ricker = np.vectorize(ricker, otypes=[np.float64])
_ricker_rate = np.vectorize(ricker_rate, otypes=[np.float64])
_mp = np.vectorize(mp_raw, otypes=[np.float64])
_mp_rate = np.vectorize(mp_raw_rate, otypes=[np.float64])


def _mp_raw(phi: np.ndarray, gamma: float, nu_deg: float) -> np.ndarray:
    """r(phi) of the module docstring (unnormalised MP acceleration), for all phi."""
    return _mp(phi, gamma, math.radians(nu_deg))


def _mp_raw_rate(phi: np.ndarray, gamma: float, nu_deg: float) -> np.ndarray:
    """dr/dphi."""
    return _mp_rate(phi, gamma, math.radians(nu_deg))


@lru_cache(maxsize=64)
def mp_peak(gamma: float, nu_deg: float) -> float:
    """r_max = max |r(phi)| over 0 <= phi <= 2 pi gamma (the MP normalisation).

    Dense sampling, then Brent's method on dr/dphi around the largest sample.
    """
    d = 2.0 * math.pi * gamma
    phi = np.linspace(0.0, d, 4001)
    r = np.abs(_mp_raw(phi, gamma, nu_deg))
    i = int(np.argmax(r))
    best = float(r[i])
    lo, hi = phi[max(i - 1, 0)], phi[min(i + 1, phi.size - 1)]
    g_lo = float(_mp_raw_rate(np.float64(lo), gamma, nu_deg))
    g_hi = float(_mp_raw_rate(np.float64(hi), gamma, nu_deg))
    if g_lo * g_hi < 0.0:
        from scipy.optimize import brentq  # only for MP pulses: not at import (~0.15 s)

        x = brentq(lambda p: float(_mp_raw_rate(np.float64(p), gamma, nu_deg)), lo, hi,
                   xtol=1e-15, rtol=4 * np.finfo(float).eps)
        best = max(best, abs(float(_mp_raw(np.float64(x), gamma, nu_deg))))
    return best


def mp_velocity_amplitude(A: float, w: float, gamma: float, nu_deg: float) -> float:
    """OpenSees ``MPAcc -AFactor`` (the MP velocity amplitude A_MP [m/s]) whose pulse has
    peak ground acceleration |A| [m/s^2] at angular frequency w = 2 pi f_p [rad/s]:
    A_MP = 2 gamma A / (w r_max)."""
    return 2.0 * gamma * A / (w * mp_peak(gamma, nu_deg))


@dataclass(frozen=True)
class PulseShape:
    """One pulse shape and its parameters; ``acc``/``rate`` are functions of phi = w t.

    shape: one of ``SHAPES``; cycles: full cycles of a sine/cosine (>= 1); gamma (>= 1)
    and nu_deg [deg]: the MP pulse's oscillation parameter and phase.
    """

    shape: str = "sine"
    cycles: int = 1
    gamma: float = 2.0
    nu_deg: float = 90.0

    def __post_init__(self) -> None:
        if self.shape not in SHAPES:
            raise ValueError(f"shape = {self.shape!r}: must be one of {', '.join(SHAPES)}")
        if isinstance(self.cycles, bool) or not isinstance(self.cycles, (int, np.integer)) \
                or self.cycles < 1:
            raise ValueError(f"cycles = {self.cycles!r}: must be an integer >= 1")
        if not (math.isfinite(self.gamma) and self.gamma >= 1.0):
            raise ValueError(f"gamma = {self.gamma!r}: must be a finite number >= 1")
        if not math.isfinite(self.nu_deg):
            raise ValueError(f"nu_deg = {self.nu_deg!r}: must be finite")

    @property
    def duration(self) -> float:
        """Pulse duration D in phase (w t): 2 pi n, 6 pi (Ricker) or 2 pi gamma (MP)."""
        return pulse_duration(self.shape, self.cycles, self.gamma)

    @property
    def label(self) -> str:
        if self.shape in PAPER_SHAPES:
            return self.shape if self.cycles == 1 else f"{self.shape}, {self.cycles} cycles"
        if self.shape == RICKER:
            return SHAPE_TITLE[RICKER]
        return f"MP, gamma = {self.gamma:g}, nu = {self.nu_deg:g} deg"

    def _on(self, phi: np.ndarray) -> np.ndarray:
        return (phi >= 0.0) & (phi <= self.duration)

    def acc(self, phi) -> np.ndarray:
        """xg''/A at phase phi = w t (any shape of array; 0 outside [0, D])."""
        phi = _phase(phi)
        if self.shape == "sine":
            f = np.sin(phi)
        elif self.shape == "cosine":
            f = np.cos(phi)
        elif self.shape == RICKER:
            f = _ricker(0.5 * phi - RICKER_TAU0)
        else:
            f = _mp_raw(phi, self.gamma, self.nu_deg) / mp_peak(self.gamma, self.nu_deg)
        return np.where(self._on(phi), f, 0.0)

    def rate(self, phi) -> np.ndarray:
        """d(xg''/A)/d(phi) at phase phi (so d xg''/dt = A w rate); 0 outside [0, D]."""
        phi = _phase(phi)
        if self.shape == "sine":
            f = np.cos(phi)
        elif self.shape == "cosine":
            f = -np.sin(phi)
        elif self.shape == RICKER:
            f = _ricker_rate(0.5 * phi - RICKER_TAU0)
        else:
            f = _mp_raw_rate(phi, self.gamma, self.nu_deg) / mp_peak(self.gamma, self.nu_deg)
        return np.where(self._on(phi), f, 0.0)

    def uplift_phase(self, A_ratio: float) -> float | None:
        """The rigid block's uplift phase w t under this pulse, or None if it never uplifts.

        The block (slenderness alpha, at rest) uplifts when |xg''| first reaches
        g tan(alpha), i.e. |A_ratio * shape(phi)| = 1 with A_ratio = A / (g tan alpha):
        the first such phi, by Brent's method on the reference function between the
        first sample past the threshold and the one before it (a lobe that only grazes
        the threshold between two of the 20 001 samples can be missed).
        """
        if A_ratio == 0.0 or not math.isfinite(A_ratio):
            return None
        phi = np.linspace(0.0, self.duration, _UPLIFT_SAMPLES)
        g = np.abs(A_ratio * self.acc(phi)) - 1.0
        hit = np.flatnonzero(g >= 0.0)
        if hit.size == 0:
            return None
        i = int(hit[0])
        if i == 0:
            return 0.0
        lo, hi = float(phi[i - 1]), float(phi[i])
        side = math.copysign(1.0, A_ratio * float(self.acc(hi)))
        # scipy.optimize (~0.15-1 s): a pulse's uplift phase only, not at import
        from scipy.optimize import brentq

        return brentq(lambda p: A_ratio * float(self.acc(p)) - side, lo, hi,
                      xtol=1e-14, rtol=4 * np.finfo(float).eps)


def default_shapes() -> tuple[PulseShape, ...]:
    """The shapes docs/excitations.md plots: sine and cosine (1 and 2 cycles), Ricker, MP."""
    return (PulseShape("sine"), PulseShape("sine", cycles=2), PulseShape("cosine"),
            PulseShape("cosine", cycles=2), PulseShape("ricker"),
            PulseShape("mp", gamma=2.0, nu_deg=90.0), PulseShape("mp", gamma=2.0, nu_deg=0.0))
