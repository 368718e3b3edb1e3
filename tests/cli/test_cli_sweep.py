"""`rocksweep sweep`, `plot` and `info` end to end, kill-and-resume, bad input."""

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
from bodies import FIG3_YAML
from helpers import kill_sweep_when, one_line_error

from rocksweep.cli import main
from rocksweep.numerics import PRESETS
from rocksweep.scene.grid import ChunkResult
from rocksweep.store.reader import read_result
from rocksweep.store.writer import SweepFile

ROOT = Path(__file__).resolve().parents[2]
CI_SMALL = ROOT / "configs" / "ci-small.yaml"

BODY3 = FIG3_YAML


def assert_same_results(a: Path, b: Path) -> None:
    ra, rb = read_result(a), read_result(b)
    assert ra.dims == rb.dims
    for name in ra.arrays:
        assert ra.arrays[name].dtype == rb.arrays[name].dtype
        np.testing.assert_array_equal(ra.arrays[name], rb.arrays[name], err_msg=name)


@pytest.fixture(scope="module")
def ci_result(tmp_path_factory):
    """configs/ci-small.yaml swept once through the CLI (in process)."""
    from click.testing import CliRunner

    out = tmp_path_factory.mktemp("ci") / "ci.h5"
    res = CliRunner().invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), "--jobs", "1"])
    assert res.exit_code == 0, res.output
    return out, res.output


def test_sweep_summary(ci_result):
    out, text = ci_result
    assert "mode1" in text and "mode2" in text and "safe" in text and "flagged" in text
    spp = PRESETS["default"].steps_per_period
    assert "points/s" in text and f"accuracy: default (steps_per_period={spp}" in text
    assert "RK4 steps:" in text
    # the certification's share of the steps, as the file records it (``rocksweep info``)
    with h5py.File(out, "r") as f:
        n = int(f.attrs["refine_evaluations"])
        total = int(f.attrs["steps_total"]) + int(f.attrs["event_steps_total"])
    assert f"certification of close calls: {n} of them ({100 * n / total:.1f}%" in text
    # one summary row per (shape, lam)
    rows = [ln.split() for ln in text.splitlines() if ln.startswith(("sine", "cosine"))]
    assert [(r[0], float(r[1])) for r in rows] == [("sine", 0.0), ("sine", 0.4),
                                                  ("cosine", 0.0), ("cosine", 0.4)]
    assert all(int(r[2]) + int(r[3]) + int(r[4]) == 64 for r in rows)


def test_file_opens_in_xarray(ci_result):
    xr = pytest.importorskip("xarray")  # in the test extra: never skipped in CI
    out, _ = ci_result
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds["outcome"].dims == ("shape", "lam", "A_ratio", "w_over_p")
        assert list(ds["shape"].values) == ["sine", "cosine"]
        np.testing.assert_array_equal(ds["lam"].values, [0.0, 0.4])
        np.testing.assert_allclose(ds["w_over_p"].values, np.linspace(0.5, 6, 8))
        assert int((ds["outcome"] < 0).sum()) == 0
        assert float(ds["alpha_cg"]) == 0.15


