"""The Python API (rocksweep.run / open / simulate), the library sweep driver, the field
table, the dask backend, and the README's "Python API" example."""

import json
import math
import os
import re
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from bodies import FIG3

import rocksweep
import rocksweep.compute.sweep as sw
from rocksweep import errors, fields
from rocksweep.cli import main
from rocksweep.compute.arguments import check_jobs
from rocksweep.compute.session import sweep_file
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.bodies import FlexibleBody
from rocksweep.scene.grid import Grid
from rocksweep.scene.inputs import load
from rocksweep.scene.parse import load_scene
from rocksweep.store.reader import read_result

ROOT = Path(__file__).resolve().parents[2]
CI_SMALL = ROOT / "configs" / "ci-small.yaml"
FIG5 = ROOT / "configs" / "fig5.yaml"

BODY3 = dict(FIG3)
SMALL = {"name": "api test", "body": BODY3, "impact": {"lam": [0.0, 0.4]},
         "pulse": {"shape": "sine", "w_over_p": {"start": 1.0, "stop": 6.0, "num": 6},
                   "A_ratio": {"start": 1.0, "stop": 8.0, "num": 5}}}


def _modules_after(code: str) -> list[str]:
    probe = (f"import sys\n{code}\n"
             "print('LOADED:' + ','.join(m for m in ('numba', 'h5py', 'matplotlib', 'xarray', "
             "'scipy', 'numpy', 'pandas', 'yaml', 'dask', 'tqdm') if m in sys.modules))")
    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    last = proc.stdout.split("LOADED:")[-1].strip()  # after any --help text
    return [m for m in last.split(",") if m]


def test_import_and_help_are_light():
    """`import rocksweep`, the command line's module and `rocksweep --help` load none of
    the heavy libraries (not even numpy: the console command sets OPENBLAS_NUM_THREADS
    before it loads)."""
    assert _modules_after("import rocksweep; rocksweep.run, rocksweep.open") == []
    assert _modules_after("import rocksweep.cli.main") == []
    assert _modules_after("from rocksweep.cli import main\ntry:\n    main(['--help'])\n"
                          "except SystemExit:\n    pass") == []
    assert _modules_after("from rocksweep.cli import main\ntry:\n    main(['sweep', '--help'])"
                          "\nexcept SystemExit:\n    pass") == []


def test_the_command_line_starts_without_the_facade_the_driver_or_outputs():
    """`import rocksweep.cli.main` (all `rocksweep --help` imports) loads none of the API
    facade (rocksweep.api: on first use), the sweep driver or outputs.py: they would add
    23% to its start-up where no .pyc is written, 10% with .pyc files (docs/performance.md,
    the command line's imports); a command loads them when it runs."""
    code = ("import sys, rocksweep.cli.main\n"
            "print(','.join(m for m in ('rocksweep.api', 'rocksweep.simulation', "
            "'rocksweep.compute.driver', 'rocksweep.outputs') if m in sys.modules))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == ""
    # loaded on first use: through a function or the module's old name alike
    code = ("import rocksweep, sys\nprint('rocksweep.api' in sys.modules, "
            "rocksweep.api.open is rocksweep.open, 'rocksweep.api' in sys.modules)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.stdout.split() == ["False", "True", "True"], proc.stderr


def test_public_names_have_docstrings_and_version(cli):
    for obj in (rocksweep.run, rocksweep.open, rocksweep.simulate, rocksweep.RocksweepError,
                rocksweep.Simulation, sweep_file):
        assert obj.__doc__ and len(obj.__doc__) > 40, obj
    from importlib.metadata import version

    assert rocksweep.__version__ == version("rocksweep")
    res = cli.invoke(main, ["--version"])
    assert res.exit_code == 0 and res.output.strip() == f"rocksweep {version('rocksweep')}"
    assert issubclass(errors.SweepError, rocksweep.RocksweepError)



def test_importing_single_runs_keeps_the_api_functions():
    """Importing the single-run module (rocksweep/compute/single.py) leaves rocksweep.run and
    rocksweep.open the API functions (a module named run.py used to replace rocksweep.run)."""
    code = ("import rocksweep\nfrom rocksweep.compute.single import run_point\n"
            "import rocksweep.compute.single\n"
            "print(rocksweep.run is rocksweep.api.run, rocksweep.open is rocksweep.api.open)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.stdout.strip() == "True True", proc.stderr


# --- run and open -------------------------------------------------------------------------

@pytest.fixture(scope="module")
def cli_file(tmp_path_factory):
    from click.testing import CliRunner

    out = tmp_path_factory.mktemp("cli") / "ci.h5"
    res = CliRunner().invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), "-q", "-j", "1"])
    assert res.exit_code == 0, res.output
    return out


