"""Runs on a building's floor and at an orientation equal runs on the motion computed
independently and given as a record.

- ``floor:``: the floor motion by scipy.signal.lsim of the same building (its ring-down
  included, 40 s of it), written as a two-column record and scaled to the same ground:
  same outcome, max|theta|/alpha within 1%; a pulse scene with ``floor:`` likewise (the
  pulse sampled by lsim's own time grid from its closed form);
- ``ground.angle``: the pre-projected record a1 cos + a2 sin, written as a record;
- a sweep over ``floor.period`` stores it as a dimension of that name, ``floor_pfa`` [g]
  per run and the building in the attributes, and reopens from its file.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from bodies import FIG3
from scipy import signal

import rocksweep
from rocksweep.physics.records import read_record, write_at2

ROOT = Path(__file__).resolve().parents[2]
NEARFAULT = ROOT / "records" / "synthetic_nearfault.AT2"
BLOCK = {"kind": "block", "alpha": 0.2, "inertia": 4.0 / 3.0}
T, ZETA, GP = 0.6, 0.05, 1.3


def lsim_floor_record(t, ground, path: Path) -> float:
    """Write the floor motion of the one-mode building under ``ground`` (samples at t) as
    a two-column record; return its peak."""
    w = 2 * math.pi / T
    sys = ([[0, 1], [-w * w, -2 * ZETA * w]], [[0], [-1]],
           [[-GP * w * w, -GP * 2 * ZETA * w]], [[1 - GP]])
    y = signal.lsim(sys, ground, t)[1]
    np.savetxt(path, np.c_[t, y])
    return float(np.max(np.abs(y)))


def same_run(a, b) -> None:
    assert a.summary["outcome"] == b.summary["outcome"]
    ta, tb = a.summary["theta_max_over_alpha"], b.summary["theta_max_over_alpha"]
    assert ta == pytest.approx(tb, rel=0.01, abs=1e-6)


@pytest.mark.parametrize(("body", "A_ratio"), [(BLOCK, 1.0), (BLOCK, 3.0), (FIG3, 1.5)])
def test_a_floor_run_is_the_run_on_the_lsim_floor_record(tmp_path, body, A_ratio):
    rec = read_record(NEARFAULT)
    t = np.arange(rec.npts + int(40.0 / rec.dt)) * rec.dt  # the record, then 40 s at rest
    ground = np.interp(t, rec.times(), rec.acc, right=0.0)
    peak = lsim_floor_record(t, ground, tmp_path / "floor.txt")
    impact = {} if body is BLOCK else {"impact": {"lam": 0.0}}
    on_floor = rocksweep.simulate({"body": body, **impact, "ground": {
        "record": str(NEARFAULT), "A_ratio": A_ratio, "p": 2.0},
        "floor": {"period": T, "damping": ZETA, "participation": GP}})
    given = rocksweep.simulate({"body": body, **impact, "ground": {
        "record": str(tmp_path / "floor.txt"), "A_ratio": A_ratio * peak / rec.pga,
        "p": 2.0}})
    same_run(on_floor, given)
    assert on_floor.summary["theta_max_over_alpha"] > 0.01  # it rocked: a real comparison


def test_a_pulse_on_a_floor_is_the_run_on_lsim_of_the_pulse(tmp_path):
    w = 2.0  # w_over_p, p = 1 rad/s: the pulse lasts pi s
    t = np.arange(int(50.0 / 1e-3)) * 1e-3
    ground = np.where(t <= 2 * math.pi / w, np.sin(w * t), 0.0)
    peak = lsim_floor_record(t, ground, tmp_path / "floor.txt")
    on_floor = rocksweep.simulate({"body": BLOCK, "pulse": {
        "shape": "sine", "w_over_p": w, "A_ratio": 1.4},
        "floor": {"period": T, "damping": ZETA, "participation": GP}})
    given = rocksweep.simulate({"body": BLOCK, "ground": {
        "record": str(tmp_path / "floor.txt"), "A_ratio": 1.4 * peak, "p": 1.0}})
    same_run(on_floor, given)
    assert on_floor.summary["theta_max_over_alpha"] > 0.01


@pytest.mark.parametrize("angle", [30.0, 135.0])
def test_a_run_at_an_angle_is_the_run_on_the_projected_record(tmp_path, angle):
    rec = read_record(NEARFAULT)
    a2 = 0.8 * np.roll(rec.acc, 300)
    write_at2(tmp_path / "h2.AT2", a2, rec.dt, "second component")
    th = math.radians(angle)
    write_at2(tmp_path / "proj.AT2", rec.acc * math.cos(th) + a2 * math.sin(th), rec.dt,
              "projected")
    proj = read_record(tmp_path / "proj.AT2")
    for A in (1.5, 2.5):
        at_angle = rocksweep.simulate({"body": BLOCK, "ground": {
            "record": str(NEARFAULT), "h2": str(tmp_path / "h2.AT2"), "angle": angle,
            "A_ratio": A, "p": 2.0}})
        given = rocksweep.simulate({"body": BLOCK, "ground": {
            "record": str(tmp_path / "proj.AT2"), "A_ratio": A * proj.pga / rec.pga,
            "p": 2.0}})
        same_run(at_angle, given)


def test_a_floor_sweep_names_its_axes_and_stores_the_building(tmp_path):
    rec = read_record(NEARFAULT)
    write_at2(tmp_path / "h2.AT2", 0.8 * np.roll(rec.acc, 300), rec.dt, "h2")
    scene = {"body": BLOCK, "ground": {"record": str(NEARFAULT),
                                       "h2": str(tmp_path / "h2.AT2"),
                                       "angle": [0.0, 90.0], "A_ratio": [1.0, 2.0],
                                       "p": [2.0, 3.0]},
             "floor": {"period": [0.3, 0.6], "damping": ZETA, "participation": GP}}
    ds = rocksweep.run(scene, output=tmp_path / "f.h5")
    assert ds["outcome"].dims == ("angle", "floor.period", "A_ratio", "p")
    assert ds["floor_pfa"].attrs["units"] == "g"
    assert "one mode" in ds.attrs["floor"] and "cascade" in ds.attrs["floor"]
    # the peak the body felt is A_ratio g tan(alpha) times the floor's gain over the ground
    pfa = ds["floor_pfa"].values
    assert np.allclose(pfa[:, :, 1], 2.0 * pfa[:, :, 0])
    assert np.all(pfa > 0.0)
    back = rocksweep.open(tmp_path / "f.h5")
    assert (back["outcome"].values == ds["outcome"].values).all()
    # the analyses rebuild the scene (ground.h2 read again): A_min reruns its points
    bd = rocksweep.boundaries(back, rtol=0.05, search=False)
    assert "floor.period" in bd["A_min"].dims and "angle" in bd["A_min"].dims


def test_spectra_run_over_the_new_axes(tmp_path):
    """A record sweep over p, A_ratio and the floor's period: one spectrum per period,
    each the spectrum of that period's own sweep (its A_min equal, bisected alike)."""
    scene = {"body": BLOCK, "ground": {"record": str(NEARFAULT), "A_ratio": [1.0, 2.0, 4.0],
                                       "p": [2.0, 3.0]},
             "floor": {"period": [0.3, 0.6], "damping": ZETA, "participation": GP}}
    ds = rocksweep.run(scene, output=tmp_path / "f.h5")
    sp = rocksweep.spectra(ds, rtol=0.05, search=False)
    assert sp["A_min"].dims == ("floor.period", "lam", "p")
    one = rocksweep.run({**scene, "floor": {**scene["floor"], "period": 0.6}},
                        output=tmp_path / "one.h5")
    sp1 = rocksweep.spectra(one, rtol=0.05, search=False)
    assert np.array_equal(sp["A_min"].sel({"floor.period": 0.6}).values,
                          sp1["A_min"].values, equal_nan=True)
    assert rocksweep.plot(sp) is not None


