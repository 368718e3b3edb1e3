"""`rocksweep sweep --adaptive`, `info`, `plot --curves` and `boundaries` end to end: the
file equals a full sweep where the diagram is resolved, is the same whatever the workers,
chunking, backend and interruptions (SIGKILL included), and resumes only with its own
settings."""

import json
from pathlib import Path

import h5py
import numpy as np
import pytest
from bodies import FIG3_YAML
from helpers import kill_sweep_when, one_line_error

import rocksweep
import rocksweep.compute.adaptive as ad
from rocksweep import errors
from rocksweep.cli import main
from rocksweep.compute.driver import SweepInterrupted, sweep_arrays
from rocksweep.compute.session import sweep_file
from rocksweep.compute.sweep import level, prepare
from rocksweep.scene.parse import parse_scene
from rocksweep.store.reader import read_result

BODY3 = FIG3_YAML
# Figure 3's body, two lam, 40 x 40: safe, mode 1 and mode 2 regions.
FIG3_SMALL = BODY3 + ("impact: {lam: [0.0, 0.4]}\n"
                      "pulse: {shape: sine, w_over_p: {start: 0.3, stop: 6, num: 40},"
                      " A_ratio: {start: 0.3, stop: 8, num: 40}}\n")
# A rigid block under long pulses: below A = g tan(alpha) (A_ratio < 1) the ground cannot
# lift it (M A h_cg < M g b: no uplift, safe); above it the long pulse tips it over.
BLOCK_LONG = ("body: {kind: block, alpha: 0.2, inertia: 1.3333333333333333}\n"
              "pulse: {shape: sine, w_over_p: {start: 0.05, stop: 0.6, num: 33},\n"
              "        A_ratio: {start: 0.5, stop: 2.5, num: 33}}\n")


def sweep(cli, scene: Path, out: Path, *args: str):
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "-q", *args])
    assert res.exit_code == 0, res.output
    return res


def assert_same_files(a: Path, b: Path) -> None:
    ra, rb = read_result(a), read_result(b)
    assert ra.arrays.keys() == rb.arrays.keys()
    for name in ra.arrays:
        assert ra.arrays[name].dtype == rb.arrays[name].dtype, name
        np.testing.assert_array_equal(ra.arrays[name], rb.arrays[name], err_msg=name)
    for k in ("points_computed", "points_filled", "points_audited", "audit_misses"):
        assert ra.attrs[k] == rb.attrs[k], k


@pytest.fixture(scope="module")
def fig3_files(tmp_path_factory):
    """FIG3_SMALL swept in full and adaptively (coarse 2) through the CLI."""
    from click.testing import CliRunner

    d = tmp_path_factory.mktemp("adaptive")
    scene = d / "fig3.yaml"
    scene.write_text(FIG3_SMALL)
    cli = CliRunner()
    full, adapt = d / "full.h5", d / "adaptive.h5"
    sweep(cli, scene, full, "-j", "2")
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(adapt), "-j", "2", "--adaptive",
                            "--coarse", "2"])
    assert res.exit_code == 0, res.output
    return scene, full, adapt, res.output


def test_adaptive_file_equals_full_sweep_on_a_known_boundary(cli, tmp_path):
    scene = tmp_path / "block.yaml"
    scene.write_text(BLOCK_LONG)
    full, adapt = tmp_path / "full.h5", tmp_path / "adaptive.h5"
    sweep(cli, scene, full, "-j", "2")
    sweep(cli, scene, adapt, "-j", "2", "--adaptive")
    f, a = read_result(full), read_result(adapt)
    A = f.coords["A_ratio"]
    assert (f.arrays["outcome"][A < 1] == 0).all()  # no uplift below g tan(alpha)
    assert (f.arrays["outcome"][A > 1.2] > 0).all()  # ... and a boundary to find
    np.testing.assert_array_equal(a.arrays["outcome"], f.arrays["outcome"])
    c = a.arrays["computed"] > 0
    assert 0 < c.sum() < 0.6 * c.size
    for name, (_, fill, _) in parse_scene(BLOCK_LONG).variables().items():
        np.testing.assert_array_equal(a.arrays[name][c], f.arrays[name][c], err_msg=name)
        if name != "outcome":  # filled points keep the "not computed" values
            np.testing.assert_array_equal(a.arrays[name][~c], np.full((~c).sum(), fill),
                                          err_msg=name)
    assert a.attrs["complete"] and a.attrs["points_done"] == c.size
    assert a.attrs["points_computed"] == c.sum()
    assert a.attrs["points_filled"] == (~c).sum()