def test_run_returns_what_the_cli_writes(cli_file, tmp_path):
    """rocksweep.run(path, output=...) writes the file the CLI writes and returns it;
    without output the Dataset is the same, with no file kept."""
    out = tmp_path / "api.h5"
    ds = rocksweep.run(CI_SMALL, output=out, jobs=2)
    xr.testing.assert_identical(ds, rocksweep.open(out))
    cli_ds = rocksweep.open(cli_file)
    assert ds.sizes == cli_ds.sizes and list(ds.data_vars) == list(cli_ds.data_vars)
    assert set(ds.coords) == set(cli_ds.coords) and set(ds.attrs) == set(cli_ds.attrs)
    raw = read_result(cli_file)  # the file through h5py, not xarray
    for name, arr in raw.arrays.items():
        assert ds[name].dtype == arr.dtype, name
        np.testing.assert_array_equal(ds[name].values, arr, err_msg=name)
    assert ds.outcome.dims == raw.dims
    np.testing.assert_array_equal(ds.w_over_p.values, np.linspace(0.5, 6, 8))
    assert float(ds.alpha_cg) == 0.15  # an unswept key: a scalar coordinate

    before = set(tmp_path.iterdir())
    mem = rocksweep.run(CI_SMALL.read_text())  # YAML text, in memory
    assert set(tmp_path.iterdir()) == before
    for name in raw.arrays:
        np.testing.assert_array_equal(mem[name].values, raw.arrays[name], err_msg=name)
    assert mem.attrs["scene"] == CI_SMALL.read_text()


def test_run_from_a_dict_with_overrides(tmp_path):
    a = rocksweep.run(SMALL, overrides={"impact.lam": 0.4})
    b = rocksweep.run(SMALL, overrides=["impact.lam=0.4"])
    assert "lam" not in a.outcome.dims and float(a.lam) == 0.4
    np.testing.assert_array_equal(a.outcome.values, b.outcome.values)
    whole = rocksweep.run(SMALL)
    np.testing.assert_array_equal(whole.outcome.sel(lam=0.4).values, a.outcome.values)
    assert a.attrs["overrides"] == '["impact.lam=0.4"]'
    assert set(np.unique(whole.outcome).tolist()) <= {0, 1, 2}


def test_open_carries_words_units_and_provenance(cli_file):
    ds = rocksweep.open(cli_file)
    assert ds.outcome.attrs["flag_meanings"].split() == ["not_run", "safe", "mode1", "mode2"]
    assert list(ds.outcome.attrs["flag_values"]) == [-1, 0, 1, 2]
    assert "horizon" in ds.status.attrs["flag_meanings"].split()
    assert ds.theta_max_over_alpha.attrs["rocksweep_units"] == "alpha_cg"
    assert ds.t_overturn.attrs["rocksweep_units"] == "1/p"
    assert ds.attrs["scene"] == CI_SMALL.read_text()
    assert ds.attrs["rocksweep_version"] == rocksweep.__version__
    assert ds.attrs["numba_version"]


def test_open_and_run_errors_are_one_line(tmp_path):
    bad = tmp_path / "x.h5"
    bad.write_text("not hdf5")
    cases = [
        (lambda: rocksweep.open(bad), "not an HDF5 file"),
        (lambda: rocksweep.open(tmp_path / "none.h5"), "no such file"),
        (lambda: rocksweep.run(SMALL, jobs=0), "jobs = 0: give a number >= 1"),
        (lambda: rocksweep.run(SMALL, resume=True), "resume=True needs output"),
        (lambda: rocksweep.run({**SMALL, "impact": {"lam": 3}}), "impact.lam = 3.0"),
        (lambda: rocksweep.run(tmp_path / "none.yaml"), "no such scene file"),
        (lambda: rocksweep.run(SMALL, output=bad), "already exists; use resume=True"),
        (lambda: rocksweep.run(SMALL, output=bad, resume=True, overwrite=True),
         "exclude each other"),
    ]
    for call, needle in cases:
        with pytest.raises(rocksweep.RocksweepError) as exc:
            call()
        assert needle in str(exc.value) and "\n" not in str(exc.value)
    assert bad.read_text() == "not hdf5"


