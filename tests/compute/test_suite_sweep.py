"""Record suites as a grid axis (ground.records, ground.scale) and rocksweep fragility.

- a suite scene's grid: lam x record x stripe (coordinate: file names), from a list, a
  glob or a listing file;
- scaling: the kernel's ground motion of every point, as an acceleration record, has the
  stripe's IM, checked independently with ``physics.intensity`` on the scaled samples;
- bad suites are one-line errors (a record listed twice, a glob matching nothing, an
  all-zero record, two records with one name, keys of the other form);
- a suite sweep end to end through the CLI and ``rocksweep.run``: the per-record IMs in
  the file, ``rocksweep fragility`` (--json, -o .csv/.h5, --plot), a resume that
  finishes missing points and one that refuses a changed record file.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from bodies import FIG3_YAML

import rocksweep
from rocksweep.errors import SceneError
from rocksweep.kernel import layout as L
from rocksweep.physics import intensity
from rocksweep.physics.bodies import G
from rocksweep.physics.records import read_record, write_at2
from rocksweep.scene.grid import Grid
from rocksweep.scene.parse import load_scene, parse_scene

ROOT = Path(__file__).resolve().parents[2]
SUITE = ROOT / "records" / "suite"
NAMES = ["SYN01.AT2", "SYN05.AT2", "SYN12.AT2"]

SCENE = """
name: suite test
""" + FIG3_YAML + """impact: {lam: [0.0, 0.4]}
ground:
  records: %s
  scale: %s
  p: %s
"""
STRIPES = "{im: PGA, values: [0.2, 0.5, 0.8, 1.2]}"


@pytest.fixture()
def suite_dir(tmp_path):
    d = tmp_path / "suite"
    d.mkdir()
    for n in NAMES:
        shutil.copy(SUITE / n, d / n)
    return d


def write_scene(tmp_path, records="suite/*.AT2", scale=STRIPES, p="2.0"):
    path = tmp_path / "s.yaml"
    path.write_text(SCENE % (records, scale, p))
    return path


def test_suite_scene_is_a_grid_over_records_and_stripes(tmp_path, suite_dir):
    sc = load_scene(write_scene(tmp_path))
    assert [a.name for a in sc.swept] == ["lam", "record", "PGA"]
    assert sc.axis("record").values == tuple(NAMES)
    assert sc.axis("PGA").values == (0.2, 0.5, 0.8, 1.2)
    assert sc.shape == (2, 3, 4) and sc.freq_axis == "p" and sc.ground
    # the same suite as a list and as a listing file (relative to the listing)
    listed = load_scene(write_scene(tmp_path, records=json.dumps([f"suite/{n}" for n in NAMES])))
    assert listed.axis("record").values == tuple(NAMES)
    (suite_dir / "mine.txt").write_text("# my records\n" + "\n".join(NAMES[::-1]) + "\n")
    sc2 = load_scene(write_scene(tmp_path, records="suite/mine.txt"))
    assert sc2.axis("record").values == tuple(NAMES[::-1])
    # the IMs are the records' own, computed once
    for i, n in enumerate(NAMES):
        rec = read_record(SUITE / n)
        assert sc.suite.pga[i] == intensity.pga(rec.acc)
        assert sc.suite.pgv[i] == intensity.pgv(rec.acc, rec.dt)
        np.testing.assert_array_equal(sc.suite.sa[i], intensity.sa(rec.acc, rec.dt, [0.2, 1.0]))


def _scaled_records(sc):
    """Every point's ground motion as (record index, stripe value, acc [g] scaled, alpha,
    p): from the kernel's rows (PAR_AMP [m/s^2] times the samples acc / PGA)."""
    grid = Grid(sc)
    cr = grid.rows(0, grid.size)
    vals = grid.index_values(np.arange(grid.size))
    out = []
    for i in range(grid.size):
        rec = cr.excitations[int(cr.which[i])].record
        r = sc.suite.records.index(rec)
        acc = cr.rows[i, L.PAR_AMP] / G * rec.acc / rec.pga
        out.append((r, vals[sc.suite.im][i], acc, cr.alpha_ref[i], vals["p"][i], rec.dt))
    return out


