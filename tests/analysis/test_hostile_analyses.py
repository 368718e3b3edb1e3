"""Hostile input to the analyses and their readers: every case answers in one line (a
RocksweepError, or a TypeError for a wrong type), or right to its stated tolerance.

No sweep runs here: the readers, the API's type checks, the calibration's and the scene's
refusals all answer before any kernel is loaded; the risk integral is checked against its
closed form on synthetic fragilities. ``scripts/hostile_probe.py`` runs the same cases
through the command line.
"""

from __future__ import annotations

import math
import os
import threading
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import rocksweep
from rocksweep.analysis import risk as risk_mod
from rocksweep.analysis.risk import check_fragility, read_hazard
from rocksweep.analysis.states import trust
from rocksweep.errors import (
    AnalysisWarning,
    CalibrationError,
    MeasuredError,
    RecordError,
    RiskError,
    RocksweepError,
    SceneError,
)
from rocksweep.physics.measured import read_measured
from rocksweep.physics.records import read_record
from rocksweep.scene.inputs import load

pytestmark = pytest.mark.faults

HAZARD = "PGA [g],annual_rate\n0.05,0.01\n0.1,0.003\n0.3,0.0004\n1.0,0.00002\n"
BLOCK = {"name": "free block", "body": {"kind": "block", "alpha": 0.2},
         "impact": {"lam": 0.0}, "initial": {"theta_over_alpha": 0.7}}


def one_line(err: pytest.ExceptionInfo, *words: str) -> str:
    text = str(err.value)
    assert "\n" not in text, text
    for w in words:
        assert w in text, (w, text)
    return text


def history(theta_scale: float = 1.0, t_scale: float = 1.0) -> pd.DataFrame:
    t = np.arange(0.0, 15.0, 0.05)
    return pd.DataFrame({"p_t": t * t_scale,
                         "theta_over_alpha": theta_scale * 0.7 * np.cos(1.3 * t)
                         * np.exp(-0.05 * t)})


def fragility(median: float, beta: float, **extra) -> xr.Dataset:
    data = {"im_median": (("lam",), [median]), "beta": (("lam",), [beta]), **extra}
    return xr.Dataset(data, coords={"lam": [0.0]}, attrs={"im": "PGA", "im_units": "g",
                                                          "ci": 0.9})


def power_law(k0: float = 1e-4, k: float = 2.0, n: int = 40) -> pd.DataFrame:
    x = np.geomspace(1e-4, 1e2, n)
    return pd.DataFrame({"PGA [g]": x, "annual_rate": k0 * x ** -k})


# --- the one reader guard ------------------------------------------------------------------

def test_a_fifo_is_refused_without_blocking(tmp_path):
    """A FIFO with no writer as a hazard, a measured history or a record: one line at
    once (a reader that opened it would wait for ever: the test's thread would hang)."""
    fifo = tmp_path / "h.csv"
    os.mkfifo(fifo)
    errors: list[Exception] = []

    def read_all() -> None:
        for read in (read_hazard, read_measured, read_record):
            try:
                read(fifo)
            except RocksweepError as err:
                errors.append(err)

    t = threading.Thread(target=read_all, daemon=True)
    t.start()
    t.join(30)
    assert not t.is_alive(), "a reader blocked on a FIFO"
    assert [type(e) for e in errors] == [RiskError, MeasuredError, RecordError]
    assert all("FIFO" in str(e) and "\n" not in str(e) for e in errors)


@pytest.mark.parametrize("text, words", [
    (HAZARD.replace(",", ";"), ("line 1", "semicolons", "commas")),
    (HAZARD.replace(",", "\t"), ("line 1", "tabs", "commas")),
    ("PGA [g],PGA [g]\n0.1,0.01\n0.2,0.001\n", ("line 1", "'PGA [g]' appears twice")),
    ("PGA [g],annual_rate\n0.1,0.01\n0.2,1e400\n", ("line 3", "annual_rate = '1e400'",
                                                    "finite")),
    ("PGA [g],annual_rate\n0.1,0.01\n0.2,x\n", ("line 3", "'x'", "not a number")),
    ("PGA [g],annual_rate\n0.1,0.001\n0.2,0.01\n", ("line 3", "must not increase")),
])
def test_hazard_csv_refusals_name_the_line(tmp_path, text, words):
    path = tmp_path / "h.csv"
    path.write_text(text)
    with pytest.raises(RiskError) as err:
        read_hazard(path)
    one_line(err, "h.csv", *words)


def oq(path: Path, T: str, imt: str, poes: str = "0.5,0.1,0.01") -> Path:
    path.write_text(f"#,,,,,\"generated_by='OpenQuake engine 3.16', investigation_time={T}, "
                    f"imt='{imt}'\"\nlon,lat,depth,poe-0.1,poe-0.3,poe-1.0\n"
                    f"10.0,45.0,0.0,{poes}\n")
    return path