def test_run_never_writes_over_its_scene(tmp_path):
    scene = tmp_path / "s.yaml"
    scene.write_text(CI_SMALL.read_text())
    with pytest.raises(rocksweep.RocksweepError, match="this command's input"):
        rocksweep.run(scene, output=scene, overwrite=True)
    assert scene.read_text() == CI_SMALL.read_text()


def test_run_resumes_a_partial_file(tmp_path):
    """A file with some points written (as after a kill) is finished by resume=True."""
    from rocksweep.store.writer import SweepFile

    out = tmp_path / "part.h5"
    full = rocksweep.run(SMALL)
    sc, _ = load(SMALL)  # the dict scene as the API parses it
    sf = SweepFile.create(out, sc)
    g = Grid(sc)
    sf.write(sw.run_chunk(g, 0, 17, sw.level(sc)))
    sf.close()
    assert int((rocksweep.open(out).outcome >= 0).sum()) == 17
    got = rocksweep.run(SMALL, output=out, resume=True)
    for name in full.data_vars:
        np.testing.assert_array_equal(got[name].values, full[name].values, err_msg=name)


# --- the driver: messages -----------------------------------------------------------------

def test_driver_says_compiling_before_an_uncached_kernel(tmp_path, monkeypatch):
    """When numba's cache lacks the variant, the sweep says so before compiling: how many
    variants, which, and their cost (the state is faked here; the real check is
    test_cache_state_of_a_fresh_cache). The time a compile takes is kept, and said the
    next time that variant compiles (issue 45: "~6 s" where variants took 22-59 s)."""
    from rocksweep.compute import compile_cost

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "cache"))  # the times' file only
    monkeypatch.setattr(compile_cost, "in_cache", lambda dispatcher: False)
    lines: list[str] = []
    sc = load_scene(CI_SMALL)
    name = compile_cost.variant_name(sw.chunk_variants(Grid(sc), sw.level(sc))[0])
    rep = sweep_file(sc, tmp_path / "c.h5", log=lines.append)
    assert rep.complete and rep.computed == 256
    i = next(i for i, ln in enumerate(lines) if ln.startswith("compiling"))
    assert lines[i] == (f"compiling 1 kernel variant this run needs ({name}), once per "
                        f"machine: ~{compile_cost.BENCH_SECONDS:.0f} s (~"
                        f"{compile_cost.BENCH_SECONDS:.0f} s a variant on a quiet 2-core "
                        "machine, more on a busy one)..."), lines[i]
    assert re.fullmatch(r"kernel compiled in \d+\.\d s", lines[i + 1])
    # a compile's time is kept per variant and forecast the next time (a variant never
    # compiled here: the median of those that were)
    compile_cost.record([name], 23.0)
    compile_cost.record(["other_a", "other_b"], 20.0)
    assert compile_cost.forecast([name]) == (23.0, "as measured here")
    assert compile_cost.forecast([name, "never"])[0] == pytest.approx(23.0 + 10.0)
    # a sliding variant never compiled here: RELATIVE times the median (1.5 x 10 s)
    assert compile_cost.forecast(["chunk_rigid_slide"])[0] == pytest.approx(15.0)
    lines.clear()
    sweep_file(sc, tmp_path / "e.h5", log=lines.append)
    assert any(ln.endswith(f"({name}), once per machine: ~23 s (as measured here)...")
               for ln in lines), lines
    monkeypatch.setattr(compile_cost, "in_cache", lambda dispatcher: None)
    lines.clear()
    sweep_file(sc, tmp_path / "d.h5", log=lines.append)
    assert "loading or compiling the kernel..." in lines


def test_cache_state_of_a_fresh_cache(tmp_path):
    """An empty numba cache directory: the variant is reported as to be compiled (no
    compilation happens here); the shared cache holds it once prepared."""
    sc = load_scene(CI_SMALL)
    sw.prepare(Grid(sc), sw.level(sc))
    assert sw.kernel_cache_state(Grid(sc), sw.level(sc)) == (0, 0)
    code = ("from rocksweep.compute import sweep as sw; from rocksweep.scene.grid import Grid; "
            "from rocksweep.scene.parse import load_scene; "
            f"sc = load_scene({str(CI_SMALL)!r}); "
            "print(sw.kernel_cache_state(Grid(sc), sw.level(sc)))")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "(1, 0)"


