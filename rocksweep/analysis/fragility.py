"""Lognormal fragility of a record suite: P(state | IM = x) = Phi(ln(x / im_median) / beta).

Reference: J. W. Baker (2015), "Efficient analytical fragility function fitting using
dynamic structural analysis", Earthquake Spectra 31(1), 579-599.

Fits (the likelihoods and their maximisers: ``rocksweep.analysis.likelihood``):

- Stripes (multiple stripe analysis: every record scaled to each IM level x_j): k_j of the
  n_j records counted at x_j reach the state; the product of binomials is maximised
  (Baker 2015, eq. 11), n_j may differ between stripes (excluded points).
- Clouds (records unscaled, or scaled by one factor each): each record i is a stripe of
  one, (x_i, 0/1): probit regression on ln IM, the same likelihood with n_i = 1.

Several states at once (docs/fragility.md, "Several states: one fit for all"): two or more
nested damage states of one chain (uplift < theta:X < overturn, or slide:D < overturn:
``analysis.states``) as one ordinal probit with a common beta, so the curves never cross;
mode1 with mode2 as competing risks with independent lognormal capacities, so P(safe) +
P(mode 1) + P(mode 2) = 1 at every x (im_median_k and beta_k describe mode k's capacity
with the other mode censoring it; ``curve`` holds the fitted P(mode k | x) themselves).
A single mode fitted alone treats the other's points as safe.

Verdicts (``reason``: "ok", or the words below joined by ","; never "ok" for these):

- how the fit ended: "no_failures" / "all_failed" (nothing / everything counted reaches
  the state: NaN, NaN); "separated" (every point that reaches it has a larger IM than
  every one that does not: the likelihood grows as beta -> 0; im_median = the geometric
  mean of the largest safe and the smallest failing IM, beta = NaN, never 0);
  "decreasing" (the best probit slope is <= 0); "no_data"; "one_stripe" (one IM level
  counted: NaN, NaN); "not_converged" (the fit's ascent stopped without meeting its
  convergence test: ``likelihood``'s module docstring; also said where the parallel test's
  free fit did not converge and its lower bound does not reject);
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
  overturning points (fit state=["mode1", "mode2"], joint=True for the competing-risk
  fit);
- "crossing" (separate fits, the default): a more severe nested state's curve lies above a
  milder one's by more than ``CROSSING_TOL`` inside the IM range of the data (a point
  cannot reach overturning without reaching theta:X or slide:D): the curves are not both
  right there;
  said on both states;
- "parallel_rejected" (``joint=True``): the likelihood-ratio test of the ordinal fit's
  common beta against a beta per state (``likelihood.parallel_lr``) rejects it at
  ``PARALLEL_P``: the joint curves misstate the data; fit the states separately;
- "incomplete": points of the curve not computed (outcome -1: a partial file, or a sweep
  still writing it); "flagged": points flagged by the kernel (horizon, caps, airborne) are left out
  and counting them as reaching the state, or as not, moves im_median by more than
  ``FLAGGED_SHIFT`` (relative).

Bootstrap: records are resampled with replacement (seeded; ``DEFAULT_BOOTSTRAP`` resamples
unless told, at most ``MAX_BOOTSTRAP``), every fit repeated on each resample in chunks of
bounded memory; the percentile intervals of im_median and beta are reported, resamples
without a finite answer left out and counted.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from rocksweep.analysis.counts import STRIPE_IMS, Counts, IMAxis, count_points, im_axis
from rocksweep.analysis.likelihood import (
    BOOT_ELEMENTS,
    CODE,
    ENDINGS,
    category_counts,
    check_bootstrap,
    fit_counts,
    fitted_curves,
    isotonic_lr,
    lognormal_cdf,
    mle_batch,
    parallel_lr,
    percentile_interval,
    resample_weights,
    stripe_rules,
)
from rocksweep.analysis.resampling import (
    DEFAULT_BOOTSTRAP,
    DEFAULT_CI,
    DEFAULT_SEED,
    check_ci,
)
from rocksweep.analysis.states import (
    SLIDE,
    nested,
    parse_state,
    parse_states,
    required,
    severity,
    state_groups,
)
from rocksweep.analysis.table import units_of
from rocksweep.errors import Arg, FragilityError, FragilityWarning, flag
from rocksweep.fields import plain
from rocksweep.vocab.ground import AVGSA
from rocksweep.vocab.kinds import FRAGILITY, KIND_ATTR
from rocksweep.vocab.outcomes import MODE1, MODE2

__all__ = ["Fit", "REASONS",
           "curves_json", "fit_cloud", "fit_stripes", "fragility", "probability"]

#: the quality words that follow how a fit ended (``likelihood.ENDINGS``)
QUALITY = ("beta_undetermined", "non_monotone", "extrapolated", "bootstrap_undefined",
           "censored", "incomplete", "flagged", "crossing", "parallel_rejected")
REASONS = ENDINGS + QUALITY
BAND_POINTS = 101
#: the pointwise band is taken over at most this many resamples (the first ones)
BAND_SAMPLES = 20_000
NONMONOTONE_P = 0.01
NONMONOTONE_SIMS = 400
NONMONOTONE_BATCH = 25  # simulations between checks of whether the verdict is decided
CENSORED_SHARE = 0.1
#: "crossing": a more severe state's separate curve above a milder one's by more than this
#: probability somewhere inside the stripes' (or the records') IM range (one percentage
#: point: theta:0.5 and overturning of a slender body, nearly one state, cross by 0.003
#: on the demo suite, less than a reader can see)
CROSSING_TOL = 0.01
#: "parallel_rejected": the common beta of a joint ordinal fit rejected at this level
PARALLEL_P = 0.05
FLAGGED_SHIFT = 0.01


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
# verdicts of one data set, and the fits of one data set
# ---------------------------------------------------------------------------------------


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
    stat = float(isotonic_lr(k[None], n)[0])
    if stat <= 1e-9:
        return False
    rng = np.random.default_rng(20261125)
    sims = rng.binomial(n.astype(np.int64), np.clip(p, 0.0, 1.0),
                        size=(NONMONOTONE_SIMS, levels.size)).astype(np.float64)
    # p_value = (1 + exceed) / (SIMS + 1) < P needs exceed below this: the simulations run
    # in batches and stop once that many exceed (the verdict is the full run's)
    limit = NONMONOTONE_P * (NONMONOTONE_SIMS + 1.0) - 1.0
    exceed = 0
    for start in range(0, NONMONOTONE_SIMS, NONMONOTONE_BATCH):
        null = isotonic_lr(sims[start:start + NONMONOTONE_BATCH], n)
        exceed += int(np.sum(null >= stat - 1e-9))
        if exceed >= limit:
            return False
    return True


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
    med, bet, code = mle_batch(lnx[None], k[None], n[None])
    why: dict[str, str] = {ENDINGS[int(code[0])]: ""}
    if stripes:
        und = stripe_rules(lnx[None], k[None], n[None], med, bet, code)
        why = {ENDINGS[int(code[0])]: ""}
        if und[0]:
            why["beta_undetermined"] = ("one stripe" if code[0] == CODE["one_stripe"] else
                                        "separated" if code[0] == CODE["separated"] else
                                        "fewer than 2 distinct fractions between 0 and 1")
        p = lognormal_cdf(np.exp(lnx), med[0], bet[0]) if np.isfinite(bet[0]) else \
            np.full(lnx.size, np.nan)
        if _non_monotone(lnx, k, n, p):
            why["non_monotone"] = "the stripe fractions fall with the IM beyond noise"
    elif code[0] == CODE["separated"]:
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
# the Dataset front end
# ---------------------------------------------------------------------------------------


def _check_args(ds: Any, im: Any, period: Any, seed: Any) -> None:
    if not isinstance(ds, xr.Dataset):
        raise FragilityError(f"ds = {type(ds).__name__}: must be a result Dataset "
                             "(rocksweep.run or rocksweep.open)")
    if im is not None and not isinstance(im, str):
        raise FragilityError(f"im = {im!r}: an IM name, one of {', '.join(STRIPE_IMS)}")
    if period is not None and (isinstance(period, bool) or not isinstance(
            period, int | float | np.integer | np.floating) or not math.isfinite(period)
            or period <= 0):
        raise FragilityError("{period}: a period in s (a number > 0, one of the stored "
                             "ground.periods), with {im}", period=Arg("period", period),
                             im=Arg("im", "Sa"))
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise FragilityError("{seed}: must be an integer >= 0", seed=Arg("seed", seed))


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
              warn: bool = True, joint: bool = False) -> xr.Dataset:
    """Lognormal fragility curves of a record-suite sweep (Baker 2015) with their verdicts.

    ds (the sweep's contract): variables ``outcome`` (int8: -1 not computed, 0 safe, 1
    mode 1, 2 mode 2), ``status`` (int32 bit flags; points with status &
    STATUS_FLAGGED are excluded and counted), ``uplifts`` (int32; state "uplift"),
    ``theta_max_over_alpha`` (float64; states "theta:X"), ``slide_max`` (float64, the
    base's largest sliding displacement in its ``units``; states "slide:D": a sweep of a
    scene with ``body.mu``); dimension ``record`` (coordinate:
    unique file names); for stripes one dimension named by ``ds.attrs["scale_im"]`` (PGA
    [g], PGV [m/s], Sa [g], PGA_ratio, PGV_ratio [-]) whose coordinate holds the levels;
    any other dims (lam, p, body keys): one curve per combination. Without a stripe
    dimension (a cloud) the IM per record is ``record_pga`` [g], ``record_pgv`` [m/s] or
    ``record_sa`` (record, period) [g] (``im=`` "PGA" (default), "PGV", "Sa" with
    ``period=`` [s]), times ``scale_factor`` (record) if present.

    state: one state word or a list (then a ``state`` dimension): "overturn" (outcome 1 or
    2), "mode1", "mode2", "uplift" (uplifts > 0 or overturned), "theta:X"
    (theta_max_over_alpha >= X or overturned, 0 < X <= 1), "slide:D" (slide_max >= D or
    overturned, D > 0 in slide_max's units). Every state is fitted alone
    (its numbers do not depend on the other states asked for; nested curves that cross
    inside the data say "crossing"); ``joint=True`` fits two or more of uplift, theta:X,
    overturn (or of slide:D, overturn: one chain, ``analysis.states``) as ordered damage
    states (one beta: the curves never cross; the likelihood-
    ratio test of that beta is stored, "parallel_rejected" where the data reject it) and
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
    record). With ``joint`` and an ordinal group, over the other dims: ``parallel_lr``
    (2 ln of the likelihood ratio, beta per state against the common one),
    ``parallel_dof``, ``parallel_p`` (chi-square p-value) and ``parallel_rejected``
    (parallel_p < ``PARALLEL_P``). attrs: rocksweep_kind "fragility" (``analysis.kinds``),
    title (the sweep's), method ("stripes-mle" | "cloud-mle"), im, im_units, period (Sa),
    avgsa_periods (AvgSa stripes), states, joint, bootstrap, seed, ci, reference;
    slide_max_units (slide:D states: D's units, those of the sweep's slide_max).
    """
    states, N, ci = _request(ds, state, im, period, bootstrap, seed, ci)
    if not isinstance(joint, bool | np.bool_):
        raise FragilityError(f"joint = {joint!r}: True or False (one beta for nested damage "
                             "states, competing risks for mode1 with mode2)")
    out_da = ds["outcome"]
    axis = im_axis(ds, out_da, im, period)
    counts = count_points(ds, states, axis, out_da)
    N = check_bootstrap(N, len(states) * counts.n_o)
    grid = np.geomspace(axis.x.min() / 2.0, axis.x.max() * 1.5, BAND_POINTS)
    groups = state_groups(states, bool(joint))
    fits = _point_fits(counts, groups, states, axis, grid, N)
    if not joint:
        _crossing(fits, counts, states, axis)
    if N:
        _bootstrap_fits(fits, counts, groups, axis, N, seed)
        _bootstrap_intervals(fits, groups, grid, N, ci)
    for o in range(counts.n_o):
        if counts.not_run[o].any():
            text = _missing_text(counts.not_run[o], axis.x if axis.stripes else None,
                                 axis.unit, axis.stripe, ds.attrs.get("complete"),
                                 counts.names)
            for i in range(len(states)):
                fits.why[i][o]["incomplete"] = text
    out = _dataset(ds, state, states, axis, counts, fits, grid, N, seed, ci)
    out.attrs["joint"] = np.int8(bool(joint))
    if warn:
        for line in verdict_lines(out, fits.why):
            warnings.warn(line, stacklevel=2)
    return out


def _request(ds: Any, state: Any, im: Any, period: Any, bootstrap: Any, seed: Any,
             ci: Any) -> tuple[list[str], int, float]:
    """The arguments of ``fragility`` checked: (states, resamples, ci); ds has outcomes
    over unique records."""
    _check_args(ds, im, period, seed)
    bootstrap = DEFAULT_BOOTSTRAP if bootstrap is None else bootstrap
    states = parse_states(state)
    ci = check_ci(ci)
    N = check_bootstrap(bootstrap, 1)
    out_da = required(ds, "outcome", "outcome codes")
    if "record" not in out_da.dims:
        where = ds.encoding.get("source")  # the file it was opened from, if any
        raise FragilityError(f"{where + ': ' if where else ''}outcome has no 'record' "
                             "dimension: not a record-suite sweep (a scene with ground.records: a "
                             "list of record files, and ground.scale)")
    names = [str(r) for r in ds["record"].values]
    if len(set(names)) != len(names):
        raise FragilityError("record: the coordinate lists a record twice")
    return states, N, ci


@dataclass
class _Fits:
    """Every state's (nS) fit of every curve (n_o): ``res`` im_median, beta and their
    interval bounds (nS, n_o); ``why[state][curve]`` {verdict word: detail}; ``curve`` (nS,
    n_o, X) at the grid; ``band`` (2, nS, n_o, X); ``samples`` (2, nS, n_o, N) im_median and
    beta of each resample; ``n_undef`` (nS, n_o) resamples without a finite fit."""

    res: dict[str, np.ndarray]
    why: list[list[dict[str, Any]]]
    fit_kind: np.ndarray
    curve: np.ndarray
    band: np.ndarray
    samples: np.ndarray
    n_undef: np.ndarray
    #: the joint ordinal fit's test of its common beta per curve: (statistic, dof) (n_o,)
    parallel: tuple[np.ndarray, np.ndarray] | None = None


_UNDETERMINED = {"one_stripe": "one IM level counted",
                 "separated": "separated data: the likelihood grows as beta -> 0"}


def _point_fits(c: Counts, groups: list[tuple[str, list[int]]], states: list[str],
                axis: IMAxis, grid: np.ndarray, N: int) -> _Fits:
    """The fit of the counted points of every group and curve, with its data verdicts."""
    nS, n_o = len(states), c.n_o
    f = _Fits({v: np.full((nS, n_o), np.nan) for v in
               ("im_median", "beta", "im_median_lo", "im_median_hi", "beta_lo", "beta_hi")},
              [[{} for _ in range(n_o)] for _ in range(nS)], np.empty(nS, dtype=object),
              np.full((nS, n_o, grid.size), np.nan),
              np.full((2, nS, n_o, grid.size), np.nan), np.full((2, nS, n_o, N), np.nan),
              np.zeros((nS, n_o), dtype=np.int64))
    lnx = np.log(axis.x)
    for o in range(n_o):
        for kind, idxs in groups:
            for i in idxs:
                f.fit_kind[i] = kind
            oh = c.onehot(kind, idxs, o, c.counted[o])
            m = category_counts(np.ones((1, c.R)), oh, axis.stripes)
            med, bet, code, und = fit_counts(kind, lnx, m, axis.stripes)
            cur = fitted_curves(kind, grid, med[0], bet[0])
            for q, i in enumerate(idxs):
                f.res["im_median"][i, o], f.res["beta"][i, o] = med[0, q], bet[0, q]
                f.curve[i, o] = cur[q]
                w = f.why[i][o]
                ending = ENDINGS[int(code[0, q])]
                w[ending] = ""
                if und[0, q]:
                    w["beta_undetermined"] = _UNDETERMINED.get(
                        ending, "fewer than 2 distinct stripe fractions strictly between 0 "
                        "and 1")
            _verdicts(kind, idxs, o, lnx, m, med[0], bet[0], f.why, c, states, axis.stripes)
            if kind == "ordinal":
                _parallel(f, o, idxs, lnx, m[0], med[0], bet[0])
    return f


def _parallel(f: _Fits, o: int, idxs: list[int], lnx: np.ndarray, m: np.ndarray,
              med: np.ndarray, bet: np.ndarray) -> None:
    """The likelihood-ratio test of an ordinal fit's common beta (``likelihood.
    parallel_lr``) for curve o, on the states it fitted (finite im_median and beta), and
    the "parallel_rejected" verdict."""
    from scipy.stats import chi2  # lazy: scipy (+0.7 s)

    if f.parallel is None:
        f.parallel = (np.full(f.n_undef.shape[1], np.nan),
                      np.zeros(f.n_undef.shape[1], np.int64))
    use = [q for q in range(len(idxs)) if np.isfinite(med[q]) and np.isfinite(bet[q])]
    if len(use) < 2:
        return
    # the counts of the fitted states: the categories of the others merged downwards
    reach = np.cumsum(m[::-1], 0)[::-1]  # (K+1, P): reaching category c or above
    sub_reach = reach[[0] + [q + 1 for q in use]]
    sub = sub_reach - np.concatenate([sub_reach[1:], np.zeros((1, m.shape[1]))], 0)
    stat, dof, conv = parallel_lr(lnx, sub, med[use], float(bet[use[0]]))
    f.parallel[0][o], f.parallel[1][o] = stat, dof
    p = float(chi2.sf(stat, dof))
    if not conv and p >= PARALLEL_P:  # a lower bound of the statistic decides nothing
        for q in use:
            f.why[idxs[q]][o]["not_converged"] = (
                f"the test of the common beta: the fit with a beta per state did not "
                f"converge; its likelihood ratio {stat:.3g} on {dof} dof is a lower bound")
    if p < PARALLEL_P:
        for q in use:
            f.why[idxs[q]][o]["parallel_rejected"] = FragilityWarning(
                f"likelihood ratio {stat:.3g} on {dof} dof, p = {p:.2g}: one beta does "
                "not fit these states; fit them separately ({joint})",
                joint=flag("joint", False))


def _crossing(f: _Fits, c: Counts, states: list[str], axis: IMAxis) -> None:
    """The "crossing" verdict of separate fits: a more severe nested state's curve above
    a milder one's by more than ``CROSSING_TOL`` inside the IM range of the counted
    data (stripes with a counted point; a cloud's counted records)."""
    order = sorted((i for i, s in enumerate(states) if not math.isnan(severity(s))),
                   key=lambda i: severity(states[i]))
    pairs = [(mild, severe) for a, mild in enumerate(order) for severe in order[a + 1:]
             if nested(states[mild], states[severe])]
    if not pairs:
        return
    for o in range(c.n_o):
        if axis.stripes:
            have = c.counted[o].any(0)
            x = axis.x[have]
        else:
            x = axis.x[c.counted[o].astype(bool)]
        if x.size < 2:
            continue
        xs = np.geomspace(x.min(), x.max(), BAND_POINTS)
        for mild, severe in pairs:
            pm = lognormal_cdf(xs, f.res["im_median"][mild, o], f.res["beta"][mild, o])
            ps = lognormal_cdf(xs, f.res["im_median"][severe, o], f.res["beta"][severe, o])
            gap = ps - pm
            if not np.any(np.isfinite(gap)) or np.nanmax(gap) <= CROSSING_TOL:
                continue
            at = xs[int(np.nanargmax(gap))]
            text = (f"{states[severe]} above {states[mild]} by up to "
                    f"{np.nanmax(gap):.3g} (at {at:.3g} {axis.unit}) inside the data")
            f.why[mild][o]["crossing"] = text
            f.why[severe][o]["crossing"] = text


def _bootstrap_fits(f: _Fits, c: Counts, groups: list[tuple[str, list[int]]],
                    axis: IMAxis, N: int, seed: int) -> None:
    """Every group refitted on N resamples of the records (in ``f.samples``), started from
    the point fit; resamples without a finite fit are NaN."""
    lnx = np.log(axis.x)
    per_fit = max(c.R * (axis.x.size if axis.stripes else 1), 1) * 3
    for start, w in resample_weights(c.R, N, seed, per_fit, c.groups):
        sl = slice(start, start + w.shape[0])
        # resamples that draw the same records (most of them, with few records) have the
        # same counts and so the same fit: each distinct one is fitted once
        wu, inv = np.unique(w, axis=0, return_inverse=True)
        inv = np.asarray(inv).ravel()
        for o in range(c.n_o):
            for kind, idxs in groups:
                oh = c.onehot(kind, idxs, o, c.counted[o])
                st = (f.res["im_median"][idxs, o], f.res["beta"][idxs, o])
                med, bet, _, _ = fit_counts(kind, lnx, category_counts(
                    wu, oh, axis.stripes), axis.stripes, start=st)
                med, bet = med[inv], bet[inv]
                bad = ~(np.isfinite(med) & np.isfinite(bet))
                med[bad], bet[bad] = np.nan, np.nan
                for q, i in enumerate(idxs):
                    f.samples[0, i, o, sl], f.samples[1, i, o, sl] = med[:, q], bet[:, q]


def _bootstrap_intervals(f: _Fits, groups: list[tuple[str, list[int]]], grid: np.ndarray,
                         N: int, ci: float) -> None:
    """The percentile intervals of im_median and beta (every resample), the
    "bootstrap_undefined" verdict, and the pointwise band of the curve (the first
    ``BAND_SAMPLES`` resamples)."""
    q = 100.0 * np.array([(1.0 - ci) / 2.0, (1.0 + ci) / 2.0])
    for o in range(f.n_undef.shape[1]):
        for kind, idxs in groups:
            med_s = f.samples[0, idxs, o].T  # (N, G)
            bet_s = f.samples[1, idxs, o].T
            for q_i, i in enumerate(idxs):
                fin = np.isfinite(med_s[:, q_i])
                f.n_undef[i, o] = int((~fin).sum())
                lo_hi = (percentile_interval(med_s[:, q_i], ci),
                         percentile_interval(bet_s[:, q_i], ci))
                (f.res["im_median_lo"][i, o], f.res["im_median_hi"][i, o]) = lo_hi[0]
                (f.res["beta_lo"][i, o], f.res["beta_hi"][i, o]) = lo_hi[1]
                if f.n_undef[i, o] > N * (1.0 - ci) / 2.0 and np.isfinite(
                        f.res["im_median"][i, o]):
                    f.why[i][o]["bootstrap_undefined"] = (
                        f"{f.n_undef[i, o]} of {N} resamples without a finite fit")
            med_s, bet_s = med_s[:BAND_SAMPLES], bet_s[:BAND_SAMPLES]
            rows = (np.all(np.isfinite(med_s) & np.isfinite(bet_s), -1)
                    if kind == "competing" else None)
            step = max(1, BOOT_ELEMENTS // max(med_s.shape[0] * len(idxs), 1))
            for g0 in range(0, grid.size, step):
                gs = slice(g0, g0 + step)
                cur = fitted_curves(kind, grid[gs], med_s if rows is None else med_s[rows],
                                    bet_s if rows is None else bet_s[rows])  # (N', G, X)
                for q_i, i in enumerate(idxs):
                    cq = cur[:, q_i]
                    cq = cq[np.all(np.isfinite(cq), -1)]
                    if cq.shape[0]:
                        f.band[:, i, o, gs] = np.percentile(cq, q, axis=0)


def _dataset(ds: xr.Dataset, state: Any, states: list[str], axis: IMAxis, c: Counts,
             f: _Fits, grid: np.ndarray, N: int, seed: int, ci: float) -> xr.Dataset:
    """The fragility Dataset (``fragility``'s docstring): a ``state`` dimension when
    ``state`` is a list."""
    nS, shape_o, others, unit = len(states), c.shape_o, c.others, axis.unit
    reason = np.array([[_words(f.why[i][o]) for o in range(c.n_o)] for i in range(nS)],
                      dtype=object)
    lead = ["state"] if not isinstance(state, str) else []
    dims_c = lead + others

    def shaped(a: np.ndarray, extra: tuple[int, ...] = ()) -> np.ndarray:
        a = a.reshape((nS,) + shape_o + extra)
        return a if lead else a[0]

    coords: dict[str, Any] = {d: ds[d] for d in others if d in ds.coords}
    coords["state"] = ("state", np.array(states, dtype=str)) if lead else ((), states[0])
    coords["im_grid"] = ("im_grid", grid, {"units": unit,
                                           "long_name": f"{axis.im_name} grid"})
    data: dict[str, Any] = {}
    data["im_median"] = (dims_c, shaped(f.res["im_median"]),
                         {"units": unit,
                          "long_name": f"median {axis.im_name} of the fragility"})
    data["beta"] = (dims_c, shaped(f.res["beta"]),
                    {"units": "1", "long_name": "lognormal standard deviation"})
    for v in ("im_median_lo", "im_median_hi", "beta_lo", "beta_hi"):
        data[v] = (dims_c, shaped(f.res[v]),
                   {"units": unit if v.startswith("im_median") else "1",
                    "long_name": f"bootstrap {ci:g} percentile interval bound"})
    data["reason"] = (dims_c, shaped(reason.astype(str)),
                      {"long_name": "verdict: ok, or the reasons joined by ',' (" +
                                    ", ".join(REASONS[1:]) + ")"})
    data["fit"] = (lead, f.fit_kind.astype(str) if lead else str(f.fit_kind[0]),
                   {"long_name": "how the state was fitted: single, ordinal (damage states, "
                                 "one beta) or competing (mode1 with mode2)"})
    data["n_boot_undefined"] = (dims_c, shaped(f.n_undef),
                                {"long_name": "bootstrap resamples without a finite fit"})
    data["n_records"] = (others, c.records_counted().reshape(shape_o).astype(np.int64),
                         {"long_name": "records with at least one counted point"})
    data["n_excluded"] = (others, c.flagged.reshape(c.n_o, -1).sum(-1).reshape(shape_o),
                          {"long_name": "flagged points (status & STATUS_FLAGGED) left out"})
    data["n_not_run"] = (others, c.not_run.reshape(c.n_o, -1).sum(-1).reshape(shape_o),
                         {"long_name": "points not computed (outcome -1) left out"})
    data["curve"] = (dims_c + ["im_grid"], shaped(f.curve, (grid.size,)),
                     {"long_name": "fitted probability of the state"})
    data["band_lo"] = (dims_c + ["im_grid"], shaped(f.band[0], (grid.size,)),
                       {"long_name": f"bootstrap {ci:g} band, lower (pointwise)"})
    data["band_hi"] = (dims_c + ["im_grid"], shaped(f.band[1], (grid.size,)),
                       {"long_name": f"bootstrap {ci:g} band, upper (pointwise)"})
    if N:
        data["im_median_samples"] = (dims_c + ["sample"], shaped(f.samples[0], (N,)),
                                     {"units": unit, "long_name": "im_median of each "
                                      "bootstrap resample (NaN: no finite fit)"})
        data["beta_samples"] = (dims_c + ["sample"], shaped(f.samples[1], (N,)),
                                {"units": "1", "long_name": "beta of each bootstrap "
                                 "resample (NaN: no finite fit)"})
    if axis.stripes:
        coords[axis.stripe] = ds[axis.stripe]
        coords["record"] = ds["record"]
        data.update(_stripe_variables(c, axis, dims_c, shaped))
    attrs = {KIND_ATTR: FRAGILITY, "title": str(ds.attrs.get("title", "")),
             "method": axis.method, "im": axis.im_name, "im_units": unit,
             "states": list(states), "bootstrap": int(N), "seed": int(seed),
             "ci": float(ci),
             "reference": "Baker (2015), Efficient analytical fragility function fitting "
                          "using dynamic structural analysis, Earthquake Spectra 31(1)"}
    if any(parse_state(s)[0] == SLIDE for s in states):  # D's units: slide_max's
        attrs["slide_max_units"] = units_of(ds["slide_max"])
    if axis.im_name == "Sa":
        attrs["period"] = axis.period
    if axis.im_name == AVGSA and "record_avgsa" in ds.variables:
        attrs["avgsa_periods"] = np.asarray(ds["record_avgsa"].attrs.get(
            "avgsa_periods", [math.nan, math.nan]), np.float64)
    if f.parallel is not None:
        from scipy.stats import chi2  # lazy: scipy (+0.7 s)

        stat, dof = f.parallel
        with np.errstate(invalid="ignore"):
            pv = np.where(np.isfinite(stat), chi2.sf(stat, np.maximum(dof, 1)), np.nan)
        data["parallel_lr"] = (others, stat.reshape(shape_o), {
            "long_name": "likelihood-ratio statistic of the common beta against a beta per "
                         "state (2 ln LR; NaN: fewer than 2 states fitted)"})
        data["parallel_dof"] = (others, dof.reshape(shape_o),
                                {"long_name": "degrees of freedom of parallel_lr"})
        data["parallel_p"] = (others, pv.reshape(shape_o),
                              {"long_name": "chi-square p-value of parallel_lr"})
        data["parallel_rejected"] = (others, (pv < PARALLEL_P).reshape(shape_o), {
            "long_name": f"the common beta rejected at p < {PARALLEL_P:g}"})
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _stripe_variables(c: Counts, axis: IMAxis, dims_c: list[str],
                      shaped: Callable[..., np.ndarray]) -> dict[str, Any]:
    """The stripes' own variables: fraction, n_failed, n_counted, and per record
    first_level and resurrection."""
    stripe, levels, R = axis.stripe, axis.x, c.R
    k = (c.hits & c.counted[None]).sum(2)  # (nS, n_o, S)
    n = c.counted.sum(1)  # (n_o, S)
    frac = np.where(n[None] > 0, k / np.maximum(n[None], 1), np.nan)
    S = levels.size
    data: dict[str, Any] = {}
    data["fraction"] = (dims_c + [stripe], shaped(frac, (S,)),
                        {"long_name": "fraction of counted records reaching the state"})
    data["n_failed"] = (dims_c + [stripe], shaped(k, (S,)))
    data["n_counted"] = (c.others + [stripe], n.reshape(c.shape_o + (S,)))
    reach = c.hits & c.counted[None]  # (nS, n_o, R, S)
    lev = np.broadcast_to(levels, reach.shape)
    first = np.where(reach, lev, np.inf).min(-1)
    safe_above = (c.counted[None] & ~c.hits) & (lev > first[..., None])
    first = np.where(np.isfinite(first), first, np.nan)
    data["first_level"] = (dims_c + ["record"], shaped(first, (R,)),
                           {"units": axis.unit, "long_name": "smallest level reaching the "
                            "state (NaN: none)"})
    data["resurrection"] = (dims_c + ["record"], shaped(safe_above.any(-1), (R,)),
                            {"long_name": "a higher counted level is safe again"})
    return data


def _verdicts(kind: str, idxs: list[int], o: int, lnx: np.ndarray, m: np.ndarray,
              med: np.ndarray, bet: np.ndarray, why: list[list[dict[str, Any]]],
              c: Counts, states: list[str], stripes: bool) -> None:
    """The data verdicts of one group's point fit (in ``why``): extrapolated,
    non_monotone (stripes), censored (a mode alone), flagged (the excluded points could
    move it)."""
    counted, flagged = c.counted[o], c.flagged[o]
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
            p = fitted_curves("competing", np.exp(lnx), np.asarray(med), np.asarray(bet))[q]
            if _non_monotone(lnx, k, n, p):
                w["non_monotone"] = ("the stripe fractions fall with the IM beyond noise "
                                     "(a competing-risk curve cannot fall)")
        kw = states[i]
        if kind == "single" and kw in (MODE1, MODE2):
            own = c.hits[i, o] & counted
            over = c.over_all[o] & counted
            other = int(over.sum() - own.sum())
            if over.sum() and other >= CENSORED_SHARE * over.sum():
                w["censored"] = FragilityWarning(
                    f"the other mode holds {other} of {int(over.sum())} overturning points; "
                    "fit mode1 and mode2 together ({joint})", joint=flag("joint"))
    if flagged.any():
        base = np.array([med[q] for q in range(len(idxs))])
        for as_cat in (0, len(idxs)):
            oh = c.onehot(kind, idxs, o, counted)
            oh[as_cat] += flagged
            mm, _, _, _ = fit_counts(kind, lnx, category_counts(np.ones((1, counted.shape[0])),
                                                                  oh, stripes), stripes)
            for q, i in enumerate(idxs):
                a, b = base[q], mm[0, q]
                moved = (np.isfinite(a) != np.isfinite(b)) or (
                    np.isfinite(a) and abs(b / a - 1.0) > FLAGGED_SHIFT)
                if moved:
                    why[i][o]["flagged"] = (f"{int(flagged.sum())} flagged points left out "
                                            "could move im_median")


def verdict_lines(frag: xr.Dataset, why: list[list[dict[str, Any]]] | None = None
                  ) -> list[FragilityWarning]:
    """One ``FragilityWarning`` per curve of a ``fragility`` Dataset whose ``reason`` is
    not "ok": where, which state, and why (with the numbers of ``why[state][curve]`` when
    given: a text, or a ``FragilityWarning`` that names an argument). ``str()`` of each is
    the line in the Python API's words; the command line says it with its options."""
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
            # the words and places are fields, not template text: a brace in a coordinate
            # or a record's name is not a field
            fields: dict[str, Any] = {"where": " " + where if where else "", "state": st}
            parts = []
            for k, wd in enumerate(words.split(",")):
                fields[f"w{k}"] = wd
                if detail.get(wd):
                    fields[f"d{k}"] = detail[wd]
                    parts.append(f"{{w{k}}} ({{d{k}}})")
                else:
                    parts.append(f"{{w{k}}}")
            lines.append(FragilityWarning("fragility{where}, state {state}: "
                                          + "; ".join(parts), **fields))
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
    # a state's model, whatever other dims ``fit`` gained (one fit per orientation answer)
    fit = frag["fit"] if "fit" in frag else None
    if fit is not None and any(d != "state" for d in fit.dims):
        fit = fit.isel({d: 0 for d in fit.dims if d != "state"})
    kinds = np.atleast_1d(np.asarray(fit.values)) if fit is not None else \
        np.array(["single"] * med.shape[0])
    states = list(np.atleast_1d(np.asarray(frag["state"].values)))
    out = np.full(med.shape + (xs.size,), np.nan)
    for i, kind in enumerate(kinds):
        if kind == "competing":
            j1, j2 = states.index(MODE1), states.index(MODE2)
            m = np.stack([med[j1], med[j2]], -1)
            b = np.stack([bet[j1], bet[j2]], -1)
            both = fitted_curves("competing", xs, m, b)
            out[i] = both[..., 0 if states[i] == MODE1 else 1, :]
        else:
            out[i] = lognormal_cdf(xs, med[i][..., None], bet[i][..., None])
    if not lead:
        out = out[0]
    return xr.DataArray(out, dims=[*(["state"] if lead else []), *dims, "im"],
                        coords={**{d: frag[d] for d in dims if d in frag.coords},
                                "state": frag["state"], "im": xs},
                        attrs={"long_name": "probability of the state", "units": "1"})


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