def test_fig3_adaptive_equals_full_and_the_library(fig3_files):
    scene, full, adapt, text = fig3_files
    f, a = read_result(full), read_result(adapt)
    flags = a.arrays["computed"]
    # equal but for one point: the tip of a wedge of mode 1 poking one point across an
    # edge of the last level whose ends agree (a one-point feature the last level fills
    # from its neighbours: rocksweep.compute.lattice.edge_points); only filled points differ
    differ = a.arrays["outcome"] != f.arrays["outcome"]
    assert np.argwhere(differ).tolist() == [[0, 22, 29]]
    assert (flags[differ] == ad.FILLED).all()
    st = ad.stats_of(flags)
    assert f"adaptive: {st.computed} of {flags.size} points computed" in text
    assert f"audit: {st.audited} points, {st.audit_misses} disagreed" in text
    # the file holds what the in-memory adaptive sweep computes
    arr, _ = sweep_arrays(parse_scene(FIG3_SMALL), jobs=1, adaptive=ad.Options(coarse=2))
    for name, v in arr.items():
        np.testing.assert_array_equal(a.arrays[name], v, err_msg=name)
    # xarray reads it; the flags are documented CF-style
    ds = rocksweep.open(adapt)
    assert ds["computed"].dtype == np.int8
    assert list(ds["computed"].attrs["flag_values"]) == [0, 1, 2, 3]
    assert ds["computed"].attrs["flag_meanings"].split() == [
        "filled", "computed", "audit_agreed", "audit_disagreed"]
    assert ds.attrs["adaptive_coarse"] == 2 and ds.attrs["adaptive_axes"] == "w_over_p A_ratio"


def test_same_file_whatever_jobs_chunks_and_backend(fig3_files, cli, tmp_path):
    scene, _, adapt, _ = fig3_files
    one = tmp_path / "one.h5"
    sweep(cli, scene, one, "-j", "1", "--chunk-size", "7", "--adaptive", "--coarse", "2",
          "--write-every", "0")
    assert_same_files(one, adapt)
    many = tmp_path / "many.h5"
    sweep(cli, scene, many, "-j", "2", "--chunk-size", "100", "--adaptive", "--coarse", "2")
    assert_same_files(many, adapt)
    distributed = pytest.importorskip("distributed")  # in the test extra: never skipped in CI
    on_dask = tmp_path / "dask.h5"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        sweep(cli, scene, on_dask, "--backend", "dask", "--scheduler",
              cluster.scheduler_address, "--chunk-size", "50", "--adaptive", "--coarse", "2")
    assert_same_files(on_dask, adapt)


@pytest.mark.parametrize("stop_in", ["coarse", "refine", "audit", "torn"])
def test_interrupted_in_any_batch_resumes_to_the_same_file(fig3_files, tmp_path,
                                                           monkeypatch, stop_in):
    """Ctrl-C in each kind of batch (the finished chunks are written), or a write cut
    between a chunk's outcome and its flags ("torn", what SIGKILL can leave): --resume
    ends with the uninterrupted file, flags of audit points included."""
    scene, _, adapt, _ = fig3_files
    sc = parse_scene(FIG3_SMALL)
    out = tmp_path / "cut.h5"
    real_run_batch = ad.run_batch
    seen = {"chunks": 0}

    def cut_run_batch(grid, flat, *args, **kw):
        for k, res in enumerate(real_run_batch(grid, flat, *args, **kw)):
            kind = ("coarse" if seen.get("kind") is None else seen["kind"])
            if stop_in in (kind, "torn") and k == 2:
                raise KeyboardInterrupt
            yield res

    real_next_step = ad.next_step

    def spy_next_step(plan, outcome, computed, near=None, prior=None):
        step = real_next_step(plan, outcome, computed, near, prior)
        seen["kind"] = step.batch.kind
        return step

    monkeypatch.setattr(ad, "run_batch", cut_run_batch)
    monkeypatch.setattr(ad, "next_step", spy_next_step)
    if stop_in == "torn":
        from rocksweep.store.writer import SweepFile

        real_write = SweepFile._write_at

        def torn(self, name, coords, values):
            if name == "computed" and len(coords) > 1:
                raise KeyboardInterrupt  # outcome written, its flags not
            real_write(self, name, coords, values)

        monkeypatch.setattr(SweepFile, "_write_at", torn)
    opts = ad.Options(coarse=2)
    with pytest.raises(SweepInterrupted):
        sweep_file(sc, out, jobs=1, chunk_size=20, write_every=0.0, adaptive=opts)
    monkeypatch.undo()
    part = read_result(out)
    assert not part.attrs["complete"]
    assert (part.arrays["computed"] > 0).sum() < part.arrays["computed"].size
    if stop_in == "audit":
        assert (part.arrays["computed"] >= 2).any()  # cut inside the audit batch
    rep = sweep_file(sc, out, jobs=2, resume=True, adaptive=opts)
    assert rep.done_before == (part.arrays["computed"] > 0).sum()
    assert_same_files(out, adapt)


