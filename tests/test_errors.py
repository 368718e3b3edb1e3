"""Every error class in ``rocksweep.errors``, and the shared argument checks written once:
an error class defined in another module, or the rtol / integer wording typed
again, fails here."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest
from bodies import FIG3_YAML
from helpers import docstring_ids

from rocksweep import errors

PKG = Path(__file__).resolve().parents[1] / "rocksweep"
# not user errors: click's usage and input errors of the CLI (how it says them), the YAML
# loader's internal signal, the driver's interrupt (a KeyboardInterrupt carrying what was
# saved)
NOT_ERRORS = {"OneLineUsageError", "InputError", "YamlError", "SweepInterrupted"}


def _bases(node: ast.ClassDef) -> list[str]:
    return [b.id if isinstance(b, ast.Name) else b.attr for b in node.bases
            if isinstance(b, ast.Name | ast.Attribute)]


def test_every_error_class_lives_in_errors_py():
    homes = {n.name for n in ast.walk(ast.parse((PKG / "errors.py").read_text()))
             if isinstance(n, ast.ClassDef)}
    elsewhere = []
    for path in sorted(PKG.rglob("*.py")):
        if path.name == "errors.py" and path.parent == PKG:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef) and node.name not in NOT_ERRORS and (
                    set(_bases(node)) & homes or any(b.endswith(("Error", "Exception"))
                                                     for b in _bases(node))):
                elsewhere.append(f"{path.relative_to(PKG.parent)}:{node.lineno} {node.name}")
    assert not elsewhere, "error classes outside rocksweep/errors.py:\n" + "\n".join(elsewhere)


def test_error_classes_form_one_hierarchy():
    assert issubclass(errors.DiagramError, errors.FigureError)
    assert issubclass(errors.BoundaryError, errors.AdaptiveError)
    assert all(issubclass(getattr(errors, n), errors.RocksweepError)
               for n in dir(errors) if n.endswith("Error") and n != "RocksweepError")


def test_rtol_and_integer_checks_have_one_wording():
    for bad in (0, 1.0, 0.2, -0.1, True, "0.1", np.nan):
        with pytest.raises(errors.ApiError, match=r"^rtol = .*: must be a relative "
                                                  r"tolerance in \(0, 0\.1\]$"):
            errors.check_rtol(bad)
    assert errors.check_rtol(np.float64(1e-3)) == 1e-3
    with pytest.raises(errors.IdaError):
        errors.check_rtol(2, errors.IdaError)
    assert errors.is_integer(np.int64(3)) and not errors.is_integer(True)
    assert not errors.is_integer(3.0)
    with pytest.raises(TypeError, match=r"^n = 2.5: must be an integer$"):
        errors.check_integer("n", 2.5)
    # nowhere else is the rtol message typed
    typed = [str(p.relative_to(PKG)) for p in PKG.rglob("*.py")
             if p.name != "errors.py" and "must be a relative tolerance" in p.read_text()]
    assert not typed


def test_adaptive_settings_are_checked_once_with_the_schema_wording():
    from rocksweep.cli.main import said
    from rocksweep.compute.adaptive import Options, Plan, check_settings
    from rocksweep.errors import AdaptiveError

    with pytest.raises(AdaptiveError) as err:
        check_settings({"margin": 9, "seed": 1})
    assert str(err.value).startswith("margin = 9: must be an integer in [0, 8]")
    assert said(err.value).startswith("--margin 9: must be an integer in [0, 8]")
    check_settings({"margin": 2, "seed": None})
    with pytest.raises(AdaptiveError, match=r"^audit = 1\.5: must be in \[0, 1\]"):
        Options(audit=1.5)
    # a Plan made directly is held to the same table as Options
    for make in (lambda: Options(margin=9), lambda: Plan((64, 64), 1, 0, margin=9, coarse=3)):
        with pytest.raises(AdaptiveError, match=r"^margin = 9: must be an integer in \[0, 8\]"):
            make()


# A command-line option in a message: "--resume", "--set KEY=VALUE" (not a matplotlib
# line style such as "--x": those are strings of at most three characters)
OPTION = re.compile(r"(?<![\w-])--[a-z]")


def test_no_library_string_names_a_command_line_option():
    """The library (everything but ``rocksweep/cli/``) writes its messages in its own
    terms: no string of its code (docstrings and comments aside) names a ``--option``; the
    command line names its options itself (``rocksweep.cli.main.option_words``)."""
    found = []
    for path in sorted(PKG.rglob("*.py")):
        if path.relative_to(PKG).parts[0] == "cli":
            continue
        tree = ast.parse(path.read_text())
        docs = docstring_ids(tree)
        for node in ast.walk(tree):
            if (isinstance(node, ast.Constant) and isinstance(node.value, str)
                    and id(node) not in docs and len(node.value) > 3
                    and OPTION.search(node.value)):
                found.append(f"{path.relative_to(PKG.parent)}:{node.lineno} {node.value!r}")
    assert not found, "command-line options in library strings:\n" + "\n".join(found)


def test_the_scan_sees_an_option():
    assert OPTION.search("x.h5: already exists; use --overwrite to replace it")
    assert not OPTION.search("use overwrite=True; a-b--c; e.g. 1e-3")


SCENE = ("name: t\n" + FIG3_YAML + "impact: {lam: [0.0, 0.2]}\n"
         "pulse: {shape: sine, w_over_p: [1.0, 2.0], A_ratio: [1.0, 2.0]}\n")


def _refusals(tmp_path: Path) -> list[tuple[str, object]]:
    """The main refusals of the Python API, each as (what, a call that raises it)."""
    import pandas as pd

    import rocksweep
    from rocksweep.compute.adaptive import Options, Plan
    from rocksweep.compute.arguments import check_sweep_arguments
    from rocksweep.compute.history import run_points
    from rocksweep.compute.session import sweep_file
    from rocksweep.scene.parse import load_scene
    from rocksweep.store.writer import SweepFile

    scene_path = tmp_path / "s.yaml"
    scene_path.write_text(SCENE)
    existing = tmp_path / "old.h5"
    existing.write_bytes(b"")
    scene = load_scene(scene_path)
    return [
        ("run onto a file", lambda: rocksweep.run(scene_path, output=existing)),
        ("sweep_file onto a file", lambda: sweep_file(scene, existing)),
        ("create onto a file", lambda: SweepFile.create(existing, scene)),
        ("resume in memory", lambda: rocksweep.run(scene_path, resume=True)),
        ("resume and overwrite", lambda: rocksweep.run(scene_path, output=tmp_path / "n.h5",
                                                       resume=True, overwrite=True)),
        ("jobs", lambda: rocksweep.run(scene_path, jobs=0)),
        ("validate without adaptive", lambda: sweep_file(scene, tmp_path / "v.h5",
                                                         validate=True)),
        ("dask without a scheduler", lambda: check_sweep_arguments(backend="dask")),
        ("a scheduler without dask", lambda: check_sweep_arguments(scheduler="tcp://h:1")),
        ("connect timeout", lambda: check_sweep_arguments(connect_timeout=0)),
        ("margin", lambda: Options(margin=9)),
        ("plan margin", lambda: Plan((64, 64), 1, 0, margin=9, coarse=3)),
        ("an override without =", lambda: rocksweep.run(scene_path, overrides=["impactlam"])),
        ("too many points to simulate", lambda: run_points(scene, 2)),
        ("one point of many", lambda: rocksweep.calibrate(
            scene_path, pd.DataFrame({"p_t": np.arange(20.0), "theta_over_alpha": np.zeros(20)}),
            fit="impact.e_factor")),
        ("rtol", lambda: rocksweep.boundaries(existing, rtol=0.3)),
    ]


def test_the_api_refuses_in_its_own_words_and_the_cli_names_options(tmp_path):
    """The main refusals of the API: one line, no ``--option``; the same error said by the
    command line names its option (``--overwrite``, ``--jobs 0``, ``--set ...``)."""
    from rocksweep.cli.main import said

    for what, call in _refusals(tmp_path):
        with pytest.raises(errors.RocksweepError) as err:
            call()
        text, cli = str(err.value), said(err.value)
        assert "\n" not in text and not OPTION.search(text), (what, text)
        assert OPTION.search(cli), (what, cli)


def test_already_exists_is_one_error_everywhere(tmp_path):
    refusals = dict(_refusals(tmp_path))
    texts = set()
    for what in ("run onto a file", "sweep_file onto a file", "create onto a file"):
        with pytest.raises(errors.OutputError) as err:
            refusals[what]()
        assert isinstance(err.value, OSError)
        texts.add(str(err.value))
    assert texts == {f"{tmp_path / 'old.h5'}: already exists; use resume=True to finish it "
                     "or overwrite=True to replace it"}


def test_an_incomplete_result_is_refused_in_one_wording(suite_result, tmp_path):
    """boundaries, spectra and IDA refuse a result with points not computed through one
    function (``SweepResult.require_complete``): one wording, naming what is missing and
    the resume that finishes it."""
    import rocksweep

    sweep = rocksweep.run(SCENE)
    suite = rocksweep.open(suite_result)
    wording = (r": incomplete result \(1 of {} points not computed yet\); {} needs every "
               r"point: finish the sweep with resume=True$")
    for ds, call, what in ((sweep, rocksweep.boundaries, "A_min"),
                           (sweep, rocksweep.spectra, "a spectrum"),
                           (suite, rocksweep.ida, "IDA")):
        outcome = ds["outcome"].values.copy()
        outcome.flat[0] = -1
        with pytest.raises(errors.RocksweepError, match=wording.format(outcome.size, what)):
            call(ds.assign(outcome=(ds["outcome"].dims, outcome)))