@pytest.mark.parametrize("jobs", [0, -5, 10**20])
def test_jobs_limits(jobs):
    n = os.cpu_count() or 1
    from rocksweep.cli.main import said

    with pytest.raises(errors.SweepError) as exc:
        check_jobs(jobs)
    if jobs < 1:
        assert str(exc.value) == f"jobs = {jobs}: give a number >= 1, or -1 for all cores"
        assert said(exc.value) == f"--jobs {jobs}: give a number >= 1, or -1 for all cores"
    else:
        assert str(exc.value).startswith(f"jobs = {jobs}: at most {4 * n} (4 x the {n} core")
        assert said(exc.value).startswith(f"--jobs {jobs}: at most {4 * n} (4 x the {n} core")
    assert check_jobs(-1) == n and check_jobs(4 * n) == 4 * n


# --- simulate -------------------------------------------------------------------------------

def test_simulate_keywords_and_dict_agree_and_history_is_physical():
    """Figure 5, lam = 0.4: overturns after impacts (the paper). The history ends where
    the body lies on its side, theta = pi/2, i.e. theta/alpha_cg = (pi/2)/0.15, and
    the energy balance E = W_in - D_damp - E_impact holds at every row."""
    a = rocksweep.simulate(FIG5, impact__lam=0.4)
    b = rocksweep.simulate(FIG5, {"impact.lam": 0.4})
    assert a.summary["outcome"] == b.summary["outcome"] == "mode1"
    assert a.summary["impacts"] >= 1
    h = a.history
    assert h.theta_over_alpha.dims == ("p_t",)
    t = h.p_t.values
    assert t[0] == 0.0 and np.all(np.diff(t) >= 0)
    assert t[-1] == pytest.approx(a.summary["t_overturn"], abs=1e-12)
    assert abs(h.theta_over_alpha.values[-1]) == pytest.approx(math.pi / 2 / 0.15, rel=1e-6)
    balance = h.W_in_over_Eref - h.D_damp_over_Eref - h.E_impact_over_Eref
    # to the integration error of the work integral: ~1e-3 E_ref at `default` (the one
    # default of sweeps and single runs), ~1e-5 E_ref at `fine`
    np.testing.assert_allclose(h.E_over_Eref.values, balance.values, atol=2e-3)
    hf = rocksweep.simulate(FIG5, impact__lam=0.4, numerics__accuracy="fine").history
    np.testing.assert_allclose(hf.E_over_Eref.values, (hf.W_in_over_Eref - hf.D_damp_over_Eref
                                                       - hf.E_impact_over_Eref).values,
                               atol=1e-4)
    assert h.theta_over_alpha.attrs["units"] == "alpha_ref"
    assert h.p_t.attrs["units"] == "1/p"
    body = FlexibleBody(**BODY3)  # u/u_cr with u_cr from the model, eq. (4)
    np.testing.assert_allclose(h.u_over_ucr.values * body.u_cr, a.run.history["u"])
    # the input pulse: one cycle of A sin(w t), A = 5 g tan(0.15)
    w, amp = 5.3, 5.0 * math.tan(0.15)
    on = t < 2 * math.pi / w
    np.testing.assert_allclose(h.xg_over_g.values[on], amp * np.sin(w * t[on]), atol=1e-9)
    fig = a.figure()
    assert len(fig.axes) >= 4


def test_simulate_runs_each_point_of_a_small_scene():
    sims = rocksweep.simulate(FIG5)  # lam: [0, 0.2, 0.4]
    assert [s.run.point.lam for s in sims] == [0.0, 0.2, 0.4]
    one = rocksweep.simulate(FIG5, impact__lam=0.4)
    assert one.summary == {**sims[2].summary, "wall_time_s": one.summary["wall_time_s"]}