def _computed_points(path: Path) -> int:
    try:
        with h5py.File(path, "r", locking=False) as f:
            return int((f["computed"][()] > 0).sum())
    except (OSError, KeyError):
        return 0


def test_sigkill_and_resume_equals_uninterrupted_run(cli, tmp_path):
    """SIGKILL a real `rocksweep sweep --adaptive` mid-run; --resume finishes the file,
    equal bit for bit to an uninterrupted run."""
    scene = tmp_path / "kill.yaml"
    scene.write_text(BODY3 + "impact: {lam: [0.0, 0.4]}\n"
                     "pulse: {shape: sine, w_over_p: {start: 0.3, stop: 6, num: 100},"
                     " A_ratio: {start: 0.3, stop: 8, num: 100}}\n")
    killed = tmp_path / "killed.h5"
    sc = parse_scene(scene.read_text())
    from rocksweep.scene.grid import Grid

    prepare(Grid(sc), level(sc))  # the subprocess loads numba's cache and starts at once
    kill_sweep_when([str(scene), "-o", str(killed), "--adaptive", "--jobs", "1",
                     "--chunk-size", "4", "--write-every", "0", "--quiet"], tmp_path,
                    lambda: _computed_points(killed) >= 300)
    partial = read_result(killed)  # a well-formed file, part done
    n_before = int((partial.arrays["computed"] > 0).sum())
    assert n_before >= 300 and not partial.attrs["complete"]

    res = cli.invoke(main, ["sweep", str(scene), "-o", str(killed), "--resume", "-j", "2",
                            "--adaptive"])
    assert res.exit_code == 0, res.output
    assert f"({n_before} were done before)" in res.output
    whole = tmp_path / "whole.h5"
    sweep(cli, scene, whole, "-j", "2", "--adaptive", "--chunk-size", "37")
    assert_same_files(killed, whole)
    r = read_result(killed)
    assert r.attrs["complete"] and r.attrs["sessions"] == 2
    # a finished file resumes to nothing at all
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(killed), "--resume", "--adaptive"])
    assert res.exit_code == 0 and "computed 0 points" in res.output, res.output


# a file with results is never to be written over as the first remedy
def keep(path) -> str:
    """The remedy said for a file of ``path``'s points that another scene cannot resume."""
    from rocksweep.store.reader import read_result

    n = int((read_result(path, ["outcome"]).arrays["outcome"] != -1).sum())
    assert n > 0
    return ("resume with the scene, --set values and options it was made with, or sweep "
            f"this scene to another -o; --overwrite would discard the {n} points it holds)")


def test_resume_with_other_settings_is_refused(fig3_files, cli, tmp_path):
    scene, full, adapt, _ = fig3_files
    out = tmp_path / "a.h5"
    out.write_bytes(adapt.read_bytes())
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "--resume", "--adaptive",
                            "--coarse", "1", "--audit", "0.05"])
    assert one_line_error(res) == (
        f"Error: {out}: cannot resume, the scene differs from the file's: adaptive.coarse: "
        "file 2, this run 1; adaptive.audit: file 0.02, this run 0.05 (" + keep(out))
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "--resume"])
    assert one_line_error(res) == (
        f"Error: {out}: cannot resume, the scene differs from the file's: adaptive: file "
        "adaptive (axes w_over_p,A_ratio, coarse 2, margin 1, final_margin 0, audit 0.02, "
        "seed 0, threshold 0.002), this run not (" + keep(out))
    other = tmp_path / "full.h5"
    other.write_bytes(full.read_bytes())
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(other), "--resume", "--adaptive"])
    assert one_line_error(res) == (
        f"Error: {other}: cannot resume, the scene differs from the file's: adaptive: file "
        "of every point, this run adaptive (" + keep(other))


@pytest.mark.parametrize("args, message", [
    (["--coarse", "2"], "--coarse is a setting of adaptive sweeps; add --adaptive"),
    # the ranges of the scene's refine: section (one table, rocksweep.schema)
    (["--adaptive", "--coarse", "-1"], "--coarse -1: must be an integer in [0, 20]"),
    (["--adaptive", "--audit", "2"], "--audit 2.0: must be in [0, 1] (share of the filled"),
    (["--adaptive", "--axes", "w_over_p,zeta"], "axis zeta (body.zeta): a diagram axis must"),
    (["--adaptive", "--axes", "w_over_p"], "give two axis names"),
])
def test_bad_adaptive_options_are_one_line_errors(fig3_files, cli, tmp_path, args, message):
    scene = fig3_files[0]
    out = tmp_path / "x.h5"
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), *args])
    assert message in one_line_error(res)
    assert not out.exists()


