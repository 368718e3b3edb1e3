"""Seismic risk of a fragility: the mean annual rate of each state and its probability in N
years, from a hazard curve.

The mean annual rate of a state (the total probability theorem over the IM; Cornell &
Krawinkler 2000, eq. 1 of the PEER framework):

    lambda_state = integral P(state | im) |d lambda_im(im)|,

P(state | im) the fragility (``rocksweep.analysis.fragility``: Phi(ln(im / im_median) /
beta), or for mode 1 and mode 2 fitted jointly their competing-risk probabilities,
``fragility.probability``)
and lambda_im(x) the hazard curve, the mean annual rate of IM > x. The probability of at
least one occurrence in N years (Poisson): 1 - exp(-lambda_state N).

Integration. The hazard is interpolated linearly in (ln x, ln lambda) between its points
(a power law is exact; a segment that ends at rate 0 is linear in lambda), so |d lambda|
= |lambda'(u)| du in u = ln x is known in closed form on each segment; each segment is
cut into ``SUB`` pieces evenly in u and integrated by 2-point Gauss-Legendre on each
(fourth order: ~1e-7 relative on the tests' power laws).

Beyond the hazard curve's range the tool BOUNDS, it does not extrapolate the hazard:

- above its largest IM x_max: events with IM > x_max happen at the rate lambda(x_max); they
  reach the state with a probability between P(x_max) (the fragility increases) and 1, so
  ``annual_rate`` adds the certain part P(x_max) lambda(x_max) (a lower bound) and
  ``annual_rate_max`` adds lambda(x_max) (the upper bound); the verdict ``above_hazard``
  says when the two differ by more than ``TAIL_SHARE`` of the rate.
- below its smallest IM x_min the hazard says nothing (the rate of small events is not
  given): they add at most P(x_min) times an unknown rate, nothing is added, and the
  verdict ``below_hazard`` says when P(x_min) > ``LOW_P`` (the rate is then a lower bound).

Hazard inputs (``read_hazard``): a two-column CSV with the header ``IM [unit],annual_rate``
(e.g. ``PGA [g],annual_rate``; ``Sa(1.0) [g]`` for Sa at 1 s; lines starting with # are
comments), the IM checked against the fragility's and the unit converted to the
fragility's where both are known (``UNIT_SI``: g, m/s^2, cm/s^2 or gal; m/s, cm/s, mm/s;
the factor is kept in the attribute ``hazard_unit``); or OpenQuake's hazard-curve
CSV (``oq export hcurves``: a comment line
``#,,,,,"generated_by=..., investigation_time=50.0, imt='PGA'"``, then
``lon,lat,depth,poe-<level>,...`` and one row per site): probabilities of exceedance in the
investigation time T converted to rates lambda = -ln(1 - poe) / T; OpenQuake's PGA and SA
are in g, its PGV in cm/s (converted to m/s); levels with poe = 1 (a rate without bound)
are left out.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from rocksweep.errors import Arg, RiskError, RocksweepError  # noqa: F401 (re-exported)
from rocksweep.physics.model import G
from rocksweep.vocab.ground import PGA, PGV, SA

__all__ = ["Hazard", "RiskError", "fragility_median", "hazard_frame", "read_hazard",
           "risk"]

SUB = 8  # pieces per hazard segment, 2 Gauss-Legendre nodes each
TAIL_SHARE = 0.01  # above_hazard when the unknown tail exceeds this share of the rate
LOW_P = 1e-3  # below_hazard when the fragility at the hazard's smallest IM exceeds this
PLOT_POINTS = 200  # the figure's grid over the hazard's range
RATE_COLUMN = "annual_rate"
#: OpenQuake's IMT units, and the factor to rocksweep's
OQ_UNITS = {PGA: ("g", 1.0), SA.upper(): ("g", 1.0), PGV: ("m/s", 0.01)}
#: Units a hazard curve may give its IM in: the factor to SI (accelerations to m/s^2,
#: velocities to m/s); a hazard in another unit of the same kind is converted. g is G,
#: the gravity of the model and of the records' PGV (9.81 m/s^2, not g_n = 9.80665)
UNIT_SI: dict[str, tuple[str, float]] = {
    "g": ("acceleration", G), "m/s^2": ("acceleration", 1.0), "m/s2": ("acceleration", 1.0),
    "cm/s^2": ("acceleration", 0.01), "cm/s2": ("acceleration", 0.01),
    "gal": ("acceleration", 0.01), "m/s": ("velocity", 1.0), "cm/s": ("velocity", 0.01),
    "mm/s": ("velocity", 0.001)}
_HEADER = re.compile(r"^\s*(?P<im>[A-Za-z][A-Za-z0-9_]*)\s*(?:\(\s*(?P<T>[0-9.eE+-]+)\s*\))?"
                     r"\s*\[(?P<unit>[^\]]*)\]\s*$")



@dataclass(frozen=True)
class Hazard:
    """A hazard curve: im [unit] float64[n] increasing (> 0), rate [1/yr] float64[n]
    non-increasing (>= 0), the IM's name (PGA, PGV, Sa, ...), its unit, Sa's period [s]
    (NaN otherwise) and where it came from."""

    im: np.ndarray
    rate: np.ndarray
    name: str
    unit: str
    period: float
    source: str


# ---------------------------------------------------------------------------------------
# reading a hazard curve
# ---------------------------------------------------------------------------------------


def _im_name(text: str) -> str:
    """An IM name as rocksweep spells it (SA, sa -> Sa; PGA, PGV upper case)."""
    t = text.strip()
    if t.lower() == SA.lower():
        return SA
    if t.upper() in (PGA, PGV):
        return t.upper()
    return t


def _checked(im: np.ndarray, rate: np.ndarray, name: str, unit: str, period: float,
             where: str) -> Hazard:
    """The one validation of a hazard curve (bad input: one line naming it)."""
    if im.size < 2:
        raise RiskError(f"{where}: {im.size} hazard level{'s' * (im.size != 1)}; a hazard "
                        "curve needs at least 2 (IM, annual rate) rows")
    for what, v in (("IM", im), (RATE_COLUMN, rate)):
        bad = ~np.isfinite(v)
        if bad.any():
            raise RiskError(f"{where}: row {int(np.argmax(bad)) + 1}: {what} = "
                            f"{v[bad][0]!r}: must be a finite number")
    if np.any(im <= 0.0):
        i = int(np.argmax(im <= 0.0))
        raise RiskError(f"{where}: row {i + 1}: IM = {im[i]!r}: must be > 0")
    if np.any(rate < 0.0):
        i = int(np.argmax(rate < 0.0))
        raise RiskError(f"{where}: row {i + 1}: {RATE_COLUMN} = {rate[i]!r}: must be >= 0 "
                        "(an annual rate of exceedance)")
    if np.any(np.diff(im) <= 0.0):
        i = int(np.argmax(np.diff(im) <= 0.0)) + 1
        raise RiskError(f"{where}: row {i + 1}: IM = {im[i]!r} after {im[i - 1]!r}: the IM "
                        "levels must increase")
    if np.any(np.diff(rate) > 0.0):
        i = int(np.argmax(np.diff(rate) > 0.0)) + 1
        raise RiskError(f"{where}: row {i + 1}: {RATE_COLUMN} = {rate[i]!r} after "
                        f"{rate[i - 1]!r}: the rates of exceedance must not increase with "
                        "the IM")
    if not rate[0] > 0.0:
        raise RiskError(f"{where}: every {RATE_COLUMN} is 0: no hazard")
    return Hazard(im, rate, name, unit, period, where)


def hazard_frame(df: Any, where: str = "hazard") -> Hazard:
    """A hazard curve from a two-column pandas DataFrame: ``IM [unit]`` (e.g. ``PGA [g]``,
    ``Sa(1.0) [g]``) and ``annual_rate`` [1/yr], one row per IM level."""
    cols = [str(c) for c in df.columns]
    if len(cols) != 2:
        raise RiskError(f"{where}: {len(cols)} columns ({', '.join(cols)}); a hazard curve "
                        f"has 2: 'IM [unit]' and '{RATE_COLUMN}' (e.g. 'PGA [g],"
                        f"{RATE_COLUMN}')")
    m = _HEADER.match(cols[0])
    if m is None:
        raise RiskError(f"{where}: first column {cols[0]!r}: must name the IM and its unit, "
                        "e.g. 'PGA [g]', 'PGV [m/s]' or 'Sa(1.0) [g]'")
    if cols[1].strip() != RATE_COLUMN:
        raise RiskError(f"{where}: second column {cols[1]!r}: must be '{RATE_COLUMN}' (mean "
                        "annual rate of exceedance [1/yr])")
    try:
        im = np.asarray(df.iloc[:, 0], dtype=np.float64)
        rate = np.asarray(df.iloc[:, 1], dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise RiskError(f"{where}: a value is not a number ({err})") from None
    period = float(m["T"]) if m["T"] else math.nan
    return _checked(im, rate, _im_name(m["im"]), m["unit"].strip(), period, where)


def _openquake(lines: list[str], where: str, site: int | None) -> Hazard:
    """OpenQuake's hazard-curve CSV (module docstring) -> Hazard in rates."""
    import csv

    meta = lines[0]
    t = re.search(r"investigation_time\s*=\s*'?([0-9.eE+-]+)", meta)
    imt = re.search(r"imt\s*=\s*['\"]([^'\"]+)['\"]", meta)  # 'PGA' (3.x), "PGA" (2.x)
    if t is None or imt is None:
        raise RiskError(f"{where}: OpenQuake header without investigation_time and imt: "
                        f"{meta[:80]!r}")
    T = float(t.group(1))
    if not (math.isfinite(T) and T > 0.0):
        raise RiskError(f"{where}: investigation_time = {t.group(1)}: must be > 0 years")
    mi = re.match(r"^\s*([A-Za-z]+)\s*(?:\(\s*([0-9.eE+-]+)\s*\))?\s*$", imt.group(1))
    if mi is None or mi.group(1).upper() not in OQ_UNITS:
        raise RiskError(f"{where}: imt = {imt.group(1)!r}: rocksweep reads PGA, PGV and SA(T)")
    unit, factor = OQ_UNITS[mi.group(1).upper()]
    rows = list(csv.reader(lines[1:]))
    head = [h.strip() for h in rows[0]]
    levels = [h for h in head if h.startswith("poe-")]
    if not levels:
        raise RiskError(f"{where}: no poe-<level> columns in {','.join(head)[:80]!r}")
    data = [r for r in rows[1:] if any(c.strip() for c in r)]
    if not data:
        raise RiskError(f"{where}: no site rows")
    if site is None and len(data) > 1:
        raise RiskError(f"{where}: {len(data)} sites; choose one with {{site}} (0 to "
                        f"{len(data) - 1}, the row order)", site=Arg("site"))
    k = 0 if site is None else int(site)
    if not 0 <= k < len(data):
        raise RiskError(f"{where}: site = {site!r}: the file has sites 0 to {len(data) - 1}")
    row = dict(zip(head, data[k], strict=False))
    try:
        x = np.array([float(h[4:]) for h in levels]) * factor
        poe = np.array([float(row[h]) for h in levels])
    except (ValueError, KeyError) as err:
        raise RiskError(f"{where}: site {k}: a value is not a number ({err})") from None
    if np.any(~np.isfinite(poe) | (poe < 0.0) | (poe > 1.0)):
        bad = poe[~np.isfinite(poe) | (poe < 0.0) | (poe > 1.0)][0]
        raise RiskError(f"{where}: site {k}: poe = {bad!r}: a probability in [0, 1]")
    keep = poe < 1.0  # poe = 1: the rate has no bound there
    with np.errstate(divide="ignore"):
        rate = -np.log1p(-poe[keep]) / T
    name = _im_name(mi.group(1))
    period = float(mi.group(2)) if mi.group(2) else math.nan
    return _checked(x[keep], rate, name, unit, period, where)


