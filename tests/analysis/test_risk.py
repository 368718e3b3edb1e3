"""rocksweep.risk: the annual rate of a state against closed forms, the hazard readers,
the bootstrap band and bad input (one line, nothing written)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from click.testing import CliRunner
from scipy import integrate
from scipy.stats import norm

import rocksweep
from rocksweep.analysis.risk import read_hazard
from rocksweep.cli import main
from rocksweep.errors import RiskError
from rocksweep.physics.bodies import G


def fragility(median, beta, **extra):
    median = np.atleast_1d(np.asarray(median, float))
    beta = np.broadcast_to(np.asarray(beta, float), median.shape)
    data = {"im_median": (("lam",), median), "beta": (("lam",), beta)}
    data.update(extra)
    return xr.Dataset(data, coords={"lam": np.arange(median.size) * 0.2},
                      attrs={"im": "PGA", "im_units": "g", "ci": 0.9})


def power_law(k0, k, lo=1e-4, hi=1e2, n=40):
    x = np.geomspace(lo, hi, n)
    return pd.DataFrame({"PGA [g]": x, "annual_rate": k0 * x ** -k})


@pytest.mark.parametrize(("k0", "k", "median", "beta"), [
    (1e-4, 2.0, 0.3, 0.4), (3e-5, 3.0, 0.8, 0.6), (1e-3, 1.5, 0.15, 0.25),
    (1e-4, 2.5, 0.5, 0.9)])
def test_power_law_hazard_meets_the_closed_form(k0, k, median, beta):
    # lambda(x) = k0 x^-k, P = Phi(ln(x/m)/beta): lambda_state = k0 m^-k exp(k^2 beta^2/2)
    rk = rocksweep.risk(fragility(median, beta), power_law(k0, k), years=50)
    exact = k0 * median ** -k * math.exp(k * k * beta * beta / 2.0)
    assert float(rk.annual_rate[0]) == pytest.approx(exact, rel=1e-2)
    assert float(rk.annual_rate[0]) == pytest.approx(exact, rel=1e-6)  # in fact far closer
    assert float(rk.probability[0]) == pytest.approx(1 - math.exp(-exact * 50), rel=1e-4)
    assert str(rk.reason.values[0]) == "ok"


@pytest.mark.parametrize(("unit", "per_g"), [("m/s^2", G), ("cm/s2", 100 * G),
                                             ("gal", 100 * G)])
def test_a_hazard_in_other_acceleration_units_is_converted(unit, per_g):
    """The same hazard curve given in m/s^2 or cm/s^2 (Gal) gives the rate of the curve in
    g (the closed form above); the conversion is stated. g is rocksweep's G, the gravity
    the records' PGV and the model use."""
    k0, k, median, beta = 1e-4, 2.0, 0.3, 0.4
    in_g = power_law(k0, k)
    other = pd.DataFrame({f"PGA [{unit}]": in_g["PGA [g]"] * per_g,
                          "annual_rate": in_g["annual_rate"]})
    rk = rocksweep.risk(fragility(median, beta), other, years=50)
    exact = k0 * median ** -k * math.exp(k * k * beta * beta / 2.0)
    assert float(rk.annual_rate[0]) == pytest.approx(exact, rel=1e-6)
    assert rk.attrs["hazard_unit"].startswith(f"{unit}, converted to g")
    assert rk.attrs["im_units"] == "g"
    np.testing.assert_allclose(rk["hazard_im"].values, in_g["PGA [g]"].values, rtol=1e-12)


def test_a_pgv_hazard_in_cm_per_s_is_converted():
    frag = fragility(0.4, 0.5)
    frag.attrs.update(im="PGV", im_units="m/s")
    x = np.geomspace(1e-3, 10.0, 40)  # m/s
    rate = 1e-3 * x ** -2.0
    in_m = rocksweep.risk(frag, pd.DataFrame({"PGV [m/s]": x, "annual_rate": rate}))
    in_cm = rocksweep.risk(frag, pd.DataFrame({"PGV [cm/s]": 100 * x, "annual_rate": rate}))
    assert float(in_cm.annual_rate[0]) == pytest.approx(float(in_m.annual_rate[0]), rel=1e-9)
    assert "hazard_unit" not in in_m.attrs and "x 0.01" in in_cm.attrs["hazard_unit"]