def test_info_counts_computed_filled_and_audited(fig3_files, cli):
    _, full, adapt, _ = fig3_files
    with h5py.File(adapt, "r") as f:
        flags = f["computed"][()].ravel()
    n = np.bincount(flags, minlength=4)
    res = cli.invoke(main, ["info", str(adapt), "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)["adaptive"]
    assert (d["points"], d["computed"], d["filled"], d["undecided"]) == (
        flags.size, n[1] + n[2] + n[3], n[0], 0)
    assert (d["audited"], d["audit_misses"]) == (n[2] + n[3], n[3])
    assert d["settings"]["coarse"] == 2 and d["settings"]["axes"] == ["w_over_p", "A_ratio"]
    res = cli.invoke(main, ["info", str(adapt)])
    assert res.exit_code == 0, res.output
    assert (f"{n[1] + n[2] + n[3]} computed ({100 * (n[1] + n[2] + n[3]) / flags.size:.2f}%), "
            f"{n[0]} filled") in res.output
    assert f"audit: {n[2] + n[3]} points, {n[3]} disagreed" in res.output
    res = cli.invoke(main, ["info", str(full), "--json"])
    assert json.loads(res.output)["adaptive"] is None


def test_plot_with_curves_and_run_api(fig3_files, cli, tmp_path):
    _, full, adapt, _ = fig3_files
    for src in (adapt, full):
        png = tmp_path / f"{src.stem}.png"
        res = cli.invoke(main, ["plot", str(src), "--curves", "-o", str(png)])
        assert res.exit_code == 0 and "warning" not in res.output, res.output
        assert png.read_bytes().startswith(b"\x89PNG")
    # filled cells are drawn as computed ones: the same figure as the full sweep's
    from rocksweep.figures.diagrams import sweep_figure

    # (flagged points carry a mark only where computed: this scene has none)
    assert not read_result(full, ["status"]).flagged.any()
    # the full file drawn with the adaptive classes (they differ at one filled point, see
    # test_fig3_adaptive_equals_full_and_the_library)
    full_as_adapt = read_result(full, ["outcome", "status"])
    full_as_adapt.arrays["outcome"] = read_result(adapt, ["outcome"]).arrays["outcome"]

    def pixels(src):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        res = src if not isinstance(src, Path) else read_result(src, ["outcome", "status"])
        canvas = FigureCanvasAgg(sweep_figure(res))
        canvas.draw()
        return np.asarray(canvas.buffer_rgba())

    np.testing.assert_array_equal(pixels(adapt), pixels(full_as_adapt))
    # --show-computed shades the computed cells: the figure differs, only for adaptive files
    shaded, plain = tmp_path / "shaded.png", tmp_path / "plain.png"
    for args, png in ((["--show-computed"], shaded), ([], plain)):
        res = cli.invoke(main, ["plot", str(adapt), *args, "-o", str(png)])
        assert res.exit_code == 0, res.output
    assert shaded.read_bytes() != plain.read_bytes()
    res = cli.invoke(main, ["plot", str(full), "--show-computed", "-o", str(shaded),
                            "--overwrite"])
    assert "not an adaptive sweep (no 'computed' flags)" in one_line_error(res)
    ds = rocksweep.run(FIG3_SMALL, jobs=2, adaptive=True, coarse=2)
    np.testing.assert_array_equal(ds["computed"].values, read_result(adapt).arrays["computed"])
    with pytest.raises(errors.ApiError, match="coarse = 2: an adaptive setting"):
        rocksweep.run(FIG3_SMALL, coarse=2)


def test_boundaries_csv_a_min_between_grid_values(fig3_files, cli, tmp_path):
    _, full, adapt, _ = fig3_files
    outs = {}
    for src in (full, adapt):
        csv, lines, fig = (tmp_path / f"{src.stem}.csv", tmp_path / f"{src.stem}-l.csv",
                           tmp_path / f"{src.stem}.png")
        res = cli.invoke(main, ["boundaries", str(src), "-o", str(csv), "--lines", str(lines),
                                "--plot", str(fig), "--rtol", "1e-4", "--no-search"])
        assert res.exit_code == 0, res.output
        assert fig.read_bytes().startswith(b"\x89PNG")
        assert lines.read_text().splitlines()[0] == "lam,line,classes,w_over_p,A_ratio"
        outs[src] = csv.read_text()
    # the grid's bracket only: the same classes give the same curves (the search below
    # the grid reads the response an adaptive file holds only where computed)
    assert outs[full] == outs[adapt]
    rows = [ln.split(",") for ln in outs[full].splitlines()]
    assert rows[0] == ["lam", "w_over_p", "A_min", "mode", "upper_bound", "method"]
    assert {r[5] for r in rows[1:]} <= {"grid+bisection", "first grid value"}
    # with the search (the default): never above the grid's bracket, and where nothing was
    # found below it, the same value as the grid's bracket gives
    searched = tmp_path / "searched.csv"
    res = cli.invoke(main, ["boundaries", str(full), "-o", str(searched), "--rtol", "1e-4"])
    assert res.exit_code == 0, res.output
    grid_rows = {(r[0], r[1]): r for r in rows[1:]}
    for r in [ln.split(",") for ln in searched.read_text().splitlines()[1:]]:
        g = grid_rows[(r[0], r[1])]
        assert float(r[2]) <= float(g[2]) * (1 + 1e-4), (r, g)
        if r[5] == "grid+bisection":
            assert abs(float(r[2]) - float(g[2])) <= 2e-4 * float(g[2]), (r, g)
    r = read_result(full)
    A, W, lam = r.coords["A_ratio"], r.coords["w_over_p"], r.coords["lam"]
    o = r.arrays["outcome"]  # (lam, A_ratio, w_over_p)
    assert len(rows) - 1 == int((o > 0).any(axis=1).sum())
    checked = 0
    for lv, wv, amin, mode, upper, _method in rows[1:]:
        k, j = list(lam).index(float(lv)), list(W).index(float(wv))
        first = int(np.argmax(o[k, :, j] > 0))
        if upper == "True":
            assert first == 0 and float(amin) == A[0]
            continue
        assert A[first - 1] < float(amin) <= A[first], (lv, wv)
        assert mode in ("mode1", "mode2")
        checked += 1
    assert checked > 40


@pytest.mark.parametrize("edit, message", [
    ("1d", "pulse.A_ratio = [2.0]: A_min needs a sweep over at least two values of it"),
    ("incomplete", "incomplete result"),
])
def test_boundaries_errors(cli, tmp_path, edit, message):
    scene = tmp_path / "s.yaml"
    text = BODY3 + ("impact: {lam: 0.0}\npulse: {shape: sine, w_over_p: {start: 0.5, "
                    "stop: 6, num: 6}, A_ratio: " + ("2.0}\n" if edit == "1d" else
                                                     "{start: 0.5, stop: 8, num: 6}}\n"))
    scene.write_text(text)
    out = tmp_path / "s.h5"
    sweep(cli, scene, out, "-j", "1")
    if edit == "incomplete":
        with h5py.File(out, "r+") as f:
            f["outcome"][0, 0] = -1
    res = cli.invoke(main, ["boundaries", str(out)])
    line = one_line_error(res)
    assert message in line and str(out) in line
    assert not (tmp_path / "s-amin.csv").exists()


def test_validate_reports_filled_cells_that_differ(fig3_files, cli, tmp_path):
    scene, full, adapt, _ = fig3_files
    out = tmp_path / "v.h5"
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "--adaptive", "--coarse",
                            "2", "--validate", "-j", "2"])
    assert res.exit_code == 0, res.output
    assert "validate: " in res.output and "lattice" in res.output
    assert_same_files(out, adapt)  # the file keeps the adaptive result
    # a fill made wrong on purpose at filled points of the lattice is reported, exactly
    sc = parse_scene(FIG3_SMALL)
    r = read_result(adapt)
    outcome, computed = r.arrays["outcome"].ravel(), r.arrays["computed"].ravel()
    from rocksweep.scene.grid import Grid

    plan = ad.make_plan(sc, coarse=2)
    v0 = ad.validate(Grid(sc), plan, outcome, computed, stride=3)
    assert v0.checked > 100 and v0.differ.size == 0
    truth = read_result(full).arrays["outcome"].ravel()
    _, ny, nx = plan.panel_shape
    lat = plan.flat_index()[:, 1::3][:, :, 1::3].ravel()
    wrong = np.sort(lat[computed[lat] == 0][::7])
    bad = outcome.copy()
    bad[wrong] = (truth[wrong] + 1) % 3
    v = ad.validate(Grid(sc), plan, bad, computed, stride=3, jobs=2)
    np.testing.assert_array_equal(v.differ, wrong)
    np.testing.assert_array_equal(v.classes, truth[wrong])