def test_simulate_runs_each_record_and_stripe_of_a_small_suite(tmp_path):
    """A suite of 2 records x 2 stripes simulated: one run per point, titled and written
    with its record's name and stripe level (the point holds a record and an amplitude:
    reading them back was a TypeError, from the API and the command)."""
    from click.testing import CliRunner

    suite = Path(__file__).resolve().parents[2] / "records" / "suite"
    scene = {"name": "suite", "body": {**FIG3}, "impact": {"lam": 0.0},
             "ground": {"records": [str(suite / "SYN01.AT2"), str(suite / "SYN02.AT2")],
                        "scale": {"im": "PGA", "values": [0.2, 0.6]}, "p": 2.0}}
    sims = rocksweep.simulate(scene)
    assert [s.title for s in sims] == [f"record = {r}, PGA = {g}" for r in
                                       ("SYN01.AT2", "SYN02.AT2") for g in (0.2, 0.6)]
    path = tmp_path / "suite.yaml"
    path.write_text(json.dumps(scene))
    res = CliRunner().invoke(main, ["simulate", str(path), "--csv", str(tmp_path / "h.csv")])
    assert res.exit_code == 0, res.output
    heads = [ln.split("]")[0] for ln in res.stdout.splitlines() if ln.startswith("[")]
    assert heads == [f"[record={r}, PGA={g}" for r in ("SYN01.AT2", "SYN02.AT2")
                     for g in (0.2, 0.6)]
    first = (tmp_path / "h.csv").read_text().splitlines()[:2]
    assert first[0].startswith("run,record,PGA,p_t,") and first[1].startswith(
        "0,SYN01.AT2,0.2,"), first


# --- fields ---------------------------------------------------------------------------------

def test_one_field_table():
    """Sweeps, the store's variable list and single runs all read rocksweep.fields."""
    plain, energy = fields.variables(), fields.variables(energy=True)
    assert list(plain) == [f.name for f in fields.SWEEP_FIELDS]
    assert list(energy)[len(plain):] == [f.name for f in fields.ENERGY_FIELDS]
    assert plain["outcome"][1] == L.OUTCOME_NOT_RUN
    # a stored variable's unit in the file is the field's (the error estimates included)
    sc = load_scene(CI_SMALL, ["outputs.check=true", "pulse.shape=sine", "impact.lam=0.0"])
    assert list(sc.variables()) == list(fields.variables(check=True))
    assert fields.UNITS["work_in_over_Eref"] == "E_ref"
    slots = [f.slot for f in fields.RUN_FIELDS]
    assert len(set(slots)) == len(slots)  # no kernel slot read twice in a run's row
    # the error estimates (outputs.check) read run slots of the half-step rerun
    assert {f.slot for f in fields.CHECK_FIELDS} <= set(slots)
    every = fields.HISTORY + fields.SLIDE_HISTORY  # (the sliding base's where it slides)
    assert len({c.slot for c in every}) == L.N_HIST == len(every)
    run = rocksweep.simulate(FIG5, impact__lam=0.0).run
    contact = {f.name for f in fields.CONTACT_FIELDS}  # only when the scene asks for them
    slide = {f.name for f in fields.FIELDS if f.slide}  # only where the scene gives mu
    assert set(run.summary()) == ({f.name for f in fields.RUN_FIELDS} - contact - slide) | {
        "accuracy", "wall_time_s", "impact_losses_over_Eref"}  # per impact: single runs
    # "steps" is the regular RK4 steps in a sweep and in a single run alike
    sc = load_scene(FIG5, ["impact.lam=0.2"])
    g = Grid(sc)
    chunk = sw.run_chunk(g, 0, 1, sw.level(sc))
    from rocksweep.compute.single import run_point

    one = run_point(sc.point({a.name: a.values[0] for a in sc.axes}), sc.numerics,
                    history=False)
    assert chunk.arrays["steps"][0] == one.summary()["steps"] == one.out[L.OUT_STEPS]
    assert chunk.arrays["event_steps"][0] == one.summary()["event_steps"]


# --- dask -----------------------------------------------------------------------------------

RAN_IN_MAIN_THREAD: list[bool] = []


def _spy_chunk(grid, a, b, level):
    RAN_IN_MAIN_THREAD.append(threading.current_thread() is threading.main_thread())
    return _REAL_RUN_CHUNK(grid, a, b, level)


_REAL_RUN_CHUNK = sw.run_chunk