def test_a_general_hazard_against_scipy_quad():
    # a curved hazard (not a power law): the integral over its range by scipy.quad on the
    # log-log interpolant, written here independently
    x = np.geomspace(0.01, 3.0, 12)
    rate = 0.05 * np.exp(-3.0 * np.sqrt(x / 0.01) / 10.0) + 1e-6 / x
    med, beta = 0.4, 0.5

    def lam(u):  # ln x -> lambda, log-log linear between the points
        return math.exp(np.interp(u, np.log(x), np.log(rate)))

    def dens(u):  # P(x) |d lambda / d u|
        h = 1e-6
        return norm.cdf((u - math.log(med)) / beta) * (lam(u - h) - lam(u + h)) / (2 * h)

    inside = sum(integrate.quad(dens, math.log(a), math.log(b), limit=200)[0]
                 for a, b in zip(x[:-1], x[1:], strict=True))
    tail = norm.cdf(math.log(x[-1] / med) / beta) * rate[-1]
    rk = rocksweep.risk(fragility(med, beta),
                        pd.DataFrame({"PGA [g]": x, "annual_rate": rate}), 10)
    assert float(rk.annual_rate[0]) == pytest.approx(inside + tail, rel=1e-3)
    assert float(rk.annual_rate_max[0]) == pytest.approx(inside + rate[-1], rel=1e-3)


def test_the_bounds_and_their_verdicts():
    # a hazard that stops below the median: the rate is a lower bound, said so
    rk = rocksweep.risk(fragility(2.0, 0.4), power_law(1e-4, 2.0, 1e-3, 1.0), 1)
    assert "above_hazard" in str(rk.reason.values[0])
    assert float(rk.annual_rate_max[0]) > float(rk.annual_rate[0])
    # a hazard that starts where the fragility is already 0.5
    rk = rocksweep.risk(fragility(0.1, 0.4), power_law(1e-4, 2.0, 0.1, 100.0), 1)
    assert "below_hazard" in str(rk.reason.values[0])


def test_bootstrap_band_from_the_fragilitys_samples():
    rng = np.random.default_rng(1)
    ms = np.exp(rng.normal(np.log(0.4), 0.1, (1, 400)))
    bs = rng.uniform(0.3, 0.5, (1, 400))
    fr = fragility(0.4, 0.4, im_median_samples=(("lam", "sample"), ms),
                   beta_samples=(("lam", "sample"), bs))
    k0, k = 1e-4, 2.0
    rk = rocksweep.risk(fr, power_law(k0, k), 50)
    each = k0 * ms[0] ** -k * np.exp(k * k * bs[0] ** 2 / 2)
    lo, hi = np.percentile(each, [5, 95])
    assert float(rk.annual_rate_lo[0]) == pytest.approx(lo, rel=1e-3)
    assert float(rk.annual_rate_hi[0]) == pytest.approx(hi, rel=1e-3)
    assert float(rk.probability_lo[0]) < float(rk.probability[0]) < float(
        rk.probability_hi[0])


def test_old_fragility_name_median_is_read():
    fr = fragility(0.3, 0.4).rename({"im_median": "median"})
    rk = rocksweep.risk(fr, power_law(1e-4, 2.0), 50)
    assert float(rk.annual_rate[0]) == pytest.approx(1e-4 * 0.3 ** -2 * math.exp(2 * 0.16),
                                                     rel=1e-3)


OQ = ("#,,,,,\"generated_by='OpenQuake engine 3.18.0', start_date='2023-10-03T06:09:08', "
      "checksum=2107362341, kind='mean', investigation_time={T}, imt='{imt}'\"\n"
      "lon,lat,depth,{cols}\n{rows}")


def oq_file(path, T, imt, levels, poes):
    cols = ",".join(f"poe-{v:.7f}" for v in levels)
    rows = "".join("0.0,0.0,-0.1," + ",".join(f"{p:.6E}" for p in ps) + "\n" for ps in poes)
    path.write_text(OQ.format(T=T, imt=imt, cols=cols, rows=rows))
    return path


