"""Every error class in ``rocksweep.errors``, and the shared argument checks written once
(issue 31): an error class defined in another module, or the rtol / integer wording typed
again, fails here."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from rocksweep import errors

PKG = Path(__file__).resolve().parents[1] / "rocksweep"
# not user errors: click's usage and input errors of the CLI (how it says them), the YAML
# loader's internal signal, the driver's interrupt (a KeyboardInterrupt carrying what was
# saved)
NOT_ERRORS = {"OneLineUsageError", "InputError", "_YamlError", "SweepInterrupted"}


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


def test_old_import_paths_keep_working():
    from rocksweep.analysis.spectrum import SpectrumError
    from rocksweep.compute.adaptive import AdaptiveError
    from rocksweep.figures.diagrams import DiagramError
    from rocksweep.scene.model import SceneError
    from rocksweep.store._common import StoreError

    assert SceneError is errors.SceneError and StoreError is errors.StoreError
    assert issubclass(DiagramError, errors.FigureError) and SpectrumError is errors.SpectrumError
    assert issubclass(errors.BoundaryError, AdaptiveError)
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
    from rocksweep.compute.adaptive import AdaptiveError, Options, Plan, check_settings

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
