"""The likelihoods of the fragility fits and their maximisers, batched over data sets
(bootstrap resamples): numpy and scipy only (``rocksweep.analysis.fragility`` turns their
answers into states, verdicts and a Dataset).

Reference: J. W. Baker (2015), "Efficient analytical fragility function fitting using
dynamic structural analysis", Earthquake Spectra 31(1), 579-599.

- One state (``mle_batch``): the product of binomials prod_j C(n_j, k_j) p_j^k_j
  (1 - p_j)^(n_j - k_j), p_j = Phi(ln(x_j / im_median) / beta) (Baker 2015, eq. 11); a cloud
  is the same likelihood with n_i = 1. It is evaluated with log Phi for p and for 1 - p, so a
  stripe with k = 0 or k = n never meets log 0 (the guard that clipping p to [eps, 1 - eps]
  gives, without the bias clipping adds), and maximised over (a, b) of Phi(a + b ln x), the
  probit generalised linear model on ln IM, by Fisher scoring with step halving: that
  log-likelihood is concave, so the maximum is unique when it exists, and by the invariance
  of maximum likelihood it gives im_median = exp(-a / b), beta = 1 / b.
- Ordered damage states (``_fit_ordinal``): an ordinal (cumulative) probit with a common
  beta, P(DS >= j | x) = Phi(ln(x / im_median_j) / beta), im_median_1 <= ... by
  construction; the multinomial likelihood of the category counts (the most severe state
  each point reaches).
- mode1 with mode2 (``_fit_competing``): competing risks with independent lognormal
  capacities C_1, C_2; P(safe | x) = S_1(x) S_2(x), P(mode k | x) = P(C_k <= x, C_k <
  C_other) (a bivariate normal probability, ``joint_models.cif``); the multinomial
  likelihood of (safe, mode 1, mode 2) counts.

The joint fits are maximised by a batched Levenberg-Marquardt ascent (``_maximise``).
``fit_counts`` fits one group of states from category counts; ``resample_weights`` draws
the bootstrap's resamples over records as count weights, in chunks of bounded memory.
Every fit returns an ending code into ``ENDINGS`` per data set.

Convergence (every maximiser here): a fit has converged when, at the point where its
ascent stops, the undamped scoring step d = I^-1 U (U the gradient, I the information) is
below the step tolerance, |d|_inf < tol (1 + |theta|_inf), or the rise it predicts, U . d /
2, is below ``RISE_TOL`` (1 + |loglik|). An ascent that stops otherwise (its iteration cap,
no step that raises the likelihood, a parameter running away) is "not_converged", never
"ok".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.special import log_ndtr, ndtr, ndtri

from rocksweep.analysis.joint_models import (
    cif,
    cif_jac,
    free_ordinal_jac,
    free_ordinal_probs,
    ordinal_jac,
    ordinal_probs,
)
from rocksweep.analysis.resampling import (
    DEFAULT_BOOTSTRAP,
    DEFAULT_CI,
    DEFAULT_SEED,
    MAX_BOOTSTRAP,
    check_ci,
)
from rocksweep.errors import FragilityError

#: how a fit ended (the codes the batched fits return are indices into this)
ENDINGS = ("ok", "no_failures", "all_failed", "separated", "decreasing", "no_data",
           "one_stripe", "not_converged")
CODE = {w: i for i, w in enumerate(ENDINGS)}
#: endings that say all there is (nothing reaches the state, all do, nothing counted)
EMPTY = [CODE[w] for w in ("no_failures", "all_failed", "no_data")]
#: the smallest competing-risk probability ``cif`` resolves (Owen's T: differences of O(1)
#: terms, absolute error ~1e-16)
COMPETING_RESOLVED = 1e-12
#: resamples are fitted in chunks of at most this many count entries (bounded memory)
BOOT_ELEMENTS = 1 << 20
#: iteration caps of the single-state scoring (``_score``) and the joint ascent
#: (``_maximise``): a row still moving after them is "not_converged"
SCORE_ITER = 200
MAX_ITER = 100
#: a fit has converged when the undamped scoring step from its point is below its step
#: tolerance, or the rise that step predicts, U . I^-1 U / 2, is below this share of
#: 1 + |loglik| (the rounding of a sum of ~1e4 log terms: no step can be told from none)
RISE_TOL = 1e-12


# ---------------------------------------------------------------------------------------
# the binomial likelihood and its maximisation (batched)
# ---------------------------------------------------------------------------------------


def mle_batch(lnx: np.ndarray, k: np.ndarray, n: np.ndarray,
               start: tuple[float, float] | None = None, tol: float = 1e-10
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MLE of the lognormal fragility for a batch of data sets.

    lnx, k, n: float64 (B, S): ln IM, points reaching the state, points counted (n = 0: the
    entry is absent); start: (im_median, beta) to start the scoring from (resamples: the
    full data's fit), tol: its relative tolerance. Returns (im_median (B,), beta (B,),
    ending code (B,) into ENDINGS); separated data give the step's IM and beta = NaN; a
    scoring that stops without converging (module docstring) NaN, NaN, "not_converged".
    """
    lnx, k, n = (np.atleast_2d(np.asarray(v, dtype=np.float64)) for v in (lnx, k, n))
    lnx = np.broadcast_to(lnx, k.shape)
    B = k.shape[0]
    median = np.full(B, np.nan)
    beta = np.full(B, np.nan)
    reason = empty_ending(k, n)
    has = n > 0
    fails = has & (k > 0)
    safes = has & (n - k > 0)
    both = reason == CODE["ok"]
    x_safe_max = np.where(safes, lnx, -np.inf).max(-1)
    x_fail_min = np.where(fails, lnx, np.inf).min(-1)
    sep = both & (x_fail_min >= x_safe_max)
    reason[sep] = CODE["separated"]
    median[sep] = np.exp(0.5 * (x_fail_min[sep] + x_safe_max[sep]))
    todo = both & ~sep
    if np.any(todo):
        st = None
        if start is not None and np.all(np.isfinite(start)) and start[1] > 0:
            st = np.broadcast_to([-math.log(start[0]) / start[1], 1.0 / start[1]],
                                 (int(todo.sum()), 2))
        a, b, conv = _score(lnx[todo], k[todo], n[todo], tol=tol, start=st)
        med, bet, rsn = np.full(a.size, np.nan), np.full(a.size, np.nan), np.zeros(a.size, int)
        up = b > 0.0
        med[up] = np.exp(-a[up] / b[up])
        bet[up] = 1.0 / b[up]
        rsn[~up] = CODE["decreasing"]
        med[~conv], bet[~conv], rsn[~conv] = np.nan, np.nan, CODE["not_converged"]
        median[todo], beta[todo], reason[todo] = med, bet, rsn
    return median, beta, reason


