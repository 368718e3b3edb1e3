"""A_min independent of the grid: the search below the first overturning grid
value finds a first overturning band narrower than the grid step, checked against the
reference path (scipy DOP853, ``rocksweep.physics.reference``, an integrator independent
of the kernel); and the bad inputs of boundaries / spectra (rtol, one A value, a
refinement over its step budget): one line, nothing written."""

import csv
import math

import numpy as np
import pytest
from bodies import FIG4
from click.testing import CliRunner

import rocksweep
import rocksweep.analysis.boundaries as bd
from rocksweep.cli import main
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import FlexibleBody
from rocksweep.physics.points import Point
from rocksweep.physics.reference import reference_run
from rocksweep.store.reader import as_result

# Figure 4's stiff body (Table 3, wn/p = 9.82) under a cosine pulse at omega/p = 1: the
# reference overturns first in a band from A_ratio ~1.025 that ends before 1.1, while the
# grid below (step 0.1) overturns first at 1.2.
BODY = dict(FIG4)
SCENE = {"name": "narrow first band", "body": BODY, "impact": {"lam": 0.0},
         "pulse": {"shape": "cosine", "w_over_p": [1.0, 1.2],
                   "A_ratio": {"start": 0.3, "stop": 2.0, "num": 18}}}
RTOL = 1e-3


def reference_outcome(a_ratio: float, w_over_p: float = 1.0) -> int:
    point = Point(FlexibleBody(**BODY), 0.0, "cosine", w_over_p, a_ratio)
    return int(reference_run(point, Numerics())["outcome"])


@pytest.fixture(scope="module")
def narrow(tmp_path_factory):
    out = tmp_path_factory.mktemp("narrow") / "narrow.h5"
    return rocksweep.run(SCENE, output=out), out


def test_a_first_band_narrower_than_the_grid_step_is_found(narrow):
    ds, out = narrow
    A = ds["A_ratio"].values
    col = ds["outcome"].sel(w_over_p=1.0).values
    first = float(A[np.argmax(col > 0)])
    # the reference: the grid values 1.0 and 1.1 are safe, 1.05 overturns: the first band
    # lies between two grid values and the grid steps over it
    assert reference_outcome(1.0) == 0 and reference_outcome(1.1) == 0
    assert reference_outcome(1.05) in (1, 2)
    assert first > 1.1
    lo, hi = 1.0, 1.05  # the reference's own A_min, bisected to 2e-4
    while hi - lo > 2e-4 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if reference_outcome(mid) else (mid, hi)
    b = rocksweep.boundaries(ds, rtol=RTOL)
    ours = float(b["A_min"].sel(w_over_p=1.0))
    assert abs(ours - hi) <= RTOL * hi + (hi - lo), (ours, hi)
    assert (first - hi) / hi > 0.1  # the grid alone is more than 10% off
    assert str(b["A_min_method"].sel(w_over_p=1.0).values) == "searched below grid"
    assert int(b["mode"].sel(w_over_p=1.0)) == reference_outcome(hi)
    # the bracket: hi overturns, lo does not, within rtol (the kernel's classes)
    row = b.sel(w_over_p=1.0)
    assert float(row["hi"] - row["lo"]) <= RTOL * float(row["hi"])
    # spectra and the command line say the same
    sp = rocksweep.spectra(ds, rtol=RTOL)
    assert float(sp["A_min"].sel(w_over_p=1.0).squeeze()) == ours
    assert str(sp["A_min_method"].sel(w_over_p=1.0).squeeze().values) == "searched below grid"
    csv_path = out.with_name("curves.csv")
    res = CliRunner().invoke(main, ["boundaries", str(out), "-o", str(csv_path), "--rtol",
                                    str(RTOL)])
    assert res.exit_code == 0, res.output
    assert "searched below grid" in res.output
    with open(csv_path, newline="") as fh:
        rows = {float(r["w_over_p"]): r for r in csv.DictReader(fh)}
    assert rows[1.0]["method"] == "searched below grid"
    assert float(rows[1.0]["A_min"]) == ours


