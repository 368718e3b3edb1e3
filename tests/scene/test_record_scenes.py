"""Recorded ground motions in scenes and in the kernel.

- records/sine_1cycle.AT2 (one cycle of 1 g sin(2 pi t / 0.5 s), DT = 1e-4 s) with
  p = 4 pi / w_over_p is the `sine` pulse of that w_over_p: outcomes, impacts and
  overturning times agree to the interpolation error (~1e-7 p*t) at converged numerics
  (320 steps per period: at `fine` the pulse's own time error after 3 impacts is 1e-3);
- in full contact the flexible body's top mass is a linear oscillator,
  u'' + 2 zeta wn u' + wn^2 u = -xg'': under the synthetic record (piecewise linear
  between samples) the kernel's u at the sample times equals scipy.signal.lsim's (exact
  for a piecewise-linear input, linear interpolation) on the same samples;
- the kernel's steps land on every sample time while the record acts;
- scene errors (both sections, a bad record) are one line; a record sweep runs end to end
  through the CLI, stores the record's attributes and refuses to resume with another
  record; `rocksweep plot` draws its (p, A_ratio) diagram.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from bodies import FIG3, FIG3_YAML
from scipy import signal

from rocksweep.compute.single import run_point
from rocksweep.errors import SceneError
from rocksweep.kernel import layout as L
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import FlexibleBody
from rocksweep.physics.ground_motion import recorded
from rocksweep.physics.points import Point
from rocksweep.physics.records import read_record
from rocksweep.scene.parse import load_scene, parse_scene
from rocksweep.vocab.ground import RECORD

ROOT = Path(__file__).resolve().parents[2]
SINE = ROOT / "records" / "sine_1cycle.AT2"
NEARFAULT = ROOT / "records" / "synthetic_nearfault.AT2"


@pytest.mark.parametrize("lam, w_over_p, A_ratio", [
    (0.4, 5.3, 5.0),   # Figure 5: overturns after 3 impacts
    (0.0, 5.3, 5.0),   # survives
    (0.0, 2.0, 3.0),
    (0.2, 1.0, 1.5),
])
def test_sine_record_is_the_sine_pulse(lam, w_over_p, A_ratio):
    body = FlexibleBody(**FIG3)
    rec = read_record(SINE)
    fine = Numerics.preset("fine", steps_per_period=320, event_tol=1e-10)
    pulse = run_point(Point(body, lam, "sine", w_over_p, A_ratio), fine, history=False)
    record = run_point(Point(body, lam, recorded(rec), math.nan, A_ratio,
                             p=4 * math.pi / w_over_p), fine, history=False)
    assert record.outcome == pulse.outcome
    assert record.impacts == pulse.impacts and record.uplifts == pulse.uplifts
    if pulse.t_overturn is not None:
        assert record.t_overturn == pytest.approx(pulse.t_overturn, abs=1e-6)
    assert record.get("t_first_impact") == pytest.approx(pulse.get("t_first_impact"),
                                                         abs=1e-6, nan_ok=True)
    assert record.theta_max_over_alpha == pytest.approx(pulse.theta_max_over_alpha, rel=1e-6)


def test_the_overturning_point_is_among_them():
    body = FlexibleBody(**FIG3)
    run = run_point(Point(body, 0.4, "sine", 5.3, 5.0), Numerics.preset("fine"), history=False)
    assert run.outcome == "mode1"  # the comparison above covers an overturning point


def test_full_contact_response_is_lsim_of_the_record():
    body = FlexibleBody(**FIG3)
    rec = read_record(NEARFAULT)
    p, A_ratio = 2.0, 0.05  # far below uplift: the base never leaves the ground
    pt = Point(body, 0.0, recorded(rec), math.nan, A_ratio, p=p)
    run = run_point(pt, Numerics.preset("fine"))
    assert run.uplifts == 0
    h = run.history
    dt_k = p * rec.dt
    t_rec = np.arange(rec.npts) * dt_k
    on_grid = np.isclose(h["t"] / dt_k, np.round(h["t"] / dt_k), rtol=0, atol=1e-9)
    on_grid &= h["t"] <= t_rec[-1] * (1 + 1e-12)
    idx = np.round(h["t"][on_grid] / dt_k).astype(int)
    assert np.array_equal(np.unique(idx), np.arange(rec.npts))  # a step on every sample
    wn, zeta = body.omega_n, body.zeta  # p = 1 in the kernel: omega_n = wn_over_p
    xg = pt.A * rec.acc / rec.pga
    sys = signal.lti([-1.0], [1.0, 2 * zeta * wn, wn * wn])
    _, u_ref, _ = signal.lsim(sys, xg, t_rec, interp=True)
    u = h["u"][on_grid]
    scale = np.max(np.abs(u_ref))
    assert scale > 0
    np.testing.assert_allclose(u, u_ref[idx], atol=1e-6 * scale)


SCENE = """
name: record test
""" + FIG3_YAML + """impact: {lam: [0.0, 0.4]}
ground:
  record: %s
  A_ratio: {start: 1.0, stop: 6.0, num: 3}
  p: {start: 1.0, stop: 4.0, num: 3}
