"""Boundary lines and A_min (rocksweep.analysis.boundaries): planted maps with analytic boundaries,
and the bisected threshold against a 10x finer uniform sweep of the real kernel."""

import numpy as np
import pytest
from bodies import FIG3_YAML

import rocksweep.analysis.boundaries as bd
from rocksweep.analysis.files import csv_text
from rocksweep.compute.driver import sweep_arrays
from rocksweep.figures.a_min import a_min_figure
from rocksweep.scene.parse import parse_scene

BODY3 = FIG3_YAML


def test_line_boundary_follows_the_analytic_line():
    x, y = np.linspace(0, 1, 41), np.linspace(0, 2, 61)
    X, Y = np.meshgrid(x, y)
    lines = bd.boundary_lines(np.where(Y > 0.5 + X, 1, 0), x, y)
    assert [ln.classes for ln in lines] == [(0, 1)] and lines[0].label == "safe|mode1"
    xy = lines[0].xy
    # a vertex is the midpoint of a grid edge the line y = 0.5 + x crosses
    half = 0.5 * max(x[1] - x[0], y[1] - y[0])
    assert np.all(np.abs(xy[:, 1] - 0.5 - xy[:, 0]) <= half + 1e-12)
    # it runs across the whole diagram: from x = 0 to x = 1 (y = 0.5 ... 1.5)
    assert {round(xy[0, 0], 9), round(xy[-1, 0], 9)} == {0.0, 1.0}
    assert np.all(np.abs(np.diff(xy, axis=0)) <= 2 * half + 1e-12)  # no jumps


def test_disc_is_one_closed_line_and_three_classes_meet_at_junctions():
    x, y = np.linspace(0, 1, 51), np.linspace(0, 1, 51)
    X, Y = np.meshgrid(x, y)
    C = np.where((X - 0.6) ** 2 + (Y - 0.3) ** 2 < 0.15**2, 2, 0)
    (disc,) = bd.boundary_lines(C, x, y)
    assert disc.classes == (0, 2)
    np.testing.assert_array_equal(disc.xy[0], disc.xy[-1])  # closed
    r = np.hypot(disc.xy[:, 0] - 0.6, disc.xy[:, 1] - 0.3)
    assert np.all(np.abs(r - 0.15) <= 0.5 * (x[1] - x[0]) + 1e-12)
    # the upper half becomes class 1: three lines meeting where the disc cuts y = 0.35
    C3 = np.where((Y > 0.35) & (C == 0), 1, C)
    lines = bd.boundary_lines(C3, x, y)
    pairs = {ln.classes for ln in lines}
    assert pairs == {(0, 1), (0, 2), (1, 2)}
    ends = [tuple(np.round(ln.xy[k], 9)) for ln in lines for k in (0, -1)]
    junctions = {e for e in ends if ends.count(e) == 3}
    assert len(junctions) == 2  # both crossings of the disc with the line
    for _jx, jy in junctions:
        assert abs(jy - 0.35) <= 0.5 * (y[1] - y[0]) + 1e-12


def test_boundary_rows_and_panels_of_a_scene():
    sc = parse_scene(BODY3 + "impact: {lam: [0.0, 0.4]}\npulse: {shape: sine, "
                     "w_over_p: {start: 0.5, stop: 2, num: 4}, A_ratio: {start: 0.1, "
                     "stop: 3, num: 5}}\n")
    outcome = np.zeros(sc.shape, np.int8)
    outcome[:, 3:, :] = 1  # A_ratio >= 2.275 overturns in mode 1
    b = bd.diagram_boundaries(sc, outcome)
    assert [p.where for p in b] == [{"lam": 0.0}, {"lam": 0.4}]
    rows = bd.boundary_rows(b)
    assert list(rows[0]) == ["lam", "line", "classes", "w_over_p", "A_ratio"]
    assert {r["A_ratio"] for r in rows} == {0.5 * (1.55 + 2.275)}


@pytest.fixture(scope="module")
def sine_scene():
    """Figure 3's body, sine pulse, lam = 0, four w samples on a coarse A grid."""
    text = (BODY3 + "impact: {lam: [0.0, 0.4]}\npulse: {shape: sine, w_over_p: "
            "[1.0, 2.5, 3.5], A_ratio: {start: 0.1, stop: 8, num: 21}}\n")
    sc = parse_scene(text)
    return text, sc, sweep_arrays(sc)[0]


