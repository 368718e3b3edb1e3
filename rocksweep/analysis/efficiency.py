"""IM efficiency: which intensity measure explains a state (overturning) best for this body.

For every IM of the records (``rocksweep.physics.suite.RECORD_IMS``: PGA, PGV, Sa(T) at
each stored period, AvgSa, Arias, CAV, D5-95, PGV/PGA, and the dimensionless
PGA/(g tan alpha) and PGV p/(g tan alpha)) the lognormal dispersion beta of the state's
fragility expressed in that IM; the smaller beta, the better the IM predicts the state
(efficiency, Luco & Cornell 2007).

Stripes (a scaled suite): each record's capacity is its first overturning level (the
smallest stripe that reaches the state, as ``fragility``'s ``first_level``), known to lie
between the stripe below it and it: an interval. In an IM J that scales with the record as
F^n (n = 1: PGA, PGV, Sa, AvgSa, CAV; n = 2: Arias), record r's capacity in J is
F^n J_r over the same interval (F the record's scale factor at those stripes), and
ln(capacity) ~ N(ln median, beta^2) is fitted by maximum likelihood with every record an
interval (records that never reach it: right-censored above the top stripe; those that
reach it at the lowest stripe: left-censored below it). An IM that scaling leaves
unchanged (n = 0: D5-95, PGV/PGA) cannot carry a fragility of its own; for it, the
capacity in the stripe IM is regressed on ln J (the same censored likelihood with mean
a + b ln J_r): beta is the dispersion left once J is known. ``beta_scale`` = beta / n (n =
1 for the regressions) is beta in units of ln(scale factor), the figure that compares IMs
that scale differently (Arias's beta is twice its sqrt's).

Clouds (unscaled suites): a probit fit of the 0/1 outcome on ln J of each record times its
factor^n (``fragility.fit_cloud``), beta = 1 / slope.

Verdicts (``reason`` per IM and curve: "ok", or the words joined by ","; also an
``AnalysisWarning``), as fragility's fits have them:

- "separated": one value (a line in ln J, for a regression) lies inside every record's
  capacity interval: the likelihood grows as beta -> 0, so beta is below what the stripes
  resolve and its value (~0.001: where the optimiser stopped) is no measurement; such IMs
  tie (the best, if the sample is large enough to tell). A linear-programming test of
  the intervals (``_separated``), not of where the optimiser stopped. A cloud's probit
  says it as fragility's does (beta NaN there);
- "few_records": fewer than ``MIN_RECORDS`` records counted: beta's own relative standard
  error (~ 1 / sqrt(2 n)) exceeds 20%, more than the differences a ranking rests on;
- "no_failures": no record reaches the state (beta NaN).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
import xarray as xr
from scipy.optimize import linprog, minimize
from scipy.special import log_ndtr

from rocksweep.analysis.fragility import fit_cloud
from rocksweep.analysis.states import counted_points, state_reached, trust
from rocksweep.errors import AnalysisWarning, EfficiencyError
from rocksweep.physics.bodies import G
from rocksweep.vocab.axes import ALPHA_KEYS
from rocksweep.vocab.ground import PGA_RATIO, PGV_OVER_PGA, PGV_RATIO, RECORD_IMS, SA, SCALE_IMS
from rocksweep.vocab.kinds import IM_EFFICIENCY, KIND_ATTR

__all__ = ["im_efficiency", "record_im_table"]

#: fewer records counted than this: the verdict "few_records" (beta's relative standard
#: error ~ 1 / sqrt(2 n) is 22% at n = 10)
MIN_RECORDS = 10



def _scalar(ds: xr.Dataset, names: tuple[str, ...]) -> xr.DataArray | None:
    for n in names:
        if n in ds.coords or n in ds.variables:
            return ds[n]
    return None


def record_im_table(ds: xr.Dataset) -> dict[str, tuple[xr.DataArray, str, int]]:
    """Every IM of the records that ``ds`` stores: name -> (values as recorded (record,)
    or broadcast over alpha/p for the dimensionless ones, units, exponent n)."""
    out: dict[str, tuple[xr.DataArray, str, int]] = {}
    for name, (var, unit, n) in RECORD_IMS.items():
        if var in ds.variables:
            out[name] = (ds[var], unit, n)
        elif name == PGV_OVER_PGA and {"record_pga", "record_pgv"} <= set(ds.variables):
            out[name] = (ds["record_pgv"] / (ds["record_pga"] * G), unit, n)
    if "record_sa" in ds.variables and "period" in ds["record_sa"].dims:
        for T in ds["period"].values:
            out[f"{SA}({float(T):g})"] = (ds["record_sa"].sel(period=T, drop=True),
                                          SCALE_IMS[SA], 1)
    alpha = _scalar(ds, ALPHA_KEYS)
    p = _scalar(ds, ("p",))
    if alpha is not None and "record_pga" in ds.variables:
        out[PGA_RATIO] = (ds["record_pga"] / np.tan(alpha), SCALE_IMS[PGA_RATIO], 1)
        if p is not None and "record_pgv" in ds.variables:
            out[PGV_RATIO] = (ds["record_pgv"] * p / (G * np.tan(alpha)),
                              SCALE_IMS[PGV_RATIO], 1)
    return out


def _interval_mle(lo: np.ndarray, hi: np.ndarray, z: np.ndarray | None
                  ) -> tuple[float, float, float]:
    """MLE of y ~ N(a + b z, s^2) from intervals lo < y <= hi (lo = -inf, hi = inf for
    censoring; lo == hi an exact value). Returns (a, b, s); b = 0 without z."""
    exact = lo == hi
    mid = np.where(np.isfinite(lo) & np.isfinite(hi), 0.5 * (lo + hi),
                   np.where(np.isfinite(lo), lo, hi))
    X = np.ones((mid.size, 1)) if z is None else np.column_stack([np.ones(mid.size), z])
    coef, *_ = np.linalg.lstsq(X, mid, rcond=None)
    res = mid - X @ coef
    s0 = max(float(np.std(res)), 0.05)
    lo_f = np.where(np.isfinite(lo), lo, -1e300)
    hi_f = np.where(np.isfinite(hi), hi, 1e300)

    def nll(theta: np.ndarray) -> float:
        mu = X @ theta[:-1]
        s = math.exp(theta[-1])
        a = (lo_f - mu) / s
        b = (hi_f - mu) / s
        # log(Phi(b) - Phi(a)) stably: log Phi(b) + log1p(-exp(log Phi(a) - log Phi(b)))
        lb, la = log_ndtr(b), log_ndtr(a)
        upper = -np.expm1(la - lb)
        # the far tail side: use the mirror for b, a > 0
        lb2, la2 = log_ndtr(-a), log_ndtr(-b)
        mirror = a > 0
        val = np.where(mirror, lb2 + np.log(np.maximum(-np.expm1(la2 - lb2), 1e-300)),
                       lb + np.log(np.maximum(upper, 1e-300)))
        dens = -0.5 * ((mid - mu) / s) ** 2 - math.log(s) - 0.5 * math.log(2 * math.pi)
        return -float(np.sum(np.where(exact, dens, val)))

    best = minimize(nll, np.append(coef, math.log(s0)), method="Nelder-Mead",
                    options={"xatol": 1e-8, "fatol": 1e-10, "maxiter": 4000})
    th = best.x
    return float(th[0]), float(th[1]) if z is not None else 0.0, math.exp(float(th[-1]))


def _separated(lo: np.ndarray, hi: np.ndarray, z: np.ndarray | None) -> bool:
    """Whether one value a (a line a + b z) lies strictly inside every interval lo < y <=
    hi (-inf, inf: censored; lo == hi an exact value, never strictly inside): the
    interval likelihood then grows as the dispersion -> 0 (no finite MLE). A linear
    programme: the largest margin t <= 1 with lo + t <= a + b z <= hi - t; separated iff
    t > 0."""
    if np.any(lo >= hi):
        return False
    X = np.ones((lo.size, 1)) if z is None else np.column_stack([np.ones(lo.size), z])
    k = X.shape[1]
    rows, rhs = [], []
    for r in range(lo.size):  # -(X a) + t <= -lo ;  X a + t <= hi
        if np.isfinite(lo[r]):
            rows.append(np.append(-X[r], 1.0))
            rhs.append(-lo[r])
        if np.isfinite(hi[r]):
            rows.append(np.append(X[r], 1.0))
            rhs.append(hi[r])
    if not rows:
        return True
    c = np.zeros(k + 1)
    c[-1] = -1.0  # maximise t
    res = linprog(c, A_ub=np.array(rows), b_ub=np.array(rhs),
                  bounds=[(None, None)] * k + [(None, 1.0)], method="highs")
    return bool(res.status == 0 and -res.fun > 1e-12)


def im_efficiency(ds: xr.Dataset, *, state: str = "overturn") -> xr.Dataset:
    """The dispersion beta of ``state``'s fragility in every IM of a record-suite sweep
    (module docstring), one value per IM and per value of the other swept keys (lam, ...).

    ds: what ``rocksweep.run`` / ``rocksweep.open`` returns for a scene with
    ``ground.records`` (IMs read from its ``record_*`` variables). state: as
    ``fragility``'s ("overturn", "mode1", "mode2", "uplift", "theta:X", "slide:D").

    Returns a Dataset over (im, other dims): ``beta`` [-] (in ln of that IM),
    ``beta_scale`` (beta / n: in ln of the scale factor, comparable across IMs),
    ``im_median`` (the median capacity in that IM; NaN for regressions), ``slope`` (the
    regression's b, NaN otherwise), ``n_records``, ``n_censored`` (never reached the
    state), ``reason`` (module docstring: "ok", or "separated", "few_records",
    "no_failures" joined by ","; an ``AnalysisWarning`` says the non-ok ones); over
    (im,): ``units``, ``exponent`` n, ``method`` ("capacity", "regression" or
    "cloud-probit"). attrs: rocksweep_kind = "im_efficiency", state, stripe_im, reason
    (the points' verdict), reference.
    """
    if not isinstance(ds, xr.Dataset) or "outcome" not in ds.variables:
        raise EfficiencyError("im_efficiency needs a record-suite sweep (rocksweep.run or "
                              "rocksweep.open of a scene with ground.records)")
    out_da = ds["outcome"]
    if "record" not in out_da.dims:
        where = ds.encoding.get("source")  # the file it was opened from, if any
        raise EfficiencyError(f"{where + ': ' if where else ''}outcome has no 'record' "
                              "dimension: not a record-suite sweep (a scene with ground.records: a "
                              "list of record files, and ground.scale)")
    table = record_im_table(ds)
    if not table:
        raise EfficiencyError("the Dataset stores no per-record IMs (record_pga, ...)")
    stripe = ds.attrs.get("scale_im")
    stripe = str(stripe) if stripe and str(stripe) in out_da.dims else None
    if stripe is not None and ds.sizes[stripe] < 2:
        level = float(np.atleast_1d(ds[stripe].values)[0])
        raise EfficiencyError(f"one {stripe} stripe ({stripe} = {level:g}): a record's "
                              "capacity is only known to lie below or above it; IM "
                              "efficiency needs a suite of at least 2 stripes")
    others = [d for d in out_da.dims if d not in ("record", stripe)]
    order = [*others, "record"] + ([stripe] if stripe else [])
    reached = state_reached(ds, state)
    counted, _, _ = counted_points(ds)
    verdict = trust(ds, f"IM efficiency, state {state}")
    hit = (reached & counted).transpose(*order).values
    cnt = counted.transpose(*order).values
    if "scale_factor" in ds.variables:
        fac = ds["scale_factor"].broadcast_like(out_da).transpose(*order).values
    else:
        fac = np.ones(hit.shape)
    shape_o = tuple(ds.sizes[d] for d in others)
    n_o = int(np.prod(shape_o)) if shape_o else 1
    R = ds.sizes["record"]
    hit = hit.reshape((n_o, R) + hit.shape[len(others) + 1:])
    cnt = cnt.reshape(hit.shape)
    fac = fac.reshape(hit.shape)
    names = list(table)
    vals = {}
    frame = out_da.isel({stripe: 0}, drop=True) if stripe else out_da
    for name in names:  # (others, record): the dimensionless IMs vary with alpha, p
        v = table[name][0].broadcast_like(frame).transpose(*others, "record")
        vals[name] = np.asarray(v.values, np.float64).reshape(n_o, R)
    nI = len(names)
    res = {k: np.full((nI, n_o), np.nan) for k in ("beta", "beta_scale", "im_median",
                                                   "slope")}
    n_rec = np.zeros((nI, n_o), np.int64)
    n_cens = np.zeros((nI, n_o), np.int64)
    why = np.full((nI, n_o), "", dtype=object)  # the fits' own words (separated, ...)
    methods = []
    for name in names:
        n = table[name][2]
        methods.append("cloud-probit" if stripe is None else
                       "capacity" if n > 0 else "regression")
    for o in range(n_o):
        if stripe is None:  # a cloud: probit on ln(J F^n)
            _cloud_fits(o, names, table, vals, fac, cnt, hit, res, n_rec, why)
        else:
            _stripe_fits(o, np.asarray(ds[stripe].values, np.float64), names, table, vals,
                         fac, cnt, hit, res, n_rec, n_cens, why)
    reason = _reasons(why, n_rec, cnt.reshape(n_o, R, -1).any(-1).sum(-1))
    _warn(state, names, reason)
    return _dataset(ds, state, verdict, stripe, others, shape_o, names, table, methods,
                    res, n_rec, n_cens, reason)


def _reasons(why: np.ndarray, n_rec: np.ndarray, counted: np.ndarray) -> np.ndarray:
    """The verdict of every (IM, curve) (module docstring): the fit's own words, then
    "few_records" where fewer than MIN_RECORDS records are counted, "no_failures" where
    no record reached the state."""
    out = np.empty(why.shape, dtype=object)
    for idx in np.ndindex(*why.shape):
        words = [w for w in str(why[idx]).split(",") if w and w != "ok"]
        n = int(n_rec[idx]) or int(counted[idx[1]])
        if n < MIN_RECORDS and "few_records" not in words:
            words.append("few_records")
        out[idx] = ",".join(dict.fromkeys(words)) or "ok"
    return out


def _warn(state: str, names: list[str], reason: np.ndarray) -> None:
    """One ``AnalysisWarning`` naming the IMs each verdict word holds for."""
    by: dict[str, list[str]] = {}
    for i, name in enumerate(names):
        for w in dict.fromkeys(x for r in reason[i] for x in str(r).split(",")):
            if w != "ok":
                by.setdefault(w, []).append(name)
    if by:
        meaning = {"separated": "beta below the stripes' resolution",
                   "few_records": f"fewer than {MIN_RECORDS} records",
                   "no_failures": "no record reaches the state"}
        text = "; ".join(f"{w} ({', '.join(ims) if len(ims) < len(names) else 'every IM'}"
                         f": {meaning.get(w, w)})" for w, ims in by.items())
        warnings.warn(f"IM efficiency, state {state}: {text}; no ranking rests on those "
                      "betas", AnalysisWarning, stacklevel=3)


def _cloud_fits(o: int, names: list[str], table: dict, vals: dict, fac: np.ndarray,
                cnt: np.ndarray, hit: np.ndarray, res: dict, n_rec: np.ndarray,
                why: np.ndarray) -> None:
    """A cloud's curve o: a probit on ln(J F^n) per IM (in ``res``, ``n_rec``; the
    probit's own verdict in ``why``)."""
    for i, name in enumerate(names):
        n = table[name][2]
        x = vals[name][o] * fac[o] ** n
        use = cnt[o] & np.isfinite(x) & (x > 0)
        if use.sum() < 2:
            continue
        fit = fit_cloud(x[use], hit[o][use])
        med, beta = fit[:2]  # (median, beta)
        why[i, o] = ",".join(w for w in fit.reason.split(",")
                             if w in ("separated", "no_failures", "all_failed",
                                      "beta_undetermined"))
        res["beta"][i, o] = beta
        res["beta_scale"][i, o] = beta / max(n, 1)
        res["im_median"][i, o] = med
        n_rec[i, o] = int(use.sum())


def _stripe_fits(o: int, levels: np.ndarray, names: list[str], table: dict, vals: dict,
                 fac: np.ndarray, cnt: np.ndarray, hit: np.ndarray, res: dict,
                 n_rec: np.ndarray, n_cens: np.ndarray, why: np.ndarray) -> None:
    """Stripes' curve o: each record's capacity bracketed between two stripes, fitted per
    IM by interval-censored maximum likelihood (in ``res``, ``n_rec``, ``n_cens``;
    "separated" in ``why`` where the intervals leave beta undetermined: NaN)."""
    h, c, f = hit[o], cnt[o], fac[o]
    first = np.where(h.any(-1), np.argmax(h, -1), -1)
    keep = c.any(-1)
    # the interval of the scale factor at capacity: (F at the stripe below, F at it]
    f_hi = np.where(first >= 0, np.take_along_axis(f, np.maximum(first, 0)[:, None],
                                                   1)[:, 0], np.inf)
    below = np.maximum(first - 1, 0)
    f_lo = np.where(first > 0, np.take_along_axis(f, below[:, None], 1)[:, 0],
                    np.where(first == 0, 0.0, f[:, -1]))
    x_hi = np.where(first >= 0, levels[np.maximum(first, 0)], np.inf)
    x_lo = np.where(first > 0, levels[below], np.where(first == 0, 0.0, levels[-1]))
    with np.errstate(divide="ignore"):
        lnf_lo, lnf_hi = np.log(f_lo[keep]), np.log(f_hi[keep])
        lnx_lo, lnx_hi = np.log(x_lo[keep]), np.log(x_hi[keep])
    if not np.isfinite(lnf_hi).any():  # nothing reaches the state
        why[:, o] = "no_failures"
        n_rec[:, o] = int(keep.sum())
        n_cens[:, o] = int(keep.sum())
        return
    for i, name in enumerate(names):
        n = table[name][2]
        J = vals[name][o][keep]
        ok = np.isfinite(J) & (J > 0)
        if ok.sum() < 3:
            continue
        lnJ = np.log(J[ok])
        lo, hi, z = ((n * lnf_lo[ok] + lnJ, n * lnf_hi[ok] + lnJ, None) if n > 0 else
                     (lnx_lo[ok], lnx_hi[ok], lnJ))
        a, b, s = _interval_mle(lo, hi, z)
        if _separated(lo, hi, z):  # the likelihood grows as s -> 0: beta unresolved
            why[i, o] = "separated"
        if n > 0:
            res["im_median"][i, o] = math.exp(a)
            res["beta"][i, o] = s
            res["beta_scale"][i, o] = s / n
        else:
            res["beta"][i, o] = s
            res["beta_scale"][i, o] = s
            res["slope"][i, o] = b
        n_rec[i, o] = int(ok.sum())
        n_cens[i, o] = int((~np.isfinite(lnf_hi[ok])).sum())


def _dataset(ds: xr.Dataset, state: str, verdict: Any, stripe: str | None,
             others: list[str], shape_o: tuple[int, ...], names: list[str], table: dict,
             methods: list[str], res: dict, n_rec: np.ndarray, n_cens: np.ndarray,
             reason: np.ndarray) -> xr.Dataset:
    """``im_efficiency``'s Dataset (its docstring)."""
    nI = len(names)
    dims = ["im", *others]

    def shaped(a: np.ndarray) -> np.ndarray:
        return a.reshape((nI,) + shape_o)

    coords: dict[str, Any] = {d: ds[d] for d in others if d in ds.coords}
    coords["im"] = ("im", np.array(names, dtype=str))
    data = {
        "beta": (dims, shaped(res["beta"]), {"units": "1", "long_name": "lognormal "
                                             "dispersion of the state's fragility in the IM"}),
        "beta_scale": (dims, shaped(res["beta_scale"]),
                       {"units": "1", "long_name": "beta / exponent: in ln(scale factor), "
                        "comparable across IMs (lower: more efficient)"}),
        "im_median": (dims, shaped(res["im_median"]), {"long_name": "median capacity in "
                                                       "the IM (units: variable units)"}),
        "slope": (dims, shaped(res["slope"]), {"long_name": "regression slope of ln "
                                               "capacity on ln IM (scale-invariant IMs)"}),
        "n_records": (dims, shaped(n_rec)),
        "n_censored": (dims, shaped(n_cens), {"long_name": "records that never reach the "
                                              "state (right-censored)"}),
        "reason": (dims, shaped(reason.astype(str)),
                   {"long_name": "verdict: ok, or separated, few_records, no_failures "
                                 "joined by ','"}),
        "units": (("im",), np.array([table[k][1] for k in names], dtype=str)),
        "exponent": (("im",), np.array([table[k][2] for k in names], np.int64),
                     {"long_name": "the IM of a record scaled by F is F^exponent times it"}),
        "method": (("im",), np.array(methods, dtype=str)),
    }
    attrs = {KIND_ATTR: IM_EFFICIENCY, "state": str(state), "reason": verdict,
             "stripe_im": stripe or "none",
             "reference": "Luco & Cornell (2007), Structural seismic demand analysis: "
                          "consideration of near-fault ground motions, Earthquake Spectra "
                          "23(2); Baker (2015), Earthquake Spectra 31(1)"}
    if "title" in ds.attrs:
        attrs["title"] = str(ds.attrs["title"])
    if "record_avgsa" in ds.variables and "avgsa_periods" in ds["record_avgsa"].attrs:
        attrs["avgsa_periods"] = [float(v) for v in ds["record_avgsa"].attrs["avgsa_periods"]]
    return xr.Dataset(data, coords=coords, attrs=attrs)