@pytest.mark.parametrize("scale, p", [
    (STRIPES, "2.0"),
    ("{im: PGV, values: [0.1, 0.4]}", "2.0"),
    ("{im: Sa, period: 0.5, values: [0.3, 1.0]}", "2.0"),
    ("{im: PGA_ratio, values: [1.0, 3.0]}", "2.0"),
    ("{im: PGV_ratio, values: [0.5, 2.0]}", "[1.0, 3.0]"),
])
def test_scaling_puts_every_record_at_the_stripe(tmp_path, suite_dir, scale, p):
    sc = load_scene(write_scene(tmp_path, scale=scale, p=p))
    im = sc.suite.im
    checked = 0
    for _r, level, acc, alpha, pv, dt in _scaled_records(sc):
        if im in ("PGA", "PGA_ratio"):
            got = intensity.pga(acc)
        elif im in ("PGV", "PGV_ratio"):
            got = intensity.pgv(acc, dt)
        else:
            got = float(intensity.sa(acc, dt, [0.5])[0])
        if im == "PGA_ratio":
            got /= math.tan(alpha)
        elif im == "PGV_ratio":
            got *= pv / (G * math.tan(alpha))
        assert got == pytest.approx(level, rel=1e-12)
        checked += 1
    assert checked == sc.size


def test_bad_suites_are_one_line_errors(tmp_path, suite_dir):
    cases = [
        (json.dumps(["suite/SYN01.AT2", "suite/SYN05.AT2", "suite/SYN01.AT2"]), STRIPES,
         r"ground.records: .*SYN01.AT2 is listed twice"),
        ("suite/*.AT3", STRIPES, r"ground.records: 'suite/\*.AT3' matches no file"),
        ("suite/*.AT2", "{im: PGD, values: [1]}", r"ground.scale.im = 'PGD': must be one of"),
        ("suite/*.AT2", "{im: PGA, values: [0.2, -1]}", r"ground.scale.values = -1.0"),
        ("suite/*.AT2", "{im: Sa, values: [0.2]}", r"ground.scale.period: missing"),
        ("suite/*.AT2", "{factor: 0}", r"ground.scale.factor = 0"),
    ]
    (tmp_path / "other").mkdir()
    shutil.copy(SUITE / "SYN01.AT2", tmp_path / "other" / "SYN01.AT2")
    cases.append((json.dumps(["suite/SYN01.AT2", "other/SYN01.AT2"]), STRIPES,
                  r"two records named SYN01.AT2"))
    zero = tmp_path / "zero.AT2"
    write_at2(zero, np.zeros(50), 0.01, "all zero")
    cases.append(("[suite/SYN01.AT2, zero.AT2]", STRIPES,
                  r"ground.records: .*zero.AT2: every value is 0"))
    for records, scale, match in cases:
        with pytest.raises(SceneError, match=match) as err:
            load_scene(write_scene(tmp_path, records=records, scale=scale))
        assert "\n" not in str(err.value)
    both = SCENE % ("suite/*.AT2", STRIPES, "2.0") + "  A_ratio: 2.0\n"
    with pytest.raises(SceneError, match=r"ground.A_ratio: not with ground.records"):
        parse_scene(both, base=tmp_path)
    with pytest.raises(SceneError, match=r"ground.scale: works with ground.records"):
        parse_scene(SCENE.replace("records: %s", f"record: {SUITE / 'SYN01.AT2'}\n  "
                                  "A_ratio: 1.0") % (STRIPES, "2.0"))


def test_unscalable_record_is_named(tmp_path, suite_dir, monkeypatch):
    """A record with PGV 0 cannot be scaled to a PGV stripe (no file has one: a
    piecewise-linear record with PGA > 0 moves; the velocity is stubbed here)."""
    monkeypatch.setattr(intensity, "pgv", lambda acc, dt: 0.0)
    with pytest.raises(SceneError, match=r"ground.records: .*SYN01.AT2: PGV = 0.0: cannot "
                       r"be scaled to a PGV stripe") as err:
        load_scene(write_scene(tmp_path, scale="{im: PGV, values: [0.1]}"))
    assert "\n" not in str(err.value)