def test_info_text_and_json(ci_result, cli):
    out, _ = ci_result
    res = cli.invoke(main, ["info", str(out)])
    assert res.exit_code == 0, res.output
    assert "256 of 256 done" in res.output and "complete" in res.output
    assert "numba" in res.output and "accuracy: default" in res.output
    res = cli.invoke(main, ["info", str(out), "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    assert d["dims"]["lam"]["values"] == [0.0, 0.4]
    assert d["dims"]["shape"]["scene_key"] == "pulse.shape"
    assert d["points_done"] == d["points_total"] == 256
    assert sum(c["safe"] + c["mode1"] + c["mode2"] for c in d["counts"]) == 256
    assert d["numerics"]["steps_per_period"] == PRESETS["default"].steps_per_period
    assert d["provenance"]["numba_version"]
    assert d["scene"] == CI_SMALL.read_text()


@pytest.mark.parametrize("suffix, magic", [(".png", b"\x89PNG"), (".pdf", b"%PDF"),
                                           (".svg", b"<?xml")])
def test_plot_formats(ci_result, cli, tmp_path, suffix, magic):
    out, _ = ci_result
    fig = tmp_path / f"fig{suffix}"
    res = cli.invoke(main, ["plot", str(out), "-o", str(fig)])
    assert res.exit_code == 0, res.output
    assert fig.read_bytes().startswith(magic)
    assert [p.name for p in tmp_path.iterdir()] == [fig.name]  # no temporary left


def test_existing_output_refused_then_overwritten_and_resumed(ci_result, cli, tmp_path):
    out = tmp_path / "o.h5"
    out.write_bytes(Path(ci_result[0]).read_bytes())
    before = out.read_bytes()
    msg = one_line_error(cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(out)]))
    assert "already exists" in msg and "--overwrite" in msg
    assert out.read_bytes() == before
    res = cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), "--resume", "-j", "1"])
    assert res.exit_code == 0, res.output
    assert "computed 0 points (256 were done before)" in res.output
    msg = one_line_error(cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), "--resume",
                                           "--set", "impact.lam=[0.0, 0.2]"]))
    assert "cannot resume" in msg and "impact.lam: file [0.0, 0.4], scene [0.0, 0.2]" in msg
    res = cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), "--overwrite", "-q",
                            "-j", "1", "--set", "pulse.shape=sine"])
    assert res.exit_code == 0 and res.output == ""
    assert read_result(out).dims == ("lam", "A_ratio", "w_over_p")


@pytest.mark.parametrize("edit, needle", [
    (("w_over_p: {start: 0.5, stop: 6, num: 8}", "w_over_p: {start: 0.0, stop: 6, num: 8}"),
     "pulse.w_over_p = 0.0"),
    (("num: 8}   # Pi5", "num: 0}   # Pi5"), "pulse.w_over_p.num = 0"),
    (("lam: [0.0, 0.4]", "lam: [0.0, .nan]"), "impact.lam = nan"),
    (("lam: [0.0, 0.4]", "lam: []"), "impact.lam = []"),
    (("A_ratio: {start: 0.5, stop: 8, num: 8}", "A_ratio: .inf"), "pulse.A_ratio = inf"),
    (("zeta: 0.05", "zeta: 0.05\n  zeta_typo: 1"), "body.zeta_typo"),
])
def test_bad_scenes_leave_no_file(cli, tmp_path, edit, needle):
    scene = tmp_path / "bad.yaml"
    scene.write_text(CI_SMALL.read_text().replace(*edit))
    assert scene.read_text() != CI_SMALL.read_text()
    msg = one_line_error(cli.invoke(main, ["sweep", str(scene), "-o",
                                           str(tmp_path / "out.h5")]))
    assert needle in msg
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.yaml"]


def test_bad_files_for_plot_and_info(cli, tmp_path):
    text = tmp_path / "a.h5"
    text.write_text("hello")
    foreign = tmp_path / "b.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = np.arange(3)
    for cmd in ("plot", "info"):
        assert "not an HDF5 file" in one_line_error(cli.invoke(main, [cmd, str(text)]))
        assert "not a rocksweep sweep result" in one_line_error(
            cli.invoke(main, [cmd, str(foreign)]))
        assert "no such file" in one_line_error(cli.invoke(main, [cmd, str(tmp_path / "c")]))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.h5", "b.h5"]


def test_bad_options(cli, tmp_path, ci_result):
    out = tmp_path / "o.h5"
    for args, needle in [(["--resume", "--overwrite"], "exclude each other"),
                         (["--backend", "dask"], "--scheduler"),
                         (["--scheduler", "tcp://x:1"], "--backend dask"),
                         (["--jobs", "0"], "--jobs 0"),
                         (["--backend", "dask", "--scheduler", "bogus://x"],
                          "cannot reach a dask scheduler")]:
        msg = one_line_error(cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), *args]))
        assert needle in msg
    assert not out.exists()
    msg = one_line_error(cli.invoke(main, ["plot", str(ci_result[0]), "-o",
                                           str(tmp_path / "f.gif")]))
    assert "'.gif'" in msg
    assert list(tmp_path.iterdir()) == []


