"""Analyses on Datasets: every analysis takes what ``rocksweep.run`` and
``rocksweep.open`` return, and the command line gives the same answers from a file."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner
from matplotlib.figure import Figure

import rocksweep
from rocksweep.cli import main

ROOT = Path(__file__).resolve().parents[2]
CI_SMALL = ROOT / "configs" / "ci-small.yaml"
SINE = {"pulse.shape": "sine"}


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    """The CI grid (sine) from run() in memory, and the same written by run(output=)
    and read back by open()."""
    out = tmp_path_factory.mktemp("an") / "ci.h5"
    mem = rocksweep.run(CI_SMALL, overrides=SINE)
    rocksweep.run(CI_SMALL, overrides=SINE, output=out)
    return mem, rocksweep.open(out), out


def test_plot_takes_run_and_open(pair):
    mem, disk, _ = pair
    figs = [rocksweep.plot(ds) for ds in (mem, disk)]
    assert all(isinstance(f, Figure) for f in figs)
    images = [_drawn(f) for f in (*figs, mem.rocksweep.plot())]  # the accessor too
    assert len(images[0]) > 0
    for other in images[1:]:
        for a, b in zip(images[0], other, strict=True):
            np.testing.assert_array_equal(a, b)


def _drawn(fig: Figure) -> list[np.ndarray]:
    """The data arrays a figure shows (images and meshes of every axes)."""
    return [np.asarray(a) for ax in fig.axes for art in (*ax.images, *ax.collections)
            if (a := art.get_array()) is not None]


def test_plot_width_presets_and_given_axes(pair):
    mem, _, _ = pair
    single = rocksweep.plot(mem, width="single")
    double = rocksweep.plot(mem, width="double")
    assert single.get_size_inches()[0] == pytest.approx(3.5)
    assert double.get_size_inches()[0] == pytest.approx(7.2)
    with pytest.raises(rocksweep.RocksweepError, match="width"):
        rocksweep.plot(mem, width="triple")
    fig = Figure(figsize=(8, 3), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    rocksweep.plot(mem.sel(lam=[0.0]), ax=ax1)
    rocksweep.plot(mem.sel(lam=[0.4]), ax=ax2)
    legends = [ax.get_legend() for ax in (ax1, ax2) if ax.get_legend() is not None]
    assert len(legends) == 1  # once per figure
    # outside the axes: anchored right of the axes box (x > 1 in axes coordinates)
    anchor = legends[0].get_bbox_to_anchor().transformed(ax1.transAxes.inverted())
    assert anchor.x0 > 1.0


def test_pdf_has_truetype_fonts(pair, tmp_path):
    mem, _, _ = pair
    from rocksweep.figures.style import save_figure

    path = save_figure(rocksweep.plot(mem), tmp_path / "f.pdf")
    data = path.read_bytes()
    assert b"/FontFile2" in data  # embedded TrueType (Type 42)
    assert b"/Subtype /Type3" not in data


def test_boundaries_from_run_open_and_cli_agree(pair, tmp_path):
    mem, disk, out = pair
    a, b = (rocksweep.boundaries(ds, rtol=1e-3) for ds in (mem, disk))
    xr.testing.assert_identical(a, b)
    assert a.A_min.dims == ("lam", "w_over_p")
    # the bracket holds A_min, to rtol
    ok = np.isfinite(a.lo.values)
    assert ok.any()
    assert np.all(a.hi.values[ok] - a.lo.values[ok] <= 1e-3 * a.hi.values[ok] + 1e-12)
    # the command writes the same numbers from the file
    csv_path = tmp_path / "amin.csv"
    res = CliRunner().invoke(main, ["boundaries", str(out), "-o", str(csv_path)])
    assert res.exit_code == 0, res.output
    rows = list(csv.DictReader(csv_path.open()))
    assert rows
    for r in rows:
        v = float(a.A_min.sel(lam=float(r["lam"]), w_over_p=float(r["w_over_p"])))
        assert math.isclose(v, float(r["A_min"]), rel_tol=1e-12)
    df = a.A_min.to_dataframe().dropna()
    assert len(df) == len(rows)
    lines = rocksweep.boundary_lines(mem)
    assert {"lam", "line", "classes", "vertex", "x", "y"} <= set(lines.columns)
    assert set(lines.classes) <= {"safe|mode1", "safe|mode2", "mode1|mode2"}


def test_not_a_result_dataset_is_one_line():
    with pytest.raises(rocksweep.RocksweepError, match="not a rocksweep result"):
        rocksweep.plot(xr.Dataset({"x": ("a", [1, 2])}))


def test_estimate_measures_on_a_sample(pair):
    mem, _, _ = pair
    est = rocksweep.estimate(CI_SMALL, overrides=SINE)
    assert est.points == mem.outcome.size == 128
    assert est.sampled == 128 and not est.compile_needed  # the kernel ran above
    evals = float((mem.steps + mem.event_steps).sum())
    assert est.evaluations == pytest.approx(evals, rel=1e-12)  # the whole grid sampled
    assert est.seconds > 0
    res = CliRunner().invoke(main, ["sweep", str(CI_SMALL), "--dry-run", "-o", "x.h5"])
    assert res.exit_code == 0 and "256 points" in res.output
    assert not Path("x.h5").exists()


def test_estimate_counts_the_half_step_rerun_of_a_check_sweep(pair):
    """``outputs.check`` reruns every point at half the step, which alone costs
    about twice the first run: the sweep costs ~3x, the estimate said 2x."""
    plain = rocksweep.estimate(CI_SMALL, overrides=SINE)
    check = rocksweep.estimate(CI_SMALL, overrides={**SINE, "outputs.check": True})
    # the step bound: ceil(T/(h/2)) is 2 ceil(T/h) or one less, so 1 + 2 per point
    assert 2.95 < check.steps_bound / plain.steps_bound <= 3.0
    # measured on the whole grid: the rerun's evaluations are run and counted (more than
    # the first run's: half the step), not a factor on the first run's (here 2.16x)
    assert check.sampled == plain.sampled == 128
    assert 1.5 < check.evaluations / plain.evaluations < 3.0
    assert check.evaluations != 2 * plain.evaluations


def test_check_fields_carry_their_units(tmp_path):
    """The per-point estimates were once written with rocksweep_units "1"."""
    ds = rocksweep.run(CI_SMALL, overrides={**SINE, "impact.lam": 0.0,
                                            "outputs.check": True})
    assert ds.check_t_overturn_diff.attrs["rocksweep_units"] == "1/p"
    assert ds.check_theta_max_diff.attrs["rocksweep_units"] == "alpha_cg"
    assert ds.A_ratio.attrs["symbol"] == "A/(g tan alpha_cg)"
    assert "[" not in ds.A_ratio.attrs["long_name"]  # units only in units


def test_simulate_with_lists_and_python_errors():
    sims = rocksweep.simulate(ROOT / "configs" / "fig5.yaml")
    assert [s.summary["outcome"] for s in sims] == ["safe", "safe", "mode1"]  # Figure 5
    assert [s.run.point.lam for s in sims] == [0.0, 0.2, 0.4]
    with pytest.raises(rocksweep.RocksweepError, match=r"overrides=\{'pulse.A_ratio'"):
        rocksweep.simulate(ROOT / "configs" / "fig3a.yaml")
    with pytest.raises(TypeError, match="bogus"):
        rocksweep.run(CI_SMALL, bogus=1)
    with pytest.raises(TypeError, match="client"):
        rocksweep.run(CI_SMALL, client=object())


def test_record_run_time_axis_in_seconds():
    sim = rocksweep.simulate(ROOT / "configs" / "record-demo.yaml",
                             {"impact.lam": 0.0, "ground.A_ratio": 2.0, "ground.p": 2.0})
    fig = sim.figure()
    assert "[s]" in fig.axes[-1].get_xlabel()
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert not any("nan" in t for t in labels)
    # the run's last time in seconds: (p t)/p with p = 2 rad/s
    t_end = max(max(line.get_xdata()) for line in fig.axes[1].get_lines() if
                len(line.get_xdata()) > 2)
    assert t_end == pytest.approx(float(sim.history.p_t[-1]) / 2.0)


def test_spectra_dataset(tmp_path):
    scene = (ROOT / "configs" / "record-demo.yaml").read_text()
    ds = rocksweep.run(scene.replace("../records/", str(ROOT / "records") + "/"),
                       overrides={"impact.lam": [0.0], "ground.A_ratio":
                                  {"start": 0.5, "stop": 6, "num": 5},
                                  "ground.p": {"start": 1, "stop": 4, "num": 4}})
    sp = rocksweep.spectra(ds, rtol=1e-2)
    assert sp.A_min.dims == ("lam", "p") and sp.theta_max_over_alpha.dims == (
        "lam", "A_ratio", "p")
    np.testing.assert_array_equal(sp.outcome.values[0], ds.outcome.transpose(
        "A_ratio", "p").values.squeeze() if "lam" not in ds.outcome.dims else
        ds.outcome.sel(lam=0.0).transpose("A_ratio", "p").values)


def test_spectra_of_a_block_name_its_alpha():
    """A block's spectra once labelled its theta with the flexible body's alpha_cg."""
    from rocksweep.figures.spectrum import spectra_figure

    ds = rocksweep.run(ROOT / "configs" / "block.yaml",
                       overrides={"pulse.shape": "sine", "pulse.w_over_p": [1.0, 2.0, 3.0],
                                  "pulse.A_ratio": [2.0, 4.0, 8.0]})
    sp = rocksweep.spectra(ds, rtol=1e-2)
    assert sp.theta_max_over_alpha.attrs["symbol"] == "max|theta|/alpha"
    assert sp.A_min.attrs["symbol"] == "A/(g tan alpha)"
    from rocksweep.analysis.spectrum import spectra as spectra_of

    fig = spectra_figure(spectra_of(ds, rtol=1e-2))
    labels = [a.get_ylabel() for a in fig.axes]
    assert labels[0] == r"max$|\theta|/\alpha$ (x: overturned)"
    assert r"\alpha_{cg}" not in " ".join(labels)


def test_python_errors_speak_python(tmp_path):
    """The API names its own arguments where the command line names flags."""
    with pytest.raises(rocksweep.RocksweepError) as err:
        rocksweep.run(CI_SMALL, overrides=["pulse.A_ratio"])
    assert "--set" not in str(err.value) and "overrides entry 'pulse.A_ratio'" in str(
        err.value)
    out = tmp_path / "o.h5"
    rocksweep.run(CI_SMALL, overrides={**SINE, "impact.lam": 0.0}, output=out)
    with pytest.raises(rocksweep.RocksweepError) as err:
        rocksweep.run(CI_SMALL, overrides={**SINE, "impact.lam": 0.0}, output=out)
    msg = str(err.value)
    assert "resume=True" in msg and "overwrite=True" in msg and "--" not in msg
    res = CliRunner().invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), "--set",
                                    "pulse.shape=sine", "--set", "impact.lam=0.0"])
    assert res.exit_code != 0 and "--resume" in res.output  # the CLI keeps its flags


def test_run_without_output_touches_no_disk(tmp_path, monkeypatch, pair):
    """run() without output= sweeps into memory (HDF5's core driver): no file in the
    working directory nor in the temporary directory, and the same Dataset as the file."""
    import tempfile

    work, tmp = tmp_path / "work", tmp_path / "tmp"
    work.mkdir()
    tmp.mkdir()
    monkeypatch.chdir(work)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    monkeypatch.setenv("TMPDIR", str(tmp))
    ds = rocksweep.run(CI_SMALL, overrides=SINE)
    assert list(work.iterdir()) == [] and list(tmp.iterdir()) == []
    _, disk, _ = pair
    xr.testing.assert_equal(ds, disk)  # values, dims, coords
    for name in ds.variables:
        assert ds[name].attrs.keys() == disk[name].attrs.keys(), name
    assert ds.attrs.keys() == disk.attrs.keys()


def test_transposed_and_partial_datasets(pair):
    """A transposed Dataset gives the same answers; a part of the grid (after .sel) is
    refused in one line by the analyses that rerun points of the whole grid."""
    mem, _, _ = pair
    xr.testing.assert_identical(rocksweep.boundaries(mem),
                                rocksweep.boundaries(mem.transpose(*mem.outcome.dims[::-1])))
    with pytest.raises(rocksweep.RocksweepError, match="part of its sweep's grid"):
        rocksweep.boundaries(mem.isel(lam=[0]))
    assert isinstance(rocksweep.plot(mem.isel(lam=[0])), Figure)  # a figure of the part
