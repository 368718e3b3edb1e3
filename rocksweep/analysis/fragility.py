"""Lognormal fragility of a record suite: P(state | IM = x) = Phi(ln(x / im_median) / beta).

Reference: J. W. Baker (2015), "Efficient analytical fragility function fitting using
dynamic structural analysis", Earthquake Spectra 31(1), 579-599.

Fits (one likelihood for both):

- Stripes (multiple stripe analysis: every record scaled to each IM level x_j): k_j of the
  n_j records counted at x_j reach the state; the likelihood is the product of binomials
  prod_j C(n_j, k_j) p_j^k_j (1 - p_j)^(n_j - k_j), p_j = Phi(ln(x_j / im_median) / beta)
  (Baker 2015, eq. 11), n_j may differ between stripes (excluded points).
- Clouds (records unscaled, or scaled by one factor each): each record i is a stripe of
  one, (x_i, 0/1): probit regression on ln IM, the same likelihood with n_i = 1.

The log-likelihood is evaluated with log Phi (``scipy.special.log_ndtr``) for p and for
1 - p, so a stripe with k = 0 or k = n never meets log 0 (the guard that clipping p to
[eps, 1 - eps] gives, without the bias clipping adds). It is maximised over (a, b) of
Phi(a + b ln x), the probit generalised linear model on ln IM, by Fisher scoring with step
halving: that log-likelihood is concave, so the maximum is unique when it exists, and by
the invariance of maximum likelihood it gives the MLE of (ln im_median, ln beta):
im_median = exp(-a / b), beta = 1 / b (the tests check it against a direct optimisation).
The scoring is vectorised over bootstrap resamples.

Several states at once (docs/fragility.md, "Joint fits"):

- ordered damage states (two or more of uplift, theta:X, overturn, which are nested: a
  point that reaches theta:0.5 reaches theta:0.25): one ordinal (cumulative) probit with a
  common beta, P(DS >= j | x) = Phi(ln(x / im_median_j) / beta), im_median_1 <= ... by
  construction, so the curves never cross; the multinomial likelihood of the category
  counts (the most severe state each point reaches) is maximised (``_fit_ordinal``);
- mode1 and mode2 together: competing risks with independent lognormal capacities C_1,
  C_2 (im_median_k, beta_k): a point overturns in the mode whose capacity its IM passes
  first; P(safe | x) = S_1(x) S_2(x), P(mode k | x) = P(C_k <= x, C_k < C_other) (a
  bivariate normal probability, ``_cif``), so P(safe) + P(mode 1) + P(mode 2) = 1 at every
  x; the multinomial likelihood of (safe, mode 1, mode 2) counts is maximised
  (``_fit_competing``). im_median_k and beta_k describe mode k's capacity with the other
  mode censoring it; ``curve`` holds the fitted P(mode k | x) themselves.
  A single mode fitted alone treats the other mode's points as safe.

Verdicts (``reason``: "ok", or the words below joined by ","; never "ok" for these):

- how the fit ended: "no_failures" / "all_failed" (nothing / everything counted reaches
  the state: NaN, NaN); "separated" (every point that reaches it has a larger IM than
  every one that does not: the likelihood grows as beta -> 0; im_median = the geometric
  mean of the largest safe and the smallest failing IM, beta = NaN, never 0);
  "decreasing" (the best probit slope is <= 0); "no_data"; "one_stripe" (one IM level
  counted: NaN, NaN); "not_converged" (a joint fit found no maximum);
- "beta_undetermined": one stripe, separation, or fewer than two distinct stripe fractions
  strictly between 0 and 1 (no slope is seen): beta = NaN;
- "non_monotone": the stripe fractions fall with the IM by more than binomial noise: the
  likelihood-ratio statistic of free fractions against their isotonic (pool-adjacent-
  violators) fit exceeds what ``NONMONOTONE_SIMS`` binomial data sets drawn from the fitted
  curve give, at level ``NONMONOTONE_P`` (a seeded parametric bootstrap);
- "extrapolated": im_median or its 16/84% points im_median exp(-/+ beta) outside the
  counted stripes (clouds: the records' IMs);
- "bootstrap_undefined": more than (1 - ci) / 2 of the resamples have no finite fit (then
  the interval's tail on that side is not known);
- "censored": a mode fitted alone while the other mode holds >= ``CENSORED_SHARE`` of the
  overturning points (fit state=["mode1", "mode2"] for the competing-risk fit);
- "incomplete": points of the curve not computed (outcome -1: a partial file, or a sweep
  still writing it); "flagged": points flagged by the kernel (horizon, caps) are left out
  and counting them as reaching the state, or as not, moves im_median by more than
  ``FLAGGED_SHIFT`` (relative).

Bootstrap: records are resampled with replacement (a seeded ``numpy.random.Generator``,
``resampling.DEFAULT_BOOTSTRAP`` resamples by default for ``rocksweep.fragility``, this
module and the command line), the fit repeated on every resample in chunks (memory bounded by
``BOOT_ELEMENTS``, at most ``MAX_BOOTSTRAP`` resamples), and the percentile interval of
im_median and beta reported; resamples without a finite answer are left out and counted.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr
from scipy.special import log_ndtr, ndtr, ndtri, owens_t

from rocksweep.analysis.resampling import (
    DEFAULT_BOOTSTRAP,
    DEFAULT_CI,
    DEFAULT_SEED,
    MAX_BOOTSTRAP,
    check_ci,
)
from rocksweep.errors import Arg, FragilityError, RocksweepError  # noqa: F401 (re-exported)
from rocksweep.fields import plain
from rocksweep.kernel import layout as L
from rocksweep.vocab.ground import CLOUD_IMS as CLOUD_IM_VARIABLES
from rocksweep.vocab.ground import SCALE_IMS
from rocksweep.vocab.outcomes import MODE1, MODE2, OVERTURN, STATES, THETA_STATE, UPLIFT

__all__ = ["Bootstrap", "DEFAULT_BOOTSTRAP", "Fit", "FragilityError", "FragilityWarning",
           "REASONS", "STRIPE_IMS", "bootstrap_records", "curves_json", "fit_cloud",
           "fit_stripes", "fragility", "parse_state", "probability"]

#: stripe dimension names (the sweep's ``scale_im``) and their units
STRIPE_IMS = SCALE_IMS
#: cloud IMs and the per-record variables they come from
CLOUD_IMS = {im: (var, SCALE_IMS[im]) for im, var in CLOUD_IM_VARIABLES.items()}
#: how a fit ended (codes of the batched fits), then the quality words
ENDINGS = ("ok", "no_failures", "all_failed", "separated", "decreasing", "no_data",
           "one_stripe", "not_converged")
QUALITY = ("beta_undetermined", "non_monotone", "extrapolated", "bootstrap_undefined",
           "censored", "incomplete", "flagged")
REASONS = ENDINGS + QUALITY
BAND_POINTS = 101
#: the pointwise band is taken over at most this many resamples (the first ones)
BAND_SAMPLES = 20_000
#: resamples are fitted in chunks of at most this many count entries (bounded memory)
BOOT_ELEMENTS = 1 << 20
NONMONOTONE_P = 0.01
NONMONOTONE_SIMS = 400
CENSORED_SHARE = 0.1
FLAGGED_SHIFT = 0.01
_CODE = {w: i for i, w in enumerate(ENDINGS)}
#: endings that say all there is (nothing reaches the state, all do, nothing counted)
_EMPTY = [_CODE[w] for w in ("no_failures", "all_failed", "no_data")]



class FragilityWarning(UserWarning):
    """A fitted curve that should not be trusted as it is (its ``reason`` is not "ok")."""


class Fit(tuple):
    """(im_median, beta) of one fit, unpacks as a pair; ``.reason`` says how it was found
    ("ok" or the verdict words joined by ",").

    im_median: the IM at P = 0.5 [the IM's units]; beta: the lognormal standard deviation.
    """

    reason: str

    def __new__(cls, im_median: float, beta: float, reason: str = "ok") -> Fit:
        obj = super().__new__(cls, (float(im_median), float(beta)))
        obj.reason = reason
        return obj

    @property
    def im_median(self) -> float:
        return self[0]

    @property
    def beta(self) -> float:
        return self[1]

    def __repr__(self) -> str:
        return f"Fit(im_median={self[0]!r}, beta={self[1]!r}, reason={self.reason!r})"


# ---------------------------------------------------------------------------------------
# the binomial likelihood and its maximisation (batched)
# ---------------------------------------------------------------------------------------


def _loglik(eta: np.ndarray, k: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Sum over the last axis of k log Phi(eta) + (n - k) log Phi(-eta)."""
    return np.sum(k * log_ndtr(eta) + (n - k) * log_ndtr(-eta), axis=-1)


def _mle_batch(lnx: np.ndarray, k: np.ndarray, n: np.ndarray,
               start: tuple[float, float] | None = None, tol: float = 1e-10
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MLE of the lognormal fragility for a batch of data sets.

    lnx, k, n: float64 (B, S): ln IM, points reaching the state, points counted (n = 0: the
    entry is absent); start: (im_median, beta) to start the scoring from (resamples: the
    full data's fit), tol: its relative tolerance. Returns (im_median (B,), beta (B,),
    ending code (B,) into ENDINGS); separated data give the step's IM and beta = NaN.
    """
    lnx, k, n = (np.atleast_2d(np.asarray(v, dtype=np.float64)) for v in (lnx, k, n))
    lnx = np.broadcast_to(lnx, k.shape)
    B = k.shape[0]
    median = np.full(B, np.nan)
    beta = np.full(B, np.nan)
    reason = np.zeros(B, dtype=np.int64)
    has = n > 0
    fails = has & (k > 0)
    safes = has & (n - k > 0)
    nk, ns = fails.any(-1), safes.any(-1)
    reason[~nk] = _CODE["no_failures"]
    reason[nk & ~ns] = _CODE["all_failed"]
    reason[~has.any(-1)] = _CODE["no_data"]
    both = nk & ns
    x_safe_max = np.where(safes, lnx, -np.inf).max(-1)
    x_fail_min = np.where(fails, lnx, np.inf).min(-1)
    sep = both & (x_fail_min >= x_safe_max)
    reason[sep] = _CODE["separated"]
    median[sep] = np.exp(0.5 * (x_fail_min[sep] + x_safe_max[sep]))
    todo = both & ~sep
    if np.any(todo):
        st = None
        if start is not None and np.all(np.isfinite(start)) and start[1] > 0:
            st = np.broadcast_to([-math.log(start[0]) / start[1], 1.0 / start[1]],
                                 (int(todo.sum()), 2))
        a, b = _score(lnx[todo], k[todo], n[todo], tol=tol, start=st)
        med, bet, rsn = np.full(a.size, np.nan), np.full(a.size, np.nan), np.zeros(a.size, int)
        up = b > 0.0
        med[up] = np.exp(-a[up] / b[up])
        bet[up] = 1.0 / b[up]
        rsn[~up] = _CODE["decreasing"]
        median[todo], beta[todo], reason[todo] = med, bet, rsn
    return median, beta, reason


def _log_cdf(e: np.ndarray) -> np.ndarray:
    """log Phi(e): log(ndtr) (half the price of ``log_ndtr``), ``log_ndtr`` where ndtr
    underflows."""
    v = ndtr(e)
    tail = v < 1e-200
    with np.errstate(divide="ignore"):
        out = np.log(v)
    if np.any(tail):
        out[tail] = log_ndtr(e[tail])
    return out


def _score(lnx: np.ndarray, k: np.ndarray, n: np.ndarray, iters: int = 200,
           tol: float = 1e-10, start: np.ndarray | None = None
           ) -> tuple[np.ndarray, np.ndarray]:
    """Fisher scoring with step halving for Phi(a + b lnx), batched over rows (each row
    has points on both sides: the maximum exists). start: (B, 2) (a, b) to start from
    (bootstrap resamples: the full data's fit; then Newton steps on the observed
    information, which converge in a few steps from there); default the pooled fraction,
    slope 0. Returns (a, b) per row."""
    # standardise ln x per row for conditioning: eta = c0 + c1 z, z = (lnx - m) / s
    w = n / n.sum(-1, keepdims=True)
    m = np.sum(w * lnx, -1, keepdims=True)
    s = np.sqrt(np.sum(w * (lnx - m) ** 2, -1, keepdims=True))
    s = np.where(s > 0.0, s, 1.0)
    z = (lnx - m) / s
    frac = np.clip(k.sum(-1) / n.sum(-1), 1e-6, 1.0 - 1e-6)
    c = np.stack([ndtri(frac), np.zeros(frac.size)], axis=-1)  # (B, 2)
    newton = start is not None
    if newton:  # eta = a + b lnx = (a + b m) + (b s) z
        c0 = start[:, 0] + start[:, 1] * m[:, 0]
        c1 = start[:, 1] * s[:, 0]
        fine = np.isfinite(c0) & np.isfinite(c1)
        c[fine] = np.stack([c0, c1], -1)[fine]
    eta = c[:, :1] + c[:, 1:] * z
    lpos, lneg = _log_cdf(eta), _log_cdf(-eta)  # log Phi(eta), log Phi(-eta)
    ll = np.sum(k * lpos + (n - k) * lneg, -1)
    active = np.ones(frac.size, dtype=bool)
    for _ in range(iters):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        e, zz, kk, nn = eta[idx], z[idx], k[idx], n[idx]
        logphi = -0.5 * e * e - 0.5 * math.log(2.0 * math.pi)
        r1 = np.exp(logphi - lpos[idx])  # phi / Phi(eta)
        r2 = np.exp(logphi - lneg[idx])  # phi / Phi(-eta)
        g = kk * r1 - (nn - kk) * r2  # d loglik / d eta
        if newton:  # observed information: -d2 loglik / d eta2 (> 0: concave)
            wgt = kk * r1 * (e + r1) + (nn - kk) * r2 * (r2 - e)
        else:
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
        lp_new, ln_new = lpos[idx].copy(), lneg[idx].copy()
        pending = np.ones(idx.size, dtype=bool)
        for _half in range(60):
            cand = c[idx][pending] + step[pending, None] * np.stack(
                [d0[pending], d1[pending]], -1)
            ecand = cand[:, :1] + cand[:, 1:] * zz[pending]
            lp_c, ln_c = _log_cdf(ecand), _log_cdf(-ecand)
            lc = np.sum(kk[pending] * lp_c + (nn[pending] - kk[pending]) * ln_c, -1)
            ok = lc >= ll0[pending] - 1e-12 * np.abs(ll0[pending])
            pi = np.flatnonzero(pending)
            c_new[pi[ok]] = cand[ok]
            ll_new[pi[ok]] = lc[ok]
            lp_new[pi[ok]], ln_new[pi[ok]] = lp_c[ok], ln_c[ok]
            step[pi[~ok]] *= 0.5
            pending[pi[ok]] = False
            if not pending.any():
                break
        delta = np.abs(c_new - c[idx]).max(-1)
        c[idx] = c_new
        eta[idx] = c_new[:, :1] + c_new[:, 1:] * zz
        ll[idx] = ll_new
        lpos[idx], lneg[idx] = lp_new, ln_new
        active[idx[(delta < tol * (1.0 + np.abs(c_new).max(-1))) | pending]] = False
    a = c[:, 0] - c[:, 1] * m[:, 0] / s[:, 0]
    b = c[:, 1] / s[:, 0]
    return a, b


def _distinct_inner(lnx: np.ndarray, k: np.ndarray, n: np.ndarray) -> tuple[np.ndarray,
                                                                           np.ndarray]:
    """Per row of (B, S) stripe data: (counted IM levels, distinct fractions strictly
    between 0 and 1 after merging repeated levels), int (B,) each."""
    lnx = np.broadcast_to(lnx, k.shape)
    levels = np.unique(lnx)
    if levels.size < lnx.shape[-1]:  # repeated levels: merge them
        kk = np.stack([np.where(lnx == v, k, 0.0).sum(-1) for v in levels], -1)
        nn = np.stack([np.where(lnx == v, n, 0.0).sum(-1) for v in levels], -1)
        k, n = kk, nn
    has = n > 0
    frac = np.where(has, k / np.where(has, n, 1.0), np.nan)
    inner = has & (frac > 0.0) & (frac < 1.0)
    f = np.where(inner, np.round(frac, 12), np.nan)
    f.sort(-1)  # NaN last
    distinct = np.sum(inner, -1) - np.sum((np.diff(f, axis=-1) == 0.0), -1)
    return has.sum(-1), distinct


def _stripe_rules(lnx, k, n, med, beta, code):
    """The stripe-only rules on batched fits (in place): one counted level -> NaN, NaN,
    "one_stripe"; fewer than two distinct inner fractions (or separation) -> beta NaN.
    Returns bool (B,) "beta_undetermined"."""
    levels, distinct = _distinct_inner(lnx, k, n)
    one = (levels == 1) & ~np.isin(code, _EMPTY)
    med[one], beta[one] = np.nan, np.nan
    code[one] = _CODE["one_stripe"]
    few = (distinct < 2) & (code == _CODE["ok"])
    beta[few] = np.nan
    return one | few | (code == _CODE["separated"])


def _isotonic_lr(k: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Likelihood-ratio statistic 2 (ll(free fractions) - ll(isotonic fractions)) of
    binomial counts k (B, S) of n (S,) > 0, stripes in increasing IM. The isotonic
    (non-decreasing) weighted fit is max_{i<=s} min_{j>=s} mean(i..j) (the min-max formula
    of the pool-adjacent-violators solution)."""
    ck = np.concatenate([np.zeros(k.shape[:-1] + (1,)), np.cumsum(k, -1)], -1)
    cn = np.concatenate([[0.0], np.cumsum(n)])
    S = n.size
    i, j = np.meshgrid(np.arange(S), np.arange(S), indexing="ij")
    valid = j >= i
    mean = np.where(valid, (ck[..., j + 1] - ck[..., i]) / np.where(valid, cn[j + 1] - cn[i],
                                                                    1.0), np.inf)
    # cmin[.., i, s] = min over j >= s of mean(i..j); iso[s] = max over i <= s
    cmin = np.flip(np.minimum.accumulate(np.flip(mean, -1), -1), -1)
    iso = np.where(valid, cmin, -np.inf).max(-2)
    free = k / n

    def xlogy(a, b):
        return np.where(a > 0, a * np.log(np.where(b > 0, b, 1.0)), 0.0)

    return 2.0 * np.sum(xlogy(k, free) - xlogy(k, iso) + xlogy(n - k, 1.0 - free)
                        - xlogy(n - k, 1.0 - iso), -1)


def _non_monotone(lnx: np.ndarray, k: np.ndarray, n: np.ndarray, p_fit: np.ndarray) -> bool:
    """The stripe fractions fall with the IM beyond binomial noise (module docstring):
    lnx, k, n (S,) one data set, p_fit (S,) the fitted probabilities (NaN: use the pooled
    fraction)."""
    keep = n > 0
    lnx, k, n, p = lnx[keep], k[keep], n[keep], p_fit[keep]
    order = np.argsort(lnx, kind="stable")
    lnx, k, n, p = lnx[order], k[order], n[order], p[order]
    levels, inv = np.unique(lnx, return_inverse=True)
    if levels.size < 3:
        return False
    k = np.bincount(inv, k)
    n = np.bincount(inv, n)
    p = np.bincount(inv, np.nan_to_num(p) * 1.0) / np.bincount(inv)
    if not np.all(np.isfinite(p_fit[keep])):
        p = np.full(levels.size, k.sum() / n.sum())
    stat = float(_isotonic_lr(k[None], n)[0])
    if stat <= 1e-9:
        return False
    rng = np.random.default_rng(20261125)
    sims = rng.binomial(n.astype(np.int64), np.clip(p, 0.0, 1.0),
                        size=(NONMONOTONE_SIMS, levels.size)).astype(np.float64)
    null = _isotonic_lr(sims, n)
    p_value = (1.0 + np.sum(null >= stat - 1e-9)) / (NONMONOTONE_SIMS + 1.0)
    return bool(p_value < NONMONOTONE_P)


def _outside(lo: float, hi: float, med: float, beta: float) -> str:
    """'' or why the curve is extrapolated: im_median or im_median exp(-/+beta) outside
    [lo, hi]."""
    if not math.isfinite(med):
        return ""
    pts = [("im_median", med)]
    if math.isfinite(beta):
        pts += [("16% point", med * math.exp(-beta)), ("84% point", med * math.exp(beta))]
    out = [f"{name} {v:.3g} {'below' if v < lo else 'above'} the data ({lo:.3g}-{hi:.3g})"
           for name, v in pts if v < lo * (1 - 1e-12) or v > hi * (1 + 1e-12)]
    return "; ".join(out)


def _words(*groups: Sequence[str]) -> str:
    seen = [w for g in groups for w in g if w and w != "ok"]
    seen = list(dict.fromkeys(seen))
    return ",".join(seen) if seen else "ok"


def _single_verdict(lnx, k, n, stripes: bool) -> tuple[Fit, dict[str, str]]:
    """The fit of one data set (lnx, k, n: (P,)) with its data verdicts and their
    explanations {word: text}."""
    med, bet, code = _mle_batch(lnx[None], k[None], n[None])
    why: dict[str, str] = {ENDINGS[int(code[0])]: ""}
    if stripes:
        und = _stripe_rules(lnx[None], k[None], n[None], med, bet, code)
        why = {ENDINGS[int(code[0])]: ""}
        if und[0]:
            why["beta_undetermined"] = ("one stripe" if code[0] == _CODE["one_stripe"] else
                                        "separated" if code[0] == _CODE["separated"] else
                                        "fewer than 2 distinct fractions between 0 and 1")
        p = lognormal_cdf(np.exp(lnx), med[0], bet[0]) if np.isfinite(bet[0]) else \
            np.full(lnx.size, np.nan)
        if _non_monotone(lnx, k, n, p):
            why["non_monotone"] = "the stripe fractions fall with the IM beyond noise"
    elif code[0] == _CODE["separated"]:
        why["beta_undetermined"] = "separated"
    counted = np.exp(lnx[n > 0])
    if counted.size:
        ext = _outside(float(counted.min()), float(counted.max()), float(med[0]),
                       float(bet[0]))
        if ext:
            why["extrapolated"] = ext
    return Fit(med[0], bet[0], _words(why)), why


def fit_stripes(im: Sequence[float] | np.ndarray, n_fail: Sequence[int] | np.ndarray,
                n_total: Sequence[int] | np.ndarray) -> Fit:
    """Maximum-likelihood lognormal fragility from stripes (Baker 2015, eq. 11).

    im: float[S] IM level of each stripe (> 0, any units; repeated levels allowed);
    n_fail: int[S] records that reach the state at that level; n_total: int[S] records
    counted there (may differ between stripes; 0 drops the stripe). Returns a ``Fit``
    (im_median [units of im], beta [-]) with ``.reason``: "ok" or the verdict words of the
    data (module docstring: degenerate data give NaN with a reason, never an exception
    for valid counts, never beta = 0).
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
    return _single_verdict(np.log(x), k, n, stripes=True)[0]


def fit_cloud(im: Sequence[float] | np.ndarray, failed: Sequence[bool] | np.ndarray) -> Fit:
    """Maximum-likelihood lognormal fragility from a cloud: probit regression of the 0/1
    outcomes ``failed`` (bool[R]) on ln ``im`` (float[R] > 0, one IM per record). Returns
    a ``Fit`` (im_median [units of im], beta [-]) with ``.reason``."""
    x = np.asarray(im, dtype=np.float64).ravel()
    f = np.asarray(failed).ravel().astype(bool)
    if x.size != f.size:
        raise FragilityError(f"im, failed: lengths {x.size}, {f.size} differ")
    if np.any(~np.isfinite(x) | (x <= 0.0)):
        raise FragilityError("im: every IM must be finite and > 0")
    return _single_verdict(np.log(x), f.astype(np.float64), np.ones(x.size),
                           stripes=False)[0]


# ---------------------------------------------------------------------------------------
# joint fits: a batched Levenberg-Marquardt ascent
# ---------------------------------------------------------------------------------------


def _multinomial_ll(p: np.ndarray, m: np.ndarray) -> np.ndarray:
    """sum over (C, P) of m log p (m = 0 terms are 0 even where p = 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sum(np.where(m > 0, m * np.log(np.maximum(p, 1e-300)), 0.0), (1, 2))


def _maximise(prob: Callable[[np.ndarray, np.ndarray], np.ndarray], m: np.ndarray,
              theta0: np.ndarray, limit: np.ndarray, iters: int = 100, tol: float = 1e-10
              ) -> tuple[np.ndarray, np.ndarray]:
    """Maximum likelihood of multinomial counts m (B, C, P) (C categories at P IM levels)
    under probabilities prob(theta (b, p), rows (b,)) -> (b, C, P), for every row of
    theta0 (B, p): Fisher scoring (information sum over c, s of n_s J J^T / p, J = dp /
    dtheta by central differences), damped (Levenberg-Marquardt) until the likelihood
    rises. A row whose |theta| passes ``limit`` (p,) runs away to a boundary (separated
    data: no maximum) and stops, not converged. Returns (theta (B, p), converged (B,))."""
    B, P = theta0.shape
    n = m.sum(1)
    th = theta0.copy()
    pr = prob(th, np.arange(B))
    ll = _multinomial_ll(pr, m)
    lam = np.full(B, 1e-6)
    active = np.isfinite(ll)
    conv = np.zeros(B, bool)
    h = 1e-6
    eye = np.eye(P)
    for _ in range(iters):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        t = th[idx]
        both = np.concatenate([t[:, None, :] + h * eye, t[:, None, :] - h * eye], 1)
        vals = prob(both.reshape(-1, P), np.repeat(idx, 2 * P)).reshape(
            (idx.size, 2 * P) + pr.shape[1:])
        J = (vals[:, :P] - vals[:, P:]) / (2.0 * h)  # (b, p, C, P)
        inv = 1.0 / np.maximum(pr[idx], 1e-300)
        g = np.einsum("bkcs,bcs->bk", J, m[idx] * inv)
        info = np.einsum("bkcs,bjcs,bcs->bkj", J, J, n[idx][:, None, :] * inv)
        f0 = ll[idx]
        bad = ~(np.all(np.isfinite(g), -1) & np.all(np.isfinite(info), (-1, -2)))
        pending = ~bad
        done_rows = np.zeros(idx.size, bool)
        for _try in range(40):
            pi = np.flatnonzero(pending)
            if pi.size == 0:
                break
            A = info[pi] + lam[idx[pi], None, None] * (eye + info[pi] * eye)
            try:
                d = np.linalg.solve(A, g[pi][..., None])[..., 0]
            except np.linalg.LinAlgError:
                d = np.stack([np.linalg.lstsq(a, b, rcond=None)[0] for a, b in
                              zip(A, g[pi], strict=True)])
            cand = t[pi] + d
            pc = prob(cand, idx[pi])
            lc = _multinomial_ll(pc, m[idx[pi]])
            up = np.isfinite(lc) & (lc >= f0[pi] - 1e-13 * np.abs(f0[pi]))
            acc = pi[up]
            th[idx[acc]] = cand[up]
            ll[idx[acc]] = lc[up]
            pr[idx[acc]] = pc[up]
            lam[idx[acc]] = np.maximum(lam[idx[acc]] * 0.1, 1e-9)
            small = np.abs(d[up]).max(-1) < tol * (1.0 + np.abs(cand[up]).max(-1))
            flat = np.abs(lc[up] - f0[pi][up]) <= 1e-14 * (1.0 + np.abs(f0[pi][up]))
            done_rows[acc[small | flat]] = True
            pending[acc] = False
            rej = pi[~up]
            lam[idx[rej]] = np.maximum(lam[idx[rej]] * 10.0, 1e-4)
            stuck = rej[lam[idx[rej]] > 1e12]
            done_rows[stuck] = True
            pending[stuck] = False
        away = np.any(np.abs(th[idx]) > limit, -1)
        conv[idx[done_rows & ~away]] = True
        active[idx[done_rows | bad | away]] = False
    return th, conv


def _standardise(lnx: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(m, s) (B,) the n-weighted mean and spread of ln x per row (s = 1 if 0)."""
    w = n / np.maximum(n.sum(-1, keepdims=True), 1e-300)
    m = np.sum(w * lnx, -1)
    s = np.sqrt(np.sum(w * (lnx - m[:, None]) ** 2, -1))
    return m, np.where(s > 0.0, s, 1.0)


def _ordinal_probs(z: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """log P(category c | z) (b, K+1, P) of the ordinal probit: theta (b, K+1) = (t_1,
    log(t_2 - t_1), ..., log(t_K - t_{K-1}), log s); P(DS >= j) = Phi(s (z - t_j)). Each
    difference of Phi is taken in the tail where it does not cancel."""
    K = theta.shape[1] - 1
    t = np.cumsum(np.concatenate([theta[:, :1], np.exp(theta[:, 1:K])], 1), 1)  # (b, K)
    s = np.exp(theta[:, K])
    e = s[:, None, None] * (z[:, None, :] - t[:, :, None])  # (b, K, P)
    lower_q, upper_q = ndtr(e), ndtr(-e)  # P(DS >= j), P(DS < j)
    one = np.ones(e.shape[:1] + (1,) + e.shape[2:])
    zero = np.zeros_like(one)
    up_q = np.concatenate([one, lower_q], 1)  # P(DS >= c)
    lo_q = np.concatenate([lower_q, zero], 1)  # P(DS >= c + 1)
    up_c = np.concatenate([zero, upper_q], 1)  # P(DS < c)
    lo_c = np.concatenate([upper_q, one], 1)  # P(DS < c + 1)
    e_next = np.concatenate([e, np.full_like(one, -np.inf)], 1)
    p = np.where(e_next > 0.0, lo_c - up_c, up_q - lo_q)
    with np.errstate(divide="ignore"):
        return np.log(np.maximum(p, 0.0))


def _fit_ordinal(lnx: np.ndarray, m: np.ndarray, start: tuple | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ordinal probit with a common beta (module docstring). lnx (b, P) ln IM; m (b, K+1,
    P) category counts (category c: the points whose most severe state reached is the
    c-th, 0: none); start: (im_median (K,), beta) to start from (resamples: the full data's
    fit). Returns (im_median (b, K), beta (b,), converged (b,))."""
    b, K1, P = m.shape
    K = K1 - 1
    n = m.sum(1)
    mu, sd = _standardise(lnx, n)
    z = (lnx - mu[:, None]) / sd[:, None]
    # start: the marginal fraction reaching each state, slope 1
    reach = np.cumsum(m[:, ::-1].sum(-1), 1)[:, ::-1][:, 1:] / np.maximum(n.sum(-1), 1)[:,
                                                                                      None]
    t0 = -ndtri(np.clip(reach, 1e-3, 1 - 1e-3))
    t0 = np.maximum.accumulate(t0 + 1e-3 * np.arange(K), 1)
    theta0 = np.concatenate([t0[:, :1], np.log(np.maximum(np.diff(t0, axis=1), 1e-3)),
                             np.zeros((b, 1))], 1)
    if start is not None and np.all(np.isfinite(start[0])) and np.isfinite(start[1]) \
            and start[1] > 0:
        ts = (np.log(np.asarray(start[0]))[None, :] - mu[:, None]) / sd[:, None]
        theta0 = np.concatenate([ts[:, :1], np.log(np.maximum(np.diff(ts, axis=1), 1e-6)),
                                 np.log(sd / start[1])[:, None]], 1)

    def prob(theta: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return np.exp(_ordinal_probs(z[rows], theta))

    limit = np.array([60.0] + [40.0] * (K - 1) + [15.0])
    theta, conv = _maximise(prob, m, theta0, limit, tol=1e-10 if start is None else 1e-7)
    t = np.cumsum(np.concatenate([theta[:, :1], np.exp(theta[:, 1:K])], 1), 1)
    s = np.exp(theta[:, K])
    return np.exp(mu[:, None] + sd[:, None] * t), sd / s, conv


def _cif(z: np.ndarray, t: np.ndarray, sig: np.ndarray) -> tuple[np.ndarray, ...]:
    """Competing lognormal capacities in standardised ln IM: z (..., P), t and sig (..., 2)
    the two capacities' means and deviations. Returns (P(safe), P(mode 1), P(mode 2))
    (..., P): P(mode k) = P(U_k <= z, U_k < U_other) = Phi2(h, q; rho), h = (z - t_k) /
    sig_k, q = (t_o - t_k) / sqrt(sig_k^2 + sig_o^2), rho = sig_k / sqrt(...) (Owen's T)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out = []
        tot = np.sqrt(sig[..., 0] ** 2 + sig[..., 1] ** 2)
        for k, o in ((0, 1), (1, 0)):
            h = (z - t[..., k, None]) / sig[..., k, None]
            q = np.broadcast_to(((t[..., o] - t[..., k]) / tot)[..., None], h.shape)
            rho = np.broadcast_to((sig[..., k] / tot)[..., None], h.shape)
            out.append(_phi2(h, q, rho))
        safe = ndtr(-(z - t[..., 0, None]) / sig[..., 0, None]) * ndtr(
            -(z - t[..., 1, None]) / sig[..., 1, None])
    return safe, out[0], out[1]


def _phi2(h: np.ndarray, k: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """Bivariate standard normal CDF P(X <= h, Y <= k), corr rho in (0, 1), by Owen's T:
    Phi2 = Phi(h)/2 + Phi(k)/2 - T(h, a_h) - T(k, a_k) - [hk < 0]/2 (Owen 1956)."""
    r = np.sqrt(1.0 - rho * rho)
    h = np.where(h == 0.0, 1e-300, h)
    k = np.where(k == 0.0, 1e-300, k)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        ah = (k - rho * h) / (h * r)
        ak = (h - rho * k) / (k * r)
    p = 0.5 * ndtr(h) + 0.5 * ndtr(k) - owens_t(h, ah) - owens_t(k, ak) - np.where(
        h * k < 0.0, 0.5, 0.0)
    return np.clip(p, 0.0, 1.0)


def _fit_competing(lnx: np.ndarray, k1: np.ndarray, k2: np.ndarray, n: np.ndarray,
                   start: np.ndarray, tol: float | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Competing lognormal capacities of mode 1 and mode 2 (module docstring), each row
    with points of both modes. lnx, k1, k2, n (b, P); start (b, 4): (ln im_median_1,
    beta_1, ln im_median_2, beta_2) to start from. Returns (im_median (b, 2), beta (b, 2),
    converged (b,))."""
    mu, sd = _standardise(lnx, n)
    z = (lnx - mu[:, None]) / sd[:, None]
    th0 = np.stack([(start[:, 0] - mu) / sd, np.log(start[:, 1] / sd),
                    (start[:, 2] - mu) / sd, np.log(start[:, 3] / sd)], -1)
    counts = np.stack([n - k1 - k2, k1, k2], 1)  # (b, 3, P)

    def prob(theta: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return np.stack(_cif(z[rows], theta[:, [0, 2]], np.exp(theta[:, [1, 3]])), 1)

    th0 = np.where(np.isfinite(th0), th0, 0.0)
    theta, conv = _maximise(prob, counts, th0, np.array([60.0, 12.0, 60.0, 12.0]),
                            tol=1e-10 if tol is None else tol)
    with np.errstate(over="ignore"):
        med = np.exp(mu[:, None] + sd[:, None] * theta[:, [0, 2]])
        beta = sd[:, None] * np.exp(theta[:, [1, 3]])
    ok = conv & np.all(np.abs(theta[:, [0, 2]]) < 60.0, -1) & np.all(
        (theta[:, [1, 3]] > -12.0) & (theta[:, [1, 3]] < 8.0), -1)
    return med, beta, ok


# ---------------------------------------------------------------------------------------
# fits of a group of states from category counts (batched over resamples)
# ---------------------------------------------------------------------------------------


def _fit_counts(kind: str, lnx: np.ndarray, m: np.ndarray, stripes: bool,
                start: tuple[np.ndarray, np.ndarray] | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Fits of one group of states from category counts m (b, C, P) at ln IM lnx (P,):
    kind "single" (C = 2: not reached, reached), "ordinal" (C = K + 1: the most severe of K
    nested states reached, in severity order) or "competing" (C = 3: safe, mode 1, mode
    2). start: the full data's (im_median (G,), beta (G,)) to start from (bootstrap
    resamples; a single state's fit then stops at 1e-7). Returns im_median, beta, ending
    code, beta undetermined: (b, G) each, G the states of the group (severity order for
    "ordinal", (mode1, mode2) for "competing")."""
    b, C, P = m.shape
    n = m.sum(1)
    lnxb = np.broadcast_to(lnx, n.shape)
    if kind == "single":
        med, bet, code = (_mle_batch(lnxb, m[:, 1], n) if start is None else
                          _mle_batch(lnxb, m[:, 1], n, (start[0][0], start[1][0]),
                                     tol=1e-7))
        und = (_stripe_rules(lnxb, m[:, 1], n, med, bet, code) if stripes else
               code == _CODE["separated"])
        return med[:, None], bet[:, None], code[:, None], und[:, None]
    if kind == "ordinal":
        return _fit_ordinal_counts(lnxb, m, n, stripes, start)
    return _fit_competing_counts(lnxb, m, n, stripes, start)


def _fit_ordinal_counts(lnx, m, n, stripes, start=None):
    b, C, P = m.shape
    K = C - 1
    reach = np.cumsum(m[:, ::-1], 1)[:, ::-1][:, 1:]  # (b, K, P): reaching state j
    med = np.full((b, K), np.nan)
    bet = np.full((b, K), np.nan)
    code = np.zeros((b, K), np.int64)
    und = np.zeros((b, K), bool)
    marg = [_mle_batch(lnx, reach[:, j], n) for j in range(K)]
    mcode = np.stack([c for _, _, c in marg], 1)
    for j in range(K):
        code[:, j] = mcode[:, j]
    fitted = ~np.isin(mcode, [_CODE[w] for w in ("no_failures", "all_failed", "no_data")])
    # eligible states are contiguous in severity (nested): fit each pattern once
    patterns, inv = np.unique(fitted, axis=0, return_inverse=True)
    inv = np.asarray(inv).ravel()
    for pi, pat in enumerate(patterns):
        rows = np.flatnonzero(inv == pi)
        js = np.flatnonzero(pat)
        if js.size == 0:
            continue
        if js.size == 1:  # one state: the binomial fit itself
            j = js[0]
            mm, bb, cc = _mle_batch(lnx[rows], reach[rows, j], n[rows])
            uu = (_stripe_rules(lnx[rows], reach[rows, j], n[rows], mm, bb, cc) if stripes
                  else cc == _CODE["separated"])
            med[rows, j], bet[rows, j], code[rows, j], und[rows, j] = mm, bb, cc, uu
            continue
        a, z = js[0], js[-1]
        sub = m[rows][:, a:z + 2]
        sub[:, 0] += m[rows][:, :a].sum(1)
        sub[:, -1] += m[rows][:, z + 2:].sum(1)
        st = None if start is None else (np.asarray(start[0])[js], np.asarray(start[1])[js[0]])
        mm, bb, conv = _fit_ordinal(lnx[rows], sub, st)
        _, sdv = _standardise(lnx[rows], n[rows])
        cc = np.where(conv, _CODE["ok"], _CODE["not_converged"])
        cc = np.where(conv & (bb < 1e-6 * sdv), _CODE["separated"], cc)
        cc = np.where(conv & (bb > 1e6 * sdv), _CODE["decreasing"], cc)
        good = cc == _CODE["ok"]
        uu = ~good
        if stripes:
            levels = np.zeros(rows.size, np.int64)
            distinct = np.zeros(rows.size, np.int64)
            for j in js:
                lv, dd = _distinct_inner(lnx[rows], reach[rows, j], n[rows])
                levels, distinct = np.maximum(levels, lv), distinct + dd
            one = levels == 1
            cc = np.where(one, _CODE["one_stripe"], cc)
            uu = uu | one | (distinct < 2)
        for q, j in enumerate(js):
            med[rows, j] = np.where(good | uu & (cc == _CODE["ok"]), mm[:, q], np.nan)
            bet[rows, j] = np.where(good & ~uu, bb, np.nan)
            code[rows, j], und[rows, j] = cc, uu
    return med, bet, code, und


def _fit_competing_counts(lnx, m, n, stripes, start=None):
    b = m.shape[0]
    k1, k2 = m[:, 1], m[:, 2]
    med = np.full((b, 2), np.nan)
    bet = np.full((b, 2), np.nan)
    code = np.zeros((b, 2), np.int64)
    und = np.zeros((b, 2), bool)
    mo, bo, co = _mle_batch(lnx, k1 + k2, n)
    code[:] = co[:, None]
    has1, has2 = k1.sum(-1) > 0, k2.sum(-1) > 0
    okrow = co == _CODE["ok"]
    for j, (own, other) in enumerate(((has1, has2), (has2, has1))):
        alone = okrow & own & ~other  # the other mode never occurs: no competition
        med[alone, j], bet[alone, j] = mo[alone], bo[alone]
        code[okrow & ~own, j] = _CODE["no_failures"]
    both = np.flatnonzero(okrow & has1 & has2)
    if both.size:
        begin = np.empty((both.size, 4))
        for j, kk in enumerate((k1, k2)):
            mm, bb, _ = _mle_batch(lnx[both], kk[both], n[both])
            fine = np.isfinite(mm) & np.isfinite(bb)
            begin[:, 2 * j] = np.where(fine, np.log(np.where(fine, mm, 1.0)),
                                       np.log(mo[both]))
            begin[:, 2 * j + 1] = np.where(fine, bb, bo[both])
        if start is not None and np.all(np.isfinite(start[0])) and np.all(
                np.isfinite(start[1])) and np.all(np.asarray(start[1]) > 0):
            full = [np.log(start[0][0]), start[1][0], np.log(start[0][1]), start[1][1]]
            first, tol = np.broadcast_to(full, (both.size, 4)), 1e-7
        else:
            first, tol = begin, None
        mm, bb, conv = _fit_competing(lnx[both], k1[both], k2[both], n[both], first, tol)
        med[both], bet[both] = mm, bb
        code[both] = np.where(conv, _CODE["ok"], _CODE["not_converged"])[:, None]
        med[both[~conv]], bet[both[~conv]] = np.nan, np.nan
    for j, kk in enumerate((k1, k2)):
        sep = code[:, j] == _CODE["separated"]
        und[:, j] = sep
        if stripes:  # (the other mode's censoring informs beta: no fraction rule)
            lv, _ = _distinct_inner(lnx, kk, n)
            one = (lv == 1) & ~np.isin(code[:, j], _EMPTY)
            code[one, j] = _CODE["one_stripe"]
            med[one, j] = np.nan
            und[:, j] |= one
        bet[und[:, j], j] = np.nan
        med[sep, j] = np.nan
    return med, bet, code, und


def _curves(kind: str, grid: np.ndarray, med: np.ndarray, bet: np.ndarray) -> np.ndarray:
    """Fitted P(state | x) (..., G, X) at grid (X,) of fits med, bet (..., G)."""
    if kind != "competing":
        return lognormal_cdf(grid, med[..., None], bet[..., None])
    lnm, sig = np.log(med), bet
    z = np.broadcast_to(np.log(grid), med.shape[:-1] + grid.shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        _, p1, p2 = _cif(z, lnm, sig)
    out = np.stack([p1, p2], -2)
    bad = ~np.all(np.isfinite(med) & np.isfinite(bet) & (bet > 0), -1)
    out[bad] = np.nan
    return out


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


def _chunks(n_records: int, n_boot: int, seed: int | np.random.Generator, per: int):
    """Resample weights in chunks: yields (start, w float (nb, R)), w[r] = how often record
    r is drawn; one Generator draws R indices a resample, as a single draw would."""
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    nb = max(1, min(n_boot, BOOT_ELEMENTS // max(per, 1)))
    for start in range(0, n_boot, nb):
        m = min(nb, n_boot - start)
        idx = rng.integers(0, n_records, size=(m, n_records))
        flat = (np.arange(m)[:, None] * n_records + idx).ravel()
        w = np.bincount(flat, minlength=m * n_records).reshape(m, n_records)
        yield start, w.astype(np.float64)


def _category_counts(w: np.ndarray, onehot: np.ndarray, stripes: bool) -> np.ndarray:
    """(b, C, P) category counts of resample weights w (b, R): onehot (C, R, S) for
    stripes (summed over records), (C, R) for a cloud (a point per record)."""
    if stripes:
        return np.einsum("br,crs->bcs", w, onehot)
    return w[:, None, :] * onehot[None]


def _interval(v: np.ndarray, ci: float) -> tuple[float, float]:
    v = v[np.isfinite(v)]
    if v.size == 0:
        return math.nan, math.nan
    q = 100.0 * np.array([(1.0 - ci) / 2.0, (1.0 + ci) / 2.0])
    lo, hi = np.percentile(v, q)
    return float(lo), float(hi)


def bootstrap_records(im: Sequence[float] | np.ndarray, failed: np.ndarray,
                      counted: np.ndarray | None = None, *,
                      n_boot: int = DEFAULT_BOOTSTRAP,
                      seed: int | np.random.Generator = DEFAULT_SEED,
                      ci: float = DEFAULT_CI) -> Bootstrap:
    """Bootstrap the fragility fit over records.

    Stripes: im float[S] (levels), failed bool[R, S] (record r reaches the state at level
    s), counted bool[R, S] (the point is counted; default all). Cloud: im float[R] (one IM
    per record), failed bool[R], counted bool[R]. Each of ``n_boot`` resamples draws R
    records with replacement (``numpy.random.default_rng(seed)``), refits, and the
    ``ci`` percentile intervals of im_median and beta are returned in a ``Bootstrap``.
    """
    x = np.asarray(im, dtype=np.float64)
    f = np.asarray(failed).astype(bool)
    c = np.ones_like(f) if counted is None else np.asarray(counted).astype(bool)
    ci = check_ci(ci)
    n_boot = _check_bootstrap(n_boot, 1)
    cloud = f.ndim == 1
    if cloud and not (x.shape == f.shape == c.shape):
        raise FragilityError("cloud: im, failed, counted must have one value per record")
    if not cloud and (f.shape != c.shape or f.shape[1:] != x.shape):
        raise FragilityError("stripes: failed and counted must be (records, stripes)")
    onehot = np.stack([c & ~f, c & f]).astype(np.float64)
    lnx = np.log(np.where(c, x, 1.0)) if cloud else np.log(x)
    med = np.full(n_boot, np.nan)
    bet = np.full(n_boot, np.nan)
    for start, w in _chunks(f.shape[0], n_boot, seed, onehot.size):
        mm, bb, _, _ = _fit_counts("single", lnx, _category_counts(w, onehot, not cloud),
                                   not cloud)
        med[start:start + w.shape[0]], bet[start:start + w.shape[0]] = mm[:, 0], bb[:, 0]
    undefined = ~(np.isfinite(med) & np.isfinite(bet))
    med, bet = np.where(undefined, np.nan, med), np.where(undefined, np.nan, bet)
    return Bootstrap(_interval(med, ci), _interval(bet, ci), med, bet, int(undefined.sum()),
                     ci)


def _check_bootstrap(n: Any, curves: int) -> int:
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 0:
        raise FragilityError(f"bootstrap = {n!r}: must be an integer >= 0 (resamples)")
    if n > MAX_BOOTSTRAP:
        raise FragilityError(f"bootstrap = {n!r}: at most {MAX_BOOTSTRAP} resamples (their "
                             f"fits are kept: {n * curves * 16 / 2**30:.1f} GiB for "
                             f"{curves} curve{'s' * (curves != 1)})")
    return int(n)


# ---------------------------------------------------------------------------------------
# states
# ---------------------------------------------------------------------------------------


STATE_WORDS = (*STATES, THETA_STATE)


def parse_state(state: str) -> tuple[str, float]:
    """("overturn" | "mode1" | "mode2" | "uplift" | "theta", threshold) of a state word;
    "theta:X" is max|theta|/alpha_cg >= X (0 < X <= 1) or overturned."""
    if not isinstance(state, str):
        raise FragilityError(f"state = {state!r}: a state is a string, one of "
                             f"{', '.join(STATE_WORDS)} (or a list of them)")
    s = state.strip()
    if s in STATES:
        return s, math.nan
    if s.startswith("theta:"):
        try:
            x = float(s[6:])
        except ValueError:
            x = math.nan
        if math.isfinite(x) and 0.0 < x <= 1.0:
            return "theta", x
        raise FragilityError(f"state {state!r}: theta:X needs a number 0 < X <= 1 "
                             "(max|theta|/alpha_cg)")
    raise FragilityError(f"state {state!r}: expected one of {', '.join(STATE_WORDS)}")


def parse_states(state: Any) -> list[str]:
    """The list of state words of ``state`` (a word or a list/tuple of words), checked:
    each word ``parse_state``, none twice, at least one."""
    if isinstance(state, str):
        states = [state]
    elif isinstance(state, list | tuple):
        states = list(state)
    else:
        raise FragilityError(f"state = {state!r}: a state word or a list of them "
                             f"({', '.join(STATE_WORDS)})")
    if not states:
        raise FragilityError("state = []: give at least one state")
    for s in states:
        parse_state(s)
    if len({s.strip() for s in states}) != len(states):
        raise FragilityError(f"state = {states!r}: lists a state twice")
    return [s.strip() for s in states]


def severity(state: str) -> float:
    """Order of the nested damage states: uplift (0) < theta:X (X) < overturn (inf); NaN
    for the modes (not nested)."""
    kind, x = parse_state(state)
    return {UPLIFT: 0.0, "theta": x, OVERTURN: math.inf}.get(kind, math.nan)


def state_groups(states: Sequence[str]) -> list[tuple[str, list[int]]]:
    """How the states are fitted: [(kind, indices into states)]: "ordinal" for two or more
    nested damage states (uplift, theta:X, overturn; indices in severity order),
    "competing" for mode1 with mode2, "single" for every other one."""
    nested = sorted((i for i, s in enumerate(states) if not math.isnan(severity(s))),
                    key=lambda i: severity(states[i]))
    modes = [states.index(s) for s in (MODE1, MODE2) if s in states]
    groups: list[tuple[str, list[int]]] = []
    if len(nested) >= 2:
        groups.append(("ordinal", nested))
    else:
        groups += [("single", [i]) for i in nested]
    if len(modes) == 2:
        groups.append(("competing", modes))
    else:
        groups += [("single", [i]) for i in modes]
    return groups


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




def _check_args(ds: Any, im: Any, period: Any, seed: Any) -> None:
    if not isinstance(ds, xr.Dataset):
        raise FragilityError(f"ds = {type(ds).__name__}: must be a result Dataset "
                             "(rocksweep.run or rocksweep.open)")
    if im is not None and not isinstance(im, str):
        raise FragilityError(f"im = {im!r}: an IM name, one of {', '.join(STRIPE_IMS)}")
    if period is not None and (isinstance(period, bool) or not isinstance(
            period, int | float | np.integer | np.floating) or not math.isfinite(period)
            or period <= 0):
        raise FragilityError(f"period = {period!r}: a period in s (a number > 0, one of the "
                             "stored ground.periods), with im='Sa'")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise FragilityError("{seed}: must be an integer >= 0", seed=Arg("seed", seed))


def _refuse_filled(ds: xr.Dataset, states: Sequence[str], counted: xr.DataArray) -> None:
    """An adaptive sweep's filled points carry only the class: refuse states that need
    more (uplift, theta:X)."""
    if "computed" not in ds.variables:
        return
    from rocksweep.compute.adaptive import FILLED

    filled = (ds["computed"] == FILLED) & counted
    n = int(filled.sum())
    need = [s for s in states if parse_state(s)[0] in (UPLIFT, "theta")]
    if n and need:
        raise FragilityError(
            f"state {need[0]!r}: {n} points of this adaptive sweep were filled from the class "
            "around them, not computed, so their uplift and theta are unknown; only "
            f"{OVERTURN}, {MODE1} and {MODE2} can be fitted (a sweep that computes every "
            "point can give it)")


def _missing_text(not_run: np.ndarray, levels: np.ndarray | None, unit: str,
                  stripe: str | None, complete: Any, names: Sequence[str]) -> str:
    """'N points not computed (at PGA 1.2-1.6 g, records ...) left out' for one curve's
    not_run (R[, S])."""
    n = int(not_run.sum())
    where = []
    if levels is not None:
        miss = levels[not_run.reshape(not_run.shape[0], -1).any(0)]
        where.append(f"{stripe} {miss.min():.3g}-{miss.max():.3g} {unit}".rstrip())
    recs = [names[r] for r in np.flatnonzero(not_run.reshape(not_run.shape[0], -1).any(-1))]
    if len(recs) < len(names):
        where.append("record" + "s" * (len(recs) > 1) + " " + ", ".join(recs[:3])
                     + (f" and {len(recs) - 3} more" if len(recs) > 3 else ""))
    state = (" (the file is not complete: a sweep still running or stopped; a resume "
             "finishes it)") if complete in (0, False) else ""
    return f"{n} points not computed at {', '.join(where)} left out{state}" if where else \
        f"{n} points not computed left out{state}"


def fragility(ds: xr.Dataset, *, state: str | Sequence[str] = "overturn",
              im: str | None = None, period: float | None = None,
              bootstrap: int | None = None, seed: int = DEFAULT_SEED, ci: float = DEFAULT_CI,
              warn: bool = True) -> xr.Dataset:
    """Lognormal fragility curves of a record-suite sweep (Baker 2015) with their verdicts.

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
    (theta_max_over_alpha >= X or overturned, 0 < X <= 1). Two or more of uplift, theta:X,
    overturn are fitted as ordered damage states (one beta: the curves never cross);
    mode1 with mode2 as competing risks (module docstring). bootstrap: resamples over
    records (0: no intervals, NaN; None: ``DEFAULT_BOOTSTRAP``; at most
    ``MAX_BOOTSTRAP``); seed: the Generator's
    seed; ci: the interval's level; warn: a ``FragilityWarning`` per curve not "ok".

    Returns a Dataset over (state,) + other dims: ``im_median`` [IM units], ``beta`` [-],
    ``im_median_lo``, ``im_median_hi``, ``beta_lo``, ``beta_hi`` (bootstrap percentile
    interval), ``reason`` ("ok" or the verdict words joined by ","), ``fit`` (single,
    ordinal or competing), ``n_records`` (records with a counted point), ``n_excluded``
    (flagged points left out), ``n_not_run`` (outcome -1 points left out),
    ``n_boot_undefined``; over ``im_grid``: ``curve`` (the fitted P(state | x)),
    ``band_lo``, ``band_hi`` (pointwise bootstrap percentiles of the curve, NaN without
    bootstrap); with bootstrap, ``im_median_samples`` and ``beta_samples`` over
    ``sample`` (each resample's fit, NaN where it has none); stripes also: ``fraction``,
    ``n_failed`` over (state, others, stripe) and ``n_counted`` over (others, stripe), and
    per record ``first_level`` (smallest level that reaches the state; NaN if none) and
    ``resurrection`` (a higher counted level does not reach it) over (state, others,
    record). attrs: rocksweep_kind "fragility" (``analysis.kinds``), title (the sweep's),
    method ("stripes-mle" | "cloud-mle"), im, im_units, period (Sa), states, bootstrap,
    seed, ci, reference.
    """
    _check_args(ds, im, period, seed)
    bootstrap = DEFAULT_BOOTSTRAP if bootstrap is None else bootstrap
    states = parse_states(state)
    ci = check_ci(ci)
    _check_bootstrap(bootstrap, 1)
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
        if period is not None and not (stripe == "Sa" and math.isclose(
                float(period), per, rel_tol=1e-9)):
            raise FragilityError(f"period = {period!r}: the stripes are {stripe}"
                                 + (f" at T = {per:g} s" if stripe == "Sa" else "")
                                 + "; leave period out")
        method = "stripes-mle"
    else:
        if period is not None and (im is None or str(im) != "Sa"):
            raise FragilityError(f"period = {period!r}: only with im='Sa'")
        rec_im, im_name, unit, per = _cloud_im(ds, im, period)
        method = "cloud-mle"
    others = [d for d in out_da.dims if d not in ("record", stripe)]
    order = others + ["record"] + ([stripe] if stripe else [])
    counted_da, flagged_da, not_run_da = counted_points(ds)
    _refuse_filled(ds, states, counted_da)
    counted = counted_da.transpose(*order).values
    n_flag = flagged_da.transpose(*order).values
    n_nrun = not_run_da.transpose(*order).values
    hits = np.stack([state_reached(ds, s).transpose(*order).values for s in states])
    over_all = state_reached(ds, OVERTURN).transpose(*order).values
    shape_o = tuple(ds.sizes[d] for d in others)
    n_o = int(np.prod(shape_o)) if shape_o else 1
    R = ds.sizes["record"]
    tail = (R, ds.sizes[stripe]) if stripe else (R,)
    counted = counted.reshape((n_o,) + tail)
    n_flag = n_flag.reshape((n_o,) + tail)
    n_nrun = n_nrun.reshape((n_o,) + tail)
    hits = hits.reshape((len(states), n_o) + tail)
    over_all = over_all.reshape((n_o,) + tail)
    nS = len(states)
    N = _check_bootstrap(bootstrap, nS * n_o)

    grid = (np.geomspace(levels.min() / 2.0, levels.max() * 1.5, BAND_POINTS) if stripe else
            np.geomspace(rec_im.min() / 2.0, rec_im.max() * 1.5, BAND_POINTS))
    groups = state_groups(states)
    res = {v: np.full((nS, n_o), np.nan) for v in
           ("im_median", "beta", "im_median_lo", "im_median_hi", "beta_lo", "beta_hi")}
    why: list[list[dict[str, str]]] = [[{} for _ in range(n_o)] for _ in range(nS)]
    fit_kind = np.empty(nS, dtype=object)
    curve = np.full((nS, n_o, grid.size), np.nan)
    band = np.full((2, nS, n_o, grid.size), np.nan)
    samples = np.full((2, nS, n_o, N), np.nan)
    n_undef = np.zeros((nS, n_o), dtype=np.int64)
    n_records = counted.reshape(n_o, R, -1).any(-1).sum(-1)

    def onehot_of(kind: str, idxs: list[int], o: int, mask: np.ndarray) -> np.ndarray:
        """(C, R[, S]) float: each counted point (mask) in its category."""
        h = hits[idxs, o] & mask[None]
        if kind == "single":
            cat = h[0].astype(np.int64)
        else:  # ordinal: the most severe reached; competing: 1 mode 1, 2 mode 2
            cat = np.max(np.stack([(j + 1) * h[j] for j in range(len(idxs))]), 0)
        C = len(idxs) + 1
        return np.stack([(cat == c) & mask for c in range(C)]).astype(np.float64)

    lnx = np.log(levels) if stripe else np.log(rec_im)
    for o in range(n_o):
        for kind, idxs in groups:
            for i in idxs:
                fit_kind[i] = kind
            oh = onehot_of(kind, idxs, o, counted[o])
            m = _category_counts(np.ones((1, R)), oh, bool(stripe))
            med, bet, code, und = _fit_counts(kind, lnx, m, bool(stripe))
            cur = _curves(kind, grid, med[0], bet[0])
            for q, i in enumerate(idxs):
                res["im_median"][i, o], res["beta"][i, o] = med[0, q], bet[0, q]
                curve[i, o] = cur[q]
                w = why[i][o]
                w[ENDINGS[int(code[0, q])]] = ""
                if und[0, q]:
                    c = ENDINGS[int(code[0, q])]
                    w["beta_undetermined"] = (
                        "one IM level counted" if c == "one_stripe" else
                        "separated data: the likelihood grows as beta -> 0" if c == "separated"
                        else "fewer than 2 distinct stripe fractions strictly between 0 and 1")
            _verdicts(kind, idxs, o, lnx, m, med[0], bet[0], why, counted[o], n_flag[o],
                      hits, over_all[o], states, bool(stripe), onehot_of)
    if N:
        per_fit = max(R * (levels.size if stripe else 1), 1) * 3
        for start, w in _chunks(R, N, seed, per_fit):
            sl = slice(start, start + w.shape[0])
            for o in range(n_o):
                for kind, idxs in groups:
                    oh = onehot_of(kind, idxs, o, counted[o])
                    st = (res["im_median"][idxs, o], res["beta"][idxs, o])
                    med, bet, _, _ = _fit_counts(kind, lnx, _category_counts(
                        w, oh, bool(stripe)), bool(stripe), start=st)
                    bad = ~(np.isfinite(med) & np.isfinite(bet))
                    med[bad], bet[bad] = np.nan, np.nan
                    for q, i in enumerate(idxs):
                        samples[0, i, o, sl], samples[1, i, o, sl] = med[:, q], bet[:, q]
        q = 100.0 * np.array([(1.0 - ci) / 2.0, (1.0 + ci) / 2.0])
        for o in range(n_o):
            for kind, idxs in groups:
                med_s = samples[0, idxs, o].T  # (N, G)
                bet_s = samples[1, idxs, o].T
                # (the intervals use every resample; the band the first BAND_SAMPLES)
                for q_i, i in enumerate(idxs):
                    fin = np.isfinite(med_s[:, q_i])
                    n_undef[i, o] = int((~fin).sum())
                    lo_hi = _interval(med_s[:, q_i], ci), _interval(bet_s[:, q_i], ci)
                    (res["im_median_lo"][i, o], res["im_median_hi"][i, o]) = lo_hi[0]
                    (res["beta_lo"][i, o], res["beta_hi"][i, o]) = lo_hi[1]
                    if n_undef[i, o] > N * (1.0 - ci) / 2.0 and np.isfinite(
                            res["im_median"][i, o]):
                        why[i][o]["bootstrap_undefined"] = (
                            f"{n_undef[i, o]} of {N} resamples without a finite fit")
                med_s, bet_s = med_s[:BAND_SAMPLES], bet_s[:BAND_SAMPLES]
                rows = (np.all(np.isfinite(med_s) & np.isfinite(bet_s), -1)
                        if kind == "competing" else None)
                step = max(1, BOOT_ELEMENTS // max(med_s.shape[0] * len(idxs), 1))
                for g0 in range(0, grid.size, step):
                    gs = slice(g0, g0 + step)
                    cur = _curves(kind, grid[gs], med_s if rows is None else med_s[rows],
                                  bet_s if rows is None else bet_s[rows])  # (N', G, X)
                    for q_i, i in enumerate(idxs):
                        c = cur[:, q_i]
                        c = c[np.all(np.isfinite(c), -1)]
                        if c.shape[0]:
                            band[:, i, o, gs] = np.percentile(c, q, axis=0)
    for o in range(n_o):
        if n_nrun[o].any():
            text = _missing_text(n_nrun[o], levels if stripe else None, unit, stripe,
                                 ds.attrs.get("complete"), names)
            for i in range(nS):
                why[i][o]["incomplete"] = text
    reason = np.array([[_words(why[i][o]) for o in range(n_o)] for i in range(nS)],
                      dtype=object)

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
    data["im_median"] = (dims_c, shaped(res["im_median"]),
                         {"units": unit, "long_name": f"median {im_name} of the fragility"})
    data["beta"] = (dims_c, shaped(res["beta"]),
                    {"units": "1", "long_name": "lognormal standard deviation"})
    for v in ("im_median_lo", "im_median_hi", "beta_lo", "beta_hi"):
        data[v] = (dims_c, shaped(res[v]),
                   {"units": unit if v.startswith("im_median") else "1",
                    "long_name": f"bootstrap {ci:g} percentile interval bound"})
    data["reason"] = (dims_c, shaped(reason.astype(str)),
                      {"long_name": "verdict: ok, or the reasons joined by ',' (" +
                                    ", ".join(REASONS[1:]) + ")"})
    data["fit"] = (lead, fit_kind.astype(str) if lead else str(fit_kind[0]),
                   {"long_name": "how the state was fitted: single, ordinal (damage states, "
                                 "one beta) or competing (mode1 with mode2)"})
    data["n_boot_undefined"] = (dims_c, shaped(n_undef),
                                {"long_name": "bootstrap resamples without a finite fit"})
    data["n_records"] = (others, n_records.reshape(shape_o).astype(np.int64),
                         {"long_name": "records with at least one counted point"})
    data["n_excluded"] = (others, n_flag.reshape(n_o, -1).sum(-1).reshape(shape_o),
                          {"long_name": "flagged points (status & STATUS_FLAGGED) left out"})
    data["n_not_run"] = (others, n_nrun.reshape(n_o, -1).sum(-1).reshape(shape_o),
                         {"long_name": "points not computed (outcome -1) left out"})
    data["curve"] = (dims_c + ["im_grid"], shaped(curve, (grid.size,)),
                     {"long_name": "fitted probability of the state"})
    data["band_lo"] = (dims_c + ["im_grid"], shaped(band[0], (grid.size,)),
                       {"long_name": f"bootstrap {ci:g} band, lower (pointwise)"})
    data["band_hi"] = (dims_c + ["im_grid"], shaped(band[1], (grid.size,)),
                       {"long_name": f"bootstrap {ci:g} band, upper (pointwise)"})
    if N:
        data["im_median_samples"] = (dims_c + ["sample"], shaped(samples[0], (N,)),
                                     {"units": unit, "long_name": "im_median of each "
                                      "bootstrap resample (NaN: no finite fit)"})
        data["beta_samples"] = (dims_c + ["sample"], shaped(samples[1], (N,)),
                                {"units": "1", "long_name": "beta of each bootstrap "
                                 "resample (NaN: no finite fit)"})
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
    attrs = {"rocksweep_kind": "fragility", "title": str(ds.attrs.get("title", "")),
             "method": method, "im": im_name, "im_units": unit, "states": list(states),
             "bootstrap": int(N), "seed": int(seed), "ci": float(ci),
             "reference": "Baker (2015), Efficient analytical fragility function fitting "
                          "using dynamic structural analysis, Earthquake Spectra 31(1)"}
    if im_name == "Sa":
        attrs["period"] = per
    out = xr.Dataset(data, coords=coords, attrs=attrs)
    if warn:
        for text in verdict_lines(out, why):
            warnings.warn(text, FragilityWarning, stacklevel=2)
    return out


def _verdicts(kind, idxs, o, lnx, m, med, bet, why, counted, flagged, hits, over_all,
              states, stripes, onehot_of) -> None:
    """The data verdicts of one group's point fit (in ``why``): extrapolated,
    non_monotone (stripes), censored (a mode alone), flagged (the excluded points could
    move it)."""
    n = m[0].sum(0)
    pts = np.exp(lnx[n > 0]) if stripes else np.exp(lnx[counted.astype(bool)])
    for q, i in enumerate(idxs):
        w = why[i][o]
        if pts.size:
            ext = _outside(float(pts.min()), float(pts.max()), float(med[q]), float(bet[q]))
            if ext:
                w["extrapolated"] = ext
        if stripes and kind != "competing":
            k = m[0, q + 1:].sum(0)
            p = lognormal_cdf(np.exp(lnx), med[q], bet[q])
            if _non_monotone(lnx, k, n, p):
                w["non_monotone"] = "the stripe fractions fall with the IM beyond noise"
        elif stripes:  # null: the fitted competing-risk probability of this mode
            k = m[0, q + 1]
            p = _curves("competing", np.exp(lnx), np.asarray(med), np.asarray(bet))[q]
            if _non_monotone(lnx, k, n, p):
                w["non_monotone"] = ("the stripe fractions fall with the IM beyond noise "
                                     "(a competing-risk curve cannot fall)")
        kw = states[i]
        if kind == "single" and kw in (MODE1, MODE2):
            own = hits[i, o] & counted
            over = over_all & counted
            other = int(over.sum() - own.sum())
            if over.sum() and other >= CENSORED_SHARE * over.sum():
                w["censored"] = (f"the other mode holds {other} of {int(over.sum())} "
                                 "overturning points; fit mode1 and mode2 together")
    if flagged.any():
        base = np.array([med[q] for q in range(len(idxs))])
        for as_cat in (0, len(idxs)):
            oh = onehot_of(kind, idxs, o, counted)
            oh[as_cat] += flagged
            mm, _, _, _ = _fit_counts(kind, lnx, _category_counts(np.ones((1, counted.shape[0])),
                                                                  oh, stripes), stripes)
            for q, i in enumerate(idxs):
                a, b = base[q], mm[0, q]
                moved = (np.isfinite(a) != np.isfinite(b)) or (
                    np.isfinite(a) and abs(b / a - 1.0) > FLAGGED_SHIFT)
                if moved:
                    why[i][o]["flagged"] = (f"{int(flagged.sum())} flagged points left out "
                                            "could move im_median")


def verdict_lines(frag: xr.Dataset, why: list[list[dict[str, str]]] | None = None
                  ) -> list[str]:
    """One line per curve of a ``fragility`` Dataset whose ``reason`` is not "ok": where,
    which state, and why (with the numbers of ``why[state][curve]`` when given)."""
    lines = []
    reason = frag["reason"]
    dims = [d for d in reason.dims if d != "state"]
    states = (list(frag["state"].values) if "state" in reason.dims
              else [frag["state"].item()])
    shape = tuple(frag.sizes[d] for d in dims)
    for si, st in enumerate(states):
        for o, pos in enumerate(np.ndindex(*shape)):
            sel = dict(zip(dims, pos, strict=True))
            one = reason.isel(sel)
            if "state" in reason.dims:
                one = one.isel(state=si)
            words = str(one.values)
            if words == "ok":
                continue
            where = ", ".join(f"{d} = {_json(frag[d].values[i]) if d in frag.coords else i}"
                              for d, i in sel.items())
            detail = why[si][o] if why is not None else {}
            parts = [f"{wd} ({detail[wd]})" if detail.get(wd) else wd
                     for wd in words.split(",")]
            lines.append(f"fragility{' ' + where if where else ''}, state {st}: "
                         + "; ".join(parts))
    return lines


def probability(frag: xr.Dataset, x: Sequence[float] | np.ndarray) -> xr.DataArray:
    """P(state | IM = x) of every curve of a ``fragility`` Dataset at the IMs x (float[X] >
    0, the fragility's IM units), by each state's model (``fit``): the lognormal CDF
    Phi(ln(x / im_median) / beta) for "single" and "ordinal" fits, the competing-risk
    probabilities P(C_k <= x, C_k < C_other) for "competing" (mode1 with mode2: not a
    lognormal CDF of their im_median and beta). NaN where a fit has no curve. Returns a
    DataArray over ``im_median``'s dims + ("im",)."""
    xs = np.asarray(x, dtype=np.float64).ravel()
    if np.any(~np.isfinite(xs) | (xs <= 0.0)):
        raise FragilityError("x: every IM must be finite and > 0")
    med_da = frag["im_median"]
    lead = "state" in med_da.dims
    dims = [d for d in med_da.dims if d != "state"]
    med = med_da.transpose(*(["state"] if lead else []), *dims).values
    bet = frag["beta"].transpose(*(["state"] if lead else []), *dims).values
    med, bet = (np.asarray(a, dtype=np.float64) if lead else np.asarray(a)[None]
                for a in (med, bet))
    kinds = np.atleast_1d(np.asarray(frag["fit"].values)) if "fit" in frag else \
        np.array(["single"] * med.shape[0])
    states = list(np.atleast_1d(np.asarray(frag["state"].values)))
    out = np.full(med.shape + (xs.size,), np.nan)
    for i, kind in enumerate(kinds):
        if kind == "competing":
            j1, j2 = states.index(MODE1), states.index(MODE2)
            m = np.stack([med[j1], med[j2]], -1)
            b = np.stack([bet[j1], bet[j2]], -1)
            both = _curves("competing", xs, m, b)
            out[i] = both[..., 0 if states[i] == MODE1 else 1, :]
        else:
            out[i] = lognormal_cdf(xs, med[i][..., None], bet[i][..., None])
    if not lead:
        out = out[0]
    return xr.DataArray(out, dims=[*(["state"] if lead else []), *dims, "im"],
                        coords={**{d: frag[d] for d in dims if d in frag.coords},
                                "state": frag["state"], "im": xs},
                        attrs={"long_name": "probability of the state", "units": "1"})


def lognormal_cdf(x, median, beta) -> np.ndarray:
    """Phi(ln(x / median) / beta), broadcast; beta = 0 is the step at the median, NaN
    beta (undetermined) gives NaN."""
    x, median, beta = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64)
                                            for v in (x, median, beta)))
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.log(x / median) / beta
    step = np.where(x >= median, 1.0, 0.0)
    return np.where(beta > 0.0, ndtr(z),
                    np.where(np.isnan(median) | np.isnan(beta), np.nan, step))



def _json(v: Any) -> Any:
    return plain(v, nan_to_none=True)

def curves_json(frag: xr.Dataset) -> dict:
    """{"curves": [{<other dims>: value, "state", "im", "method", "fit", "im_median",
    "beta", "im_median_ci": [lo, hi], "beta_ci": [lo, hi], "n_records", "n_excluded",
    "n_not_run", "n_boot_undefined", "reason"},
    ...]} with plain Python numbers (NaN as None), one entry per curve of ``fragility``."""
    others = [d for d in frag["im_median"].dims if d != "state"]
    states = (list(frag["state"].values) if "state" in frag["im_median"].dims
              else [frag["state"].item()])
    curves = []
    shape = tuple(frag.sizes[d] for d in others)
    for st_i, st in enumerate(states):
        for pos in np.ndindex(*shape):
            sel = dict(zip(others, pos, strict=True))
            one = frag.isel(sel)
            if "state" in frag["im_median"].dims:
                one = one.isel(state=st_i)
            entry: dict[str, Any] = {d: _json(frag[d].values[i]) if d in frag.coords
                                     else int(i) for d, i in sel.items()}
            entry.update({
                "state": str(st), "im": frag.attrs["im"], "method": frag.attrs["method"],
                "fit": str(one["fit"].values),
                "im_median": _json(float(one["im_median"])),
                "beta": _json(float(one["beta"])),
                "im_median_ci": [_json(float(one["im_median_lo"])),
                                 _json(float(one["im_median_hi"]))],
                "beta_ci": [_json(float(one["beta_lo"])), _json(float(one["beta_hi"]))],
                "n_records": int(one["n_records"]), "n_excluded": int(one["n_excluded"]),
                "n_not_run": int(one["n_not_run"]),
                "n_boot_undefined": int(one["n_boot_undefined"]),
                "reason": str(one["reason"].values),
            })
            curves.append(entry)
    return {"curves": curves}