@pytest.mark.parametrize("T, imt, words", [
    ("50.0.1", "PGA", "investigation_time = '50.0.1'"),
    ("e", "PGA", "investigation_time = 'e'"),
    ("50.0", "SA(1.0.0)", "imt = 'SA(1.0.0)'"),
    ("50.0", "SA(e)", "imt = 'SA(e)'"),
])
def test_openquake_headers_are_parsed_strictly(tmp_path, T, imt, words):
    with pytest.raises(RiskError) as err:
        read_hazard(oq(tmp_path / "oq.csv", T, imt))
    one_line(err, "oq.csv, line 1", words)


def test_openquake_poe_rising_through_one_is_refused(tmp_path):
    """poe = 1 levels are left out only after every level is checked: a poe that rises
    to 1 above a lower one is a broken curve, not a shorter one."""
    with pytest.raises(RiskError) as err:
        read_hazard(oq(tmp_path / "oq.csv", "50.0", "PGA", "0.5,1.0,1.0"))
    one_line(err, "poe-0.3", "must not increase")
    hz = read_hazard(oq(tmp_path / "ok.csv", "50.0", "PGA", "1.0,0.5,0.1"))
    assert hz.im.tolist() == [0.3, 1.0]  # the leading poe = 1 level left out


@pytest.mark.parametrize("frame, words", [
    (pd.DataFrame([[0.0, 0.0, 0.7]], columns=["p_t ", "p_t", "theta_over_alpha"]),
     ("column 'p_t' appears twice",)),
    (history(t_scale=1e298), ("p_t", "magnitude at most 1e+100")),
])
def test_measured_columns_and_values(frame, words):
    with pytest.raises(MeasuredError) as err:
        read_measured(frame)
    one_line(err, *words)


def test_measured_csv_with_semicolons(tmp_path):
    path = tmp_path / "m.csv"
    history().to_csv(path, sep=";", index=False)
    with pytest.raises(MeasuredError) as err:
        read_measured(path)
    one_line(err, "m.csv, line 1", "semicolons")


def test_options_that_would_be_ignored_are_refused(tmp_path):
    """A site for a one-curve hazard, p for a dimensionless history: said, not ignored."""
    path = tmp_path / "h.csv"
    path.write_text(HAZARD)
    with pytest.raises(RiskError) as err:
        read_hazard(path, site=0)
    one_line(err, "site = 0", "h.csv")
    with pytest.raises(CalibrationError) as err:
        rocksweep.calibrate(BLOCK, history(), "impact.lam", p=3.0)
    one_line(err, "p = 3.0", "p_t, theta_over_alpha")


# --- the API's door --------------------------------------------------------------------------

@pytest.mark.parametrize("call, words", [
    (lambda: rocksweep.plot(None), "ds = None"),
    (lambda: rocksweep.plot(5), "ds = 5"),
    (lambda: rocksweep.plot([1, 2]), "ds = [1, 2]"),
    (lambda: rocksweep.plot(xr.Dataset(), ax=5), "ax = 5"),
    (lambda: rocksweep.table(None), "ds = None"),
    (lambda: rocksweep.calibrate(BLOCK, history(), "impact.lam", bounds=[0, 1]),
     "bounds = [0, 1]"),
    (lambda: rocksweep.calibrate(BLOCK, history(), "impact.lam", p="3"), "p = '3'"),
    (lambda: rocksweep.risk(fragility(0.3, 0.4), power_law(), site=1.5), "site = 1.5"),
    (lambda: rocksweep.risk(fragility(0.3, 0.4), power_law(), site=True), "site = True"),
    (lambda: rocksweep.risk(fragility(0.3, 0.4), 5), "hazard = int"),
    (lambda: rocksweep.calibrate(BLOCK, history(), None), "fit = None"),
    (lambda: rocksweep.calibrated_overrides(5), "fit = 5"),
    (lambda: rocksweep.open(5), "path = 5"),
])
def test_a_wrong_type_is_one_typeerror(call, words):
    with pytest.raises(TypeError) as err:
        call()
    one_line(err, words, "must be")


# --- calibration and scenes ----------------------------------------------------------------

@pytest.mark.parametrize("kwargs, words", [
    ({"fit": "initial.u_over_ucr"}, ("fit initial.u_over_ucr", "not a number of this "
                                     "scene")),
    ({"bounds": {"impact.e_factor": (0.5, 1.0)}}, ("bounds 'impact.e_factor'",
                                                   "not a fitted key")),
    ({"measured": history(theta_scale=10 / 0.2 / 0.7)}, ("|theta| = 10 rad", "pi/2")),
    ({"measured": history(t_scale=1e4)}, ("spans", "at most 10000")),
])
def test_calibration_refuses_what_it_cannot_fit(kwargs, words):
    """The top mass of a rigid block (the fit hung), bounds of a key not fitted (were
    ignored), a 'measurement' no rocking block can make (was fitted), a history so long
    that every candidate's run would take minutes."""
    args = {"fit": "impact.lam", "measured": history(), **kwargs}
    with pytest.raises(CalibrationError) as err:
        rocksweep.calibrate(BLOCK, args["measured"], args["fit"], bounds=args.get("bounds"))
    one_line(err, *words)