def test_openquake_poe_becomes_a_rate(tmp_path):
    levels = np.geomspace(0.005, 3.0, 20)
    rate = 2e-5 * levels ** -2.0
    T = 2.0
    poe = 1 - np.exp(-rate * T)
    poe[0] = 1.0  # a level certain to be exceeded: no rate, left out
    hz = read_hazard(oq_file(tmp_path / "hc.csv", T, "PGA", levels, [poe]))
    assert hz.name == "PGA" and hz.unit == "g"
    assert hz.notes.startswith("1 level(s) with poe = 1 left out") and "0.005 g" in hz.notes
    rk = rocksweep.risk(fragility(0.3, 0.4), hz)
    assert rk.attrs["hazard_notes"] == hz.notes  # the result says what was left out
    np.testing.assert_allclose(hz.im, levels[1:], rtol=1e-5)  # 7 decimals in the header
    np.testing.assert_allclose(hz.rate, rate[1:], rtol=1e-5)
    # OpenQuake's PGV is in cm/s
    hv = read_hazard(oq_file(tmp_path / "pgv.csv", 1.0, "PGV", [10.0, 50.0], [[0.1, 0.01]]))
    assert hv.unit == "m/s" and hv.im.tolist() == pytest.approx([0.1, 0.5])
    # several sites: one must be chosen
    two = oq_file(tmp_path / "two.csv", T, "PGA", levels[1:], [poe[1:], poe[1:] / 2])
    with pytest.raises(RiskError, match="2 sites"):
        read_hazard(two)
    assert read_hazard(two, site=1).rate[0] == pytest.approx(
        -math.log1p(-poe[1] / 2) / T, rel=1e-5)


BAD = {
    "non-monotone": "PGA [g],annual_rate\n0.1,1e-2\n0.2,2e-2\n0.4,1e-4\n",
    "negative": "PGA [g],annual_rate\n0.1,1e-2\n0.2,-1e-3\n",
    "other IM": "PGV [m/s],annual_rate\n0.1,1e-2\n0.2,1e-3\n",
    "other unit": "PGA [ft/s2],annual_rate\n0.1,1e-2\n0.2,1e-3\n",
    "a velocity unit": "PGA [cm/s],annual_rate\n0.1,1e-2\n0.2,1e-3\n",
    "one row": "PGA [g],annual_rate\n0.1,1e-2\n",
    "NaN": "PGA [g],annual_rate\n0.1,nan\n0.2,1e-3\n",
    "no unit": "PGA,annual_rate\n0.1,1e-2\n0.2,1e-3\n",
}
WORDS = {"non-monotone": "must not increase", "negative": "must be >= 0",
         "other IM": "not the fragility's IM", "other unit": "cannot be converted",
         "a velocity unit": "cannot be converted", "one row": "at least 2",
         "NaN": "finite", "no unit": "unit"}


@pytest.fixture(scope="module")
def frag_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("risk") / "frag.h5"
    fragility([0.3, 0.5], 0.4).to_netcdf(path, engine="h5netcdf")
    return path


@pytest.mark.parametrize("case", list(BAD))
def test_bad_hazard_is_one_line_and_writes_nothing(case, tmp_path, frag_file):
    hz = tmp_path / "hz.csv"
    hz.write_text(BAD[case])
    with pytest.raises(RiskError, match=WORDS[case]):
        rocksweep.risk(xr.load_dataset(frag_file, engine="h5netcdf"), hz)
    out = tmp_path / "risk.h5"
    res = CliRunner().invoke(main, ["risk", str(frag_file), "--hazard", str(hz), "-o",
                                    str(out)])
    assert res.exit_code != 0 and "Traceback" not in res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error:") and WORDS[case] in lines[0]
    assert not out.exists() and list(tmp_path.iterdir()) == [hz]


@pytest.mark.parametrize("years", [0, -5, math.nan, math.inf])
def test_years_must_be_positive(years, tmp_path, frag_file):
    with pytest.raises(RiskError, match="years"):
        rocksweep.risk(fragility(0.3, 0.4), power_law(1e-4, 2.0), years=years)
    hz = tmp_path / "hz.csv"
    power_law(1e-4, 2.0).to_csv(hz, index=False)
    out = tmp_path / "r.csv"
    res = CliRunner().invoke(main, ["risk", str(frag_file), "--hazard", str(hz),
                                    "--years", str(years), "-o", str(out)])
    assert res.exit_code != 0 and res.output.startswith("Error:") and "years" in res.output
    assert not out.exists()


