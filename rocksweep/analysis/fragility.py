"""Lognormal fragility of a record suite: P(state | IM = x) = Phi(ln(x / median) / beta).

Reference: J. W. Baker (2015), "Efficient analytical fragility function fitting using
dynamic structural analysis", Earthquake Spectra 31(1), 579-599.

Fits (one likelihood for both):

- Stripes (multiple stripe analysis: every record scaled to each IM level x_j): k_j of the
  n_j records counted at x_j reach the state; the likelihood is the product of binomials
  prod_j C(n_j, k_j) p_j^k_j (1 - p_j)^(n_j - k_j), p_j = Phi(ln(x_j / median) / beta)
  (Baker 2015, eq. 11), n_j may differ between stripes (excluded points).
- Clouds (records unscaled, or scaled by one factor each): each record i is a stripe of
  one, (x_i, 0/1): probit regression on ln IM, the same likelihood with n_i = 1.

The log-likelihood is evaluated with log Phi (``scipy.special.log_ndtr``) for p and for
1 - p, so a stripe with k = 0 or k = n never meets log 0 (the guard that clipping p to
[eps, 1 - eps] gives, without the bias clipping adds). It is maximised over (a, b) of
Phi(a + b ln x), the probit generalised linear model on ln IM, by Fisher scoring with step
halving: that log-likelihood is concave, so the maximum is unique when it exists, and by
the invariance of maximum likelihood it gives the MLE of (ln median, ln beta): median =
exp(-a / b), beta = 1 / b (the tests check it against a direct optimisation over ln median
and ln beta). The scoring is vectorised over bootstrap resamples.

Degenerate data (no finite MLE), answered without an exception, with a ``reason``:

- "no_failures": no counted point reaches the state: median = NaN, beta = NaN (the median
  lies beyond the largest IM; nothing can be said about beta);
- "all_failed": every counted point reaches it: median = NaN, beta = NaN;
- "separated": every point that reaches the state has a larger IM than every one that
  does not (a step; at most one stripe holds both): the likelihood grows as beta -> 0, so
  beta = 0 and median = the geometric mean of the largest safe and the smallest failing IM
  (that stripe itself when one stripe holds both);
- "decreasing": the best probit slope is <= 0 (fewer failures at larger IM): NaN, NaN;
- "no_data": nothing counted: NaN, NaN;
- "ok": a finite MLE.

Bootstrap: records are resampled with replacement (a seeded ``numpy.random.Generator``),
the fit repeated on every resample, and the percentile interval of median and beta
reported; resamples without a finite answer (no_failures, ...) are left out and counted.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr
from scipy.special import log_ndtr, ndtr, ndtri

from rocksweep.errors import FragilityError  # noqa: F401 (defined there; re-exported)
from rocksweep.kernel import layout as L
from rocksweep.vocab.ground import CLOUD_IMS as CLOUD_IM_VARIABLES
from rocksweep.vocab.ground import SCALE_IMS
from rocksweep.vocab.outcomes import STATES, THETA_STATE

__all__ = ["Bootstrap", "Fit", "FragilityError", "STRIPE_IMS", "bootstrap_records",
           "curves_json", "fit_cloud", "fit_stripes", "fragility", "parse_state"]

#: stripe dimension names (the sweep's ``scale_im``) and their units
STRIPE_IMS = SCALE_IMS
#: cloud IMs and the per-record variables they come from
CLOUD_IMS = {im: (var, SCALE_IMS[im]) for im, var in CLOUD_IM_VARIABLES.items()}
REASONS = ("ok", "no_failures", "all_failed", "separated", "decreasing", "no_data")
BAND_POINTS = 101



class Fit(tuple):
    """(median, beta) of one fit, unpacks as a pair; ``.reason`` says how it was found.

    median: the IM at P = 0.5 [the IM's units]; beta: the lognormal standard deviation [-].
    """

    reason: str

    def __new__(cls, median: float, beta: float, reason: str = "ok") -> Fit:
        obj = super().__new__(cls, (float(median), float(beta)))
        obj.reason = reason
        return obj

    @property
    def median(self) -> float:
        return self[0]

    @property
    def beta(self) -> float:
        return self[1]

    def __repr__(self) -> str:
        return f"Fit(median={self[0]!r}, beta={self[1]!r}, reason={self.reason!r})"


# ---------------------------------------------------------------------------------------
# the likelihood and its maximisation (batched)
# ---------------------------------------------------------------------------------------


def _loglik(eta: np.ndarray, k: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Sum over the last axis of k log Phi(eta) + (n - k) log Phi(-eta)."""
    return np.sum(k * log_ndtr(eta) + (n - k) * log_ndtr(-eta), axis=-1)


def _mle_batch(lnx: np.ndarray, k: np.ndarray, n: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MLE of the lognormal fragility for a batch of data sets.

    lnx, k, n: float64 (B, S): ln IM, points reaching the state, points counted (n = 0: the
    entry is absent). Returns (median (B,), beta (B,), reason index (B,) into REASONS).
    """
    lnx, k, n = (np.atleast_2d(np.asarray(v, dtype=np.float64)) for v in (lnx, k, n))
    B = lnx.shape[0]
    median = np.full(B, np.nan)
    beta = np.full(B, np.nan)
    reason = np.zeros(B, dtype=np.int64)
    has = n > 0
    fails = has & (k > 0)
    safes = has & (n - k > 0)
    nk, ns = fails.any(-1), safes.any(-1)
    reason[~nk] = REASONS.index("no_failures")
    reason[nk & ~ns] = REASONS.index("all_failed")
    reason[~has.any(-1)] = REASONS.index("no_data")
    both = nk & ns
    x_safe_max = np.where(safes, lnx, -np.inf).max(-1)
    x_fail_min = np.where(fails, lnx, np.inf).min(-1)
    sep = both & (x_fail_min >= x_safe_max)
    reason[sep] = REASONS.index("separated")
    median[sep] = np.exp(0.5 * (x_fail_min[sep] + x_safe_max[sep]))
    beta[sep] = 0.0
    todo = both & ~sep
    if np.any(todo):
        a, b = _score(lnx[todo], k[todo], n[todo])
        med, bet, rsn = np.full(a.size, np.nan), np.full(a.size, np.nan), np.zeros(a.size, int)
        up = b > 0.0
        med[up] = np.exp(-a[up] / b[up])
        bet[up] = 1.0 / b[up]
        rsn[~up] = REASONS.index("decreasing")
        median[todo], beta[todo], reason[todo] = med, bet, rsn
    return median, beta, reason


def _score(lnx: np.ndarray, k: np.ndarray, n: np.ndarray, iters: int = 200,
           tol: float = 1e-10) -> tuple[np.ndarray, np.ndarray]:
    """Fisher scoring with step halving for Phi(a + b lnx), batched over rows (each row
    has points on both sides: the maximum exists). Returns (a, b) per row."""
    # standardise ln x per row for conditioning: eta = c0 + c1 z, z = (lnx - m) / s
    w = n / n.sum(-1, keepdims=True)
    m = np.sum(w * lnx, -1, keepdims=True)
    s = np.sqrt(np.sum(w * (lnx - m) ** 2, -1, keepdims=True))
    s = np.where(s > 0.0, s, 1.0)
    z = (lnx - m) / s
    frac = np.clip(k.sum(-1) / n.sum(-1), 1e-6, 1.0 - 1e-6)
    c = np.stack([ndtri(frac), np.zeros(frac.size)], axis=-1)  # (B, 2)
    eta = c[:, :1] + c[:, 1:] * z
    ll = _loglik(eta, k, n)
    active = np.ones(frac.size, dtype=bool)
    for _ in range(iters):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        e, zz, kk, nn = eta[idx], z[idx], k[idx], n[idx]
        logphi = -0.5 * e * e - 0.5 * math.log(2.0 * math.pi)
        r1 = np.exp(logphi - log_ndtr(e))  # phi / Phi(eta)
        r2 = np.exp(logphi - log_ndtr(-e))  # phi / Phi(-eta)
        g = kk * r1 - (nn - kk) * r2  # d loglik / d eta
        wgt = nn * r1 * r2  # expected information per unit of eta
        U0, U1 = g.sum(-1), (g * zz).sum(-1)
        I00, I01, I11 = wgt.sum(-1), (wgt * zz).sum(-1), (wgt * zz * zz).sum(-1)
        det = I00 * I11 - I01 * I01
        det = np.where(det > 0.0, det, np.finfo(float).tiny)
        d0 = (I11 * U0 - I01 * U1) / det
        d1 = (I00 * U1 - I01 * U0) / det
        step = np.ones(idx.size)
        ll0 = ll[idx]
        c_new = c[idx].copy()
        ll_new = ll0.copy()
        pending = np.ones(idx.size, dtype=bool)
        for _half in range(60):
            cand = c[idx][pending] + step[pending, None] * np.stack(
                [d0[pending], d1[pending]], -1)
            ecand = cand[:, :1] + cand[:, 1:] * zz[pending]
            lc = _loglik(ecand, kk[pending], nn[pending])
            ok = lc >= ll0[pending] - 1e-12 * np.abs(ll0[pending])
            pi = np.flatnonzero(pending)
            c_new[pi[ok]] = cand[ok]
            ll_new[pi[ok]] = lc[ok]
            step[pi[~ok]] *= 0.5
            pending[pi[ok]] = False
            if not pending.any():
                break
        delta = np.abs(c_new - c[idx]).max(-1)
        c[idx] = c_new
        eta[idx] = c_new[:, :1] + c_new[:, 1:] * zz
        ll[idx] = ll_new
        active[idx[(delta < tol * (1.0 + np.abs(c_new).max(-1))) | pending]] = False
    a = c[:, 0] - c[:, 1] * m[:, 0] / s[:, 0]
    b = c[:, 1] / s[:, 0]
    return a, b


def _fit_one(lnx, k, n) -> Fit:
    med, bet, rsn = _mle_batch(lnx[None, :], k[None, :], n[None, :])
    return Fit(med[0], bet[0], REASONS[int(rsn[0])])


def fit_stripes(im: Sequence[float] | np.ndarray, n_fail: Sequence[int] | np.ndarray,
                n_total: Sequence[int] | np.ndarray) -> Fit:
    """Maximum-likelihood lognormal fragility from stripes (Baker 2015, eq. 11).

    im: float[S] IM level of each stripe (> 0, any units; repeated levels allowed);
    n_fail: int[S] records that reach the state at that level; n_total: int[S] records
    counted there (may differ between stripes; 0 drops the stripe). Returns a ``Fit``
    (median [units of im], beta [-]) with ``.reason`` (module docstring: degenerate data
    give NaN or beta = 0 with a reason, never an exception for valid counts).
    """
    x = np.asarray(im, dtype=np.float64).ravel()
    k = np.asarray(n_fail, dtype=np.float64).ravel()
    n = np.asarray(n_total, dtype=np.float64).ravel()
    if not (x.size == k.size == n.size):
        raise FragilityError(f"im, n_fail, n_total: lengths {x.size}, {k.size}, {n.size} "
                             "differ")
    if np.any(~np.isfinite(x) | (x <= 0.0)):
        raise FragilityError("im: every IM level must be finite and > 0")
    if np.any((k < 0) | (n < 0) | (k > n)) or np.any(~np.isfinite(k) | ~np.isfinite(n)):
        raise FragilityError("counts: need 0 <= n_fail <= n_total at every stripe")
    return _fit_one(np.log(x), k, n)


def fit_cloud(im: Sequence[float] | np.ndarray, failed: Sequence[bool] | np.ndarray) -> Fit:
    """Maximum-likelihood lognormal fragility from a cloud: probit regression of the 0/1
    outcomes ``failed`` (bool[R]) on ln ``im`` (float[R] > 0, one IM per record). Returns
    a ``Fit`` (median [units of im], beta [-]) with ``.reason``."""
    x = np.asarray(im, dtype=np.float64).ravel()
    f = np.asarray(failed).ravel().astype(bool)
    if x.size != f.size:
        raise FragilityError(f"im, failed: lengths {x.size}, {f.size} differ")
    if np.any(~np.isfinite(x) | (x <= 0.0)):
        raise FragilityError("im: every IM must be finite and > 0")
    return _fit_one(np.log(x), f.astype(np.float64), np.ones(x.size))


# ---------------------------------------------------------------------------------------
# bootstrap over records
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Bootstrap:
    """Bootstrap over records: median_ci, beta_ci: (lo, hi) percentile intervals at level
    ``ci``; medians, betas: float[N] of the resamples (NaN where a resample has no finite
    answer); n_undefined: how many resamples those are."""

    median_ci: tuple[float, float]
    beta_ci: tuple[float, float]
    medians: np.ndarray
    betas: np.ndarray
    n_undefined: int
    ci: float


def _resample_indices(n_records: int, n_boot: int, seed: int | np.random.Generator
                      ) -> np.ndarray:
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    return rng.integers(0, n_records, size=(n_boot, n_records))


def _boot_fits(im: np.ndarray, failed: np.ndarray, counted: np.ndarray, idx: np.ndarray,
               cloud: bool) -> tuple[np.ndarray, np.ndarray]:
    """(medians, betas) float[N] over resamples idx (N, R). Stripes: im (S,), failed and
    counted bool (R, S); cloud: im (R,), failed and counted bool (R,)."""
    if idx.shape[0] == 0:
        return np.empty(0), np.empty(0)
    if cloud:
        lnx = np.log(np.where(counted, im, 1.0))[idx]
        k = (failed & counted).astype(np.float64)[idx]
        n = counted.astype(np.float64)[idx]
    else:
        kf = (failed & counted).astype(np.float64)
        nf = counted.astype(np.float64)
        k = kf[idx].sum(1)  # (N, S)
        n = nf[idx].sum(1)
        lnx = np.broadcast_to(np.log(im), k.shape)
    med, bet, _ = _mle_batch(lnx, k, n)
    return med, bet


def _interval(v: np.ndarray, ci: float) -> tuple[float, float]:
    v = v[np.isfinite(v)]
    if v.size == 0:
        return math.nan, math.nan
    q = 100.0 * np.array([(1.0 - ci) / 2.0, (1.0 + ci) / 2.0])
    lo, hi = np.percentile(v, q)
    return float(lo), float(hi)


def bootstrap_records(im: Sequence[float] | np.ndarray, failed: np.ndarray,
                      counted: np.ndarray | None = None, *, n_boot: int = 200,
                      seed: int | np.random.Generator = 0, ci: float = 0.9) -> Bootstrap:
    """Bootstrap the fragility fit over records.

    Stripes: im float[S] (levels), failed bool[R, S] (record r reaches the state at level
    s), counted bool[R, S] (the point is counted; default all). Cloud: im float[R] (one IM
    per record), failed bool[R], counted bool[R]. Each of ``n_boot`` resamples draws R
    records with replacement (``numpy.random.default_rng(seed)``), refits, and the
    ``ci`` percentile intervals of median and beta are returned in a ``Bootstrap``.
    """
    x = np.asarray(im, dtype=np.float64)
    f = np.asarray(failed).astype(bool)
    c = np.ones_like(f) if counted is None else np.asarray(counted).astype(bool)
    if not (0.0 < ci < 1.0):
        raise FragilityError(f"ci = {ci!r}: must be in (0, 1)")
    cloud = f.ndim == 1
    if cloud and not (x.shape == f.shape == c.shape):
        raise FragilityError("cloud: im, failed, counted must have one value per record")
    if not cloud and (f.shape != c.shape or f.shape[1:] != x.shape):
        raise FragilityError("stripes: failed and counted must be (records, stripes)")
    idx = _resample_indices(f.shape[0], int(n_boot), seed)
    med, bet = _boot_fits(x, f, c, idx, cloud)
    undefined = ~(np.isfinite(med) & np.isfinite(bet))
    med, bet = np.where(undefined, np.nan, med), np.where(undefined, np.nan, bet)
    return Bootstrap(_interval(med, ci), _interval(bet, ci), med, bet, int(undefined.sum()),
                     ci)


# ---------------------------------------------------------------------------------------
# states
# ---------------------------------------------------------------------------------------


def parse_state(state: str) -> tuple[str, float]:
    """("overturn" | "mode1" | "mode2" | "uplift" | "theta", threshold) of a state word;
    "theta:X" is max|theta|/alpha_cg >= X (X > 0) or overturned."""
    s = str(state).strip()
    if s in STATES:
        return s, math.nan
    if s.startswith("theta:"):
        try:
            x = float(s[6:])
        except ValueError:
            x = math.nan
        if math.isfinite(x) and x > 0.0:
            return "theta", x
        raise FragilityError(f"state {state!r}: theta:X needs a number X > 0 "
                             "(max|theta|/alpha_cg)")
    raise FragilityError(f"state {state!r}: expected {', '.join(STATES)} or {THETA_STATE}")


def _need(ds: xr.Dataset, name: str, why: str) -> xr.DataArray:
    if name not in ds.variables:
        raise FragilityError(f"the Dataset has no variable {name!r} ({why})")
    return ds[name]


def state_reached(ds: xr.Dataset, state: str) -> xr.DataArray:
    """bool DataArray (the outcome's dims): the point reaches ``state`` (``parse_state``)."""
    kind, x = parse_state(state)
    out = _need(ds, "outcome", "outcome codes")
    over = (out == L.OUTCOME_MODE1) | (out == L.OUTCOME_MODE2)
    if kind == "overturn":
        return over
    if kind == "mode1":
        return out == L.OUTCOME_MODE1
    if kind == "mode2":
        return out == L.OUTCOME_MODE2
    if kind == "uplift":
        return (_need(ds, "uplifts", f"state {state}") > 0) | over
    return (_need(ds, "theta_max_over_alpha", f"state {state}") >= x) | over


def counted_points(ds: xr.Dataset) -> tuple[xr.DataArray, xr.DataArray, xr.DataArray]:
    """(counted, flagged, not_run) bool DataArrays: flagged = status &
    ``kernel.layout.STATUS_FLAGGED`` (horizon, step cap, event cap, non-finite: the one
    definition of a flagged point, as ``rocksweep.fields`` documents it), not_run = outcome
    -1 and not flagged; counted = neither."""
    out = _need(ds, "outcome", "outcome codes")
    status = _need(ds, "status", "status bit flags: flagged points are excluded")
    flagged = (status.astype(np.int64) & int(L.STATUS_FLAGGED)) != 0
    not_run = (out == L.OUTCOME_NOT_RUN) & ~flagged
    return ~flagged & ~not_run, flagged, not_run


# ---------------------------------------------------------------------------------------
# the Dataset front end
# ---------------------------------------------------------------------------------------


def _cloud_im(ds: xr.Dataset, im: str | None, period: float | None
              ) -> tuple[np.ndarray, str, str, float]:
    name = "PGA" if im is None else str(im)
    if name not in CLOUD_IMS:
        raise FragilityError(f"im = {im!r}: a cloud (no stripe dimension) takes one of "
                             f"{', '.join(CLOUD_IMS)}")
    var, unit = CLOUD_IMS[name]
    da = _need(ds, var, f"the per-record {name} of a cloud")
    per = math.nan
    if name == "Sa":
        if "period" not in da.dims:
            raise FragilityError(f"{var} has no 'period' dimension")
        periods = np.asarray(da["period"].values, dtype=np.float64)
        if period is None:
            if periods.size != 1:
                raise FragilityError(f"im = 'Sa' needs period= (one of "
                                     f"{', '.join(f'{p:g}' for p in periods)} s)")
            period = float(periods[0])
        hit = np.flatnonzero(np.isclose(periods, float(period), rtol=1e-9, atol=0.0))
        if hit.size == 0:
            raise FragilityError(f"period = {period!r}: {var} holds periods "
                                 f"{', '.join(f'{p:g}' for p in periods)} s")
        da = da.isel(period=int(hit[0]))
        per = float(periods[hit[0]])
    if set(da.dims) != {"record"}:
        raise FragilityError(f"{var} must lie along 'record' only, has {da.dims}")
    x = np.asarray(da.transpose("record").values, dtype=np.float64)
    if "scale_factor" in ds.variables:
        x = x * np.asarray(ds["scale_factor"].transpose("record").values, dtype=np.float64)
    if np.any(~np.isfinite(x) | (x <= 0.0)):
        bad = ds["record"].values[~np.isfinite(x) | (x <= 0.0)][0]
        raise FragilityError(f"record {bad}: {name} must be finite and > 0 for a cloud fit")
    return x, name, unit, per


def fragility(ds: xr.Dataset, *, state: str | Sequence[str] = "overturn",
              im: str | None = None, period: float | None = None, bootstrap: int = 0,
              seed: int = 0, ci: float = 0.9) -> xr.Dataset:
    """Lognormal fragility curves of a record-suite sweep (Baker 2015).

    ds (the sweep's contract): variables ``outcome`` (int8: -1 not computed, 0 safe, 1
    mode 1, 2 mode 2), ``status`` (int32 bit flags; points with status &
    STATUS_FLAGGED are excluded and counted), ``uplifts`` (int32; state "uplift"),
    ``theta_max_over_alpha`` (float64; states "theta:X"); dimension ``record`` (coordinate:
    unique file names); for stripes one dimension named by ``ds.attrs["scale_im"]`` (PGA
    [g], PGV [m/s], Sa [g], PGA_ratio, PGV_ratio [-]) whose coordinate holds the levels;
    any other dims (lam, p, body keys): one curve per combination. Without a stripe
    dimension (a cloud) the IM per record is ``record_pga`` [g], ``record_pgv`` [m/s] or
    ``record_sa`` (record, period) [g] (``im=`` "PGA" (default), "PGV", "Sa" with
    ``period=`` [s]), times ``scale_factor`` (record) if present.

    state: one state word or a list (then a ``state`` dimension): "overturn" (outcome 1 or
    2), "mode1", "mode2", "uplift" (uplifts > 0 or overturned), "theta:X"
    (theta_max_over_alpha >= X or overturned). bootstrap: number of resamples over records
    (0: no intervals, NaN); seed: the Generator's seed; ci: the interval's level.

    Returns a Dataset over (state,) + other dims: ``median`` [IM units], ``beta`` [-],
    ``median_lo``, ``median_hi``, ``beta_lo``, ``beta_hi`` (bootstrap percentile interval),
    ``n_records`` (records with a counted point), ``n_excluded`` (flagged points left
    out), ``n_not_run`` (outcome -1 points left out), ``n_boot_undefined``, ``reason``
    (str, ``REASONS``); ``band_lo``, ``band_hi`` over ``im_grid`` (pointwise bootstrap
    percentiles of the curve, NaN without bootstrap); stripes also: ``fraction``,
    ``n_failed`` over (state, others, stripe) and ``n_counted`` over (others, stripe), and
    per record ``first_level`` (smallest level that reaches the state; NaN if none) and
    ``resurrection`` (a higher counted level does not reach it) over (state, others,
    record). attrs: method ("stripes-mle" | "cloud-mle"), im, im_units, period (Sa),
    states, bootstrap, seed, ci, reference.
    """
    states = [state] if isinstance(state, str) else list(state)
    if not states:
        raise FragilityError("state: give at least one state")
    for s in states:
        parse_state(s)
    if len(set(states)) != len(states):
        raise FragilityError(f"state: {states} lists a state twice")
    if not (0.0 < ci < 1.0):
        raise FragilityError(f"ci = {ci!r}: must be in (0, 1)")
    if int(bootstrap) < 0:
        raise FragilityError(f"bootstrap = {bootstrap!r}: must be >= 0")
    out_da = _need(ds, "outcome", "outcome codes")
    if "record" not in out_da.dims:
        raise FragilityError("outcome has no 'record' dimension: not a record-suite sweep")
    names = [str(r) for r in ds["record"].values]
    if len(set(names)) != len(names):
        raise FragilityError("record: the coordinate lists a record twice")
    scale_im = ds.attrs.get("scale_im")
    stripe = str(scale_im) if scale_im is not None and str(scale_im) in out_da.dims else None
    if scale_im not in (None, "", "none") and stripe is None:
        raise FragilityError(f"scale_im = {scale_im!r} but outcome has no such dimension")
    if stripe is not None:
        if stripe not in STRIPE_IMS:
            raise FragilityError(f"scale_im = {stripe!r}: one of {', '.join(STRIPE_IMS)}")
        if im is not None and str(im) != stripe:
            raise FragilityError(f"im = {im!r}: the stripes are levels of {stripe}; a "
                                 "stripe fit uses that IM")
        levels = np.asarray(ds[stripe].values, dtype=np.float64)
        if np.any(~np.isfinite(levels) | (levels <= 0.0)):
            raise FragilityError(f"{stripe}: every stripe level must be finite and > 0")
        im_name, unit, per = stripe, STRIPE_IMS[stripe], math.nan
        if stripe == "Sa":
            per = float(ds.attrs.get("scale_period", math.nan))
        method = "stripes-mle"
    else:
        rec_im, im_name, unit, per = _cloud_im(ds, im, period)
        method = "cloud-mle"
    others = [d for d in out_da.dims if d not in ("record", stripe)]
    order = others + ["record"] + ([stripe] if stripe else [])
    counted, flagged, not_run = counted_points(ds)
    counted = counted.transpose(*order).values
    n_flag = flagged.transpose(*order).values
    n_nrun = not_run.transpose(*order).values
    hits = np.stack([state_reached(ds, s).transpose(*order).values for s in states])
    shape_o = tuple(ds.sizes[d] for d in others)
    n_o = int(np.prod(shape_o)) if shape_o else 1
    R = ds.sizes["record"]
    tail = (R, ds.sizes[stripe]) if stripe else (R,)
    counted = counted.reshape((n_o,) + tail)
    n_flag = n_flag.reshape((n_o,) + tail)
    n_nrun = n_nrun.reshape((n_o,) + tail)
    hits = hits.reshape((len(states), n_o) + tail)

    if stripe:
        grid = np.geomspace(levels.min() / 2.0, levels.max() * 1.5, BAND_POINTS)
    else:
        grid = np.geomspace(rec_im.min() / 2.0, rec_im.max() * 1.5, BAND_POINTS)
    idx = _resample_indices(R, int(bootstrap), seed)
    nS = len(states)
    res = {v: np.full((nS, n_o), np.nan) for v in
           ("median", "beta", "median_lo", "median_hi", "beta_lo", "beta_hi")}
    reason = np.empty((nS, n_o), dtype=object)
    n_undef = np.zeros((nS, n_o), dtype=np.int64)
    band = np.full((2, nS, n_o, grid.size), np.nan)
    n_records = counted.reshape(n_o, R, -1).any(-1).sum(-1)
    for si in range(nS):
        for o in range(n_o):
            c, h = counted[o], hits[si, o] & counted[o]
            if stripe:
                fit = _fit_one(np.log(levels), h.sum(0).astype(float),
                               c.sum(0).astype(float))
            else:
                fit = _fit_one(np.log(np.where(c, rec_im, 1.0)), h.astype(float),
                               c.astype(float))
            res["median"][si, o], res["beta"][si, o] = fit
            reason[si, o] = fit.reason
            if bootstrap:
                med, bet = _boot_fits(levels if stripe else rec_im, h, c, idx, not stripe)
                bad = ~(np.isfinite(med) & np.isfinite(bet))
                n_undef[si, o] = int(bad.sum())
                med, bet = med[~bad], bet[~bad]
                (res["median_lo"][si, o], res["median_hi"][si, o]) = _interval(med, ci)
                (res["beta_lo"][si, o], res["beta_hi"][si, o]) = _interval(bet, ci)
                if med.size:
                    curves = lognormal_cdf(grid[None, :], med[:, None], bet[:, None])
                    q = 100.0 * np.array([(1.0 - ci) / 2.0, (1.0 + ci) / 2.0])
                    band[:, si, o] = np.percentile(curves, q, axis=0)

    # assemble
    lead = ["state"] if not isinstance(state, str) else []
    dims_c = lead + others

    def shaped(a: np.ndarray, extra: tuple[int, ...] = ()) -> np.ndarray:
        a = a.reshape((nS,) + shape_o + extra)
        return a if lead else a[0]

    coords: dict[str, Any] = {d: ds[d] for d in others if d in ds.coords}
    if lead:
        coords["state"] = ("state", np.array(states, dtype=str))
    else:
        coords["state"] = ((), states[0])
    coords["im_grid"] = ("im_grid", grid, {"units": unit, "long_name": f"{im_name} grid"})
    data: dict[str, Any] = {}
    data["median"] = (dims_c, shaped(res["median"]),
                      {"units": unit, "long_name": f"median {im_name} of the fragility"})
    data["beta"] = (dims_c, shaped(res["beta"]),
                    {"units": "1", "long_name": "lognormal standard deviation"})
    for v in ("median_lo", "median_hi", "beta_lo", "beta_hi"):
        data[v] = (dims_c, shaped(res[v]),
                   {"units": unit if v.startswith("median") else "1",
                    "long_name": f"bootstrap {ci:g} percentile interval bound"})
    data["reason"] = (dims_c, shaped(reason.astype(str)),
                      {"long_name": "how the fit ended: " + ", ".join(REASONS)})
    data["n_boot_undefined"] = (dims_c, shaped(n_undef),
                                {"long_name": "bootstrap resamples without a finite fit"})
    data["n_records"] = (others, n_records.reshape(shape_o).astype(np.int64),
                         {"long_name": "records with at least one counted point"})
    data["n_excluded"] = (others, n_flag.reshape(n_o, -1).sum(-1).reshape(shape_o),
                          {"long_name": "flagged points (status & STATUS_FLAGGED) left out"})
    data["n_not_run"] = (others, n_nrun.reshape(n_o, -1).sum(-1).reshape(shape_o),
                         {"long_name": "points not computed (outcome -1) left out"})
    data["band_lo"] = (dims_c + ["im_grid"], shaped(band[0], (grid.size,)),
                       {"long_name": f"bootstrap {ci:g} band, lower (pointwise)"})
    data["band_hi"] = (dims_c + ["im_grid"], shaped(band[1], (grid.size,)),
                       {"long_name": f"bootstrap {ci:g} band, upper (pointwise)"})
    if stripe:
        coords[stripe] = ds[stripe]
        coords["record"] = ds["record"]
        k = (hits & counted[None]).sum(2)  # (nS, n_o, S)
        n = counted.sum(1)  # (n_o, S)
        frac = np.where(n[None] > 0, k / np.maximum(n[None], 1), np.nan)
        S = levels.size
        data["fraction"] = (dims_c + [stripe], shaped(frac, (S,)),
                            {"long_name": "fraction of counted records reaching the state"})
        data["n_failed"] = (dims_c + [stripe], shaped(k, (S,)))
        data["n_counted"] = (others + [stripe], n.reshape(shape_o + (S,)))
        reach = hits & counted[None]  # (nS, n_o, R, S)
        lev = np.broadcast_to(levels, reach.shape)
        first = np.where(reach, lev, np.inf).min(-1)
        safe_above = (counted[None] & ~hits) & (lev > first[..., None])
        first = np.where(np.isfinite(first), first, np.nan)
        data["first_level"] = (dims_c + ["record"], shaped(first, (R,)),
                               {"units": unit, "long_name": "smallest level reaching the "
                                "state (NaN: none)"})
        data["resurrection"] = (dims_c + ["record"], shaped(safe_above.any(-1), (R,)),
                                {"long_name": "a higher counted level is safe again"})
    attrs = {"method": method, "im": im_name, "im_units": unit, "states": list(states),
             "bootstrap": int(bootstrap), "seed": int(seed), "ci": float(ci),
             "reference": "Baker (2015), Efficient analytical fragility function fitting "
                          "using dynamic structural analysis, Earthquake Spectra 31(1)"}
    if im_name == "Sa":
        attrs["period"] = per
    return xr.Dataset(data, coords=coords, attrs=attrs)


def lognormal_cdf(x, median, beta) -> np.ndarray:
    """Phi(ln(x / median) / beta), broadcast; beta = 0 is the step at the median."""
    x, median, beta = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64)
                                            for v in (x, median, beta)))
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.log(x / median) / beta
    step = np.where(x >= median, 1.0, 0.0)
    return np.where(beta > 0.0, ndtr(z), np.where(np.isnan(median), np.nan, step))


