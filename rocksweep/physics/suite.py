"""A suite of ground-motion records and how each run scales one (no numba here).

A scene's ``ground.records`` (``rocksweep.scene.parse``) becomes a ``Suite``: the records
read once, their intensity measures computed once (``rocksweep.physics.intensity``; the
list is ``RECORD_IMS``: PGA [g], PGV [m/s], Sa(T) [g] at 5% damping, Arias intensity [m/s],
CAV [m/s], D5-95 [s], PGV/PGA [s], AvgSa [g]) and the scaling rule ``ground.scale``:

- stripes, ``{im: IM, values: [x_1, ...]}``: at stripe j every record is multiplied by the
  factor that makes its IM equal x_j: PGA, PGV, Sa (at ``scale.period``), AvgSa (over
  ``avgsa_range``) and CAV by x_j / IM, Arias (F^2 times the record's) by sqrt(x_j / IM);
  PGA_ratio = PGA / (g tan alpha_ref) (the A_ratio of a single-record scene) and
  PGV_ratio = PGV p / (g tan alpha_ref) (Dimitrakopoulos & Paraskeva 2015), whose factor
  also depends on the body's slenderness alpha_ref (alpha_cg, or alpha for a block) and,
  for PGV_ratio, on p [rad/s];
- a cloud, ``none`` or ``{factor: F}``: every record as recorded, times F (1 for none).

The kernel sees a scaled record as its samples acc / PGA (shared by all runs of the record,
``rocksweep.compute.sweep``) and a peak |xg''| = factor * PGA [g]; that peak is passed
as the point's A_ratio = factor * PGA / tan(alpha_ref) (``peak_ratio``), so the rows are
filled by the same code as a single record's (``points.fill_rows``).

AvgSa's period range is ``ground.avgsa: [T_lo, T_hi]`` [s]; by default 0.2 to 3 times the
reference period T_ref: ``scale.period`` for Sa stripes, else 2 pi / p of the body's
frequency parameter p (the geometric mean of p when p is swept), ``avgsa_rule`` says which.

Warnings (``RecordWarning``, one line each, issued once per suite by ``warn``): a record
whose ground velocity ends far from 0 (|v_end| > ``DRIFT_SHARE`` of its PGV: not baseline
corrected, the ground keeps moving after the record) and scale factors above
``MAX_FACTOR`` (heavily scaled records bias the response, Luco & Bazzurro 2007).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from rocksweep.errors import SuiteError
from rocksweep.physics import intensity
from rocksweep.physics.bodies import G
from rocksweep.physics.path import rotd50_peaks
from rocksweep.physics.records import GroundRecord
from rocksweep.vocab.ground import (
    ARIAS,
    AVGSA,
    CAV,
    D5_95,
    H1,
    PGA,
    PGA_RATIO,
    PGV,
    PGV_OVER_PGA,
    PGV_RATIO,
    RATIO_OF,
    RECORD_IMS,
    ROTD50,
    ROTD50_IMS,
    SA_DAMPING,
    SCALE_IMS,
)

# the IMs (and their units), Sa's damping ratio and default periods: rocksweep.vocab.ground
ZETA = SA_DAMPING
#: AvgSa's default range: these multiples of the reference period
AVGSA_RANGE = (0.2, 3.0)
#: warn when a record's final ground velocity exceeds this share of its PGV
DRIFT_SHARE = 0.1
#: warn when a record is scaled by more than this factor
MAX_FACTOR = 5.0



class RecordWarning(UserWarning):
    """A record that can be used but should be looked at (drift, a large scale factor);
    ``str()`` is one line."""


@dataclass(frozen=True, eq=False)
class Suite:
    """Records and their scaling (see the module docstring).

    records: the records in the order given; names: their file names (unique; the
    ``record`` coordinate); im: the stripe IM (one of SCALE_IMS) or None for a cloud;
    levels: the stripe values (empty for a cloud); period: Sa's period [s] for im = "Sa"
    (NaN otherwise); factor: the cloud's factor (NaN for stripes); periods: the periods
    [s] of the stored ``sa``; pga [g], pgv [m/s]: float64[R]; sa [g]: float64[R, P];
    scale_sa [g]: float64[R], Sa at ``period`` (NaN unless im = "Sa"); arias [m/s], cav
    [m/s], d5_95 [s], avgsa [g], v_end [m/s] (ground velocity at the last sample):
    float64[R]; avgsa_range: (T_lo, T_hi) [s] of AvgSa and avgsa_rule: how it was chosen.
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
    arias: np.ndarray = field(repr=False, default=None)
    cav: np.ndarray = field(repr=False, default=None)
    d5_95: np.ndarray = field(repr=False, default=None)
    avgsa: np.ndarray = field(repr=False, default=None)
    v_end: np.ndarray = field(repr=False, default=None)
    avgsa_range: tuple[float, float] = (math.nan, math.nan)
    avgsa_rule: str = ""
    # a suite of multi-component records (a folder of PEER downloads): each record's
    # second horizontal and vertical (empty: single-component records); the horizontal
    # whose IM scales the records: "H1" (the first component) or "RotD50" (the median over
    # orientations of the two horizontals, ``path.rotd50_peaks``), its values float64[R]
    h2: tuple = ()
    vertical: tuple = ()
    component: str = H1
    rotd50: np.ndarray | None = field(repr=False, default=None)
    # whether each record's vertical acts on the body (``ground.vertical: true|false`` of a
    # folder suite; default: when the folder has UP files), scaled by the record's factor
    vertical_acts: bool = False

    def acting_vertical(self, r: int) -> GroundRecord | None:
        """Record r's vertical component when it acts on the body (``vertical_acts``),
        else None."""
        return self.vertical[r] if self.vertical_acts else None

    def vertical_ims(self) -> dict[str, np.ndarray]:
        """``record_pga_v`` [g] (the vertical's peak) and ``record_v_over_h`` (PGA_v over
        the scaling component's PGA: H1's or RotD50's), float64[R]; {} without
        verticals."""
        if not self.vertical:
            return {}
        pga_v = np.array([np.nan if v is None else v.pga for v in self.vertical])
        pga_h = self.rotd50 if (self.component == ROTD50 and self.im in (PGA, PGA_RATIO)) \
            else self.pga
        return {"record_pga_v": pga_v, "record_v_over_h": pga_v / pga_h}

    def record_ims(self) -> dict[str, np.ndarray]:
        """Each ``RECORD_IMS`` variable (not Sa) -> float64[R], the records as recorded."""
        own = {PGA: self.pga, PGV: self.pgv, ARIAS: self.arias, CAV: self.cav,
               D5_95: self.d5_95, PGV_OVER_PGA: self.pgv / (self.pga * G), AVGSA: self.avgsa}
        return {RECORD_IMS[k][0]: np.asarray(v, np.float64) for k, v in own.items()}

    def warn(self, alpha_ref, p) -> None:
        """Issue the suite's ``RecordWarning``s (module docstring) for bodies of slenderness
        ``alpha_ref`` [rad] and frequency parameters ``p`` [rad/s] (the swept values)."""
        R = len(self.records)
        drift = np.abs(self.v_end) > DRIFT_SHARE * self.pgv
        if drift.any():
            worst = int(np.argmax(np.where(drift, np.abs(self.v_end) / self.pgv, -1.0)))
            warnings.warn(RecordWarning(
                f"ground.records: {int(drift.sum())} of {R} records end with a ground "
                f"velocity above {DRIFT_SHARE:.0%} of their PGV (not baseline-corrected: "
                f"the ground keeps moving after the record), e.g. {self.names[worst]} ends "
                f"at {self.v_end[worst]:+.3g} m/s (PGV {self.pgv[worst]:.3g} m/s)"),
                stacklevel=2)
        if self.im is None and not (self.factor > MAX_FACTOR):
            return
        a = np.asarray(alpha_ref, np.float64).ravel()
        pp = np.asarray(p, np.float64).ravel()
        r, s, aa, ppp = np.meshgrid(np.arange(R), np.arange(max(len(self.levels), 1)), a,
                                    pp, indexing="ij")
        f = self.factors(r.ravel(), None if self.im is None else s.ravel(), aa.ravel(),
                         ppp.ravel()).reshape(r.shape)
        big = f > MAX_FACTOR
        if big.any():
            i = np.unravel_index(int(np.argmax(f)), f.shape)
            unit = SCALE_IMS.get(self.im or "", "1")
            at = (f" at {self.im} = {self.levels[i[1]]:g}{'' if unit == '1' else ' ' + unit}"
                  if self.im is not None else "")
            n_rec = int(big.reshape(R, -1).any(-1).sum())
            warnings.warn(RecordWarning(
                f"ground.scale: {n_rec} of {R} records are scaled by more than "
                f"{MAX_FACTOR:g}x (largest {f[i]:.3g}x: {self.names[i[0]]}{at}); heavily "
                "scaled records may not represent motions of that intensity"), stacklevel=2)

    @property
    def scaled(self) -> bool:
        return self.im is not None

    def record_im(self) -> np.ndarray:
        """Each record's own value of the stripe IM (PGA_ratio: its PGA, PGV_ratio: its
        PGV), float64[R]."""
        if self.component == ROTD50:
            return self.rotd50
        if self.im in (PGA, PGA_RATIO):
            return self.pga
        if self.im in (PGV, PGV_RATIO):
            return self.pgv
        if self.im == "Sa":
            return self.scale_sa
        own = {AVGSA: self.avgsa, CAV: self.cav, ARIAS: self.arias}
        if self.im in own:
            return own[self.im]
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
        # the IM of the record times F is F^n times its IM (``RECORD_IMS``; Arias: n = 2)
        n = RECORD_IMS[self.im][2] if self.im in RECORD_IMS else 1
        ratio = x / own if n == 1 else (x / own) ** (1.0 / n)
        return np.broadcast_to(ratio, np.broadcast_shapes(
            r.shape, np.shape(alpha_ref), np.shape(p))).copy()

    def peak_ratio(self, r: np.ndarray, s: np.ndarray | None, alpha_ref: np.ndarray,
                   p: np.ndarray) -> np.ndarray:
        """The scaled record's peak |xg''| / (g tan alpha_ref): the A_ratio the kernel's
        rows take (PGA_ratio stripes: the stripe value itself)."""
        if self.im == PGA_RATIO and self.component == H1:
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
               periods: list[float], avgsa_range: tuple[float, float] | None = None,
               avgsa_rule: str = "", h2: tuple = (), vertical: tuple = (),
               component: str = H1, vertical_acts: bool = False) -> Suite:
    """A Suite with every record's IMs computed (once). avgsa_range: (T_lo, T_hi) [s] of
    AvgSa (default ``AVGSA_RANGE`` times ``period``, or times 1 s without one). A record
    whose IM to scale is not a finite number > 0 (PGV 0, Sa 0) is a ``SuiteError`` naming
    its file."""
    n = len(records)
    pga = np.empty(n)
    pgv = np.empty(n)
    sa = np.empty((n, len(periods)))
    scale_sa = np.full(n, math.nan)
    if avgsa_range is None:
        t_ref = period if math.isfinite(period) else 1.0
        avgsa_range = (AVGSA_RANGE[0] * t_ref, AVGSA_RANGE[1] * t_ref)
        avgsa_rule = avgsa_rule or (f"{AVGSA_RANGE[0]:g}-{AVGSA_RANGE[1]:g} x T_ref = "
                                    f"{t_ref:g} s")
    more = {k: np.empty(n) for k in ("arias", "cav", "d5_95", "avgsa", "v_end")}
    for i, rec in enumerate(records):
        more["arias"][i] = intensity.arias(rec.acc, rec.dt)
        more["cav"][i] = intensity.cav(rec.acc, rec.dt)
        more["d5_95"][i] = intensity.significant_duration(rec.acc, rec.dt)
        more["avgsa"][i] = intensity.avg_sa(rec.acc, rec.dt, *avgsa_range, ZETA)
        more["v_end"][i] = intensity.final_velocity(rec.acc, rec.dt)
        pga[i] = intensity.pga(rec.acc)
        pgv[i] = intensity.pgv(rec.acc, rec.dt)
        sa[i] = intensity.sa(rec.acc, rec.dt, list(periods), ZETA)
        if im == "Sa":
            hit = [j for j, t in enumerate(periods) if t == period]
            scale_sa[i] = (sa[i, hit[0]] if hit else
                           float(intensity.sa(rec.acc, rec.dt, [period], ZETA)[0]))
    rotd50 = None
    if component == ROTD50:  # the stripe IM of the two horizontals, median over angles
        rotd50 = np.array([rotd50_im(r, s, im, period) for r, s in zip(records, h2,
                                                                         strict=True)])
    suite = Suite(tuple(records), tuple(names), im, tuple(float(v) for v in levels),
                  float(period), float(factor), tuple(float(t) for t in periods), pga, pgv,
                  sa, scale_sa, **more,
                  avgsa_range=(float(avgsa_range[0]), float(avgsa_range[1])),
                  avgsa_rule=avgsa_rule, h2=tuple(h2), vertical=tuple(vertical),
                  component=component, rotd50=rotd50,
                  vertical_acts=bool(vertical_acts and vertical))
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