def test_cli_writes_csv_and_h5(tmp_path, frag_file):
    hz = tmp_path / "hz.csv"
    power_law(1e-4, 2.0).to_csv(hz, index=False)
    out = tmp_path / "r.csv"
    res = CliRunner().invoke(main, ["risk", str(frag_file), "--hazard", str(hz),
                                    "--years", "10", "-o", str(out)])
    assert res.exit_code == 0, res.output
    table = pd.read_csv(out)
    exact = 1e-4 * np.array([0.3, 0.5]) ** -2 * math.exp(2 * 0.16)
    np.testing.assert_allclose(table["annual_rate"], exact, rtol=1e-3)
    np.testing.assert_allclose(table["probability"], 1 - np.exp(-10 * exact), rtol=1e-3)
    h5 = tmp_path / "r.h5"
    assert CliRunner().invoke(main, ["risk", str(frag_file), "--hazard", str(hz), "-o",
                                     str(h5)]).exit_code == 0
    back = rocksweep.open(h5)
    assert back.attrs["rocksweep_kind"] == "risk"
    fig = rocksweep.plot(back)
    assert len(fig.axes) == 3


def test_the_fits_verdict_carries_over():
    fr = fragility([0.3, 0.5], 0.4, reason=(("lam",), np.array(["ok", "extrapolated"])))
    rk = rocksweep.risk(fr, power_law(1e-4, 2.0), 50)
    assert rk.reason.values.tolist() == ["ok", "fit_extrapolated"]


def test_shipped_example_hazard_with_comments_reads():
    from pathlib import Path

    hz = read_hazard(Path(__file__).resolve().parents[2] / "configs" / "hazard-example.csv")
    assert hz.name == "PGA" and hz.unit == "g" and hz.im.size == 16
    assert np.all(np.diff(hz.rate) < 0)


def test_the_integrand_integrates_to_the_rate():
    # the figure's integrand P(x) |d lambda / d ln x| over ln x, by the trapezoid rule,
    # is the rate over the hazard's range (the certain tail above aside)
    x = np.geomspace(0.01, 3.0, 12)
    rate = 0.05 * np.exp(-3.0 * np.sqrt(x / 0.01) / 10.0) + 1e-6 / x
    rk = rocksweep.risk(fragility(0.4, 0.5), pd.DataFrame({"PGA [g]": x,
                                                           "annual_rate": rate}), 10)
    area = integrate.trapezoid(rk.rate_density[0].values, np.log(rk.im_level.values))
    tail = float(rk.fragility[0, -1]) * rate[-1]
    assert area + tail == pytest.approx(float(rk.annual_rate[0]), rel=5e-3)  # 200 points


def test_older_openquake_header(tmp_path):
    # OpenQuake 2.x: "# ..., investigation_time=1.0, imt=\"SA(1.0)\"" before the columns
    path = tmp_path / "old.csv"
    path.write_text("# source_model_tree_path=('b1',), gsim_tree_path=('b1',), "
                    "investigation_time=1.0, imt=\"SA(1.0)\"\n"
                    "lon,lat,depth,poe-0.1,poe-0.2,poe-0.4\n0,0,0,0.1,0.01,0.001\n")
    hz = read_hazard(path)
    assert (hz.name, hz.unit, hz.period) == ("Sa", "g", 1.0)
    np.testing.assert_allclose(hz.rate, -np.log1p(-np.array([0.1, 0.01, 0.001])))


