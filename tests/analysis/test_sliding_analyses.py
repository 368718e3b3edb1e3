"""The analyses of a sliding base (issue 44, item 5) on synthetic Datasets shaped like the
sweeps of a scene with ``body.mu`` (no kernel runs): the damage state slide:D in fragility,
risk and IDA, and the regime map. Expected values are counted by hand from the tables
below, not from the code."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from helpers import one_line_error
from matplotlib.collections import PathCollection, QuadMesh
from matplotlib.figure import Figure

import rocksweep
from rocksweep import errors
from rocksweep.analysis import fragility as F
from rocksweep.analysis import ida as IDA
from rocksweep.analysis.regimes import REGIME_WORDS, regime_index, regime_word
from rocksweep.analysis.states import state_groups
from rocksweep.cli import main
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.bodies import G
from rocksweep.scene.grid import ChunkResult
from rocksweep.scene.parse import parse_scene
from rocksweep.store.writer import SweepFile

ROOT = Path(__file__).resolve().parents[2]

# ---------------------------------------------------------------------------------------
# slide:D in fragility
# ---------------------------------------------------------------------------------------

# 4 records x 4 PGA levels by hand; D's level 0.2 is flagged (event cap): left out
OUTCOME = np.array([[0, 0, 1, 1],   # A
                    [0, 2, 0, 1],   # B
                    [0, 0, 0, 0],   # C
                    [0, 0, 1, 0]],  # D
                   np.int8)
SLIDE = np.array([[0.05, 0.30, 0.20, 0.10],   # A: overturned at 0.3, 0.4 (slide small)
                  [0.00, 0.00, 0.60, 0.00],   # B: overturned at 0.2 and 0.4
                  [0.10, 0.25, 0.24, 1.00],   # C: 0.25 exactly at 0.2 (>= D counts)
                  [0.30, 0.90, 0.00, 0.10]])  # D: 0.9 at the flagged 0.2
PGA = [0.1, 0.2, 0.3, 0.4]


def slide_suite(units: str = "b") -> xr.Dataset:
    status = np.zeros((4, 4), np.int32)
    status[3, 1] = L.STATUS_EVENT_CAP
    dims = ("record", "PGA")
    return xr.Dataset(
        {"outcome": (dims, OUTCOME.copy()), "status": (dims, status),
         "uplifts": (dims, np.zeros((4, 4), np.int32)),
         "theta_max_over_alpha": (dims, np.full((4, 4), 0.1)),
         "slide_max": (dims, SLIDE.copy(), {"units": units}),
         "slide_final": (dims, SLIDE / 2, {"units": units})},
        coords={"record": ["A.AT2", "B.AT2", "C.AT2", "D.AT2"], "PGA": PGA},
        attrs={"scale_im": "PGA"})


def test_slide_states_count_the_points_by_hand():
    fr = F.fragility(slide_suite(), state=["slide:0.25", "slide:0.5", "overturn"],
                     bootstrap=0, warn=False)
    # by hand from the tables: reached = slide_max >= D or outcome 1, 2; D's 0.2 left out
    assert fr["n_counted"].values.tolist() == [4, 3, 4, 4]
    assert fr["n_failed"].sel(state="slide:0.25").values.tolist() == [1, 3, 3, 3]
    assert fr["n_failed"].sel(state="slide:0.5").values.tolist() == [0, 1, 3, 3]
    assert fr["n_failed"].sel(state="overturn").values.tolist() == [0, 1, 2, 2]
    first = fr["first_level"].sel(state="slide:0.25").values
    assert np.allclose(first, [0.2, 0.2, 0.2, 0.1])
    # C slides less at 0.3 than at 0.2, D less at 0.4 than at 0.1: both "resurrect"
    assert fr["resurrection"].sel(state="slide:0.25").values.tolist() == [False, False, True,
                                                                          True]
    assert np.allclose(fr["first_level"].sel(state="slide:0.5").values, [0.3, 0.2, 0.4, 0.3])


def test_an_overturned_point_exceeds_every_slide_state():
    ds = slide_suite()
    ds["slide_max"][:] = 0.0  # nothing slides: only overturning reaches slide:D
    fr = F.fragility(ds, state=["slide:0.01", "slide:100", "overturn"], bootstrap=0,
                     warn=False)
    for s in ("slide:0.01", "slide:100"):
        assert fr["n_failed"].sel(state=s).values.tolist() == [0, 1, 2, 2]


def test_the_units_are_the_datasets_and_said():
    # D is compared with slide_max as stored, in the units it carries: a sweep's scale
    # (rocksweep_units: b; its CF units "1"), else its units
    fr = F.fragility(slide_suite("m"), state="slide:0.25", bootstrap=0, warn=False)
    assert fr["n_failed"].values.tolist() == [1, 3, 3, 3]
    assert fr.attrs["slide_max_units"] == "m"
    stored = slide_suite("1")
    stored["slide_max"].attrs["rocksweep_units"] = "b"
    fr_b = F.fragility(stored, state="slide:0.25", bootstrap=0, warn=False)
    assert fr_b.attrs["slide_max_units"] == "b"
    assert "slide_max_units" not in F.fragility(slide_suite(), state="overturn",
                                                bootstrap=0, warn=False).attrs
    fig = rocksweep.plot(fr)
    assert any("D in m" in a.get_title() for a in fig.axes)


@pytest.mark.parametrize("state, words", [
    ("slide:-1", ["'slide:-1'", "D > 0"]), ("slide:abc", ["'slide:abc'", "D > 0"]),
    ("slide:0", ["'slide:0'", "D > 0"]), ("slide:nan", ["'slide:nan'", "D > 0"]),
    ("slide:inf", ["'slide:inf'", "D > 0"]), ("slide", ["'slide'", "slide:D"]),
    ("slide:", ["'slide:'", "D > 0"])])
def test_bad_slide_states_are_one_line(state, words):
    with pytest.raises(errors.FragilityError) as err:
        F.fragility(slide_suite(), state=state, bootstrap=0)
    text = str(err.value)
    assert "\n" not in text and all(w in text for w in words), text


def test_slide_state_without_slide_max_is_one_line():
    ds = slide_suite().drop_vars(["slide_max", "slide_final"])
    for call in (lambda: F.fragility(ds, state="slide:0.5", bootstrap=0),
                 lambda: rocksweep.im_efficiency(ds.assign(record_pga=(
                     "record", [0.3, 0.4, 0.5, 0.6])), state="slide:0.5")):
        with pytest.raises(errors.RocksweepError) as err:
            call()
        text = str(err.value)
        assert "\n" not in text
        assert "'slide:0.5'" in text and "slide_max" in text and "body.mu" in text
    # the rocking states still work on it
    assert F.fragility(ds, state="theta:0.5", bootstrap=0, warn=False)["n_failed"].size == 4


def test_the_chains_of_nested_states():
    # by hand: rocking uplift < theta:X < overturn, sliding slide:D < overturn
    assert state_groups(["overturn", "slide:0.5", "slide:0.1"], joint=True) == [
        ("ordinal", [2, 1, 0])]
    assert state_groups(["uplift", "theta:0.5", "slide:0.2"], joint=True) == [
        ("ordinal", [0, 1]), ("single", [2])]
    assert state_groups(["slide:0.2", "mode1", "mode2"], joint=True) == [
        ("competing", [1, 2]), ("single", [0])]
    assert state_groups(["theta:0.5", "slide:0.2"], joint=True) == [
        ("single", [0]), ("single", [1])]
    with pytest.raises(errors.FragilityError) as err:
        state_groups(["theta:0.5", "overturn", "slide:0.2"], joint=True)
    text = str(err.value)
    assert "\n" not in text and "theta:0.5, overturn (rocking)" in text
    assert "slide:0.2, overturn (sliding)" in text and "joint=False" in text


def capacities(n=40, seed=3):
    """Stripes of records with lognormal overturning capacities: each rocks to theta:0.5
    at a quarter of its capacity, slides 0.1 b from a fifth of it and 0.3 b from
    two fifths (``slide_max``), and 0 b in ``slide_none`` (slide:D is then overturning's
    curve, far below theta:0.5's)."""
    rng = np.random.default_rng(seed)
    levels = np.geomspace(0.05, 2.0, 12)
    cap = rng.lognormal(math.log(0.5), 0.4, n)
    lev = levels[None, :] / cap[:, None]
    dims = ("record", "PGA")
    return xr.Dataset(
        {"outcome": (dims, (lev >= 1.0).astype(np.int8)),
         "status": (dims, np.zeros(lev.shape, np.int32)),
         "uplifts": (dims, (lev >= 0.1).astype(np.int32)),
         "theta_max_over_alpha": (dims, np.where(lev >= 0.25, 0.6, 0.1)),
         "slide_max": (dims, np.where(lev >= 0.4, 0.3, np.where(lev >= 0.2, 0.1, 0.0)),
                       {"units": "b"}),
         "slide_none": (dims, np.zeros(lev.shape), {"units": "b"})},
        coords={"record": [f"R{i}.AT2" for i in range(n)], "PGA": levels},
        attrs={"scale_im": "PGA"})


def test_crossing_is_said_only_of_nested_states():
    ds = capacities()
    ds["slide_max"] = ds["slide_none"]
    fr = F.fragility(ds, state=["slide:0.1", "theta:0.5"], bootstrap=0, warn=False)
    # theta:0.5 above slide:0.1 everywhere: not nested (a body may rock without sliding)
    assert float(fr["im_median"].sel(state="theta:0.5")) < 0.5 * float(
        fr["im_median"].sel(state="slide:0.1"))
    assert "crossing" not in " ".join(fr["reason"].values.tolist())
    # the same curves as uplift and theta:0.5 of the rocking chain do say it
    ds2 = ds.assign(uplifts=(ds["outcome"].dims, (ds["outcome"].values > 0).astype(np.int32)))
    fr2 = F.fragility(ds2, state=["uplift", "theta:0.5"], bootstrap=0, warn=False)
    assert all("crossing" in r for r in fr2["reason"].values.tolist())


def test_joint_slide_states_and_their_risk_are_ordered():
    ds = capacities()
    fr = rocksweep.fragility(ds, state=["overturn", "slide:0.2", "slide:0.05"], joint=True,
                             bootstrap=0)
    assert fr["fit"].values.tolist() == ["ordinal"] * 3
    assert fr["reason"].values.tolist() == ["ok"] * 3
    # the medians by construction: the capacities' 0.5 g times 1, 0.4, 0.2
    assert fr["im_median"].values == pytest.approx([0.5, 0.2, 0.1], rel=0.2)
    c = fr["curve"]
    assert np.all(c.sel(state="slide:0.05") >= c.sel(state="slide:0.2") - 1e-12)
    assert np.all(c.sel(state="slide:0.2") >= c.sel(state="overturn") - 1e-12)
    hazard = pd.DataFrame({"PGA [g]": [0.05, 0.1, 0.2, 0.5, 1.0, 2.0],
                           "annual_rate": [0.2, 0.05, 0.01, 1e-3, 1e-4, 1e-5]})
    rk = rocksweep.risk(fr, hazard, years=50)
    rate = rk["annual_rate"]
    assert float(rate.sel(state="slide:0.05")) >= float(rate.sel(state="slide:0.2"))
    assert float(rate.sel(state="slide:0.2")) >= float(rate.sel(state="overturn")) > 0


def test_efficiency_of_a_slide_state_finds_the_im_that_sets_the_sliding():
    """The base slides 0.3 b where the scaled PGV reaches 0.2 m/s (overturning never):
    PGV explains slide:0.3 exactly, PGA keeps the scatter of ln(capacity)."""
    rng = np.random.default_rng(5)
    n, levels = 60, np.geomspace(0.05, 5.0, 400)
    pga = rng.uniform(0.1, 0.4, n)
    pgv = pga * rng.lognormal(np.log(0.08), 0.4, n) * 9.81
    cap = 0.2 * pga / pgv  # the capacity in PGA (scaled PGV = PGV * level / pga)
    lev = levels[None, :] / cap[:, None]
    dims = ("record", "PGA")
    ds = xr.Dataset(
        {"outcome": (dims, np.zeros(lev.shape, np.int8)),
         "status": (dims, np.zeros(lev.shape, np.int32)),
         "slide_max": (dims, 0.3 * lev, {"units": "b"}),
         "record_pga": (("record",), pga), "record_pgv": (("record",), pgv),
         "scale_factor": (dims, levels[None, :] / pga[:, None])},
        coords={"record": [f"r{i}.AT2" for i in range(n)], "PGA": levels},
        attrs={"scale_im": "PGA"})
    b = rocksweep.im_efficiency(ds, state="slide:0.3").beta.to_series()
    step = np.log(levels[1] / levels[0])
    assert b["PGV"] < step
    assert b["PGA"] == pytest.approx(np.std(np.log(cap)), rel=0.03)


# ---------------------------------------------------------------------------------------
# slide:D in IDA: the stripes from the Dataset, the bisection from runs (a stand-in for
# the kernel whose sliding displacement is known in closed form)
# ---------------------------------------------------------------------------------------

SUITE = """
name: slide ida
body: {kind: block, alpha: 0.2}
impact: {lam: 0.0}
ground:
  records: [ROOT/records/suite/SYN01.AT2, ROOT/records/suite/SYN05.AT2,
            ROOT/records/suite/SYN12.AT2]
  scale: {im: PGA, values: [0.2, 0.4, 0.6, 0.8]}
  p: 2.0
"""
#: each record's level [g] at which its base slides D = 0.5 b: slide_max = 0.5 PGA / level
CAPACITY = {"SYN01": 0.3137, "SYN05": 0.6571, "SYN12": 0.9}
D = 0.5


def zero_sweep(scene: str, out: Path) -> xr.Dataset:
    """The result file of ``scene`` with every variable 0 (no kernel runs), opened."""
    sc = parse_scene(scene)
    sf = SweepFile.create(out, sc)
    n = sf.grid.size
    arrays = {k: np.full(n, 0, dt) for k, (dt, _, _) in sc.variables().items()}
    sf.write(ChunkResult(0, n, arrays, 0.0))
    sf.close()
    return rocksweep.open(out)


def suite_file(tmp_path: Path, with_slide: bool = True) -> tuple[Path, xr.Dataset]:
    out = tmp_path / "suite.h5"
    ds = zero_sweep(SUITE.replace("ROOT", str(ROOT)), out)
    if with_slide:
        level = ds["PGA"] * xr.ones_like(ds["outcome"], float)
        cap = xr.DataArray([CAPACITY[Path(str(r)).stem] for r in ds["record"].values],
                           coords={"record": ds["record"]})
        ds["slide_max"] = D * level / cap
        ds["slide_max"].attrs["units"] = "b"
    return out, ds


class _Run:
    """A stand-in for ``compute.single.Run``: safe, unflagged, slide_max linear in the
    scaled record's PGA (the point's A is PGA g)."""

    def __init__(self, point):
        self.out = np.zeros(L.N_OUT)
        self.point = point
        self.out[L.OUT_OUTCOME] = 0
        self.out[L.OUT_STATUS] = 0

    def get(self, name):
        assert name == "slide_max"
        pga = self.point.A / G
        return D * pga / CAPACITY[self.point.excitation.record.name]


def test_ida_of_a_slide_state_bisects_each_records_level(tmp_path, monkeypatch):
    _, ds = suite_file(tmp_path)
    runs = []

    def fake(point, numerics, history=True, contact=False):
        runs.append(point)
        return _Run(point)

    monkeypatch.setattr(IDA, "run_point", fake)
    rtol = 1e-3
    r = rocksweep.ida(ds, rtol=rtol, state=f"slide:{D}")
    assert r.attrs["state"] == f"slide:{D}" and runs
    for name, cap in CAPACITY.items():
        rec = [v for v in r["record"].values if Path(str(v)).stem == name][0]
        one = r.sel(record=rec)
        # by hand: the first stripe at or above the capacity, the one below it
        levels = [0.2, 0.4, 0.6, 0.8]
        above = [v for v in levels if v >= cap]
        if not above:
            assert np.isnan(float(one["ida_im"]))
            continue
        hi0 = above[0]
        below = [v for v in levels if v < hi0]
        assert float(one["ida_lo"]) >= below[-1] and float(one["ida_hi"]) <= hi0
        assert float(one["ida_lo"]) < cap <= float(one["ida_hi"])
        assert float(one["ida_hi"]) - float(one["ida_lo"]) <= rtol * float(one["ida_hi"])
        assert int(one["mode"]) == 0  # reached without overturning
    # the curves drawn are the sliding displacement's, ending at D
    assert "slide_max" in r and IDA.curve_end(f"slide:{D}") == D
    assert isinstance(rocksweep.plot(r), Figure)


def test_ida_slide_state_without_slide_max_is_one_line(tmp_path):
    out, ds = suite_file(tmp_path, with_slide=False)
    for given in (ds, out):
        with pytest.raises(errors.IdaError) as err:
            rocksweep.ida(given, state="slide:0.5")
        text = str(err.value)
        assert "\n" not in text and "slide_max" in text and "'slide:0.5'" in text
    with pytest.raises(errors.IdaError) as err:
        rocksweep.ida(ds, state="slide:-1")
    assert "'slide:-1'" in str(err.value) and "D > 0" in str(err.value)


def test_cli_slide_states_are_one_line_errors_and_write_nothing(tmp_path, cli):
    out, _ = suite_file(tmp_path, with_slide=False)
    csv = tmp_path / "c.csv"
    for state, words in (("slide:-1", "D > 0"), ("slide:abc", "D > 0"),
                         ("slide:0.5", "slide_max")):
        res = cli.invoke(main, ["fragility", str(out), "--state", state, "-o", str(csv),
                                "--bootstrap", "0"])
        line = one_line_error(res)
        assert line.startswith("Error:") and state in line and words in line, line
        assert not csv.exists()
    res = cli.invoke(main, ["fragility", str(out), "--state", "slide:0.5", "--rtol", "0.01"])
    line = one_line_error(res)
    assert "slide:0.5" in line and "slide_max" in line, line


# ---------------------------------------------------------------------------------------
# the regime map
# ---------------------------------------------------------------------------------------

# bits: rest 1, slide 2, rock 4, slide-rock 8 (vocab.phases codes 0..3)
BY_HAND = {0: "rest", 1: "rest", 2: "slide", 3: "slide", 4: "rock", 5: "rock",
           6: "slide+rock", 7: "slide+rock", 8: "slide-rock", 9: "slide-rock",
           10: "slide+slide-rock", 12: "rock+slide-rock", 13: "rock+slide-rock",
           14: "slide+rock+slide-rock", 15: "slide+rock+slide-rock"}


def test_regime_words_by_hand():
    for bits, word in BY_HAND.items():
        assert regime_word(bits) == word, bits
    assert len(REGIME_WORDS) == len(set(BY_HAND.values())) == 8
    idx = regime_index(np.array([2.0, 16, -1, np.nan, 2.5, 12]))
    assert [REGIME_WORDS[i] if i >= 0 else None for i in idx] == [
        "slide", None, None, None, None, "rock+slide-rock"]


MUS = [0.1, 0.3, 0.5]
AS = [0.5, 1.0, 2.0, 3.0]
# Shenton-like by hand (rows A ascending, columns mu ascending): low mu slides, high mu
# rocks, between both
REGIME = np.array([[1, 1, 1],
                   [3, 1, 1],
                   [3, 7, 5],
                   [11, 15, 13]], np.int64)
OUT = np.array([[0, 0, 0],
                [0, 0, 0],
                [0, 1, 0],
                [0, 2, 1]], np.int8)


def regime_sweep(tmp_path: Path) -> tuple[Path, xr.Dataset]:
    out = tmp_path / "regime.h5"
    ds = zero_sweep("name: shenton\nbody: {kind: block, alpha: 0.2, mu: [0.1, 0.3, 0.5]}\n"
                    "pulse: {shape: sine, w_over_p: 3, A_ratio: [0.5, 1.0, 2.0, 3.0]}\n", out)
    grid = xr.DataArray(REGIME, dims=("A_ratio", "mu"), coords={"A_ratio": AS, "mu": MUS})
    ds["regime"] = grid.transpose(*ds["outcome"].dims)
    ds["outcome"] = xr.DataArray(OUT, dims=("A_ratio", "mu")).transpose(*ds["outcome"].dims)
    status = np.zeros((4, 3), np.int32)
    status[0, 2] = L.STATUS_HORIZON
    ds["status"] = xr.DataArray(status, dims=("A_ratio", "mu")).transpose(
        *ds["outcome"].dims)
    return out, ds


def test_regime_map_colours_marks_and_legend(tmp_path):
    _, ds = regime_sweep(tmp_path)
    fig = ds.rocksweep.plot(x="body.mu", y="A_ratio", regime=True)
    ax = [a for a in fig.axes if a.get_visible()][0]
    mesh = [c for c in ax.collections if isinstance(c, QuadMesh)][0]
    drawn = np.asarray(mesh.get_array()).reshape(4, 3)
    # the mesh holds 1 + the word's index (0: not computed); the words by hand
    words = [[REGIME_WORDS[int(v) - 1] for v in row] for row in drawn]
    assert words == [["rest", "rest", "rest"], ["slide", "rest", "rest"],
                     ["slide", "slide+rock", "rock"],
                     ["slide+slide-rock", "slide+rock+slide-rock", "rock+slide-rock"]]
    # overturned: mode 1 at (mu 0.3, A 2) and (0.5, 3), mode 2 at (0.3, 3)
    marks = [c for c in ax.collections if isinstance(c, PathCollection)]
    pts = sorted(tuple(map(float, p)) for c in marks for p in c.get_offsets())
    assert pts == [(0.3, 2.0), (0.3, 3.0), (0.5, 3.0)]
    # the flagged point (mu 0.5, A 0.5) crossed
    crosses = [ln for ln in ax.lines if ln.get_marker() == "x"]
    assert [tuple(map(float, xy)) for ln in crosses for xy in ln.get_xydata()] == [(0.5, 0.5)]
    labels = [t.get_text() for lg in fig.legends for t in lg.get_texts()]
    # the words drawn (no run visited slide-rock alone), then the marks
    assert labels[:7] == ["rest", "slide", "rock", "slide+rock", "slide+slide-rock",
                          "rock+slide-rock", "slide+rock+slide-rock"]
    assert [lab.split(" ")[0] + " " + lab.split(" ")[1] for lab in labels[7:9]] == [
        "mode 1", "mode 2"]
    assert labels[9:] == ["flagged (horizon)"]


def test_regime_map_errors_are_one_line(tmp_path):
    _, ds = regime_sweep(tmp_path)
    cases = [
        (ds.drop_vars("regime"), {}, ["regime", "body.mu"]),
        (ds.assign(regime=ds["regime"] + 16), {}, ["regime holds", "0 to 15"]),
        (ds, {"mu": True}, ["mu=True", "regime=True"]),
        (ds, {"compare": "lam", "x": "mu"}, ["regime=True", "compare"]),
        (ds, {"curves": True}, ["regime=True", "curves=True"]),
    ]
    for d, kw, words in cases:
        with pytest.raises(errors.RocksweepError) as err:
            rocksweep.plot(d, regime=True, **kw)
        text = str(err.value)
        assert "\n" not in text and all(w in text for w in words), text
    with pytest.raises(TypeError):
        rocksweep.plot(ds, regime="yes")


def test_cli_plot_regime(tmp_path, cli):
    out, ds = regime_sweep(tmp_path)
    fig = tmp_path / "r.png"
    # a scene without body.mu has no regime (the sliding kernel writes it): one line,
    # nothing written
    no_mu = tmp_path / "no_mu.h5"
    zero_sweep("name: rigid\nbody: {kind: block, alpha: 0.2}\n"
               "pulse: {shape: sine, w_over_p: 3, A_ratio: [0.5, 1.0]}\n", no_mu)
    res = cli.invoke(main, ["plot", str(no_mu), "--regime", "-o", str(fig)])
    line = one_line_error(res)
    assert res.exit_code != 0 and "no regime" in line and "body.mu" in line
    assert not fig.exists()
    res = cli.invoke(main, ["plot", str(out), "--regime", "--mu", "-o", str(fig)])
    assert "--mu and --regime" in one_line_error(res) and not fig.exists()
    res = cli.invoke(main, ["plot", str(out), "--regime", "--compare", "lam", "-o", str(fig)])
    assert "--regime and --compare" in one_line_error(res) and not fig.exists()