def test_spectra_without_the_search_take_the_grids_bracket_as_boundaries_do(narrow, tmp_path):
    """spectra(search=False) (and ``rocksweep spectrum --no-search``) bisect the grid's
    bracket only: the band below the grid is missed, A_min is that of boundaries with
    search=False, fewer kernel runs, and the Dataset says which it was."""
    ds, out = narrow
    fast = rocksweep.spectra(ds, rtol=RTOL, search=False)
    full = rocksweep.spectra(ds, rtol=RTOL)
    b = rocksweep.boundaries(ds, rtol=RTOL, search=False)
    a_fast = float(fast["A_min"].sel(w_over_p=1.0).squeeze())
    assert a_fast == float(b["A_min"].sel(w_over_p=1.0))
    assert a_fast > 1.1 > float(full["A_min"].sel(w_over_p=1.0).squeeze())
    assert "searched below grid" not in set(fast["A_min_method"].values.ravel().tolist())
    assert fast.attrs["search"] == 0 and full.attrs["search"] == 1
    assert fast.attrs["runs"] < full.attrs["runs"]
    with pytest.raises(rocksweep.RocksweepError, match="^search = 'no': must be True or "
                                                       "False$"):
        rocksweep.spectra(ds, search="no")
    fig = tmp_path / "sp.png"
    res = CliRunner().invoke(main, ["spectrum", str(out), "-o", str(fig), "--rtol", str(RTOL),
                                    "--no-search"])
    assert res.exit_code == 0, res.output
    assert f"({fast.attrs['runs']} kernel runs" in res.output and fig.exists()


def test_the_search_stays_within_its_budget(narrow):
    ds, _ = narrow
    b = rocksweep.boundaries(ds, rtol=RTOL)
    n_a = ds.sizes["A_ratio"]
    # the search's runs a column, plus a bisection of the scan's spacing to rtol
    assert (b["runs"].values <= bd.SEARCH_RUNS + math.ceil(math.log2(0.1 / RTOL))).all()
    assert b["runs"].values.max() < 20 * n_a


# --- bad input ----------------------------------------------------------------------------

BAD_RTOL = [0, 0.0, -1e-3, 0.2, 1.0, float("nan"), True, "0.01"]


@pytest.mark.parametrize("rtol", BAD_RTOL)
def test_bad_rtol_is_one_line_naming_it(narrow, rtol):
    ds, _ = narrow
    for analysis in (rocksweep.boundaries, rocksweep.spectra):
        with pytest.raises(rocksweep.RocksweepError) as err:
            analysis(ds, rtol=rtol)
        assert str(err.value) == (f"rtol = {rtol!r}: must be a relative tolerance in "
                                  "(0, 0.1]")


@pytest.mark.parametrize("command,suffix", [("boundaries", "c.csv"),
                                            ("spectrum", "s.png")])
@pytest.mark.parametrize("rtol", ["0", "0.2", "-1", "nan"])
def test_cli_bad_rtol_is_a_usage_error_and_writes_nothing(narrow, tmp_path, command,
                                                          suffix, rtol):
    _, out = narrow
    target = tmp_path / suffix
    res = CliRunner().invoke(main, [command, str(out), "-o", str(target), "--rtol", rtol])
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"Error: --rtol {float(rtol)!r}: "
                                                   "must be a relative tolerance in (0, 0.1]")
    assert not target.exists() and list(tmp_path.iterdir()) == []


def test_one_amplitude_is_one_line_and_writes_nothing(tmp_path):
    out = tmp_path / "one.h5"
    one = {**SCENE, "pulse": {**SCENE["pulse"], "A_ratio": [1.5]}}
    ds = rocksweep.run(one, output=out)
    for analysis in (rocksweep.boundaries, rocksweep.spectra):
        with pytest.raises(rocksweep.RocksweepError) as err:
            analysis(ds)
        msg = str(err.value)
        assert "\n" not in msg and "A_ratio" in msg and "1.5" in msg, msg
    target = tmp_path / "c.csv"
    res = CliRunner().invoke(main, ["boundaries", str(out), "-o", str(target)])
    assert res.exit_code != 0 and "A_ratio = [1.5]" in res.output
    assert len(res.output.strip().splitlines()) == 1 and not target.exists()


def test_a_refinement_over_its_step_budget_runs_nothing(narrow, tmp_path, monkeypatch):
    ds, out = narrow
    monkeypatch.setattr(bd, "MAX_REFINE_STEPS", 1e6)  # a budget this refinement exceeds
    calls = []

    def evaluate(points):
        calls.append(len(points))
        return np.zeros(len(points), np.int8)

    sc = bd.check_result(as_result(ds))
    with pytest.raises(rocksweep.RocksweepError) as err:
        bd.a_min(sc, ds["outcome"].values, RTOL, evaluate=evaluate)
    assert str(err.value).startswith(f"rtol = {RTOL:g}: refining A_min of 2 columns")
    assert "above the budget of 1e+06" in str(err.value) and calls == []
    target = tmp_path / "c.csv"
    res = CliRunner().invoke(main, ["boundaries", str(out), "-o", str(target)])
    assert res.exit_code != 0 and "above the budget" in res.output
    assert len(res.output.strip().splitlines()) == 1 and not target.exists()
