"""rocksweep.im_efficiency on synthetic suites whose capacities are known, and on a real
sweep through the CLI."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

import rocksweep
from rocksweep.analysis.efficiency import im_efficiency
from rocksweep.cli import main

R = 60
LEVELS = np.geomspace(0.05, 5.0, 400)  # fine stripes: the interval barely matters


def suite(capacity_pga, pga, pgv, d595, arias=None):
    """A stripes Dataset over (record, PGA): outcome 1 where the stripe >= the record's
    capacity in PGA."""
    over = LEVELS[None, :] >= capacity_pga[:, None]
    ds = xr.Dataset(
        {"outcome": (("record", "PGA"), over.astype(np.int8)),
         "status": (("record", "PGA"), np.zeros(over.shape, np.int32)),
         "record_pga": (("record",), pga), "record_pgv": (("record",), pgv),
         "record_d5_95": (("record",), d595),
         "scale_factor": (("record", "PGA"), LEVELS[None, :] / pga[:, None])},
        coords={"record": [f"r{i}.AT2" for i in range(R)], "PGA": LEVELS,
                "alpha_cg": 0.15, "p": 2.0},
        attrs={"scale_im": "PGA"})
    if arias is not None:
        ds["record_arias"] = (("record",), arias)
    return ds


def test_the_im_that_sets_the_capacity_has_no_dispersion():
    rng = np.random.default_rng(3)
    pga = rng.uniform(0.1, 0.4, R)
    pgv = pga * rng.lognormal(np.log(0.08), 0.4, R) * 9.81  # PGV/PGA varies by record
    # overturning when the scaled PGV exceeds 0.3 m/s: capacity in PGA = 0.3 * pga / pgv
    cap = 0.3 * pga / pgv
    ds = suite(cap, pga, pgv, rng.uniform(5, 30, R), arias=rng.lognormal(-1, 0.3, R))
    eff = im_efficiency(ds)
    b = eff.beta.to_series()
    step = np.log(LEVELS[1] / LEVELS[0])  # the stripes' resolution
    assert b["PGV"] < step  # PGV explains it exactly
    assert eff.im_median.sel(im="PGV").item() == pytest.approx(0.3, rel=step)
    # PGA's dispersion is the scatter of ln(capacity) (an independent np.std)
    assert b["PGA"] == pytest.approx(np.std(np.log(cap)), rel=0.03)
    # PGV/PGA sets the capacity in PGA exactly (cap = 0.3 / (9.81 PGV/PGA)): a regression
    # with slope -1 and nothing left over
    assert b["PGV_over_PGA"] < step
    assert eff.slope.sel(im="PGV_over_PGA").item() == pytest.approx(-1.0, abs=0.02)
    # D5-95 is unrelated: its regression leaves PGA's scatter
    assert b["D5_95"] == pytest.approx(np.std(np.log(cap)), rel=0.15)
    # Arias scales as F^2: its beta is twice the scatter of ln(F at capacity) + its own
    assert eff.exponent.sel(im="Arias").item() == 2
    lnF = np.log(cap / pga)
    assert b["Arias"] == pytest.approx(np.std(2 * lnF + np.log(ds.record_arias.values)),
                                       rel=0.03)
    assert eff.beta_scale.sel(im="Arias").item() == pytest.approx(b["Arias"] / 2)
    # the dimensionless ratios are PGA and PGV over constants here
    assert b["PGA_ratio"] == pytest.approx(b["PGA"], rel=1e-6)
    assert eff.im_median.sel(im="PGA_ratio").item() == pytest.approx(
        eff.im_median.sel(im="PGA").item() / np.tan(0.15), rel=1e-6)


def test_censored_records_are_counted_not_dropped():
    rng = np.random.default_rng(5)
    pga = rng.uniform(0.1, 0.4, R)
    cap = rng.lognormal(np.log(2.0), 0.8, R)  # many above the top stripe (5 g)
    ds = suite(cap, pga, pga * 0.8, np.full(R, 10.0))
    eff = im_efficiency(ds)
    n_cens = int((cap > LEVELS[-1]).sum())
    assert n_cens > 0 and eff.n_censored.sel(im="PGA").item() == n_cens
    # the censored MLE recovers the lognormal that dropping them would bias low
    assert eff.beta.sel(im="PGA").item() == pytest.approx(0.8, rel=0.2)
    kept = np.log(cap[cap <= LEVELS[-1]])
    assert eff.im_median.sel(im="PGA").item() > np.exp(kept.mean())


def test_cli_on_a_real_sweep(tmp_path, suite_result):
    out = tmp_path / "eff.csv"
    fig = tmp_path / "eff.png"
    res = CliRunner().invoke(main, ["efficiency", str(suite_result), "-o", str(out),
                                    "--plot", str(fig)])
    assert res.exit_code == 0, res.output
    assert out.exists() and fig.exists()
    eff = rocksweep.open(suite_result).rocksweep.im_efficiency()
    assert {"PGA", "PGV", "Arias", "CAV", "D5_95", "PGV_over_PGA", "AvgSa"} <= set(
        eff.im.values.tolist())
    assert np.isfinite(eff.beta.sel(im="AvgSa")).all()
    # every column once (shape_x / shape_y came from merging two frames), one row per
    # (IM, curve), the verdict in its column
    import pandas as pd

    head = out.read_text().splitlines()[0].split(",")
    assert len(head) == len(set(head)) and not any(c.endswith(("_x", "_y")) for c in head)
    rows = pd.read_csv(out)
    assert len(rows) == eff["beta"].size and "reason" in rows.columns


def test_cloud_is_a_probit_per_im():
    from scipy.optimize import minimize
    from scipy.stats import norm

    rng = np.random.default_rng(8)
    pga = rng.lognormal(np.log(0.3), 0.5, 80)
    pgv = pga * rng.lognormal(np.log(0.6), 0.3, 80)
    fails = rng.random(80) < norm.cdf(np.log(pgv / 0.2) / 0.3)
    ds = xr.Dataset({"outcome": (("record",), fails.astype(np.int8)),
                     "status": (("record",), np.zeros(80, np.int32)),
                     "record_pga": (("record",), pga), "record_pgv": (("record",), pgv),
                     "scale_factor": (("record",), np.ones(80))},
                    coords={"record": [f"r{i}" for i in range(80)]})
    eff = im_efficiency(ds)
    assert set(eff.method.values) == {"cloud-probit"}

    def direct(x):  # an independent probit MLE over (ln median, ln beta)
        def nll(t):
            p = np.clip(norm.cdf((np.log(x) - t[0]) / np.exp(t[1])), 1e-15, 1 - 1e-15)
            return -np.sum(np.where(fails, np.log(p), np.log1p(-p)))
        return np.exp(minimize(nll, [np.log(np.median(x)), -1.0], method="Nelder-Mead",
                               options={"xatol": 1e-10, "fatol": 1e-12}).x)

    for im, x in (("PGA", pga), ("PGV", pgv)):
        med, beta = direct(x)
        assert eff.beta.sel(im=im).item() == pytest.approx(beta, rel=1e-4)
        assert eff.im_median.sel(im=im).item() == pytest.approx(med, rel=1e-4)
    assert eff.beta.sel(im="PGV").item() < eff.beta.sel(im="PGA").item()


def test_a_small_or_separated_sample_gets_a_verdict():
    """4 records, one censored: beta 0.001-0.002 was ranked and said ok (issue 45). Four
    records are few_records for every IM; three records whose capacities in PGA share a
    value (0.2-0.4 g) are separated: beta there is below the stripes' resolution."""
    import warnings

    from rocksweep.analysis.efficiency import MIN_RECORDS, _separated
    from rocksweep.errors import AnalysisWarning

    levels = np.array([0.1, 0.2, 0.4, 0.8])
    pga = np.array([0.2, 0.3, 0.25, 0.35])
    cap = np.array([0.3, 0.35, 0.38, 0.7])  # all reach it between 0.2 and 0.8 g
    over = levels[None, :] >= cap[:, None]
    ds = xr.Dataset(
        {"outcome": (("record", "PGA"), over.astype(np.int8)),
         "status": (("record", "PGA"), np.zeros(over.shape, np.int32)),
         "record_pga": (("record",), pga), "record_pgv": (("record",), 1.2 * pga),
         "scale_factor": (("record", "PGA"), levels[None, :] / pga[:, None])},
        coords={"record": [f"r{i}.AT2" for i in range(4)], "PGA": levels},
        attrs={"scale_im": "PGA"})
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        eff = im_efficiency(ds)
    # (0.2, 0.4] x 3 and (0.4, 0.8]: no common value; one record fewer: 0.3 g in all three
    assert not _separated(np.log([0.2, 0.2, 0.2, 0.4]), np.log([0.4, 0.4, 0.4, 0.8]), None)
    assert _separated(np.log([0.2, 0.2, 0.3]), np.log([0.4, 0.4, np.inf]), None)
    assert list(eff["reason"].values) == ["few_records"] * eff.sizes["im"]
    said = [str(w.message) for w in got if issubclass(w.category, AnalysisWarning)]
    assert len(said) == 1 and "few_records (every IM: fewer than 10 records)" in said[0]
    three = ds.isel(record=[0, 1, 2])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        e3 = im_efficiency(three)
    assert "separated" in str(e3["reason"].sel(im="PGA").values)
    assert MIN_RECORDS == 10
    # a regression's line through every interval: separated (slope 1 through exact data)
    z = np.log([1.0, 2.0, 4.0])
    assert _separated(z - 0.1, z + 0.1, z) and not _separated(z - 0.1, z + 0.1,
                                                               np.array([0.0, 1.0, 0.0]))