def test_the_vertical_reaches_the_floor_unfiltered(tmp_path):
    """ground.vertical with a floor: the run equals the run on the lsim floor record with
    the same vertical component (resampled onto its samples, at rest after its end)."""
    rec = read_record(NEARFAULT)
    write_at2(tmp_path / "up.AT2", 0.4 * np.roll(rec.acc, 200), rec.dt, "vertical")
    t = np.arange(rec.npts + int(40.0 / rec.dt)) * rec.dt
    ground = np.interp(t, rec.times(), rec.acc, right=0.0)
    peak = lsim_floor_record(t, ground, tmp_path / "floor.txt")
    up = str(tmp_path / "up.AT2")
    on_floor = rocksweep.simulate({"body": BLOCK, "ground": {
        "record": str(NEARFAULT), "vertical": up, "A_ratio": 1.5, "p": 2.0},
        "floor": {"period": T, "damping": ZETA, "participation": GP}})
    given = rocksweep.simulate({"body": BLOCK, "ground": {
        "record": str(tmp_path / "floor.txt"), "vertical": up,
        "A_ratio": 1.5 * peak / rec.pga, "p": 2.0}})
    same_run(on_floor, given)
    without = rocksweep.simulate({"body": BLOCK, "ground": {
        "record": str(NEARFAULT), "A_ratio": 1.5, "p": 2.0},
        "floor": {"period": T, "damping": ZETA, "participation": GP}})
    assert without.summary["theta_max_over_alpha"] != on_floor.summary["theta_max_over_alpha"]