def test_suite_sweep_end_to_end(tmp_path, suite_dir, cli):
    from rocksweep.cli.main import main

    scene = write_scene(tmp_path)
    out = tmp_path / "frag.h5"
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "--quiet", "--jobs", "2"])
    assert res.exit_code == 0, res.output
    with h5py.File(out) as f:
        assert [v.decode() if isinstance(v, bytes) else v for v in f["record"][()]] == NAMES
        assert f.attrs["scale_im"] == "PGA" and math.isnan(f.attrs["scale_period"])
        assert f["record_pga"].attrs["units"] == "g" and f["record_pgv"].attrs["units"] == "m/s"
        assert f["PGA"].attrs["units"] == "g"
    ds = rocksweep.open(out)
    assert ds["outcome"].dims == ("lam", "record", "PGA")
    assert (ds["outcome"] >= 0).all() and (ds["outcome"] > 0).any() and (ds["outcome"] == 0).any()
    assert ds["record_sa"].dims == ("record", "period")
    assert ds["period"].values.tolist() == [0.2, 1.0] and ds["period"].attrs["units"] == "s"
    for i, n in enumerate(NAMES):
        rec = read_record(SUITE / n)
        assert float(ds["record_pga"][i]) == intensity.pga(rec.acc)
        assert int(ds["record_npts"][i]) == rec.npts and str(ds["record_sha256"][i].values) \
            == rec.sha256
        np.testing.assert_allclose(ds["scale_factor"][i].values,
                                   np.array([0.2, 0.5, 0.8, 1.2]) / rec.pga, rtol=1e-15)
    # rocksweep.run gives the same points
    run = rocksweep.run(scene, jobs=1)
    np.testing.assert_array_equal(run["outcome"].values, ds["outcome"].values)
    np.testing.assert_array_equal(run["theta_max_over_alpha"].values,
                                  ds["theta_max_over_alpha"].values)
    frag = rocksweep.fragility(run, bootstrap=20)
    assert frag.attrs["method"] == "stripes-mle" and frag.attrs["im"] == "PGA"
    assert frag["im_median"].dims == ("lam",) and int(frag["n_records"][0]) == 3
    same = ds.rocksweep.fragility(bootstrap=20)
    np.testing.assert_array_equal(same["im_median"].values, frag["im_median"].values)

    # the CLI: --json, -o .csv and .h5, --plot
    res = cli.invoke(main, ["fragility", str(out), "--json", "--bootstrap", "20"])
    assert res.exit_code == 0, res.output
    curves = json.loads(res.stdout)["curves"]
    assert [c["lam"] for c in curves] == [0.0, 0.4]
    for c in curves:
        assert {"lam", "state", "im", "method", "im_median", "beta", "im_median_ci", "beta_ci",
                "n_records", "n_excluded"} <= set(c)
        assert c["state"] == "overturn" and c["n_records"] == 3 and c["n_excluded"] == 0
    assert curves[0]["im_median"] == pytest.approx(float(frag["im_median"][0]))
    res = cli.invoke(main, ["fragility", str(out), "-o", str(tmp_path / "c.csv"),
                            "--plot", str(tmp_path / "f.png"), "--bootstrap", "20"])
    assert res.exit_code == 0, res.output
    assert "lam" in res.output and "median" in res.output
    lines = (tmp_path / "c.csv").read_text().splitlines()
    assert lines[0].startswith("lam,state,im,method,fit,im_median,beta") and len(lines) == 3
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "f.png").stat().st_size > 10_000
    res = cli.invoke(main, ["fragility", str(out), "-o", str(tmp_path / "c.h5"),
                            "--state", "overturn,uplift", "--bootstrap", "0"])
    assert res.exit_code == 0, res.output
    import xarray as xr

    with xr.open_dataset(tmp_path / "c.h5", engine="h5netcdf") as back:
        assert back["im_median"].dims == ("state", "lam")
        assert list(back["state"].values) == ["overturn", "uplift"]
    res = cli.invoke(main, ["info", str(out)])
    assert res.exit_code == 0 and "SYN01.AT2 .. SYN12.AT2" not in res.output  # 3: listed
    assert "SYN01.AT2, SYN05.AT2, SYN12.AT2" in res.output
    # a record suite has no stability diagram: plot draws its overturning fragility
    res = cli.invoke(main, ["plot", str(out), "-o", str(tmp_path / "p.png")])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    res = cli.invoke(main, ["fragility", str(out), "--state", "topple"])
    assert res.exit_code == 2 and "state 'topple'" in res.output
    assert "Traceback" not in res.output

    # resume: points lost are computed again, to the same values
    with h5py.File(out, "r+") as f:
        f["outcome"][1, 2, :] = -1
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "--resume", "--quiet"])
    assert res.exit_code == 0, res.output
    np.testing.assert_array_equal(rocksweep.open(out)["outcome"].values, ds["outcome"].values)
    # a record file changed: resume refuses, naming it
    path = suite_dir / "SYN05.AT2"
    path.write_text(path.read_text().replace("\n", "\n ", 1) + "")
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "--resume", "--quiet"])
    assert res.exit_code == 2
    assert "ground.records: SYN05.AT2 changed since the sweep" in res.output
    assert "Traceback" not in res.output


