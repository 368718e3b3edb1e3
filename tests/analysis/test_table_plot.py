"""rocksweep.table (one row per run, no duplicates) and rocksweep.plot of every kind of
rocksweep Dataset."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from matplotlib.figure import Figure

import rocksweep
from rocksweep.analysis.kinds import dataset_kind
from rocksweep.cli import main
from rocksweep.physics.bodies import G


@pytest.fixture(scope="module")
def ds(suite_result):
    return rocksweep.open(suite_result)


def test_one_row_per_run_with_the_runs_ims(ds):
    t = rocksweep.table(ds)
    assert len(t) == ds.outcome.size  # to_dataframe() has one row per run and period
    assert len(ds.to_dataframe()) == ds.outcome.size * ds.sizes["period"]
    assert not t[["lam", "record", "PGA"]].duplicated().any()
    # every run's outcome where the Dataset has it
    for _, row in t.sample(20, random_state=0).iterrows():
        one = ds.sel(lam=row["lam"], record=row["record"], PGA=row["PGA"])
        assert row["outcome"] == int(one.outcome)
        assert row["scale_factor"] == pytest.approx(float(one.scale_factor))
    # the scaled IMs: PGA is the stripe; PGV, Arias, D5-95 follow F^n
    np.testing.assert_allclose(t["pga"], t["PGA"], rtol=1e-12)
    np.testing.assert_allclose(t["pgv"], t["record_pgv"] * t["scale_factor"], rtol=1e-12)
    np.testing.assert_allclose(t["arias"], t["record_arias"] * t["scale_factor"] ** 2,
                               rtol=1e-12)
    np.testing.assert_allclose(t["d5_95"], t["record_d5_95"], rtol=1e-12)
    np.testing.assert_allclose(t["pgv_over_pga"], t["pgv"] / (t["pga"] * G), rtol=1e-9)
    assert {"record_sa(0.2)", "record_sa(1)", "sa(0.2)", "sa(1)"} <= set(t.columns)
    # the dimensionless IMs of each run: PGA/(g tan alpha_cg), PGV p/(g tan alpha_cg)
    np.testing.assert_allclose(t["pga_ratio"], t["PGA"] / np.tan(0.15), rtol=1e-12)
    np.testing.assert_allclose(t["pgv_ratio"], t["pgv"] * 2.0 / (G * np.tan(0.15)),
                               rtol=1e-12)
    assert t.attrs["units"]["arias"] == "m/s" and t.attrs["units"]["d5_95"] == "s"
    assert "record_sha256" not in t.columns


def test_cli_table_csv_and_parquet(ds, suite_result, tmp_path):
    csv = tmp_path / "runs.csv"
    res = CliRunner().invoke(main, ["table", str(suite_result), "-o", str(csv)])
    assert res.exit_code == 0, res.output
    back = pd.read_csv(csv)
    assert len(back) == ds.outcome.size and not back.duplicated().any()
    # units in the header; the status in words
    assert {"arias [m/s]", "PGA [g]", "d5_95 [s]", "outcome", "status_words"} <= set(
        back.columns)
    words = dict(zip(back["status"], back["status_words"].fillna(""), strict=True))
    from rocksweep.kernel import layout as L  # noqa: N812

    for bits, text in words.items():
        assert ("overturned" in text.split(",")) == bool(bits & L.STATUS_OVERTURNED)
    assert set(back["outcome_word"]) <= {"safe", "mode1", "mode2"}
    pq = tmp_path / "runs.parquet"
    pytest.importorskip("pyarrow", reason="Parquet needs pyarrow (the test extra)")
    assert CliRunner().invoke(main, ["table", str(suite_result), "-o", str(pq)]).exit_code == 0
    pd.testing.assert_frame_equal(pd.read_parquet(pq), rocksweep.table(ds),
                                  check_dtype=False)
    import pyarrow.parquet as pqf

    schema = pqf.read_schema(pq)
    assert schema.field("arias").metadata[b"units"] == b"m/s"
    bad = CliRunner().invoke(main, ["table", str(suite_result), "-o", str(tmp_path / "x.txt")])
    assert bad.exit_code != 0 and bad.output.startswith("Error:") and ".parquet" in bad.output


def test_plot_draws_every_kind(ds):
    fr = rocksweep.fragility(ds, state=["overturn", "mode1"], bootstrap=20)
    eff = rocksweep.im_efficiency(ds)
    x = np.geomspace(0.01, 5.0, 20)
    rk = rocksweep.risk(fr, pd.DataFrame({"PGA [g]": x, "annual_rate": 1e-4 * x ** -2.0}))
    for d, kind in ((ds, "sweep"), (fr, "fragility"), (eff, "im_efficiency"),
                    (rk, "risk")):
        assert dataset_kind(d) == kind
        assert d.attrs.get("rocksweep_kind", "sweep") == kind
        fig = rocksweep.plot(d)
        assert isinstance(fig, Figure) and fig.axes
        assert isinstance(d.rocksweep.plot(), Figure)
    # the fragility: IM on a log axis, beta in the legend, the legend outside the axes
    fig = rocksweep.plot(fr)
    ax = fig.axes[0]
    assert ax.get_xscale() == "log"
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("beta" in t for t in texts)
    fig.canvas.draw()
    leg = ax.get_legend().get_window_extent()
    box = ax.get_window_extent()
    assert leg.y1 <= box.y0 + 1  # below the axes: covers no data
    # the table of an analysis: one row per curve
    assert len(rocksweep.table(rk)) == rk.annual_rate.size
    assert len(rocksweep.table(eff)) == eff.beta.size


def test_plot_of_a_foreign_dataset_is_one_line():
    import xarray as xr

    with pytest.raises(rocksweep.RocksweepError) as err:
        rocksweep.plot(xr.Dataset({"x": ("t", [1.0, 2.0])}))
    assert "\n" not in str(err.value)


@pytest.mark.filterwarnings("ignore::rocksweep.physics.suite.RecordWarning")
def test_plot_of_ida_and_spectra_datasets(ds):
    import xarray as xr

    ida = rocksweep.ida(ds, rtol=0.05)
    assert dataset_kind(ida) == "ida" and ida.attrs["rocksweep_kind"] == "ida"
    fig = rocksweep.plot(ida)
    # IDA curves: one panel per lam, max|theta|/alpha against the IM, one curve per record
    # ending at its bisected first overturning level at the limit 1
    assert len(fig.axes) == ds.sizes["lam"]
    ax = fig.axes[0]
    assert ax.get_xscale() == "log"
    v = ida.ida_im.isel(lam=0).values
    ends = {round(float(ln.get_xdata()[0]), 12) for ln in ax.lines
            if len(ln.get_xdata()) == 1 and ln.get_ydata()[0] == 1.0}
    assert ends == {round(float(x), 12) for x in v[np.isfinite(v)]}
    lam, A, p = [0.0, 0.4], [1.0, 2.0, 3.0], np.linspace(1, 5, 7)
    sp = xr.Dataset(
        {"theta_max_over_alpha": (("lam", "A_ratio", "p"), np.random.default_rng(0)
                                  .uniform(0.1, 1.0, (2, 3, 7))),
         "outcome": (("lam", "A_ratio", "p"), np.zeros((2, 3, 7), np.int8)),
         "A_min": (("lam", "p"), np.full((2, 7), 2.5)),
         "mode": (("lam", "p"), np.ones((2, 7), np.int8))},
        coords={"lam": lam, "A_ratio": A, "p": p})
    assert dataset_kind(sp) == "spectra"
    fig = rocksweep.plot(sp)
    assert len(fig.axes) == 2 and "at overturning onset" in fig.axes[1].get_ylabel()


def test_diagram_options_on_a_suite_are_one_line(suite_result):
    res = CliRunner().invoke(main, ["plot", str(suite_result), "--x", "lam", "-o",
                                    str(suite_result.with_name("x.png"))])
    assert res.exit_code != 0 and res.output.startswith("Error: --x lam: a record-suite")
    assert len(res.output.strip().splitlines()) == 1
    assert not suite_result.with_name("x.png").exists()


def test_a_flagged_run_is_one_rule_kept_in_the_table_left_out_of_analyses(ds):
    """An airborne run (the body left the ground) is stored safe and flagged; the table
    said "flagged ... left out" yet kept its row (issue 45). One rule: the table keeps
    every run and says so, naming the flag; the analyses leave it out."""
    import warnings

    from rocksweep.analysis.states import counted_points
    from rocksweep.errors import AnalysisWarning
    from rocksweep.vocab.outcomes import STATUS_BIT

    one = ds.copy(deep=True)
    st = one["status"].values
    st.flat[0] = STATUS_BIT["airborne"] | STATUS_BIT["settled"]
    one["outcome"].values.flat[0] = 0
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        t = rocksweep.table(one)
    said = [str(w.message) for w in got if issubclass(w.category, AnalysisWarning)]
    assert len(t) == one.outcome.size and "airborne" in t["status_words"].iloc[0]
    assert said == [f"table: flagged: 1 of {one.outcome.size} points flagged by the kernel "
                    "(airborne 1), kept (their status_words say why; the analyses leave "
                    "them out)"]
    assert not bool(counted_points(one)[0].values.flat[0])  # the analyses do not count it
