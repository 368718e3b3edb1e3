"""The thin facade: each argument check and each piece of work lives in the room
that does it (analysis.boundaries, analysis.calibrate, analysis.fragility,
analysis.spectrum, compute.history, compute.session), with the words the API always used, and
what ``rocksweep.<function>`` returns is what it returned before."""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest
import xarray as xr
from bodies import FIG3

import rocksweep
from rocksweep.analysis.boundaries import boundaries_dataset
from rocksweep.analysis.calibrate import calibrate_scene
from rocksweep.analysis.kinds import dataset_kind
from rocksweep.cli.main import said
from rocksweep.errors import ApiError, CalibrationError


@pytest.mark.parametrize("kw, words", [
    ({"mode": 3}, "mode = 3: must be None, 1 or 2"),
    ({"mode": "1"}, "mode = '1': must be None, 1 or 2"),
    ({"search": "yes"}, "search = 'yes': must be True or False"),
    ({"rtol": 0.5}, "rtol = 0.5: must be a relative tolerance in (0, 0.1]"),
])
def test_boundaries_checks_its_arguments_before_the_result(kw, words):
    """The checks are boundaries_dataset's (the facade's words): an empty Dataset, no
    result at all, is not read before a bad argument is refused."""
    for call in (rocksweep.boundaries, boundaries_dataset):
        with pytest.raises(ApiError) as exc:
            call(xr.Dataset(), **kw)
        assert str(exc.value) == words


@pytest.mark.parametrize("fit, ci, words", [
    ([], 0.95, "fit = []: give at least one key, e.g. impact.lam"),
    (["impact.lam", "impact.lam"], 0.95,
     "fit = ['impact.lam', 'impact.lam']: a key is given twice"),
    ("impact.lam", 0.3, "ci = 0.3: must be in [0.5, 1)"),
    ("impact.lam", 1, "ci = 1: must be in [0.5, 1)"),
    ("impact.lam", True, "ci = True: must be in [0.5, 1)"),
])
def test_calibrate_checks_fit_and_ci_before_the_scene(tmp_path, fit, ci, words):
    """calibrate_scene checks fit and ci first: a scene file that does not exist is not
    looked at (its error would be a SceneError)."""
    missing = tmp_path / "no-such-scene.yaml"
    for call in (lambda: rocksweep.calibrate(missing, None, fit, ci=ci),
                 lambda: calibrate_scene(missing, None, fit, None, ci)):
        with pytest.raises(CalibrationError) as exc:
            call()
        assert str(exc.value) == words


def test_simulate_refuses_a_grid_naming_its_longest_key():
    scene = {"name": "too many", "body": dict(FIG3), "impact": {"lam": [0.0, 0.4]},
             "pulse": {"shape": "sine", "w_over_p": 2.0,
                       "A_ratio": {"start": 1.0, "stop": 8.0, "num": 51}}}
    with pytest.raises(ApiError) as exc:
        rocksweep.simulate(scene)
    assert str(exc.value) == (
        "the scene has 102 points (pulse.A_ratio has 51 values): simulate runs at most 100; "
        "pass overrides={'pulse.A_ratio': ...}, or use rocksweep.run for a grid")
    from rocksweep.compute.history import API_MAX_RUNS

    assert API_MAX_RUNS == 100  # the limit the message names


def test_simulation_is_the_facades_type():
    sim = rocksweep.simulate({"name": "one", "body": dict(FIG3), "impact": {"lam": 0.2},
                              "pulse": {"shape": "sine", "w_over_p": 2.0, "A_ratio": 3.0}})
    assert isinstance(sim, rocksweep.Simulation) and sim.title == "one"
    assert sim.history.attrs["title"] == "one" and sim.summary["outcome"] == sim.run.outcome


@pytest.fixture(scope="module")
def suite_ds(suite_result):
    return rocksweep.open(suite_result)