def test_a_min_equals_a_10x_finer_sweep(sine_scene):
    text, sc, full = sine_scene
    rtol = 1e-3
    curves = bd.a_min(sc, full["outcome"], rtol=rtol, theta=full["theta_max_over_alpha"],
                      uplifts=full["uplifts"])
    assert [c.where for c in curves] == [{"lam": 0.0}, {"lam": 0.4}]
    A = np.asarray(sc.axis("A_ratio").values)
    fine_sc = parse_scene(text.replace("num: 21", "num: 201"))  # spacing / 10
    fine = sweep_arrays(fine_sc)[0]["outcome"]
    Af = np.asarray(fine_sc.axis("A_ratio").values)
    for p, c in enumerate(curves):
        for j in range(3):
            over = np.flatnonzero(fine[p, :, j] > 0)
            i = over[0]
            assert i > 0
            # the threshold lies in (Af[i-1], Af[i]]; A_min to within rtol of it
            tol = rtol * c.a_min[j]
            assert Af[i - 1] - tol <= c.a_min[j] <= Af[i] + tol, (p, j)
            assert c.mode[j] == fine[p, i, j]
            assert c.hi[j] - c.lo[j] <= tol  # bisected, not the grid spacing
            assert c.hi[j] - c.lo[j] < (A[1] - A[0]) / 100
            assert c.runs[j] - c.searched[j] <= 20  # the bisection (after the search)
            assert c.searched[j] <= bd.SEARCH_RUNS


def test_a_min_of_a_synthetic_threshold_and_csv():
    sc = parse_scene(BODY3 + "impact: {lam: 0.0}\npulse: {shape: [sine, cosine], "
                     "w_over_p: {start: 1, stop: 3, num: 5}, A_ratio: {start: 0, "
                     "stop: 4, num: 9}}\n")
    w = np.asarray(sc.axis("w_over_p").values)

    def threshold(shape, wv):
        return 1.0 + 0.3 * wv + (0.5 if shape == "cosine" else 0.0)

    def evaluate(points):
        return np.array([2 if p.A_ratio >= threshold(p.shape, p.w_over_p) else 0
                         for p in points], np.int8)

    A = np.asarray(sc.axis("A_ratio").values)
    outcome = np.stack([(A[:, None] >= threshold(s, w)[None, :]) * 2
                        for s in ("sine", "cosine")]).astype(np.int8)
    curves = bd.a_min(sc, outcome, rtol=1e-4, evaluate=evaluate)
    for c, s in zip(curves, ("sine", "cosine"), strict=True):
        np.testing.assert_allclose(c.a_min, threshold(s, w), rtol=1e-4)
        assert (c.mode == 2).all()
    rows = bd.a_min_rows(curves)
    assert list(rows[0]) == ["shape", "w_over_p", "A_min", "mode", "upper_bound", "method"]
    text = csv_text(rows)
    assert text.splitlines()[0] == "shape,w_over_p,A_min,mode,upper_bound,method"
    assert len(text.splitlines()) == 1 + 10 and "cosine,3.0," in text
    fig = a_min_figure(curves, bd.diagram_boundaries(sc, outcome), title="t")
    assert type(fig).__name__ == "Figure" and len(fig.axes) == 1
    # one entry per panel and one for the line style of the mode drawn (mode 2 only)
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()][-1:] == ["mode2"]
    assert len(fig.axes[0].get_legend().get_texts()) == 3


def test_a_min_first_value_overturns_is_an_upper_bound():
    sc = parse_scene(BODY3 + "impact: {lam: 0.0}\npulse: {shape: sine, "
                     "w_over_p: {start: 1, stop: 2, num: 2}, A_ratio: {start: 1, "
                     "stop: 2, num: 3}}\n")
    outcome = np.array([[1, 0], [1, 0], [1, 0]], np.int8)
    (c,) = bd.a_min(sc, outcome, evaluate=lambda pts: np.zeros(len(pts), np.int8))
    assert c.a_min[0] == 1.0 and np.isnan(c.lo[0]) and np.isnan(c.a_min[1])
    assert bd.a_min_rows([c])[0]["upper_bound"] is True


# --- rocksweep boundaries -o CURVES.h5 ----------------------------------------------------