def test_a_single_run_states_its_floor_pfa_as_the_sweep_stores_it(tmp_path):
    scene = {"body": BLOCK, "ground": {"record": str(NEARFAULT), "A_ratio": 1.5, "p": 2.0},
             "floor": {"period": T, "damping": ZETA, "participation": GP}}
    one = rocksweep.simulate(scene)
    ds = rocksweep.run(scene)
    assert one.summary["floor_pfa"] == pytest.approx(float(ds["floor_pfa"]), rel=1e-12)
    # the ground's peak is A_ratio g tan(alpha) = 1.5 tan(0.2) g; this building amplifies it
    assert one.summary["floor_pfa"] > 1.5 * math.tan(0.2)
    assert "floor_pfa" not in rocksweep.simulate({**scene, "floor": None}).summary


MODE = {"period": T, "damping": ZETA, "participation": GP}
SECOND = {"period": 0.15, "damping": 0.03, "participation": -0.4}


@pytest.mark.parametrize("motion", [
    {"ground": {"record": str(NEARFAULT), "A_ratio": [1.0, 2.5], "p": [2.0, 3.0]}},
    {"pulse": {"shape": "sine", "w_over_p": [1.5, 3.0], "A_ratio": [1.0, 2.5]}},
], ids=["record", "pulse"])
def test_a_list_of_modes_sweeps_without_an_angle(tmp_path, motion):
    """``floor: {modes: [...]}`` (one mode or two) under one record or a pulse, no angle
    axis: the sweep completes (issue 45: a worker's ValueError, an INCOMPLETE file); one
    mode in the list is the one-mode keys' building, bit for bit; two modes are each
    point's single run."""
    one = rocksweep.run({"body": BLOCK, **motion, "floor": {"modes": [MODE]}},
                        output=tmp_path / "one.h5")
    keys = rocksweep.run({"body": BLOCK, **motion, "floor": MODE})
    assert one.attrs["complete"] == 1
    for k in ("outcome", "theta_max_over_alpha", "floor_pfa"):
        assert np.array_equal(one[k].values, keys[k].values, equal_nan=True), k
    assert (one["outcome"].values > 0).any()  # some overturn: a real comparison
    two = rocksweep.run({"body": BLOCK, **motion, "floor": {"modes": [MODE, SECOND]}},
                        output=tmp_path / "two.h5")
    assert two.attrs["complete"] == 1
    assert not np.array_equal(two["floor_pfa"].values, one["floor_pfa"].values)
    singles = rocksweep.simulate({"body": BLOCK, **motion,
                                  "floor": {"modes": [MODE, SECOND]}})  # in grid order
    words = {0: "safe", 1: "mode1", 2: "mode2"}
    for run, code, pfa in zip(singles, two["outcome"].values.ravel(),
                              two["floor_pfa"].values.ravel(), strict=True):
        assert run.summary["outcome"] == words[int(code)]
        assert run.summary["floor_pfa"] == pfa  # the one definition, bit for bit


def test_felt_motion_is_what_the_kernel_runs(tmp_path):
    """rocksweep.felt_motion (issue 45: a public way to the motion the body feels): the
    samples after the angle and the floor, scaled as the point runs, equal the ground
    acceleration the kernel recorded in its history at every row (linear between
    samples), up to the record's end; the ground's H1 at the same scale has the point's
    peak A_ratio g tan(alpha)."""
    from rocksweep.errors import RocksweepError

    rec = ROOT / "records" / "suite"
    scene = {"name": "felt", "body": {"kind": "block", "alpha": 0.2},
             "impact": {"lam": 0.0},
             "ground": {"record": str(rec / "SYN01.AT2"), "h2": str(rec / "SYN02.AT2"),
                        "angle": 30.0, "A_ratio": 0.8, "p": 2.0},
             "floor": {"period": 0.5, "damping": 0.05, "participation": 1.3}}
    ds = rocksweep.felt_motion(scene)
    h = rocksweep.simulate(scene).history
    t = h.p_t.values / 2.0
    inside = t < ds.t.values[-1]
    felt = np.interp(t[inside], ds.t.values, ds.a_h.values)
    assert np.max(np.abs(felt - h.xg_over_g.values[inside])) < 1e-9 * np.max(np.abs(felt))
    assert np.max(np.abs(ds.a_ground.values)) == pytest.approx(0.8 * math.tan(0.2), rel=1e-6)
    with pytest.raises(RocksweepError, match="2 points"):
        rocksweep.felt_motion(scene, {"ground.angle": [0, 90]})
