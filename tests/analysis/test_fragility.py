"""Lognormal fragility fits (rocksweep.analysis.fragility) and their Dataset front end."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import xarray as xr
from scipy.optimize import minimize
from scipy.stats import norm

from rocksweep import errors
from rocksweep.analysis import fragility as F
from rocksweep.analysis import likelihood as LK
from rocksweep.kernel import layout as L

MEDIAN, BETA = 0.4, 0.4
LEVELS = np.geomspace(0.1, 1.2, 10)


def direct_mle(x, k, n):
    """An independent MLE: Nelder-Mead over (ln median, ln beta) on the clipped binomial
    likelihood (the textbook recipe)."""
    x, k, n = (np.asarray(v, dtype=float) for v in (x, k, n))

    def nll(t):
        p = np.clip(norm.cdf((np.log(x) - t[0]) / np.exp(t[1])), 1e-15, 1 - 1e-15)
        return -np.sum(k * np.log(p) + (n - k) * np.log1p(-p))

    best = min((minimize(nll, [m0, b0], method="Nelder-Mead",
                         options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 5000})
                for m0 in (np.log(np.median(x)), 0.0) for b0 in (-1.0, 0.0)),
               key=lambda r: r.fun)
    return math.exp(best.x[0]), math.exp(best.x[1])


# ---------------------------------------------------------------------------------------
# fits
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(5))
def test_stripe_fit_equals_a_direct_optimisation(seed):
    rng = np.random.default_rng(seed)
    n = rng.integers(5, 40, LEVELS.size)  # unequal counts per stripe
    k = rng.binomial(n, norm.cdf(np.log(LEVELS / MEDIAN) / BETA))
    fit = F.fit_stripes(LEVELS, k, n)
    assert fit.reason == "ok"
    med, beta = fit
    ref = direct_mle(LEVELS, k, n)
    assert med == pytest.approx(ref[0], rel=1e-5)
    assert beta == pytest.approx(ref[1], rel=1e-5)


def test_stripe_mle_recovers_a_known_lognormal_from_binomial_counts():
    # 300 data sets of independent binomial counts: the estimates centre on the truth
    rng = np.random.default_rng(11)
    n = np.full(LEVELS.size, 30)
    p = norm.cdf(np.log(LEVELS / MEDIAN) / BETA)
    fits = [F.fit_stripes(LEVELS, rng.binomial(n, p), n) for _ in range(300)]
    # the data follow the model: the only verdict is the non-monotone test's false alarm,
    # at its level (1 %)
    assert {f.reason for f in fits} <= {"ok", "non_monotone"}
    assert sum(f.reason == "ok" for f in fits) >= 294
    lnm = np.log([f.im_median for f in fits])
    betas = np.array([f.beta for f in fits])
    se = lnm.std() / math.sqrt(lnm.size)
    assert abs(lnm.mean() - math.log(MEDIAN)) < 4 * se
    assert abs(np.median(betas) - BETA) < 0.03


def capacities_failed(rng, n_records=40, median=MEDIAN, beta=BETA, levels=LEVELS):
    """Each record overturns from its own lognormal capacity up: failed[r, s]."""
    cap = rng.lognormal(math.log(median), beta, n_records)
    return levels[None, :] >= cap[:, None]


def test_bootstrap_interval_covers_the_true_median():
    # records with lognormal capacities (the model a record bootstrap assumes): the 99 %
    # interval holds the true median in at least 95 of 100 trials, and the 90 % interval is
    # not uselessly wide (it misses in at least 2 of 100) nor too narrow (>= 80 of 100)
    hit99 = hit90 = 0
    for trial in range(100):
        failed = capacities_failed(np.random.default_rng(1000 + trial))
        b99 = LK.bootstrap_records(LEVELS, failed, n_boot=200, seed=trial, ci=0.99)
        b90 = LK.bootstrap_records(LEVELS, failed, n_boot=200, seed=trial, ci=0.90)
        hit99 += b99.median_ci[0] <= MEDIAN <= b99.median_ci[1]
        hit90 += b90.median_ci[0] <= MEDIAN <= b90.median_ci[1]
    assert hit99 >= 95
    assert 80 <= hit90 <= 98


def test_bootstrap_is_seeded():
    failed = capacities_failed(np.random.default_rng(5))
    a = LK.bootstrap_records(LEVELS, failed, n_boot=50, seed=3)
    b = LK.bootstrap_records(LEVELS, failed, n_boot=50, seed=3)
    c = LK.bootstrap_records(LEVELS, failed, n_boot=50, seed=4)
    assert np.array_equal(a.medians, b.medians, equal_nan=True)
    assert not np.array_equal(a.medians, c.medians, equal_nan=True)
    assert a.medians.shape == (50,)


def test_zero_and_full_stripes_are_used_not_clipped_away():
    # 0/N below and N/N above with intermediate stripes between: a finite MLE, equal to the
    # direct optimisation, and the 0/N, N/N stripes do move it (they carry information)
    x = np.array([0.1, 0.2, 0.3, 0.4, 0.6, 0.9])
    n = np.array([20, 20, 20, 20, 20, 20])
    k = np.array([0, 0, 4, 9, 20, 20])
    fit = F.fit_stripes(x, k, n)
    assert fit.reason == "ok"
    assert fit.im_median == pytest.approx(direct_mle(x, k, n)[0], rel=1e-5)
    assert fit.beta == pytest.approx(direct_mle(x, k, n)[1], rel=1e-5)
    partial = F.fit_stripes(x[2:4], k[2:4], n[2:4])
    assert partial.beta != pytest.approx(fit.beta, rel=1e-3)


def test_degenerate_stripes_answer_with_a_reason():
    n = np.full(4, 10)
    x = np.array([0.1, 0.2, 0.4, 0.8])
    none = F.fit_stripes(x, np.zeros(4), n)
    assert none.reason == "no_failures" and math.isnan(none.im_median) and math.isnan(none.beta)
    every = F.fit_stripes(x, n, n)
    assert every.reason == "all_failed" and math.isnan(every.im_median)
    # a step between 0.2 and 0.4: the likelihood grows as beta -> 0, so beta is not
    # determined (NaN, never 0) and the median is at their geometric mean
    step = F.fit_stripes(x, [0, 0, 10, 10], n)
    assert step.reason == "separated,beta_undetermined" and math.isnan(step.beta)
    assert step.im_median == pytest.approx(math.sqrt(0.2 * 0.4))
    # quasi-separated at one mixed stripe: the step sits at that stripe
    quasi = F.fit_stripes(x, [0, 3, 10, 10], n)
    assert quasi.reason.startswith("separated") and quasi.im_median == pytest.approx(0.2)
    down = F.fit_stripes(x, [8, 6, 4, 2], n)
    assert down.reason == "decreasing" and math.isnan(down.im_median)
    empty = F.fit_stripes(x, np.zeros(4), np.zeros(4))
    assert empty.reason == "no_data"


def test_stripes_with_no_records_are_ignored():
    x = np.array([0.1, 0.2, 0.3, 0.5, 0.8])
    k = np.array([1, 3, 0, 12, 18])
    n = np.array([20, 20, 0, 20, 20])
    assert tuple(F.fit_stripes(x, k, n)) == pytest.approx(
        tuple(F.fit_stripes(x[n > 0], k[n > 0], n[n > 0])), rel=1e-9)


def test_bad_counts_are_errors():
    with pytest.raises(errors.FragilityError):
        F.fit_stripes([0.1, 0.2], [3, 1], [2, 2])
    with pytest.raises(errors.FragilityError):
        F.fit_stripes([0.0, 0.2], [0, 1], [2, 2])


def test_cloud_fit_recovers_a_known_probit():
    rng = np.random.default_rng(2)
    im = rng.lognormal(math.log(0.5), 0.7, 2000)
    failed = rng.random(im.size) < norm.cdf(np.log(im / 0.6) / 0.35)
    fit = F.fit_cloud(im, failed)
    assert fit.reason == "ok"
    # standard errors at n = 2000 are ~0.01 on ln median and ~0.02 on beta
    assert fit.im_median == pytest.approx(0.6, rel=0.05)
    assert fit.beta == pytest.approx(0.35, rel=0.12)
    ref = direct_mle(im, failed.astype(float), np.ones(im.size))
    assert fit.im_median == pytest.approx(ref[0], rel=1e-5)
    assert fit.beta == pytest.approx(ref[1], rel=1e-5)


# ---------------------------------------------------------------------------------------
# the Dataset front end
# ---------------------------------------------------------------------------------------


def suite_dataset(n_records=30, lams=(0.0, 0.2), medians=(0.4, 0.55), seed=0,
                  flag_every=0):
    """A synthetic stripes Dataset: outcome (lam, record, PGA), overturning from a
    lognormal capacity per record and lam; uplifts from half the capacity; theta from the
    level / capacity; every flag_every-th point flagged (horizon) and set safe."""
    rng = np.random.default_rng(seed)
    z = rng.standard_normal(n_records)
    cap = np.exp(np.log(np.array(medians))[:, None] + BETA * z[None, :])  # (lam, record)
    lev = LEVELS[None, None, :]
    over = lev >= cap[..., None]
    mode = np.where(rng.random(over.shape) < 0.7, 1, 2)
    outcome = np.where(over, mode, 0).astype(np.int8)
    uplifts = np.where(lev >= 0.5 * cap[..., None], 3, 0).astype(np.int32)
    theta = np.where(over, np.nan, lev / cap[..., None])
    status = np.where(over, L.STATUS_OVERTURNED, L.STATUS_REST).astype(np.int32)
    if flag_every:
        flat = status.reshape(-1)
        out = outcome.reshape(-1)
        flat[::flag_every] = L.STATUS_HORIZON
        out[::flag_every] = 0
    dims = ("lam", "record", "PGA")
    ds = xr.Dataset(
        {"outcome": (dims, outcome), "uplifts": (dims, uplifts),
         "theta_max_over_alpha": (dims, theta), "status": (dims, status)},
        coords={"lam": list(lams), "record": [f"SYN{i + 1:02d}.AT2" for i in range(n_records)],
                "PGA": LEVELS},
        attrs={"scale_im": "PGA"})
    return ds


def test_fragility_of_stripes_recovers_each_lam_and_counts():
    ds = suite_dataset(n_records=60)
    fr = F.fragility(ds, bootstrap=100, seed=1)
    assert fr.attrs["method"] == "stripes-mle" and fr.attrs["im"] == "PGA"
    assert fr["im_median"].dims == ("lam",)
    for i, true in enumerate((0.4, 0.55)):
        med = float(fr["im_median"][i])
        assert med == pytest.approx(true, rel=0.2)
        assert float(fr["im_median_lo"][i]) < med < float(fr["im_median_hi"][i])
        assert float(fr["beta_lo"][i]) < float(fr["beta"][i]) < float(fr["beta_hi"][i])
    # the counts the fit used, computed here from the outcome
    over = ds["outcome"].isin([1, 2])
    assert np.array_equal(fr["n_failed"].values, over.sum("record").values)
    assert np.array_equal(fr["n_counted"].values, np.full((2, LEVELS.size), 60))
    assert np.allclose(fr["fraction"].values, over.mean("record").values)
    assert np.all(fr["n_records"].values == 60) and np.all(fr["n_excluded"].values == 0)
    # the fit itself equals fit_stripes on those counts
    k0 = over.isel(lam=0).sum("record").values
    assert float(fr["im_median"][0]) == pytest.approx(
        F.fit_stripes(LEVELS, k0, np.full(LEVELS.size, 60)).im_median, rel=1e-12)
    # band: inside [0, 1], lower <= upper, and it holds the fitted curve at the median
    lo, hi = fr["band_lo"].values, fr["band_hi"].values
    assert np.all((lo >= 0) & (hi <= 1) & (lo <= hi))
    g = fr["im_grid"].values
    j = np.argmin(np.abs(np.log(g / float(fr["im_median"][0]))))
    assert lo[0, j] < 0.5 < hi[0, j]


def test_flagged_points_are_excluded_and_counted():
    ds = suite_dataset(flag_every=7)
    fr = F.fragility(ds)
    flagged = (ds["status"] & L.STATUS_FLAGGED) != 0
    assert np.array_equal(fr["n_excluded"].values, flagged.sum(("record", "PGA")).values)
    assert int(fr["n_excluded"].sum()) == math.ceil(ds["outcome"].size / 7)
    counted = ~flagged
    assert np.array_equal(fr["n_counted"].values, counted.sum("record").values)
    over = ds["outcome"].isin([1, 2]) & counted
    k = over.isel(lam=1).sum("record").values
    n = counted.isel(lam=1).sum("record").values
    assert float(fr["im_median"][1]) == pytest.approx(F.fit_stripes(LEVELS, k, n).im_median,
                                                   rel=1e-12)
    # a flagged point counted as safe would give another answer
    n_all = np.full(LEVELS.size, ds.sizes["record"])
    assert float(fr["im_median"][1]) != pytest.approx(F.fit_stripes(LEVELS, k, n_all).im_median,
                                                   rel=1e-6)


def test_not_run_points_are_left_out():
    ds = suite_dataset()
    ds["outcome"][0, 0, :] = L.OUTCOME_NOT_RUN
    ds["status"][0, 0, :] = 0
    fr = F.fragility(ds)
    assert int(fr["n_not_run"][0]) == LEVELS.size and int(fr["n_not_run"][1]) == 0
    assert int(fr["n_records"][0]) == ds.sizes["record"] - 1


def small_dataset():
    """4 records x 4 PGA levels by hand (one lam)."""
    outcome = np.array([[0, 0, 1, 1],   # A: first at 0.3, stays
                        [0, 2, 0, 1],   # B: first at 0.2, safe again at 0.3
                        [0, 0, 0, 0],   # C: never
                        [0, 0, 1, 0]],  # D: first at 0.3 (0.2 flagged), safe at 0.4
                       dtype=np.int8)
    status = np.zeros((4, 4), dtype=np.int32)
    status[3, 1] = L.STATUS_EVENT_CAP
    uplifts = np.array([[0, 1, 2, 2], [0, 0, 0, 1], [0, 0, 0, 0], [1, 0, 0, 0]], np.int32)
    theta = np.array([[0.1, 0.3, 9, 9], [0.2, 9, 0.7, 9], [0.0, 0.1, 0.2, 0.6],
                      [0.0, 0.4, 9, 0.3]])
    return xr.Dataset(
        {"outcome": (("record", "PGA"), outcome), "status": (("record", "PGA"), status),
         "uplifts": (("record", "PGA"), uplifts),
         "theta_max_over_alpha": (("record", "PGA"), theta)},
        coords={"record": ["A.AT2", "B.AT2", "C.AT2", "D.AT2"],
                "PGA": [0.1, 0.2, 0.3, 0.4]},
        attrs={"scale_im": "PGA"})


def test_state_definitions_and_per_record_levels():
    ds = small_dataset()
    fr = F.fragility(ds, state=["overturn", "mode1", "mode2", "uplift", "theta:0.5"])
    assert list(fr["state"].values) == ["overturn", "mode1", "mode2", "uplift", "theta:0.5"]
    # by hand; level 0.2 of D is flagged (3 counted there)
    assert np.array_equal(fr["n_counted"].values, [4, 3, 4, 4])
    expect = {"overturn": [0, 1, 2, 2], "mode1": [0, 0, 2, 2], "mode2": [0, 1, 0, 0],
              "uplift": [1, 2, 2, 2], "theta:0.5": [0, 1, 3, 3]}
    for s, k in expect.items():
        assert fr["n_failed"].sel(state=s).values.tolist() == k, s
    first = fr["first_level"].sel(state="overturn").values
    assert np.allclose(first, [0.3, 0.2, np.nan, 0.3], equal_nan=True)
    assert fr["resurrection"].sel(state="overturn").values.tolist() == [False, True, False,
                                                                        True]
    assert np.allclose(fr["first_level"].sel(state="uplift").values, [0.2, 0.2, np.nan, 0.1],
                       equal_nan=True)
    # B has no uplift at 0.3, D none at 0.4: both "resurrect"
    assert fr["resurrection"].sel(state="uplift").values.tolist() == [False, True, False,
                                                                      True]
    assert int(fr["n_excluded"]) == 1


def test_a_single_state_has_no_state_dimension():
    fr = F.fragility(small_dataset(), state="overturn")
    assert "state" not in fr["im_median"].dims and fr["state"].item() == "overturn"


def test_bad_requests_are_one_line_errors():
    ds = small_dataset()
    for kw in ({"state": "topple"}, {"state": "theta:-1"}, {"im": "PGV"}, {"ci": 1.5}):
        with pytest.raises(errors.FragilityError) as err:
            F.fragility(ds, **kw)
        assert "\n" not in str(err.value)
    with pytest.raises(errors.FragilityError):
        F.fragility(ds.drop_vars("status"))


def cloud_dataset(n=400, seed=4):
    rng = np.random.default_rng(seed)
    pga = rng.lognormal(math.log(0.3), 0.6, n)
    factor = np.full(n, 2.0)
    sa = np.stack([pga * 2.5, pga * 1.2], axis=1)
    im = pga * factor
    over = rng.random(n) < norm.cdf(np.log(im / 0.7) / 0.3)
    outcome = np.where(over, 1, 0).astype(np.int8)[None, :]
    return xr.Dataset(
        {"outcome": (("lam", "record"), outcome),
         "status": (("lam", "record"), np.zeros((1, n), np.int32)),
         "record_pga": ("record", pga), "record_pgv": ("record", pga * 0.8),
         "record_sa": (("record", "period"), sa), "scale_factor": ("record", factor)},
        coords={"lam": [0.0], "record": [f"R{i}" for i in range(n)], "period": [0.2, 1.0]})


def test_cloud_dataset_uses_the_scaled_record_ims():
    ds = cloud_dataset()
    fr = F.fragility(ds)
    assert fr.attrs["method"] == "cloud-mle" and fr.attrs["im"] == "PGA"
    assert float(fr["im_median"][0]) == pytest.approx(0.7, rel=0.1)
    im = ds["record_pga"].values * 2.0
    assert float(fr["im_median"][0]) == pytest.approx(
        F.fit_cloud(im, ds["outcome"].values[0] > 0).im_median, rel=1e-12)
    sa = F.fragility(ds, im="Sa", period=1.0)
    assert float(sa["im_median"][0]) == pytest.approx(1.2 * float(fr["im_median"][0]), rel=1e-9)
    assert sa.attrs["period"] == 1.0
    with pytest.raises(errors.FragilityError):
        F.fragility(ds, im="Sa")  # two periods: which one?
    assert "fraction" not in fr and "first_level" not in fr


def test_curves_json():
    ds = suite_dataset()
    fr = F.fragility(ds, state=["overturn", "uplift"], bootstrap=20, seed=2)
    doc = F.curves_json(fr)
    text = json.dumps(doc, allow_nan=False)  # plain numbers only
    assert json.loads(text) == doc
    curves = doc["curves"]
    assert len(curves) == 4
    keys = {"lam", "state", "im", "method", "im_median", "beta", "im_median_ci", "beta_ci",
            "n_records", "n_excluded", "n_not_run", "reason"}
    for c in curves:
        assert keys <= set(c)
        assert isinstance(c["lam"], float) and isinstance(c["n_records"], int)
        assert c["im"] == "PGA" and c["method"] == "stripes-mle"
        assert len(c["im_median_ci"]) == 2 and c["im_median_ci"][0] <= c["im_median"]
    first = curves[0]
    assert (first["lam"], first["state"]) == (0.0, "overturn")
    assert first["im_median"] == float(fr["im_median"].sel(state="overturn", lam=0.0))


def test_without_bootstrap_the_intervals_are_nan():
    fr = F.fragility(suite_dataset(n_records=20), bootstrap=0)
    assert "im_median_samples" not in fr
    assert np.all(np.isnan(fr["im_median_lo"].values)) and np.all(np.isnan(fr["band_hi"].values))
    assert np.all(np.isfinite(fr["im_median"].values))


def test_cloud_bootstrap_interval_holds_the_truth():
    fr = F.fragility(cloud_dataset(), bootstrap=200, seed=5)
    lo, hi = float(fr["im_median_lo"][0]), float(fr["im_median_hi"][0])
    assert lo < float(fr["im_median"][0]) < hi
    assert lo < 0.7 < hi
    assert float(fr["beta_lo"][0]) < 0.3 < float(fr["beta_hi"][0])


def test_bootstrap_of_nearly_degenerate_data_counts_undefined_resamples():
    # two of 12 records overturn near the top; record 1 is safe again at the level where
    # record 0 alone fails. A resample has a finite fit only if it draws both: without
    # record 0 the fractions take one value strictly between 0 and 1 (beta undetermined),
    # without record 1 the data are separated. P(both drawn) = 1 - 2 (11/12)^12 +
    # (10/12)^12 = 0.408
    failed = np.zeros((12, LEVELS.size), dtype=bool)
    failed[0, -3:] = True
    failed[1, [-3, -1]] = True
    b = LK.bootstrap_records(LEVELS, failed, n_boot=300, seed=0)
    p_undef = 2 * (11 / 12) ** 12 - (10 / 12) ** 12
    sd = math.sqrt(300 * p_undef * (1 - p_undef))
    assert abs(b.n_undefined - 300 * p_undef) < 4 * sd
    assert np.isnan(b.medians).sum() == b.n_undefined
    assert np.isfinite(b.median_ci[0])