@pytest.mark.parametrize("extra, words", [
    ({"initial": {"theta_over_alpha": None}}, "initial.theta_over_alpha = null"),
    ({"initial": None}, "initial = null"),
    ({"pulse": None}, "pulse = null"),
    ({"initial": {"thetadot_over_palpha": 1e300}}, "initial.thetadot_over_palpha = 1e+300"),
])
def test_null_and_huge_initial_states_are_refused(extra, words):
    with pytest.raises(SceneError) as err:
        load({**BLOCK, **extra})
    one_line(err, words)


# --- risk: trusted numbers and bounded memory -----------------------------------------------

@pytest.mark.parametrize("beta", [0.0, 1e-9, 1e-6, 1e-3])
def test_steep_fragility_meets_the_closed_form(beta):
    """lambda = k0 m^-k exp(k^2 beta^2 / 2) to 1e-6 (docs/risk.md), also for the step of
    beta = 0 (it was 1.9e-3 off at beta = 1e-6)."""
    rk = rocksweep.risk(fragility(0.3, beta), power_law())
    exact = 1e-4 * 0.3 ** -2.0 * math.exp(4.0 * beta * beta / 2.0)
    assert float(rk.annual_rate[0]) == pytest.approx(exact, rel=1e-6)


@pytest.mark.parametrize("median, beta, words", [
    (0.3, -0.4, "beta = -0.4"), (-1.0, 0.4, "im_median = -1.0"),
    (0.3, math.inf, "beta = inf")])
def test_a_fragility_no_fit_gives_is_refused(median, beta, words):
    with pytest.raises(RiskError) as err:
        rocksweep.risk(fragility(median, beta), power_law())
    one_line(err, words)


def test_the_chunked_integral_is_the_whole_one(monkeypatch):
    """Chunks of the quadrature (the memory bound) change no rate: 7 (curve, node) values
    a chunk against all at once, bootstrap resamples included."""
    rng = np.random.default_rng(1)
    fr = fragility(0.3, 0.4, im_median_samples=(("lam", "sample"), 0.3 * np.exp(
        0.1 * rng.standard_normal((1, 9)))), beta_samples=(("lam", "sample"), 0.4 + 0.1 *
                                                           rng.random((1, 9))))
    whole = rocksweep.risk(fr, power_law())
    monkeypatch.setattr(risk_mod, "CHUNK_ELEMENTS", 7)
    chunked = rocksweep.risk(fr, power_law())
    for name in ("annual_rate", "annual_rate_lo", "annual_rate_hi"):
        np.testing.assert_allclose(chunked[name], whole[name], rtol=1e-12)


def test_risk_names_the_file_that_is_no_fragility():
    sweep = xr.Dataset({"outcome": (("A_ratio",), [0]), "status": (("A_ratio",), [0])})
    with pytest.raises(RiskError) as err:
        check_fragility(sweep, "p.h5")
    one_line(err, "p.h5: a sweep without records")
    rk = rocksweep.risk(fragility(0.3, 0.4), power_law())
    with pytest.raises(RiskError) as err:
        check_fragility(rk, "r.h5")
    one_line(err, "r.h5: a risk Dataset, not a fragility")


# --- one trust verdict ---------------------------------------------------------------------

def test_trust_says_incomplete_and_flagged():
    """The one verdict of the analyses: points not computed (a partial file) and flagged
    points, counted, with an AnalysisWarning; a complete, unflagged sweep is ok."""
    from rocksweep.kernel import layout as L

    out = np.array([[0, 1, -1], [2, -1, 0]], np.int8)
    status = np.zeros(out.shape, np.int32)
    status[1, 2] = int(L.STATUS_FLAGGED) & -int(L.STATUS_FLAGGED)  # its lowest flag bit
    ds = xr.Dataset({"outcome": (("record", "PGA"), out),
                     "status": (("record", "PGA"), status)}, attrs={"complete": 0})
    with pytest.warns(AnalysisWarning, match="efficiency: incomplete: 2 of 6 points"):
        verdict = trust(ds, "efficiency")
    assert "the file is not complete" in verdict and "flagged: 1 of 6 points" in verdict
    ok = ds.assign(outcome=ds.outcome.where(ds.outcome >= 0, 0), status=ds.status * 0)
    assert trust(ok, "efficiency") == "ok"