def test_cloud_suite(tmp_path, suite_dir):
    sc = write_scene(tmp_path, scale="{factor: 2.5}", p="2.0")
    ds = rocksweep.run(sc)
    assert ds["outcome"].dims == ("lam", "record") and ds.attrs["scale_im"] == "none"
    np.testing.assert_array_equal(ds["scale_factor"].values, [2.5, 2.5, 2.5])
    frag = rocksweep.fragility(ds, bootstrap=0)
    assert frag.attrs["method"] == "cloud-mle"
    none = rocksweep.run(write_scene(tmp_path, scale="none"))
    np.testing.assert_array_equal(none["scale_factor"].values, [1.0, 1.0, 1.0])


def test_suite_on_a_dask_cluster(tmp_path, suite_dir):
    """The chunks of a suite run on a dask cluster (in-process workers) as locally; a
    chunk's task (the grid with the suite's records) pickles, as process workers need."""
    import pickle

    distributed = pytest.importorskip("distributed")  # in the test extra: never skipped
    from rocksweep.compute.driver import sweep_arrays

    scene = write_scene(tmp_path, scale="{im: PGA, values: [0.5, 1.0]}")
    sc = load_scene(scene)
    back = pickle.loads(pickle.dumps(Grid(sc)))
    np.testing.assert_array_equal(back.rows(0, back.size).rows, Grid(sc).rows(0, sc.size).rows)
    local = sweep_arrays(sc, jobs=1)[0]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        on = sweep_arrays(sc, backend="dask", scheduler=cluster.scheduler_address, chunk_size=4)[0]
    for name, v in local.items():
        np.testing.assert_array_equal(on[name], v, err_msg=name)


def test_avgsa_cav_arias_are_stripe_ims_and_scale_invariant_ims_are_refused(tmp_path,
                                                                           suite_dir):
    sc = load_scene(write_scene(tmp_path, scale="{im: AvgSa, values: [0.1, 0.3]}"))
    assert [a.name for a in sc.swept] == ["lam", "record", "AvgSa"]
    assert sc.suite.avgsa_range[0] < sc.suite.avgsa_range[1]  # the range it scales to
    for im in ("CAV", "Arias"):
        assert load_scene(write_scene(tmp_path, scale=f"{{im: {im}, values: [1.0]}}")
                          ).suite.im == im
    with pytest.raises(SceneError, match=r"ground.scale.im = D5_95: does not change when a "
                       r"record is scaled") as err:
        load_scene(write_scene(tmp_path, scale="{im: D5_95, values: [10]}"))
    assert "\n" not in str(err.value)