def test_plot_of_a_line_sweep_draws_a_line_plot(cli, tmp_path):
    scene = tmp_path / "line.yaml"
    scene.write_text(BODY3 + "impact: {lam: 0.2}\n"
                     "pulse: {shape: sine, w_over_p: [1.0, 2.0, 3.0], A_ratio: 2.0}\n")
    out = tmp_path / "line.h5"
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "-q", "-j", "1"])
    assert res.exit_code == 0, res.output
    res = cli.invoke(main, ["plot", str(out), "-o", str(tmp_path / "f.png")])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("args, message", [
    (["--jobs", "0"], "--jobs 0: give a number >= 1, or -1 for all cores"),
    (["--jobs", "-5"], "--jobs -5: give a number >= 1, or -1 for all cores"),
    (["--write-every", "nan"], "--write-every nan: give a finite number of seconds >= 0 "
                               "(0: write every chunk as it finishes)"),
    (["--write-every", "inf"], "--write-every inf: give a finite number of seconds >= 0 "
                               "(0: write every chunk as it finishes)"),
    (["--write-every", "-1"], "--write-every -1.0: give a finite number of seconds >= 0 "
                              "(0: write every chunk as it finishes)"),
])
def test_bad_numbers_are_one_line_errors(cli, tmp_path, args, message):
    out = tmp_path / "o.h5"
    msg = one_line_error(cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), *args]))
    assert msg == f"Error: {message}"
    assert not out.exists()


def test_absurd_jobs_is_one_line_error(cli, tmp_path):
    n = os.cpu_count() or 1
    out = tmp_path / "o.h5"
    msg = one_line_error(cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), "--jobs",
                                           "99999999999999999999"]))
    assert msg == (f"Error: --jobs 99999999999999999999: at most {4 * n} (4 x the {n} "
                   f"core{'s' * (n > 1)} of this machine: each thread keeps a core busy, so "
                   "more threads only wait for one)")
    assert not out.exists()


def test_sweep_refuses_to_write_over_its_scene(cli, tmp_path):
    scene = tmp_path / "s.yaml"
    scene.write_text(CI_SMALL.read_text())
    msg = one_line_error(cli.invoke(main, ["sweep", str(scene), "-o", str(scene),
                                           "--overwrite"]))
    assert msg == f"Error: {scene}: is this command's input; choose another output path"
    assert scene.read_text() == CI_SMALL.read_text()