def test_fragility_of_a_path_is_that_of_its_dataset(suite_result, suite_ds):
    """rocksweep.fragility takes a Dataset or its file (the one path-or-Dataset helper),
    and the Dataset says its kind and the sweep's title (set by analysis.fragility)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        by_path = rocksweep.fragility(suite_result, bootstrap=0)
        by_ds = rocksweep.fragility(suite_ds, bootstrap=0)
        from rocksweep.analysis.fragility import fragility as fit

        direct = fit(suite_ds, bootstrap=0)
    xr.testing.assert_identical(by_path, by_ds)
    xr.testing.assert_identical(by_ds, direct)
    assert by_ds.attrs["rocksweep_kind"] == "fragility" == dataset_kind(by_ds)
    assert by_ds.attrs["title"] == suite_ds.attrs["title"] == "small suite"
    assert hasattr(by_path, "rocksweep")  # the accessor is registered from a path too


def test_fragility_of_neither_is_one_line():
    with pytest.raises(TypeError) as exc:  # a wrong type is a TypeError naming the argument
        rocksweep.fragility(5)
    assert str(exc.value).startswith("ds = 5: must be an xarray Dataset")
    assert "\n" not in str(exc.value)


def test_spectra_say_their_kind_and_check_rtol_once():
    scene = {"name": "spectra facade", "body": dict(FIG3), "impact": {"lam": 0.0},
             "pulse": {"shape": "sine", "w_over_p": {"start": 1.0, "stop": 4.0, "num": 3},
                       "A_ratio": {"start": 1.0, "stop": 8.0, "num": 4}}}
    ds = rocksweep.run(scene)
    with pytest.raises(ApiError, match=r"^rtol = 0\.5: must be a relative tolerance"):
        rocksweep.spectra(ds, rtol=0.5)
    sp = rocksweep.spectra(ds, rtol=0.1)
    assert sp.attrs["rocksweep_kind"] == "spectra" == dataset_kind(sp)
    assert sp.attrs["title"] == "spectra facade"
    assert np.all(np.isfinite(sp["A_min"].values) | (sp["A_min_method"] == "not found"))


def test_run_checks_before_the_output_and_returns_the_file(tmp_path):
    """run hands its checks to compute.session.run_session: a bad argument leaves no file;
    with output the Dataset is the file's, with the accessor."""
    out = tmp_path / "r.h5"
    scene = {"name": "run facade", "body": dict(FIG3), "impact": {"lam": 0.0},
             "pulse": {"shape": "sine", "w_over_p": 2.0, "A_ratio": [1.0, 4.0]}}
    with pytest.raises(TypeError, match="^progress = 1: must be True or False$"):
        rocksweep.run(scene, output=out, progress=1)
    with pytest.raises(ApiError, match="^coarse = 2: an adaptive setting; add adaptive=True$"
                       ) as err:
        rocksweep.run(scene, output=out, coarse=2)
    assert said(err.value) == "--coarse 2: an adaptive setting; add --adaptive"
    assert not out.exists()
    ds = rocksweep.run(scene, output=out)
    xr.testing.assert_identical(ds, rocksweep.open(out))
    assert ds.rocksweep.outcome_words().shape == ds["outcome"].shape