def _plain(v: Any) -> Any:
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def curves_json(frag: xr.Dataset) -> dict:
    """{"curves": [{<other dims>: value, "state", "im", "method", "median", "beta",
    "median_ci": [lo, hi], "beta_ci": [lo, hi], "n_records", "n_excluded", "reason"},
    ...]} with plain Python numbers (NaN as None), one entry per curve of ``fragility``."""
    others = [d for d in frag["median"].dims if d != "state"]
    states = (list(frag["state"].values) if "state" in frag["median"].dims
              else [frag["state"].item()])
    curves = []
    shape = tuple(frag.sizes[d] for d in others)
    for st_i, st in enumerate(states):
        for pos in np.ndindex(*shape):
            sel = dict(zip(others, pos, strict=True))
            one = frag.isel(sel)
            if "state" in frag["median"].dims:
                one = one.isel(state=st_i)
            entry: dict[str, Any] = {d: _plain(frag[d].values[i]) if d in frag.coords
                                     else int(i) for d, i in sel.items()}
            entry.update({
                "state": str(st), "im": frag.attrs["im"], "method": frag.attrs["method"],
                "median": _plain(float(one["median"])), "beta": _plain(float(one["beta"])),
                "median_ci": [_plain(float(one["median_lo"])), _plain(float(one["median_hi"]))],
                "beta_ci": [_plain(float(one["beta_lo"])), _plain(float(one["beta_hi"]))],
                "n_records": int(one["n_records"]), "n_excluded": int(one["n_excluded"]),
                "reason": str(one["reason"].values),
            })
            curves.append(entry)
    return {"curves": curves}