def empty_ending(k: np.ndarray, n: np.ndarray) -> np.ndarray:
    """How a fit of counts k of n (B, S) ends before any fitting: "no_failures" (no
    counted point reaches the state), "all_failed" (every one does), "no_data" (none
    counted), else "ok" (a fit is needed): int (B,) codes into ENDINGS."""
    has = n > 0
    nk = (has & (k > 0)).any(-1)
    ns = (has & (n - k > 0)).any(-1)
    reason = np.zeros(k.shape[0], dtype=np.int64)
    reason[~nk] = CODE["no_failures"]
    reason[nk & ~ns] = CODE["all_failed"]
    reason[~has.any(-1)] = CODE["no_data"]
    return reason


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


def _score(lnx: np.ndarray, k: np.ndarray, n: np.ndarray, iters: int | None = None,
           tol: float = 1e-10, start: np.ndarray | None = None
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fisher scoring with step halving for Phi(a + b lnx), batched over rows (each row
    has points on both sides: the maximum exists). start: (B, 2) (a, b) to start from
    (bootstrap resamples: the full data's fit; then Newton steps on the observed
    information, which converge in a few steps from there); default the pooled fraction,
    slope 0. A row stops when its accepted step is below tol (relative), or when halving
    finds no step that does not lower the likelihood; it has converged if the full
    scoring step from where it stopped meets the module docstring's test (else it goes
    on: a halved step is small because it was halved). iters: at most this many steps
    (None: ``SCORE_ITER``). Returns (a, b, converged) per row."""
    iters = SCORE_ITER if iters is None else iters
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
    conv = np.zeros(frac.size, dtype=bool)
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
        scale = 1.0 + np.abs(c_new).max(-1)
        # the test on the full step from the point just left (a point no worse is kept)
        met = (np.maximum(np.abs(d0), np.abs(d1)) < tol * scale) | (
            0.5 * (U0 * d0 + U1 * d1) <= RISE_TOL * (1.0 + np.abs(ll0)))
        c[idx] = c_new
        eta[idx] = c_new[:, :1] + c_new[:, 1:] * zz
        ll[idx] = ll_new
        lpos[idx], lneg[idx] = lp_new, ln_new
        stop = ((delta < tol * scale) & met) | pending
        conv[idx[stop & met]] = True
        active[idx[stop]] = False
    a = c[:, 0] - c[:, 1] * m[:, 0] / s[:, 0]
    b = c[:, 1] / s[:, 0]
    return a, b, conv


def distinct_inner(lnx: np.ndarray, k: np.ndarray, n: np.ndarray) -> tuple[np.ndarray,
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


def stripe_rules(lnx: np.ndarray, k: np.ndarray, n: np.ndarray, med: np.ndarray,
                 beta: np.ndarray, code: np.ndarray) -> np.ndarray:
    """The stripe-only rules on batched fits (in place): one counted level -> NaN, NaN,
    "one_stripe"; fewer than two distinct inner fractions (or separation) -> beta NaN.
    Returns bool (B,) "beta_undetermined"."""
    levels, distinct = distinct_inner(lnx, k, n)
    one = (levels == 1) & ~np.isin(code, EMPTY)
    med[one], beta[one] = np.nan, np.nan
    code[one] = CODE["one_stripe"]
    few = (distinct < 2) & (code == CODE["ok"])
    beta[few] = np.nan
    return one | few | (code == CODE["separated"])


def isotonic_fit(k: np.ndarray, n: np.ndarray) -> np.ndarray:
    """The weighted isotonic (non-decreasing) fit of the fractions k / n: float64 (B, S)
    for binomial counts k (B, S) of n (S,) > 0, stripes in increasing IM. Pool adjacent
    violators, row by row: each stripe is pushed as a block and merged with the block
    before it while that one's mean is larger (each stripe pushed once, merged away at
    most once: O(S) per row, O(B S) memory). Plain Python lists: on 400 x 2000 counts
    ~3x faster than the same stack vectorised over rows."""
    k = np.asarray(k, np.float64)
    n = np.asarray(n, np.float64)
    B, S = k.shape
    iso = np.empty((B, S))
    weights = n.tolist()
    for b in range(B):
        ks: list[float] = []  # the blocks: sum of k, sum of n, first stripe
        ns: list[float] = []
        first: list[int] = []
        for s, (kk, nn) in enumerate(zip(k[b].tolist(), weights, strict=True)):
            ks.append(kk)
            ns.append(nn)
            first.append(s)
            # mean(block before) > mean(last block), without dividing (sums of n > 0)
            while len(ks) > 1 and ks[-2] * ns[-1] > ks[-1] * ns[-2]:
                k_last, n_last = ks.pop(), ns.pop()
                first.pop()
                ks[-1] += k_last
                ns[-1] += n_last
        iso[b] = np.repeat(np.array(ks) / np.array(ns), np.diff(np.append(first, S)))
    return iso


def isotonic_lr(k: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Likelihood-ratio statistic 2 (ll(free fractions) - ll(isotonic fractions)) of
    binomial counts k (B, S) of n (S,) > 0, stripes in increasing IM (``isotonic_fit``):
    float64 (B,)."""
    k = np.asarray(k, np.float64)
    n = np.asarray(n, np.float64)
    iso = isotonic_fit(k, n)
    free = k / n

    def xlogy(a, b):
        return np.where(a > 0, a * np.log(np.where(b > 0, b, 1.0)), 0.0)

    return 2.0 * np.sum(xlogy(k, free) - xlogy(k, iso) + xlogy(n - k, 1.0 - free)
                        - xlogy(n - k, 1.0 - iso), -1)