def test_info_counts_per_swept_key_in_ranges(cli, tmp_path):
    """A 101-value lam axis: counts per key are in the JSON for every value, and the text
    shows them as at most 10 ranges per table (synthetic results: no kernel)."""
    from rocksweep.scene.parse import parse_scene

    sc = parse_scene(BODY3 + "impact: {lam: {start: 0, stop: 1, num: 101}}\n"
                     "pulse: {shape: sine, w_over_p: [1.0, 2.0, 3.0], A_ratio: [2.0, 4.0]}\n")
    out = tmp_path / "long.h5"
    sf = SweepFile.create(out, sc)
    n = sf.grid.size
    assert n == 606
    arrays = {k: np.full(n, 0, dtype) for k, (dtype, _, _) in sc.variables().items()}
    outcome = np.arange(n) % 3  # flat order: lam, A_ratio, w_over_p (w fastest)
    arrays["outcome"][:] = outcome
    sf.write(ChunkResult(0, n - 6, {k: v[:n - 6] for k, v in arrays.items()}, 0.0))
    sf.close()
    res = cli.invoke(main, ["info", str(out), "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    grid = outcome.reshape(101, 2, 3).astype(int)
    grid[-1] = -1  # the last lam's 6 points are not computed
    lam_rows = d["counts_by_key"]["lam"]
    assert len(lam_rows) == 101 and lam_rows[0]["lam"] == 0.0 and lam_rows[-1]["lam"] == 1.0
    for i, r in enumerate(lam_rows):
        assert r["mode1"] == int((grid[i] == 1).sum()) and r["safe"] == int((grid[i] == 0).sum())
        assert r["not_computed"] == int((grid[i] == -1).sum())
    w_rows = d["counts_by_key"]["w_over_p"]
    assert [r["w_over_p"] for r in w_rows] == [1.0, 2.0, 3.0]
    assert [r["mode2"] for r in w_rows] == [int((grid[..., j] == 2).sum()) for j in range(3)]
    res = cli.invoke(main, ["info", str(out)])
    assert res.exit_code == 0, res.output
    text = res.output.splitlines()
    assert len(text) < 40, res.output
    lam_lines = [ln for ln in text if re.match(r"\s+sine\s", ln)]
    assert 1 <= len(lam_lines) <= 10
    assert lam_lines[0].split()[1] == "0" and lam_lines[-1].split()[3] == "1"
    assert any(re.match(r"\s+A_ratio\s", ln) for ln in text)
    assert "missing" in res.output


def test_plot_block_scene_with_panels_and_partial_file(cli, tmp_path):
    """A block-body scene with a swept body key: one panel per alpha; points
    not computed yet are drawn grey with a warning. Results are synthetic (no kernel)."""
    from rocksweep.scene.parse import parse_scene

    sc = parse_scene("body: {kind: block, alpha: [0.15, 0.25]}\n"
                     "pulse: {shape: [sine, cosine], w_over_p: {start: 0.5, stop: 6, num: 6},"
                     " A_ratio: {start: 0.5, stop: 6, num: 5}}\n")
    out = tmp_path / "block.h5"
    sf = SweepFile.create(out, sc)
    n = sf.grid.size // 2
    arrays = {k: np.full(n, 0, dtype) for k, (dtype, _, _) in sc.variables().items()}
    arrays["outcome"][:] = np.arange(n) % 3
    sf.write(ChunkResult(0, n, arrays, 0.0))
    sf.close()
    fig = tmp_path / "block.png"
    res = cli.invoke(main, ["plot", str(out), "-o", str(fig)])
    assert res.exit_code == 0, res.output
    assert f"{sf.grid.size - n} of {sf.grid.size} points not computed" in res.output
    assert fig.read_bytes().startswith(b"\x89PNG")
    from rocksweep.figures.diagrams import y_label

    assert y_label("block") == r"$A/(g\,\tan\alpha)$"
    assert y_label("flexible") == r"$A/(g\,\tan\alpha_{cg})$"


def _done_points(path: Path) -> int:
    try:
        with h5py.File(path, "r", locking=False) as f:
            return int((f["outcome"][()] >= 0).sum())
    except (OSError, KeyError):
        return 0


def test_kill_and_resume_equals_uninterrupted_run(cli, tmp_path):
    """SIGKILL a real `rocksweep sweep` mid-run; --resume finishes the file without
    recomputing finished points, and the result equals an uninterrupted run."""
    scene = tmp_path / "kill.yaml"
    scene.write_text(BODY3 + "impact: {lam: [0.0, 0.4]}\n"
                     "pulse: {shape: sine, w_over_p: {start: 0.3, stop: 6, num: 40},"
                     " A_ratio: {start: 0.3, stop: 8, num: 40}}\n")
    killed = tmp_path / "killed.h5"
    total = 3200
    # compile here if need be, so the subprocess loads numba's cache and starts at once
    from rocksweep.compute.sweep import level, prepare
    from rocksweep.scene.grid import Grid
    from rocksweep.scene.parse import load_scene

    sc = load_scene(scene)
    prepare(Grid(sc), level(sc))
    kill_sweep_when([str(scene), "-o", str(killed), "--jobs", "1", "--chunk-size", "40",
                     "--write-every", "0", "--quiet"], tmp_path,
                    lambda: _done_points(killed) >= 400)
    partial = read_result(killed)  # a well-formed file, part done
    n_before = int(partial.done.sum())
    assert 400 <= n_before < total
    assert not partial.attrs["finished"]

    res = cli.invoke(main, ["sweep", str(scene), "-o", str(killed), "--resume", "-j", "1"])
    assert res.exit_code == 0, res.output
    assert f"computed {total - n_before} points ({n_before} were done before)" in res.output

    whole = tmp_path / "whole.h5"
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(whole), "-j", "2", "-q",
                            "--chunk-size", "37"])
    assert res.exit_code == 0, res.output
    assert_same_results(killed, whole)
    r = read_result(killed)
    assert r.attrs["complete"] and r.attrs["finished"] and r.attrs["sessions"] == 2