@pytest.mark.filterwarnings("ignore")
def test_competing_modes_integrate_their_own_probabilities():
    # mode1 and mode2 fitted jointly are not lognormal CDFs of their im_median and beta:
    # the rate integrates fragility.probability (checked here with scipy.quad)
    from rocksweep.analysis.fragility import probability

    rng = np.random.default_rng(2)
    R, levels = 60, np.geomspace(0.1, 3.0, 12)
    c1 = rng.lognormal(np.log(0.8), 0.4, R)  # each record's capacity in mode 1, mode 2
    c2 = rng.lognormal(np.log(1.1), 0.4, R)
    over = levels[None, :] >= np.minimum(c1, c2)[:, None]
    outcome = np.where(over, np.where((c1 < c2)[:, None], 1, 2), 0).astype(np.int8)
    ds = xr.Dataset({"outcome": (("lam", "record", "PGA"), outcome[None]),
                     "status": (("lam", "record", "PGA"), np.zeros((1, R, 12), np.int32))},
                    coords={"lam": [0.0], "record": [f"r{i}" for i in range(R)],
                            "PGA": levels}, attrs={"scale_im": "PGA"})
    fr = rocksweep.fragility(ds, state=["mode1", "mode2"], bootstrap=10, joint=True)
    assert set(fr.fit.values.tolist()) == {"competing"}
    x = np.geomspace(0.01, 5.0, 30)
    k0, k = 1e-4, 2.0
    rk = rocksweep.risk(fr, pd.DataFrame({"PGA [g]": x, "annual_rate": k0 * x ** -k}))
    for s in range(2):
        def dens(u, s=s):  # P(x) |d lambda / d ln x| of the power law
            p = probability(fr, [math.exp(u)]).isel(state=s, lam=0).item()
            return p * k * k0 * math.exp(-k * u)
        inside = integrate.quad(dens, math.log(0.01), math.log(5.0), limit=200)[0]
        top = probability(fr, [5.0]).isel(state=s, lam=0).item() * k0 * 5.0 ** -k
        got = float(rk.annual_rate.isel(state=s, lam=0))
        assert got == pytest.approx(inside + top, rel=1e-4)
        lognormal = fragility(float(fr.im_median.isel(state=s, lam=0)),
                              float(fr.beta.isel(state=s, lam=0)))
        plain = float(rocksweep.risk(lognormal, pd.DataFrame(
            {"PGA [g]": x, "annual_rate": k0 * x ** -k})).annual_rate[0])
        if s == 1:  # mode 2, censored by mode 1: far from its lognormal reading
            assert abs(got / plain - 1) > 0.05


def test_openquake_avgsa_ia_and_cav_are_read_in_rocksweeps_units(tmp_path):
    # openquake.hazardlib.imt: AvgSA in g, IA (Arias) in m/s, CAV in g s
    hz = read_hazard(oq_file(tmp_path / "avg.csv", 1.0, "AvgSA", [0.1, 0.5], [[0.1, 0.01]]))
    assert (hz.name, hz.unit) == ("AvgSa", "g") and hz.im.tolist() == pytest.approx([0.1, 0.5])
    ia = read_hazard(oq_file(tmp_path / "ia.csv", 1.0, "IA", [0.1, 0.5], [[0.1, 0.01]]))
    assert (ia.name, ia.unit) == ("Arias", "m/s")
    cav = read_hazard(oq_file(tmp_path / "cav.csv", 1.0, "CAV", [0.1, 0.5], [[0.1, 0.01]]))
    assert (cav.name, cav.unit) == ("CAV", "m/s")
    assert cav.im.tolist() == pytest.approx([0.1 * G, 0.5 * G])


def test_an_avgsa_hazard_meets_the_closed_form():
    k0, k, median, beta = 1e-4, 2.0, 0.3, 0.4
    fr = fragility(median, beta)
    fr.attrs["im"] = "AvgSa"
    hz = power_law(k0, k).rename(columns={"PGA [g]": "AvgSa [g]"})
    rk = rocksweep.risk(fr, hz, years=50)
    exact = k0 * median ** -k * math.exp(k * k * beta * beta / 2.0)
    assert float(rk.annual_rate[0]) == pytest.approx(exact, rel=1e-6)
    with pytest.raises(RiskError, match="not the fragility's IM AvgSa"):
        rocksweep.risk(fr, power_law(k0, k), years=50)


def test_an_openquake_header_says_only_what_it_misses(tmp_path):
    path = oq_file(tmp_path / "hc.csv", 1.0, "PGA", [0.1, 0.2], [[0.1, 0.01]])
    text = path.read_text().replace("investigation_time=1.0, ", "")
    path.write_text(text)
    with pytest.raises(RiskError, match="has no investigation_time: ") as err:
        read_hazard(path)
    assert "and no imt" not in str(err.value)  # imt is there: not named missing