# ---------------------------------------------------------------------------------------
# joint fits: a batched Levenberg-Marquardt ascent
# ---------------------------------------------------------------------------------------


def _multinomial_ll(p: np.ndarray, m: np.ndarray) -> np.ndarray:
    """sum over (C, P) of m log p (m = 0 terms are 0 even where p = 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sum(np.where(m > 0, m * np.log(np.maximum(p, 1e-300)), 0.0), (1, 2))


def _maximise(prob: Callable[[np.ndarray, np.ndarray], np.ndarray], m: np.ndarray,
              theta0: np.ndarray, limit: np.ndarray, iters: int | None = None,
              tol: float = 1e-10,
              jac: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
              resolved: float = 1e-300) -> tuple[np.ndarray, np.ndarray]:
    """Maximum likelihood of multinomial counts m (B, C, P) (C categories at P IM levels)
    under probabilities prob(theta (b, p), rows (b,)) -> (b, C, P), for every row of
    theta0 (B, p): Fisher scoring (information sum over c, s of n_s J J^T / p, J = dp /
    dtheta (b, p, C, P): ``jac(theta, rows)`` if given, else central differences),
    damped (Levenberg-Marquardt) until the likelihood rises. A row whose |theta| passes
    ``limit`` (p,) runs away to a boundary (separated data: no maximum) and stops, not
    converged. resolved: the smallest probability prob resolves (a difference of O(1)
    terms loses the rest): cells below it leave the information (an exact ``jac`` there
    against a p that cancelled to ~0 would make J^2 / p explode and stall the ascent); the
    gradient keeps them, so the maximum is the same. A row stops when an accepted step is
    below tol (relative) or leaves the likelihood flat, or when no damping finds a step
    that raises it; it has converged only if the undamped step from where it stopped meets
    the module docstring's test (a step small because it was damped goes on). iters: at
    most this many steps (None: ``MAX_ITER``). Returns (theta (B, p), converged (B,))."""
    iters = MAX_ITER if iters is None else iters
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
        if jac is not None:
            J = jac(t, idx)
        else:
            both = np.concatenate([t[:, None, :] + h * eye, t[:, None, :] - h * eye], 1)
            vals = prob(both.reshape(-1, P), np.repeat(idx, 2 * P)).reshape(
                (idx.size, 2 * P) + pr.shape[1:])
            J = (vals[:, :P] - vals[:, P:]) / (2.0 * h)  # (b, p, C, P)
        inv = 1.0 / np.maximum(pr[idx], 1e-300)
        g = np.einsum("bkcs,bcs->bk", J, m[idx] * inv)
        if resolved > 1e-300:
            inv = np.where(pr[idx] >= resolved, inv, 0.0)
        info = np.einsum("bkcs,bjcs,bcs->bkj", J, J, n[idx][:, None, :] * inv)
        f0 = ll[idx]
        bad = ~(np.all(np.isfinite(g), -1) & np.all(np.isfinite(info), (-1, -2)))
        pending = ~bad
        done_rows = np.zeros(idx.size, bool)
        ends = np.zeros(idx.size, bool)  # an accepted step small or flat: test the point
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
            ends[acc[small | flat]] = True
            pending[acc] = False
            rej = pi[~up]
            lam[idx[rej]] = np.maximum(lam[idx[rej]] * 10.0, 1e-4)
            stuck = rej[lam[idx[rej]] > 1e12]
            done_rows[stuck] = True
            pending[stuck] = False
        # the test at the point each stopping row's last step left (only those rows)
        met = np.zeros(idx.size, bool)
        test = np.flatnonzero(ends | done_rows)
        met[test] = _scoring_met(g[test], info[test], t[test], f0[test], tol)
        done_rows |= ends & met
        away = np.any(np.abs(th[idx]) > limit, -1)
        conv[idx[done_rows & met & ~away]] = True
        active[idx[done_rows | bad | away]] = False
    return th, conv


def _scoring_met(g: np.ndarray, info: np.ndarray, theta: np.ndarray, ll: np.ndarray,
                 tol: float) -> np.ndarray:
    """The convergence test (module docstring) at points theta (b, p) with gradient g (b,
    p), information info (b, p, p) and log-likelihood ll (b,): bool (b,)."""
    if g.shape[0] == 0:
        return np.zeros(0, bool)
    try:
        d = np.linalg.solve(info, g[..., None])[..., 0]
    except np.linalg.LinAlgError:  # a singular information: the least-norm step
        d = np.stack([np.linalg.lstsq(a, b, rcond=None)[0] for a, b in
                      zip(info, g, strict=True)])
    small = np.abs(d).max(-1) < tol * (1.0 + np.abs(theta).max(-1))
    rise = 0.5 * np.sum(g * d, -1) <= RISE_TOL * (1.0 + np.abs(ll))
    return np.all(np.isfinite(d), -1) & (small | rise)


def _standardise(lnx: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(m, s) (B,) the n-weighted mean and spread of ln x per row (s = 1 if 0)."""
    w = n / np.maximum(n.sum(-1, keepdims=True), 1e-300)
    m = np.sum(w * lnx, -1)
    s = np.sqrt(np.sum(w * (lnx - m[:, None]) ** 2, -1))
    return m, np.where(s > 0.0, s, 1.0)


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
        return np.exp(ordinal_probs(z[rows], theta))

    limit = np.array([60.0] + [40.0] * (K - 1) + [15.0])
    def jac(theta: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return ordinal_jac(z[rows], theta)

    theta, conv = _maximise(prob, m, theta0, limit, tol=1e-10 if start is None else 1e-7,
                            jac=jac)
    t = np.cumsum(np.concatenate([theta[:, :1], np.exp(theta[:, 1:K])], 1), 1)
    s = np.exp(theta[:, K])
    return np.exp(mu[:, None] + sd[:, None] * t), sd / s, conv


def parallel_lr(lnx: np.ndarray, m: np.ndarray, med: np.ndarray, beta: float
                ) -> tuple[float, int, bool]:
    """The likelihood-ratio test of the ordinal probit's common beta: (2 (ll_free -
    ll_common), degrees of freedom K - 1) for category counts m (K+1, P) at ln IM lnx (P,)
    and the common-beta fit (im_median (K,), beta). ll_free is the multinomial likelihood
    maximised with a beta per state, P(DS >= j) = Phi(ln(x / im_median_j) / beta_j) (the
    non-parallel, generalised ordinal probit), started from the common fit: the ascent
    only accepts steps that raise it, so the statistic is >= 0. Curves that cross where
    there are counts make a category's probability 0 (the likelihood -inf there).
    Returns (statistic, dof, converged): a free fit that did not converge (module
    docstring) gives a lower bound of the statistic."""
    K = m.shape[0] - 1
    n = m.sum(0)
    mu, sd = _standardise(lnx[None], n[None])
    z = (lnx - mu[0]) / sd[0]

    def prob(theta: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return free_ordinal_probs(z, theta)

    def jac(theta: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return free_ordinal_jac(z, theta)

    t0 = (np.log(np.asarray(med, np.float64)) - mu[0]) / sd[0]
    theta0 = np.concatenate([t0, np.full(K, np.log(sd[0] / beta))])[None]
    common = _multinomial_ll(prob(theta0, np.zeros(1, np.int64)), m[None])[0]
    limit = np.array([60.0] * K + [15.0] * K)
    theta, conv = _maximise(prob, m[None], theta0, limit, tol=1e-9, jac=jac)
    free = _multinomial_ll(prob(theta, np.zeros(1, np.int64)), m[None])[0]
    return max(0.0, 2.0 * float(free - common)), K - 1, bool(conv[0])


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
        return np.stack(cif(z[rows], theta[:, [0, 2]], np.exp(theta[:, [1, 3]])), 1)

    def jac(theta: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return cif_jac(z[rows], theta[:, [0, 2]], np.exp(theta[:, [1, 3]]))

    th0 = np.where(np.isfinite(th0), th0, 0.0)
    theta, conv = _maximise(prob, counts, th0, np.array([60.0, 12.0, 60.0, 12.0]),
                            tol=1e-10 if tol is None else tol, jac=jac,
                            resolved=COMPETING_RESOLVED)
    with np.errstate(over="ignore"):
        med = np.exp(mu[:, None] + sd[:, None] * theta[:, [0, 2]])
        beta = sd[:, None] * np.exp(theta[:, [1, 3]])
    ok = conv & np.all(np.abs(theta[:, [0, 2]]) < 60.0, -1) & np.all(
        (theta[:, [1, 3]] > -12.0) & (theta[:, [1, 3]] < 8.0), -1)
    return med, beta, ok


# ---------------------------------------------------------------------------------------
# fits of a group of states from category counts (batched over resamples)
# ---------------------------------------------------------------------------------------


def fit_counts(kind: str, lnx: np.ndarray, m: np.ndarray, stripes: bool,
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
        med, bet, code = (mle_batch(lnxb, m[:, 1], n) if start is None else
                          mle_batch(lnxb, m[:, 1], n, (start[0][0], start[1][0]),
                                     tol=1e-7))
        und = (stripe_rules(lnxb, m[:, 1], n, med, bet, code) if stripes else
               code == CODE["separated"])
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
    # the states nothing or everything reaches need no fit (their ending is all there is)
    code[:] = np.stack([empty_ending(reach[:, j], n) for j in range(K)], 1)
    fitted = code == CODE["ok"]
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
            mm, bb, cc = mle_batch(lnx[rows], reach[rows, j], n[rows])
            uu = (stripe_rules(lnx[rows], reach[rows, j], n[rows], mm, bb, cc) if stripes
                  else cc == CODE["separated"])
            med[rows, j], bet[rows, j], code[rows, j], und[rows, j] = mm, bb, cc, uu
            continue
        a, z = js[0], js[-1]
        sub = m[rows][:, a:z + 2]
        sub[:, 0] += m[rows][:, :a].sum(1)
        sub[:, -1] += m[rows][:, z + 2:].sum(1)
        st = None if start is None else (np.asarray(start[0])[js], np.asarray(start[1])[js[0]])
        mm, bb, conv = _fit_ordinal(lnx[rows], sub, st)
        _, sdv = _standardise(lnx[rows], n[rows])
        cc = np.where(conv, CODE["ok"], CODE["not_converged"])
        cc = np.where(conv & (bb < 1e-6 * sdv), CODE["separated"], cc)
        cc = np.where(conv & (bb > 1e6 * sdv), CODE["decreasing"], cc)
        good = cc == CODE["ok"]
        uu = ~good
        if stripes:
            levels = np.zeros(rows.size, np.int64)
            distinct = np.zeros(rows.size, np.int64)
            for j in js:
                lv, dd = distinct_inner(lnx[rows], reach[rows, j], n[rows])
                levels, distinct = np.maximum(levels, lv), distinct + dd
            one = levels == 1
            cc = np.where(one, CODE["one_stripe"], cc)
            uu = uu | one | (distinct < 2)
        for q, j in enumerate(js):
            med[rows, j] = np.where(good | uu & (cc == CODE["ok"]), mm[:, q], np.nan)
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
    mo, bo, co = mle_batch(lnx, k1 + k2, n)
    code[:] = co[:, None]
    has1, has2 = k1.sum(-1) > 0, k2.sum(-1) > 0
    okrow = co == CODE["ok"]
    for j, (own, other) in enumerate(((has1, has2), (has2, has1))):
        alone = okrow & own & ~other  # the other mode never occurs: no competition
        med[alone, j], bet[alone, j] = mo[alone], bo[alone]
        code[okrow & ~own, j] = CODE["no_failures"]
    both = np.flatnonzero(okrow & has1 & has2)
    if both.size:
        begin = np.empty((both.size, 4))
        for j, kk in enumerate((k1, k2)):
            mm, bb, _ = mle_batch(lnx[both], kk[both], n[both])
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
        code[both] = np.where(conv, CODE["ok"], CODE["not_converged"])[:, None]
        med[both[~conv]], bet[both[~conv]] = np.nan, np.nan
    for j, kk in enumerate((k1, k2)):
        sep = code[:, j] == CODE["separated"]
        und[:, j] = sep
        if stripes:  # (the other mode's censoring informs beta: no fraction rule)
            lv, _ = distinct_inner(lnx, kk, n)
            one = (lv == 1) & ~np.isin(code[:, j], EMPTY)
            code[one, j] = CODE["one_stripe"]
            med[one, j] = np.nan
            und[:, j] |= one
        bet[und[:, j], j] = np.nan
        med[sep, j] = np.nan
    return med, bet, code, und


def fitted_curves(kind: str, grid: np.ndarray, med: np.ndarray, bet: np.ndarray
                  ) -> np.ndarray:
    """Fitted P(state | x) (..., G, X) at grid (X,) of fits med, bet (..., G)."""
    if kind != "competing":
        return lognormal_cdf(grid, med[..., None], bet[..., None])
    lnm, sig = np.log(med), bet
    z = np.broadcast_to(np.log(grid), med.shape[:-1] + grid.shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        _, p1, p2 = cif(z, lnm, sig)
    out = np.stack([p1, p2], -2)
    bad = ~np.all(np.isfinite(med) & np.isfinite(bet) & (bet > 0), -1)
    out[bad] = np.nan
    return out


# ---------------------------------------------------------------------------------------
# bootstrap over records: resamples as count weights
# ---------------------------------------------------------------------------------------


def resample_weights(n_records: int, n_boot: int, seed: int | np.random.Generator,
                     per: int, groups: np.ndarray | None = None
                     ) -> Iterator[tuple[int, np.ndarray]]:
    """Resample weights in chunks: yields (start, w float (nb, R)), w[r] = how often record
    r is drawn; one Generator draws R indices a resample, as a single draw would.
    groups: int[R], the record each of the R samples belongs to (0..G-1; several samples
    of one record, e.g. its orientations): the G records are drawn, each with all its
    samples (a cluster bootstrap: the samples of a record are not independent)."""
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    G = n_records if groups is None else int(groups.max()) + 1
    nb = max(1, min(n_boot, BOOT_ELEMENTS // max(per, 1)))
    for start in range(0, n_boot, nb):
        m = min(nb, n_boot - start)
        idx = rng.integers(0, G, size=(m, G))
        flat = (np.arange(m)[:, None] * G + idx).ravel()
        w = np.bincount(flat, minlength=m * G).reshape(m, G)
        if groups is not None:
            w = w[:, groups]
        yield start, w.astype(np.float64)


def category_counts(w: np.ndarray, onehot: np.ndarray, stripes: bool) -> np.ndarray:
    """(b, C, P) category counts of resample weights w (b, R): onehot (C, R, S) for
    stripes (summed over records), (C, R) for a cloud (a point per record)."""
    if stripes:
        return np.einsum("br,crs->bcs", w, onehot)
    return w[:, None, :] * onehot[None]


def percentile_interval(v: np.ndarray, ci: float) -> tuple[float, float]:
    v = v[np.isfinite(v)]
    if v.size == 0:
        return math.nan, math.nan
    q = 100.0 * np.array([(1.0 - ci) / 2.0, (1.0 + ci) / 2.0])
    lo, hi = np.percentile(v, q)
    return float(lo), float(hi)


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
    n_boot = check_bootstrap(n_boot, 1)
    cloud = f.ndim == 1
    if cloud and not (x.shape == f.shape == c.shape):
        raise FragilityError("cloud: im, failed, counted must have one value per record")
    if not cloud and (f.shape != c.shape or f.shape[1:] != x.shape):
        raise FragilityError("stripes: failed and counted must be (records, stripes)")
    onehot = np.stack([c & ~f, c & f]).astype(np.float64)
    lnx = np.log(np.where(c, x, 1.0)) if cloud else np.log(x)
    med = np.full(n_boot, np.nan)
    bet = np.full(n_boot, np.nan)
    for start, w in resample_weights(f.shape[0], n_boot, seed, onehot.size):
        mm, bb, _, _ = fit_counts("single", lnx, category_counts(w, onehot, not cloud),
                                   not cloud)
        med[start:start + w.shape[0]], bet[start:start + w.shape[0]] = mm[:, 0], bb[:, 0]
    undefined = ~(np.isfinite(med) & np.isfinite(bet))
    med, bet = np.where(undefined, np.nan, med), np.where(undefined, np.nan, bet)
    return Bootstrap(percentile_interval(med, ci), percentile_interval(bet, ci), med, bet,
                     int(undefined.sum()), ci)


def check_bootstrap(n: Any, curves: int) -> int:
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 0:
        raise FragilityError(f"bootstrap = {n!r}: must be an integer >= 0 (resamples)")
    if n > MAX_BOOTSTRAP:
        raise FragilityError(f"bootstrap = {n!r}: at most {MAX_BOOTSTRAP} resamples (their "
                             f"fits are kept: {n * curves * 16 / 2**30:.1f} GiB for "
                             f"{curves} curve{'s' * (curves != 1)})")
    return int(n)


def lognormal_cdf(x: np.ndarray | float, median: np.ndarray | float,
                  beta: np.ndarray | float) -> np.ndarray:
    """Phi(ln(x / median) / beta), broadcast; beta = 0 is the step at the median, NaN
    beta (undetermined) gives NaN."""
    x, median, beta = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64)
                                            for v in (x, median, beta)))
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.log(x / median) / beta
    step = np.where(x >= median, 1.0, 0.0)
    return np.where(beta > 0.0, ndtr(z),
                    np.where(np.isnan(median) | np.isnan(beta), np.nan, step))