"""


def test_scene_errors_are_one_line(tmp_path):
    both = SCENE % "x.AT2" + "pulse: {shape: sine, w_over_p: 1, A_ratio: 1}\n"
    with pytest.raises(SceneError, match="pulse, ground: give one of them"):
        parse_scene(both)
    with pytest.raises(SceneError, match=r"ground.record: .*missing.AT2: no such record file"):
        parse_scene(SCENE % "missing.AT2", base=tmp_path)
    bad = tmp_path / "bad.AT2"
    bad.write_text("a\nb\nc\nNPTS= 3, DT= .01 SEC\n1 2\n")
    with pytest.raises(SceneError, match=r"bad.AT2, line 5: the file ends after 2 values"):
        parse_scene(SCENE % "bad.AT2", base=tmp_path)
    with pytest.raises(SceneError, match=r"ground.p = 0.0: must be in \[1e-3, 1000\] rad/s"):
        parse_scene((SCENE % str(NEARFAULT)).replace("start: 1.0, stop: 4.0", "start: 0.0, "
                                                                               "stop: 4.0"))


def test_record_path_is_relative_to_the_scene_file(tmp_path):
    (tmp_path / "records").mkdir()
    shutil.copy(NEARFAULT, tmp_path / "records" / NEARFAULT.name)
    scene = tmp_path / "s.yaml"
    scene.write_text(SCENE % f"records/{NEARFAULT.name}")
    sc = load_scene(scene)
    assert sc.record.sha256 == read_record(NEARFAULT).sha256
    assert [a.name for a in sc.swept] == ["lam", "A_ratio", "p"]


def test_record_sweep_end_to_end(tmp_path, cli):
    from rocksweep.cli.main import main

    (tmp_path / "records").mkdir()
    shutil.copy(NEARFAULT, tmp_path / "records" / NEARFAULT.name)
    scene = tmp_path / "s.yaml"
    scene.write_text(SCENE % f"records/{NEARFAULT.name}")
    out = tmp_path / "r.h5"
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    rec = read_record(NEARFAULT)
    with h5py.File(out) as f:
        assert f.attrs["record_sha256"] == rec.sha256
        assert f.attrs["record_npts"] == rec.npts == 5001
        assert f.attrs["record_dt"] == rec.dt and f.attrs["record_pga"] == rec.pga
        assert f.attrs["record_name"] == "synthetic_nearfault"
        outcome = f["outcome"][...]
        assert outcome.shape == (2, 3, 3) and (outcome >= 0).all()
        assert list(f["p"][...]) == [1.0, 2.5, 4.0]
    assert (outcome > 0).any() and (outcome == 0).any()  # both classes on this grid
    res = cli.invoke(main, ["plot", str(out), "-o", str(tmp_path / "r.png")])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "r.png").stat().st_size > 10_000
    # spectra: the bisected A_min lies in its grid bracket, overturns there (hi), and the
    # bracket's low end does not; to rtol
    res = cli.invoke(main, ["spectrum", str(out), "-o", str(tmp_path / "s.png"),
                            "--rtol", "1e-2"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "s.png").stat().st_size > 10_000
    from rocksweep.analysis.boundaries import kernel_evaluator
    from rocksweep.analysis.spectrum import spectra
    from rocksweep.store.reader import read_result, result_scene

    sp = spectra(out, rtol=1e-2)
    assert sp.freq == "p" and sp.lam.tolist() == [0.0, 0.4] and sp.runs > 0
    rebuilt = result_scene(read_result(out, ["outcome"]))
    evaluate = kernel_evaluator(rebuilt)
    checked = 0
    for lam, c in zip(sp.lam, sp.a_min, strict=True):
        for j in np.flatnonzero(np.isfinite(c.lo)):
            assert c.hi[j] - c.lo[j] <= 1e-2 * c.hi[j]
            pts = [rebuilt.point({**FIG3,
                                "lam": lam, "shape": RECORD, "p": c.x[j], "A_ratio": a})
                   for a in (c.lo[j], c.hi[j])]
            lo_cls, hi_cls = evaluate(pts)
            assert lo_cls == 0 and hi_cls == c.mode[j] > 0
            checked += 1
    assert checked > 0
    # another record under the same name: resume refuses
    data = (tmp_path / "records" / NEARFAULT.name).read_text().replace(".1", ".2", 1)
    (tmp_path / "records" / NEARFAULT.name).write_text(data)
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "--resume", "--quiet"])
    assert res.exit_code == 2
    assert "ground.record: file synthetic_nearfault (sha256" in res.output


def test_reference_path_runs_records_sample_by_sample():
    """The scipy reference integrates a record interval by interval: the sine record and
    the sine pulse give the same overturning time (interpolation error ~1e-7)."""
    from rocksweep.physics.reference import reference_run

    body = FlexibleBody(**FIG3)
    rec = read_record(SINE)
    a = reference_run(Point(body, 0.4, "sine", 5.3, 5.0))
    b = reference_run(Point(body, 0.4, recorded(rec), math.nan, 5.0, p=4 * math.pi / 5.3))
    assert a["outcome"] == b["outcome"] == L.OUTCOME_MODE1
    assert a["impacts"] == b["impacts"] and b["anomalies"] == 0
    assert b["t_overturn"] == pytest.approx(a["t_overturn"], abs=1e-6)