def test_dask_one_thread_cluster_computes_every_chunk(tmp_path, cli_file, monkeypatch):
    """A cluster of one worker thread: every chunk runs on the cluster, none in this
    process's main thread (joblib's dask backend with n_jobs = 1 ran them all here)."""
    distributed = pytest.importorskip("distributed")  # in the test extra: never skipped
    monkeypatch.setattr(sw, "run_chunk", _spy_chunk)
    RAN_IN_MAIN_THREAD.clear()
    out = tmp_path / "d.h5"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        sweep_file(load_scene(CI_SMALL), out, backend="dask",
                       scheduler=cluster.scheduler_address, chunk_size=16)
    assert len(RAN_IN_MAIN_THREAD) == 16 and not any(RAN_IN_MAIN_THREAD)
    a, b = read_result(out), read_result(cli_file)
    for name in b.arrays:
        np.testing.assert_array_equal(a.arrays[name], b.arrays[name], err_msg=name)


def test_dask_cluster_without_workers_is_an_error(tmp_path, monkeypatch, cli):
    distributed = pytest.importorskip("distributed")
    monkeypatch.setattr(sw, "NO_WORKERS_TIMEOUT", 1.0)
    out = tmp_path / "n.h5"
    with distributed.LocalCluster(n_workers=0, processes=False,
                                  dashboard_address=None) as cluster:
        res = cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(out), "-q", "--backend",
                                "dask", "--scheduler", cluster.scheduler_address])
    assert res.exit_code == 2
    assert res.output.strip().splitlines() == [
        f"Error: dask cluster {cluster.scheduler_address}: no worker joined in 1 s; start "
        f"workers (dask worker {cluster.scheduler_address}), then rerun with --resume"]
    assert read_result(out).done.sum() == 0  # the file is there to resume


def test_dask_losing_every_worker_mid_sweep_saves_and_stops(tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    monkeypatch.setattr(sw, "NO_WORKERS_TIMEOUT", 1.0)
    out = tmp_path / "l.h5"
    sc = load_scene(CI_SMALL)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        real = sw.run_chunks

        def run_then_lose_workers(*args, **kwargs):
            for i, res in enumerate(real(*args, **kwargs)):
                if i == 2:
                    cluster.scale(0)  # every worker leaves the cluster
                yield res

        monkeypatch.setattr(sw, "run_chunks", run_then_lose_workers)
        with pytest.raises(errors.SweepError) as exc:
            sweep_file(sc, out, backend="dask", scheduler=cluster.scheduler_address,
                           chunk_size=1, write_every=1000.0)
    msg = str(exc.value)
    assert "lost all its workers" in msg and "resume=True" in msg and "\n" not in msg
    r = read_result(out)
    assert 3 <= int(r.done.sum()) < 256  # what finished was written before the error
    assert not r.attrs["complete"]


# --- the README -----------------------------------------------------------------------------

@pytest.mark.parametrize("dask", [True, False], ids=["with-dask", "quick-start-install"])
def test_readme_python_api_example_runs(tmp_path, monkeypatch, dask):
    """The README's Python section, run as a notebook would run it (one namespace): it
    estimates, sweeps, plots, extracts A_min as a DataFrame, runs on a two-worker
    LocalCluster through client= and simulates, and writes no file where it runs. On the
    quick start's install (no ``.[dask]``: dask hidden) it runs too, without the cluster."""
    if not dask:
        for name in ("dask", "distributed", "dask.distributed"):
            monkeypatch.setitem(sys.modules, name, None)  # import fails, find_spec: None
    import pandas as pd
    from matplotlib.figure import Figure

    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Python API"):]
    section = section[:section.index("\n## ", 3)]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert blocks, "no python block under ## Python API"
    monkeypatch.chdir(tmp_path)
    ns: dict = {}
    for code in blocks:
        exec(compile(code, "README.md", "exec"), ns)  # noqa: S102
    assert list(tmp_path.iterdir()) == []  # nothing written
    assert isinstance(ns["ds"], xr.Dataset) and isinstance(ns["fig"], Figure)
    assert isinstance(ns["table"], pd.DataFrame) and "A_min" in ns["table"]
    assert isinstance(ns["lines"], pd.DataFrame) and len(ns["lines"]) > 0
    if dask:
        assert ns["on_cluster"].attrs["backend"].startswith("dask")
    else:
        assert "on_cluster" not in ns
    est = ns["rocksweep"].estimate(ns["scene"])
    assert est.points == ns["ds"].outcome.size
    assert [s.summary["outcome"] for s in ns["sims"]] == ["safe", "mode1"]  # Figure 5