def rotd50_im(h1: GroundRecord, h2: GroundRecord, im: str | None, period: float) -> float:
    """RotD50 (Boore 2010) of a two-component record's IM: PGA (and PGA_ratio's) [g], PGV
    (and PGV_ratio's) [m/s] of the velocities at the samples, or Sa(period) [g] at 5%
    damping of the oscillator's responses (its free vibration one period past the record
    included): the median over the angles 0..179 deg of the peak of the projected series."""
    if im not in ROTD50_IMS:
        raise SuiteError(f"RotD50 of {im}: defined for {', '.join(ROTD50_IMS)} only")
    n = max(h1.npts, h2.npts)
    a1, a2 = (np.pad(r.acc, (0, n - r.npts)) for r in (h1, h2))
    if im in (PGA, PGA_RATIO):
        return rotd50_peaks(a1, a2)
    if im in (PGV, PGV_RATIO):
        return rotd50_peaks(intensity.velocity(a1, h1.dt), intensity.velocity(a2, h1.dt))
    w = 2.0 * math.pi / period
    m = int(min(max(math.ceil(32 * h1.dt / period), 1), 64))
    h = h1.dt / m
    tau = np.arange(1, int(math.ceil(period / h)) + 1) * h
    us = []
    for a in (a1, a2):
        x = -intensity.refined(a, h1.dt, m)
        u, v = intensity.nj_response(x, w, ZETA, h, rate=True)
        us.append(np.concatenate((u, intensity.free_vibration(
            float(u[-1]), float(v[-1]), w, ZETA, tau)[0])))
    return w * w * rotd50_peaks(*us)