def test_ctrl_c_writes_every_finished_chunk_before_it_exits(tmp_path):
    """Chunks are written in batches (--write-every); an interrupt writes the pending ones
    first, so Ctrl-C loses nothing, and the message counts what the file holds."""
    scene = tmp_path / "int.yaml"
    scene.write_text(BODY3 + "impact: {lam: 0.2}\n"
                     "pulse: {shape: sine, w_over_p: {start: 0.3, stop: 6, num: 600},"
                     " A_ratio: {start: 0.3, stop: 8, num: 600}}\n")
    out = tmp_path / "int.h5"
    from rocksweep.compute.sweep import level, prepare
    from rocksweep.scene.grid import Grid
    from rocksweep.scene.parse import load_scene

    sc = load_scene(scene)
    prepare(Grid(sc), level(sc))
    proc = subprocess.Popen(
        [sys.executable, "-m", "rocksweep", "sweep", str(scene),
         "-o", str(out), "--jobs", "1", "--chunk-size", "50", "--write-every", "1000"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None and not out.exists():
            time.sleep(0.01)
        time.sleep(1.5)
        assert proc.poll() is None, "the sweep ended before it could be interrupted"
        assert _done_points(out) == 0  # nothing written yet: all of it is pending
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    line = [ln for ln in err.splitlines() if ln.startswith("interrupted: ")]
    assert len(line) == 1 and "Traceback" not in err, err
    saved = int(line[0].split()[1])
    assert 0 < saved < 90_000
    assert _done_points(out) == saved


def test_sweep_on_a_dask_cluster_equals_local(ci_result, cli, tmp_path):
    distributed = pytest.importorskip("distributed")  # in the test extra: never skipped in CI
    out = tmp_path / "dask.h5"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        res = cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), "-q", "--backend",
                                "dask", "--scheduler", cluster.scheduler_address,
                                "--chunk-size", "20"])
    assert res.exit_code == 0, res.output
    assert_same_results(out, ci_result[0])


def test_the_command_exits_fast_and_leaves_complete_output(tmp_path):
    """``rocksweep`` (``cli.entry``) skips the interpreter's teardown after a command that
    succeeded: the file it wrote is complete, its printed output whole (JSON parses); a
    failed command exits as usual with its one line."""
    import json

    import rocksweep

    out = tmp_path / "fast.h5"
    run = [sys.executable, "-m", "rocksweep"]
    sweep = subprocess.run([*run, "sweep", str(CI_SMALL), "-o", str(out), "-q", "--set",
                            "pulse.shape=sine"], capture_output=True, text=True, timeout=300)
    assert sweep.returncode == 0, sweep.stderr
    assert rocksweep.open(out).attrs["complete"] == 1
    info = subprocess.run([*run, "info", str(out), "--json"], capture_output=True, text=True,
                          timeout=120)
    assert info.returncode == 0 and json.loads(info.stdout)["points_done"] == 128
    bad = subprocess.run([*run, "info", str(tmp_path / "none.h5")], capture_output=True,
                         text=True, timeout=120)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1