def read_hazard(source: Any, *, site: int | None = None) -> Hazard:
    """A hazard curve from a path (a two-column CSV ``IM [unit],annual_rate`` or
    OpenQuake's hazard-curve CSV, told apart by its ``#`` first line), a pandas DataFrame
    of the two columns, or a ``Hazard``. site: the row of an OpenQuake file with several
    sites. Bad input is a one-line ``RiskError`` naming the file, the row and the value."""
    if isinstance(source, Hazard):
        return source
    if hasattr(source, "columns") and hasattr(source, "iloc"):
        return hazard_frame(source)
    if not isinstance(source, str | Path):
        raise RiskError(f"hazard = {type(source).__name__}: a CSV path or a pandas DataFrame "
                        f"('IM [unit]', '{RATE_COLUMN}')")
    path = Path(source)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as err:
        raise RiskError(f"{path}: cannot read the hazard curve "
                        f"({getattr(err, 'strerror', None) or type(err).__name__})") from None
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines:
        raise RiskError(f"{path}: empty hazard file")
    if lines[0].lstrip().startswith("#") and any(
            ln.replace(" ", "").startswith("lon,lat") for ln in lines[1:3]):
        return _openquake(lines, str(path), site)
    lines = [ln for ln in lines if not ln.lstrip().startswith("#")]  # comments
    if not lines:
        raise RiskError(f"{path}: no header 'IM [unit],{RATE_COLUMN}'")
    import csv

    rows = list(csv.reader(lines))
    head, body = rows[0], rows[1:]
    if any(len(r) != len(head) for r in body):
        i = next(i for i, r in enumerate(body) if len(r) != len(head))
        raise RiskError(f"{path}: row {i + 1}: {len(body[i])} values, the header has "
                        f"{len(head)}")
    import pandas as pd

    try:
        df = pd.DataFrame([[float(c) for c in r] for r in body], columns=head)
    except ValueError as err:
        raise RiskError(f"{path}: a value is not a number ({err})") from None
    if not body:
        df = pd.DataFrame(columns=head)
    return hazard_frame(df, str(path))