def test_boundaries_h5_holds_what_the_csv_files_hold(cli, tmp_path):
    """-o CURVES.h5 writes the A_min curves (the -o CSV rows) and the boundary polylines
    (the --lines CSV rows) of every panel, readable with h5py and xarray."""
    import csv

    import h5py
    import xarray as xr

    from rocksweep.cli import main

    scene = tmp_path / "s.yaml"
    scene.write_text(BODY3 + "impact: {lam: [0.0, 0.4]}\npulse: {shape: [sine, cosine], "
                     "w_over_p: {start: 0.5, stop: 6, num: 12}, A_ratio: {start: 0.3, "
                     "stop: 8, num: 12}}\n")
    out = tmp_path / "s.h5"
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "-q", "-j", "1"])
    assert res.exit_code == 0, res.output
    amin, lines, h5 = tmp_path / "a.csv", tmp_path / "l.csv", tmp_path / "c.h5"
    res = cli.invoke(main, ["boundaries", str(out), "-o", str(amin), "--lines", str(lines)])
    assert res.exit_code == 0, res.output
    res = cli.invoke(main, ["boundaries", str(out), "-o", str(h5)])
    assert res.exit_code == 0, res.output
    assert "boundary lines" in res.output
    assert not list(tmp_path.glob(".*partial*"))  # written atomically, nothing left over

    def read_csv(path):
        with open(path, newline="") as fh:
            return list(csv.DictReader(fh))

    def value(v):  # CSV cells back to values; h5 attributes to plain values
        if isinstance(v, bytes):
            v = v.decode()
        if isinstance(v, str):
            try:
                return float(v)
            except ValueError:
                return v
        return v.item() if isinstance(v, np.generic) else v

    from rocksweep.vocab.outcomes import outcome_word

    a_rows, l_rows = [], []
    with h5py.File(h5, "r") as f:
        assert f.attrs["x_axis"] == "w_over_p" and f.attrs["y_axis"] == "A_ratio"
        assert f.attrs["panels"] == 4 and f.attrs["rtol"] == 1e-3
        for i in range(int(f.attrs["panels"])):
            g = f[f"a_min/panel_{i}"]
            where = {k: value(g.attrs[k]) for k in str(g.attrs["where"]).split()}
            assert set(where) == {"shape", "lam"}
            for j, a in enumerate(g["A_min"][:]):
                if np.isnan(a):
                    continue
                a_rows.append({**where, "w_over_p": float(g["w_over_p"][j]),
                               "A_min": float(a), "mode": outcome_word(int(g["mode"][j])),
                               "upper_bound": bool(g["upper_bound"][j]),
                               "method": str(g["A_min_method"].attrs["flag_meanings"]
                                             ).split(";")[int(g["A_min_method"][j])]})
            gl = f[f"lines/panel_{i}"]
            assert {k: value(gl.attrs[k]) for k in where} == where
            for n in range(len(gl)):
                ds = gl[f"line_{n}"]
                assert ds.shape[1] == 2 and ds.attrs["class_a"] < ds.attrs["class_b"]
                for x, y in ds[:]:
                    l_rows.append({**where, "line": n, "classes": ds.attrs["classes"],
                                   "w_over_p": float(x), "A_ratio": float(y)})
    want_a = [{k: value(v) for k, v in r.items()} for r in read_csv(amin)]
    for r in want_a:
        r["upper_bound"] = r["upper_bound"] == "True"
    want_l = [{k: value(v) for k, v in r.items()} for r in read_csv(lines)]
    for r in want_l:
        r["line"] = int(r["line"])
    assert len(want_a) > 10 and len(want_l) > 10  # curves and lines to compare
    assert a_rows == want_a
    assert l_rows == want_l
    # xarray opens an A_min panel as a Dataset over w_over_p
    ds = xr.open_dataset(h5, group="a_min/panel_1", engine="h5netcdf")
    assert ds["A_min"].dims == ("w_over_p",) and ds.attrs["shape"] == "sine"
    assert ds.attrs["lam"] == 0.4
    ds.close()


@pytest.mark.parametrize("name", ["c.txt", "c", "c.h5.bak"])
def test_boundaries_output_suffix_is_csv_or_h5(cli, tmp_path, name):
    from rocksweep.cli import main

    res = cli.invoke(main, ["boundaries", str(tmp_path / "missing.h5"), "-o",
                            str(tmp_path / name)])
    assert res.exit_code != 0 and "Traceback" not in res.output
    (line,) = res.output.strip().splitlines()
    suffix = name.rpartition(".")[2] if "." in name else None
    assert line.startswith(f"Error: -o {tmp_path / name}: unsupported suffix ")
    assert (f"'.{suffix}'" if suffix else "'(none)'") in line
    assert line.endswith("use .csv, .h5 or .hdf5")
    assert not (tmp_path / name).exists()


def test_boundaries_of_a_record_suite_is_one_line(cli, suite_result):
    """A suite sweep has stripes, not an A_ratio axis: A_min has no diagram to search (it
    was a KeyError traceback)."""
    from helpers import one_line_error

    from rocksweep.cli import main

    line = one_line_error(cli.invoke(main, ["boundaries", str(suite_result)]), 2)
    assert line.startswith(f"Error: {suite_result}: A_ratio: not an axis of the scene"), line
    assert "record, PGA" in line and "boundaries need a diagram over two swept axes" in line
