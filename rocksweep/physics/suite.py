"""A suite of ground-motion records and how each run scales one (no numba here).

A scene's ``ground.records`` (``rocksweep.scene.parse``) becomes a ``Suite``: the records
read once, their intensity measures computed once (``rocksweep.physics.intensity``: PGA
[g], PGV [m/s], Sa(T) [g] at 5% damping) and the scaling rule ``ground.scale``:

- stripes, ``{im: IM, values: [x_1, ...]}``: at stripe j every record is multiplied by the
  factor that makes its IM equal x_j: PGA, PGV, Sa (at ``scale.period``) directly;
  PGA_ratio = PGA / (g tan alpha_ref) (the A_ratio of a single-record scene) and
  PGV_ratio = PGV p / (g tan alpha_ref) (Dimitrakopoulos & Paraskeva 2015), whose factor
  also depends on the body's slenderness alpha_ref (alpha_cg, or alpha for a block) and,
  for PGV_ratio, on p [rad/s];
- a cloud, ``none`` or ``{factor: F}``: every record as recorded, times F (1 for none).

The kernel sees a scaled record as its samples acc / PGA (shared by all runs of the record,
``rocksweep.compute.sweep``) and a peak |xg''| = factor * PGA [g]; that peak is passed
as the point's A_ratio = factor * PGA / tan(alpha_ref) (``peak_ratio``), so the rows are
filled by the same code as a single record's (``points.fill_rows``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rocksweep.errors import SuiteError  # noqa: F401 (defined there; re-exported)
from rocksweep.physics.model import G
from rocksweep.physics.records import GroundRecord
from rocksweep.vocab.ground import (  # noqa: F401
    DEFAULT_PERIODS,
    PGA,
    PGA_RATIO,
    PGV,
    PGV_RATIO,
    RATIO_OF,
    SA,
    SA_DAMPING,
    SCALE_IMS,
)

# the IMs (and their units), Sa's damping ratio and default periods: rocksweep.vocab.ground
ZETA = SA_DAMPING


@dataclass(frozen=True, eq=False)
class Suite:
    """Records and their scaling (see the module docstring).

    records: the records in the order given; names: their file names (unique; the
    ``record`` coordinate); im: the stripe IM (one of SCALE_IMS) or None for a cloud;
    levels: the stripe values (empty for a cloud); period: Sa's period [s] for im = "Sa"
    (NaN otherwise); factor: the cloud's factor (NaN for stripes); periods: the periods
    [s] of the stored ``sa``; pga [g], pgv [m/s]: float64[R]; sa [g]: float64[R, P];
    scale_sa [g]: float64[R], Sa at ``period`` (NaN unless im = "Sa").
    """

    records: tuple[GroundRecord, ...]
    names: tuple[str, ...]
    im: str | None
    levels: tuple[float, ...]
    period: float
    factor: float
    periods: tuple[float, ...]
    pga: np.ndarray = field(repr=False)
    pgv: np.ndarray = field(repr=False)
    sa: np.ndarray = field(repr=False)
    scale_sa: np.ndarray = field(repr=False)

    @property
    def scaled(self) -> bool:
        return self.im is not None

    def record_im(self) -> np.ndarray:
        """Each record's own value of the stripe IM (PGA_ratio: its PGA, PGV_ratio: its
        PGV), float64[R]."""
        if self.im in (PGA, PGA_RATIO):
            return self.pga
        if self.im in (PGV, PGV_RATIO):
            return self.pgv
        if self.im == "Sa":
            return self.scale_sa
        raise ValueError("a cloud has no stripe IM")

    def factors(self, r: np.ndarray, s: np.ndarray | None, alpha_ref: np.ndarray,
                p: np.ndarray) -> np.ndarray:
        """The factor that multiplies record r (int64[n]) at stripe s (int64[n]; None for
        a cloud) for bodies of slenderness alpha_ref [rad] and frequency parameter p
        [rad/s] (float64[n], broadcast)."""
        r = np.asarray(r, np.int64)
        if self.im is None:
            return np.broadcast_to(np.float64(self.factor),
                                   np.broadcast_shapes(r.shape, np.shape(alpha_ref))).copy()
        x = np.asarray(self.levels, np.float64)[np.asarray(s, np.int64)]
        own = self.record_im()[r]
        if self.im == "PGA_ratio":
            return x * np.tan(alpha_ref) / own
        if self.im == "PGV_ratio":
            return x * G * np.tan(alpha_ref) / (np.asarray(p, np.float64) * own)
        return np.broadcast_to(x / own, np.broadcast_shapes(
            r.shape, np.shape(alpha_ref), np.shape(p))).copy()

    def peak_ratio(self, r: np.ndarray, s: np.ndarray | None, alpha_ref: np.ndarray,
                   p: np.ndarray) -> np.ndarray:
        """The scaled record's peak |xg''| / (g tan alpha_ref): the A_ratio the kernel's
        rows take (PGA_ratio stripes: the stripe value itself)."""
        if self.im == "PGA_ratio":
            x = np.asarray(self.levels, np.float64)[np.asarray(s, np.int64)]
            return np.broadcast_to(x, np.broadcast_shapes(
                x.shape, np.shape(alpha_ref), np.shape(p))).copy()
        return (self.factors(r, s, alpha_ref, p) * self.pga[np.asarray(r, np.int64)]
                / np.tan(alpha_ref))

    def scale_dependence(self) -> tuple[str, ...]:
        """What a factor depends on beside (record, stripe): "alpha_ref" (PGA_ratio,
        PGV_ratio) and "p" (PGV_ratio)."""
        return {PGA_RATIO: ("alpha_ref",), PGV_RATIO: ("alpha_ref", "p")}.get(
            self.im or "", ())



def make_suite(records: list[GroundRecord], names: list[str], im: str | None,
               levels: list[float], period: float, factor: float,
               periods: list[float]) -> Suite:
    """A Suite with every record's IMs computed (once). A record whose IM to scale is not
    a finite number > 0 (PGV 0, Sa 0) is a ``SuiteError`` naming its file."""
    from rocksweep.physics import intensity  # scipy.signal: loaded by suite scenes only

    n = len(records)
    pga = np.empty(n)
    pgv = np.empty(n)
    sa = np.empty((n, len(periods)))
    scale_sa = np.full(n, math.nan)
    for i, rec in enumerate(records):
        pga[i] = intensity.pga(rec.acc)
        pgv[i] = intensity.pgv(rec.acc, rec.dt)
        sa[i] = intensity.sa(rec.acc, rec.dt, list(periods), ZETA)
        if im == "Sa":
            hit = [j for j, t in enumerate(periods) if t == period]
            scale_sa[i] = (sa[i, hit[0]] if hit else
                           float(intensity.sa(rec.acc, rec.dt, [period], ZETA)[0]))
    suite = Suite(tuple(records), tuple(names), im, tuple(float(v) for v in levels),
                  float(period), float(factor), tuple(float(t) for t in periods), pga, pgv,
                  sa, scale_sa)
    if im is not None:
        own = suite.record_im()
        for i, rec in enumerate(records):
            v = float(own[i])
            if not (math.isfinite(v) and v > 0.0):
                what = RATIO_OF.get(im, im)
                per = f"({period:g} s)" if im == "Sa" else ""
                raise SuiteError(f"{rec.source}: {what}{per} = {v!r}: cannot be scaled to "
                                 f"a {im} stripe (needs a record with {what} > 0)")
    return suite