# ---------------------------------------------------------------------------------------
# the fragility's names (29a renames median -> im_median; both are read, here only)
# ---------------------------------------------------------------------------------------


def fragility_median(fr: xr.Dataset) -> tuple[xr.DataArray, str]:
    """(the fitted median DataArray, its name): ``im_median``, or ``median`` in fragility
    Datasets made before that variable was renamed."""
    for name in ("im_median", "median"):
        if name in fr.data_vars:
            return fr[name], name
    raise RiskError("not a fragility Dataset (no im_median and beta; make one with "
                    "rocksweep.fragility)")


# ---------------------------------------------------------------------------------------
# the integral
# ---------------------------------------------------------------------------------------


def _density(hz: Hazard, x: np.ndarray) -> np.ndarray:
    """|d lambda / d ln x| of the log-log interpolated hazard at x (inside its range)."""
    lx = np.log(hz.im)
    u = np.log(x)
    i = np.clip(np.searchsorted(lx, u, side="right") - 1, 0, lx.size - 2)
    r0, r1 = hz.rate[i], hz.rate[i + 1]
    du = lx[i + 1] - lx[i]
    pos = r1 > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(pos, (np.log(np.where(pos, r1, 1.0)) - np.log(r0)) / du, 0.0)
        out = np.where(pos, -slope * r0 * np.exp(slope * (u - lx[i])), (r0 - r1) / du)
    return out


