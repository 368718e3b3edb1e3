"""Every file an analysis command writes opens with ``rocksweep.open`` and says its kind
(``rocksweep_kind``); one CSV rule for every table."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import yaml
from click.testing import CliRunner
from test_calibrate import ALPHA, BLOCK, free_block_history, noisy

import rocksweep
from rocksweep.analysis.files import csv_text, write_curves_h5
from rocksweep.analysis.kinds import dataset_kind
from rocksweep.cli.main import main


def _run(*args: str) -> None:
    res = CliRunner().invoke(main, list(args))
    assert res.exit_code == 0, res.output


def _opens_as(path, kind: str) -> None:
    ds = rocksweep.open(path)
    assert ds.attrs["rocksweep_kind"] == kind
    assert dataset_kind(ds) == kind


def test_fragility_risk_and_efficiency_files_open_with_their_kind(tmp_path, suite_result):
    frag, risk, eff = (tmp_path / f"{n}.h5" for n in ("frag", "risk", "eff"))
    _run("fragility", str(suite_result), "--bootstrap", "5", "-o", str(frag))
    _opens_as(frag, "fragility")
    back = rocksweep.open(frag)
    assert back.attrs["states"] == ["overturn"]  # a list attribute comes back a list
    hazard = tmp_path / "hazard.csv"
    x = np.geomspace(1e-3, 1e2, 30)
    pd.DataFrame({"PGA [g]": x, "annual_rate": 1e-4 * x ** -2.0}).to_csv(hazard, index=False)
    _run("risk", str(frag), "--hazard", str(hazard), "-o", str(risk))
    _opens_as(risk, "risk")
    _run("efficiency", str(suite_result), "-o", str(eff))
    _opens_as(eff, "im_efficiency")
    # a sweep result says its kind by its format (its attrs are the file's provenance)
    assert dataset_kind(rocksweep.open(suite_result)) == "sweep"


def test_calibration_file_opens_with_its_kind(tmp_path):
    t, theta = free_block_history(0.9, t_end=10.0)
    scene, meas, out = tmp_path / "block.yaml", tmp_path / "m.csv", tmp_path / "fit.h5"
    scene.write_text(yaml.safe_dump(BLOCK))
    noisy(t, theta / ALPHA, 0.01).to_csv(meas, index=False)
    _run("calibrate", str(scene), str(meas), "--fit", "impact.e", "-o", str(out))
    _opens_as(out, "calibration")
    assert abs(float(rocksweep.open(out)["estimate"][0]) - 0.9) < 0.02


def test_boundaries_file_opens_as_its_a_min_curves(tmp_path):
    from rocksweep.analysis.boundaries import AMinCurve, curves_dataset

    x = np.array([1.0, 2.0, 3.0])
    curves = [AMinCurve({"lam": lam}, x, np.array([1.5, np.nan, 2.5]),
                        np.array([1, 0, 2], np.int8), np.array([1.4, np.nan, 2.4]),
                        np.array([1.5, np.nan, 2.5]), np.array([7, 3, 9]))
              for lam in (0.0, 0.2)]
    path = tmp_path / "b.h5"
    write_curves_h5(path, curves, [], {"rtol": 1e-3})
    back = rocksweep.open(path)
    assert back.attrs["rocksweep_kind"] == "boundaries"
    want = curves_dataset(curves)
    for name in ("A_min", "mode", "lo", "hi", "runs", "A_min_method"):
        np.testing.assert_array_equal(back[name].values, want[name].values)
    assert back["lam"].values.tolist() == [0.0, 0.2]


def test_one_csv_rule_for_rows_and_frames():
    rows = [{"a": 0.1, "b": None, "c": "x", "d": 3, "e": math.nan},
            {"a": 1 / 3, "b": 2.5, "c": "y", "d": 4, "e": 1e-300}]
    text = csv_text(rows)
    assert text == ("a,b,c,d,e\n0.1,,x,3,\n0.3333333333333333,2.5,y,4,1e-300\n")
    assert csv_text(pd.DataFrame(rows)).splitlines()[1:] == [
        "0.1,,x,3,", "0.3333333333333333,2.5,y,4,1e-300"]
    back = pd.read_csv(pd.io.common.StringIO(text))
    assert back["a"].tolist() == [0.1, 1 / 3]  # floats read back exactly