def test_an_analysis_called_first_on_a_path_has_the_accessor(tmp_path):
    """A fresh interpreter whose first call is ``boundaries`` or ``spectra`` on a file gets
    ``ds.rocksweep`` on the result (before, only run, open and some analyses set it up)."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    out = tmp_path / "r.h5"
    rocksweep.run(root / "configs" / "ci-small.yaml", output=out,
                  overrides=["pulse.shape=sine"])
    code = ("import sys, rocksweep\n"
            "b = rocksweep.boundaries(sys.argv[1], search=False)\n"
            "print(hasattr(b, 'rocksweep'), type(b.rocksweep.plot()).__name__)\n")
    res = subprocess.run([sys.executable, "-c", code, str(out)], capture_output=True,
                         text=True, cwd=tmp_path, timeout=300)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["True", "Figure"]


def _fresh(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)


def test_the_accessor_is_there_after_importing_xarray_then_rocksweep():
    """``import xarray, rocksweep``: ``ds.rocksweep`` on any Dataset before any call of the
    API; ``import rocksweep`` alone imports no xarray (and so registers nothing)."""
    res = _fresh("import xarray as xr, rocksweep\n"
                 "ds = xr.Dataset({'outcome': ('x', [0, 1])})\n"
                 "print(type(ds.rocksweep).__name__)")
    assert res.returncode == 0 and res.stdout.split() == ["RocksweepAccessor"], res.stderr
    res = _fresh("import sys, rocksweep\nprint('xarray' in sys.modules)")
    assert res.returncode == 0 and res.stdout.split() == ["False"], res.stderr


def test_the_accessor_is_there_after_importing_rocksweep_then_xarray():
    """``import rocksweep`` loads no xarray, yet ``ds.rocksweep`` is there once xarray is
    imported, before any call of the API (rocksweep.accessor.watch)."""
    res = _fresh("import sys, rocksweep\nloaded = 'xarray' in sys.modules\n"
                 "import xarray as xr\n"
                 "print(loaded, type(xr.Dataset().rocksweep).__name__)")
    assert res.returncode == 0 and res.stdout.split() == ["False", "RocksweepAccessor"], \
        res.stderr


def test_every_analysis_is_on_the_accessor():
    """Every public function whose first argument is a Dataset is a method of
    ``ds.rocksweep`` (made from ``api.ANALYSES``; calibrated_overrides is as_overrides)."""
    import inspect

    from rocksweep.accessor import accessor_class
    from rocksweep.api import ANALYSES

    RocksweepAccessor = accessor_class()  # noqa: N806 (ds.rocksweep's class)

    renamed = {"calibrated_overrides": "as_overrides"}
    of_a_dataset = []
    for name in rocksweep.__all__:
        fn = getattr(rocksweep, name)
        first = next(iter(inspect.signature(fn).parameters.values()), None) \
            if inspect.isfunction(fn) else None
        if first is not None and "Dataset" in str(first.annotation):
            of_a_dataset.append(name)
            assert callable(getattr(RocksweepAccessor, renamed.get(name, name), None)), name
    assert {"floor_spectrum", "im_efficiency", "plot", "fragility"} <= set(of_a_dataset)
    assert sorted(f.__name__ for f in ANALYSES) == sorted(
        n for n in of_a_dataset if n not in renamed)


def test_an_accessor_method_hands_the_dataset_and_arguments_over():
    """``ds.rocksweep.f(...)`` answers as ``rocksweep.f(ds, ...)``, for an analysis added
    last (floor_spectrum) as for the first."""
    from rocksweep.errors import FloorError

    ds = xr.Dataset({"outcome": ("x", [0, 1])})
    with pytest.raises(ApiError) as direct:
        rocksweep.boundaries(ds, mode=3)
    with pytest.raises(ApiError) as method:
        ds.rocksweep.boundaries(mode=3)
    assert str(method.value) == str(direct.value) == "mode = 3: must be None, 1 or 2"
    with pytest.raises(FloorError, match="no floor.period dimension"):
        ds.rocksweep.floor_spectrum()
    with pytest.raises(TypeError, match=r"takes hazard by position"):
        ds.rocksweep.risk("hazard.csv", 50)


def test_the_accessor_methods_take_keywords_only():
    import inspect

    from rocksweep.accessor import accessor_class

    for name in ("plot", "boundaries", "spectra", "fragility", "ida", "im_efficiency"):
        params = list(inspect.signature(getattr(accessor_class(), name)).parameters.values())
        assert [p.kind for p in params[1:]] == [inspect.Parameter.VAR_KEYWORD], name