def _fragility_p(x: np.ndarray, median: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Phi(ln(x / median) / beta) over (curves..., x); beta = 0: the step at the median."""
    from scipy.special import ndtr

    med = median[..., None]
    b = beta[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.log(x / med) / b
    step = (x >= med).astype(np.float64)
    return np.where(b > 0.0, ndtr(z), np.where(np.isfinite(med), step, np.nan))


def _nodes(hz: Hazard) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes x_j and weights w_j (2 per piece, ``SUB`` pieces per hazard
    segment evenly in u = ln x) with sum_j f(x_j) w_j ~ integral f |d lambda| over the
    hazard's range: w_j = the quadrature weight times |d lambda / d u| at the node (exact
    for the log-log interpolant: lambda' = s lambda on a segment of log-log slope s;
    a segment that ends at rate 0 is linear in lambda: constant lambda')."""
    g = np.array([-1.0, 1.0]) / math.sqrt(3.0)  # 2-point Gauss-Legendre on [-1, 1]
    lx = np.log(hz.im)
    xs, ws = [], []
    for i in range(hz.im.size - 1):
        r0, r1 = hz.rate[i], hz.rate[i + 1]
        du = (lx[i + 1] - lx[i]) / SUB
        centres = lx[i] + du * (np.arange(SUB) + 0.5)
        u = (centres[:, None] + 0.5 * du * g[None, :]).ravel()
        if r1 > 0.0:
            slope = (math.log(r1) - math.log(r0)) / (lx[i + 1] - lx[i])
            dens = -slope * r0 * np.exp(slope * (u - lx[i]))
        else:
            dens = np.full(u.size, (r0 - r1) / (lx[i + 1] - lx[i]))
        xs.append(u)
        ws.append(0.5 * du * dens)
    return np.exp(np.concatenate(xs)), np.concatenate(ws)


def _curve_p(fr: xr.Dataset, med: xr.DataArray, beta: xr.DataArray, dims: list[str]):
    """x -> P(state | x) float[..., x] over ``dims`` (+ any extra dims of med, e.g.
    ``sample``, last before x): the fragility's own model (``fragility.probability``: the
    competing-risk probabilities for mode1 with mode2 fitted jointly, the lognormal CDF
    otherwise) when the Dataset says which (``fit``), else the lognormal CDF."""
    extra = [d for d in med.dims if d not in dims]
    order = [*dims, *extra]
    if "fit" in fr.data_vars and "state" in fr.coords:
        from rocksweep.analysis.fragility import probability

        like = xr.Dataset({"im_median": med, "beta": beta, "fit": fr["fit"]},
                          coords={"state": fr["state"]})

        def p(x: np.ndarray) -> np.ndarray:
            return np.asarray(probability(like, x).transpose(*order, "im").values,
                              np.float64)
        return p
    m = np.asarray(med.transpose(*order).values, np.float64)
    b = np.asarray(beta.transpose(*order).values, np.float64)
    return lambda x: _fragility_p(x, m, b)


def _rates(hz: Hazard, p) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(annual_rate, annual_rate_max, P at x_min, P at x_max) for the fragility curves
    x -> p(x) float[..., x] (module docstring)."""
    x, w = _nodes(hz)
    inside = p(x) @ w
    ends = p(hz.im[[0, -1]])
    p_lo, p_hi = ends[..., 0], ends[..., 1]
    top = hz.rate[-1]
    return inside + p_hi * top, inside + top, p_lo, p_hi


def _interval(v: np.ndarray, ci: float) -> tuple[np.ndarray, np.ndarray]:
    """Percentile interval at level ci over the last axis, finite values only."""
    q = 100.0 * np.array([(1.0 - ci) / 2.0, (1.0 + ci) / 2.0])
    out = np.full((2,) + v.shape[:-1], np.nan)
    for idx in np.ndindex(*v.shape[:-1]):
        w = v[idx]
        w = w[np.isfinite(w)]
        if w.size:
            out[(slice(None),) + idx] = np.percentile(w, q)
    return out[0], out[1]


def _check_years(years: Any) -> float:
    if isinstance(years, bool) or not isinstance(years, int | float | np.integer |
                                                  np.floating):
        raise RiskError(f"years = {years!r}: must be a number of years > 0")
    y = float(years)
    if not (math.isfinite(y) and y > 0.0):
        raise RiskError(f"years = {years!r}: must be a finite number of years > 0")
    return y


def _unit_factor(frm: str, to: str) -> float | None:
    """x [frm] times this is x [to]; None when either unit is unknown or their kinds
    differ (``UNIT_SI``)."""
    a, b = UNIT_SI.get(frm.strip().lower()), UNIT_SI.get(to.strip().lower())
    if a is None or b is None or a[0] != b[0]:
        return None
    return a[1] / b[1]


def _check_match(fr: xr.Dataset, hz: Hazard) -> Hazard:
    """The hazard curve in the fragility's IM units (converted where both units are known),
    or a RiskError naming what does not match."""
    im, unit = str(fr.attrs.get("im", "")), str(fr.attrs.get("im_units", ""))
    if not im:
        raise RiskError("the fragility Dataset has no attribute im (the IM its curves are "
                        "over)")
    if hz.name != im:
        raise RiskError(f"{hz.source}: hazard IM {hz.name} [{hz.unit}] is not the "
                        f"fragility's IM {im} [{unit}]; use a hazard curve of {im}")
    if hz.unit != unit:
        factor = _unit_factor(hz.unit, unit)
        if factor is None:
            known = ", ".join(UNIT_SI)
            raise RiskError(f"{hz.source}: hazard unit [{hz.unit}] for {hz.name} is not the "
                            f"fragility's [{unit}] and cannot be converted to it (known "
                            f"units: {known}); convert the hazard curve to {unit}")
        hz = replace(hz, im=hz.im * factor, unit=unit)
    if im == "Sa":
        per = float(fr.attrs.get("period", math.nan))
        if not (math.isfinite(hz.period) and math.isfinite(per)
                and math.isclose(hz.period, per, rel_tol=1e-6)):
            raise RiskError(f"{hz.source}: hazard Sa period {hz.period:g} s is not the "
                            f"fragility's {per:g} s")
    return hz


def risk(fr: xr.Dataset, hazard: Any, years: float = 50.0, *,
         site: int | None = None) -> xr.Dataset:
    """Mean annual rate and probability in ``years`` of each state of a fragility Dataset.

    fr: what ``rocksweep.fragility`` returns (``im_median`` or ``median`` [IM units],
    ``beta``, attrs ``im``, ``im_units``; with bootstrap, ``im_median_samples`` and
    ``beta_samples`` over ``sample``); hazard: a path (two-column CSV ``IM [unit],
    annual_rate`` or OpenQuake's hazard-curve CSV), a DataFrame or a ``Hazard``; years:
    N > 0; site: the row of an OpenQuake file with several sites.

    Returns a Dataset over the fragility's dims (state, lam, ...): ``annual_rate``
    [1/yr] (the integral over the hazard's range plus the certain tail above it: a lower
    bound, module docstring), ``annual_rate_max`` (the tail above at its largest),
    ``probability`` = 1 - exp(-annual_rate years), their ``_lo``/``_hi`` (the bootstrap
    percentile interval at the fragility's ``ci`` from its resamples; NaN without them),
    ``reason`` ("ok", or "above_hazard", "below_hazard", "no_fit", and the fragility's
    own non-ok reasons as "fit_<reason>", joined by ","); for the
    figure ``hazard_rate`` over ``hazard_im`` (the curve read), and over ``im_level`` (a
    grid over the hazard's range) ``fragility`` and ``rate_density`` = P(state | x)
    |d lambda / d ln x| [1/yr], the integrand. attrs: rocksweep_kind = "risk", years, im,
    im_units, hazard_source, extrapolation, ci.
    """
    if not isinstance(fr, xr.Dataset):
        raise RiskError(f"fr = {type(fr).__name__}: a fragility Dataset "
                        "(rocksweep.fragility)")
    med_da, med_name = fragility_median(fr)
    if "beta" not in fr.data_vars:
        raise RiskError("not a fragility Dataset (no beta)")
    N = _check_years(years)
    read = read_hazard(hazard, site=site)
    hz = _check_match(fr, read)
    dims = list(med_da.dims)
    curve = _curve_p(fr, med_da, fr["beta"], dims)
    rate, rate_max, p_lo, p_hi = _rates(hz, curve)
    ci = float(fr.attrs.get("ci", 0.9))
    lo = hi = np.full(rate.shape, np.nan)
    samples = f"{med_name}_samples"
    if samples in fr.data_vars and "beta_samples" in fr.data_vars:
        ms, bs = fr[samples], fr["beta_samples"]
        ok = np.isfinite(ms) & np.isfinite(bs)
        r_s, _, _, _ = _rates(hz, _curve_p(fr, ms.where(ok), bs.where(ok), dims))
        lo, hi = _interval(r_s, ci)
    reasons = np.empty(rate.shape, dtype=object)
    unknown_top = rate_max - rate
    fit_reason = (np.asarray(fr["reason"].transpose(*dims).values, dtype=str)
                  if "reason" in fr.data_vars and set(fr["reason"].dims) == set(dims)
                  else np.full(rate.shape, "ok"))
    for idx in np.ndindex(*rate.shape):
        bits = [f"fit_{r}" for r in str(fit_reason[idx]).split(",")
                if r and r != "ok"]  # the fragility's own verdict carries over
        if not math.isfinite(rate[idx]):
            bits.append("no_fit" if not bits else "no_rate")
        else:
            if unknown_top[idx] > TAIL_SHARE * rate[idx]:
                bits.append("above_hazard")
            if p_lo[idx] > LOW_P:
                bits.append("below_hazard")
        reasons[idx] = ",".join(bits) or "ok"

    def prob(r: np.ndarray) -> np.ndarray:
        return -np.expm1(-r * N)

    coords: dict[str, Any] = {d: fr[d] for d in dims if d in fr.coords}
    if "state" in fr.coords and "state" not in dims:
        coords["state"] = fr["state"]
    grid = np.geomspace(hz.im[0], hz.im[-1], PLOT_POINTS)
    dens = _density(hz, grid)
    p_grid = curve(grid)
    unit = hz.unit
    data: dict[str, Any] = {
        "annual_rate": (dims, rate, {"units": "1/yr", "long_name": "mean annual rate of the "
                                     "state (hazard range + certain tail above)"}),
        "annual_rate_max": (dims, rate_max, {"units": "1/yr", "long_name": "mean annual rate "
                                             "with the tail above the hazard at its largest"}),
        "annual_rate_lo": (dims, lo, {"units": "1/yr", "long_name": f"bootstrap {ci:g} "
                                      "interval, lower"}),
        "annual_rate_hi": (dims, hi, {"units": "1/yr", "long_name": f"bootstrap {ci:g} "
                                      "interval, upper"}),
        "probability": (dims, prob(rate), {"units": "1", "long_name": f"probability in "
                                           f"{N:g} years"}),
        "probability_lo": (dims, prob(lo), {"units": "1"}),
        "probability_hi": (dims, prob(hi), {"units": "1"}),
        "reason": (dims, reasons.astype(str), {"long_name": "ok, or above_hazard, "
                                               "below_hazard, no_fit, fit_<the fit's "
                                               "reason>"}),
        "hazard_rate": (("hazard_im",), hz.rate, {"units": "1/yr", "long_name": "hazard "
                                                  "curve: annual rate of IM > x"}),
        "fragility": ([*dims, "im_level"], p_grid, {"units": "1"}),
        "rate_density": ([*dims, "im_level"], p_grid * np.maximum(dens, 0.0),
                         {"units": "1/yr", "long_name": "P(state | x) |d lambda / d ln x|: "
                          "the integrand over ln x"}),
    }
    coords["hazard_im"] = ("hazard_im", hz.im, {"units": unit})
    coords["im_level"] = ("im_level", grid, {"units": unit})
    attrs = {"rocksweep_kind": "risk", "years": N, "im": hz.name, "im_units": unit,
             "hazard_source": hz.source, "ci": ci,
             "extrapolation": "bound: above the hazard's largest IM the certain tail "
                              "P(x_max) lambda(x_max) is added (annual_rate_max: "
                              "lambda(x_max)); below its smallest IM nothing is added",
             "reference": "Cornell & Krawinkler (2000), Progress and challenges in "
                          "seismic performance assessment, PEER Center News 3(2)"}
    if math.isfinite(hz.period):
        attrs["period"] = hz.period
    if read.unit != hz.unit:
        attrs["hazard_unit"] = (f"{read.unit}, converted to {hz.unit} "
                                f"(x {_unit_factor(read.unit, hz.unit):.6g})")
    for k in ("title", "states"):
        if k in fr.attrs:
            attrs[k] = fr.attrs[k]
    return xr.Dataset(data, coords=coords, attrs=attrs)
