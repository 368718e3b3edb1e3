"""Scenes with a vertical ground acceleration (docs/vertical.md): the keys, the swept
harmonic's dimensions, the record's vertical resampled onto the horizontal's samples, the
bad inputs refused in one line with nothing written, a sweep's file keeping the vertical."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import one_line_error

from rocksweep.errors import SceneError
from rocksweep.kernel import layout as L
from rocksweep.scene.parse import parse_scene

BLOCK = "body: {kind: block, alpha: 0.2}\n"


def _write(path, t, a):
    np.savetxt(path, np.c_[t, a])
    return path


@pytest.fixture()
def files(tmp_path):
    t = np.arange(0.0, 2.0 + 0.005, 0.01)
    _write(tmp_path / "h.txt", t, np.where(t <= 1.0, 0.3 * np.sin(2 * np.pi * t), 0.0))
    _write(tmp_path / "v.txt", t, 0.4 * np.sin(6 * np.pi * t))
    tf = np.arange(0.0, 1.5 + 0.0025, 0.005)  # another DT, shorter, linear: exact
    _write(tmp_path / "v_fine.txt", tf, 0.1 - 0.2 * tf)
    _write(tmp_path / "v_down.txt", t, np.full(t.size, -0.6))
    return tmp_path


def test_pulse_vertical_axes_and_variant():
    sc = parse_scene(BLOCK + "pulse: {shape: sine, w_over_p: 3.0, A_ratio: 1.5, vertical: "
                     "{amplitude: [0.2, 0.5], w_over_p: 9.0}}")
    assert sc.ground == L.GROUND_VERTICAL and sc.has_vertical
    assert [a.name for a in sc.swept] == ["vertical.amplitude"]
    assert sc.axis("vertical.phase").values == (0.0,)
    p = sc.point({a.name: a.values[-1] for a in sc.axes})
    assert (p.excitation.harmonic.amplitude, p.excitation.harmonic.w_over_p) == (0.5, 9.0)


def test_record_vertical_with_another_dt_is_resampled(files):
    sc = parse_scene(BLOCK + "ground: {record: h.txt, vertical: v_fine.txt, A_ratio: 1.0, "
                     "p: 2.0}", base=files)
    v = sc.excitation({}).vertical_acc
    t = sc.record.times()
    assert v.shape == (sc.record.npts,)
    np.testing.assert_allclose(v, np.where(t <= 1.5 + 1e-9, 0.1 - 0.2 * t, 0.0), atol=1e-9)
    assert str(files / "v_fine.txt") in sc.inputs


@pytest.mark.parametrize("ground, message", [
    ("pulse: {shape: sine, w_over_p: 3.0, A_ratio: 1.5, vertical: {amplitude: [0.5, 1.2], "
     "w_over_p: 9.0, phase: -90}}",
     "pulse.vertical.amplitude = 1.2: with pulse.vertical.phase = -90.0 deg, a_v = -1.2 g at "
     "t = 0"),
    ("pulse: {shape: sine, w_over_p: 3.0, A_ratio: 1.5, vertical: {w_over_p: 9.0}}",
     "pulse.vertical.amplitude: missing required key"),
    ("pulse: {shape: sine, w_over_p: 3.0, A_ratio: 1.5, vertical: {amplitude: 0.3, "
     "w_over_p: 9.0, period: 2}}", "pulse.vertical.period: unknown key"),
    ("pulse: {shape: sine, w_over_p: 3.0, A_ratio: 1.5, vertical: {amplitude: 0.3, "
     "w_over_p: -1}}", "pulse.vertical.w_over_p = -1.0: must be >= 0"),
    ("ground: {record: h.txt, vertical: v_down.txt, A_ratio: [1.0, 8.0], p: 2.0}",
     "ground.vertical = "),
    ("ground: {records: [h.txt], vertical: v.txt, p: 2.0}",
     "ground.vertical = 'v.txt': with ground.records, true or false"),
])
def test_bad_vertical_is_one_line(files, ground, message):
    with pytest.raises(SceneError) as err:
        parse_scene(BLOCK + ground, base=files)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_cli_refuses_a_falling_start_and_writes_nothing(cli, files):
    from rocksweep.cli.main import main

    scene = files / "s.yaml"
    scene.write_text(BLOCK + "ground: {record: h.txt, vertical: v_down.txt, A_ratio: 8.0, "
                     "p: 2.0}\n")
    out = files / "out.h5"
    line = one_line_error(cli.invoke(main, ["sweep", str(scene), "-o", str(out)]), 2)
    assert "ground.vertical" in line and "must be > -1 g" in line
    assert not out.exists()


def test_record_vertical_sweep_keeps_the_vertical(cli, files):
    import h5py

    from rocksweep.cli.main import main
    from rocksweep.store.reader import read_result, result_scene

    scene = files / "s.yaml"
    scene.write_text(BLOCK + "ground: {record: h.txt, vertical: v.txt, A_ratio: [1.0, 2.5], "
                     "p: 2.0}\n")
    out = files / "out.h5"
    res = cli.invoke(main, ["sweep", str(scene), "-o", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    with h5py.File(out) as f:
        assert f.attrs["vertical_PGA_v"] == pytest.approx(0.4, rel=1e-6)
        assert f.attrs["vertical_VH_ratio"] == pytest.approx(0.4 / 0.3, rel=1e-6)
    # info says whether the verticals acted (issue 45), a folder's UP files kept off too
    from types import SimpleNamespace

    from rocksweep.analysis.summary import format_info, info_dict, read_info, vertical_info

    said = [ln for ln in format_info(info_dict(read_info(out))) if ln.startswith("vertical")]
    assert said == ["vertical ground acceleration: acted: ground.vertical v (PGA_v 0.4 g as "
                    "recorded, scaled with the record), the kernel's vertical variant"]
    up = {"suite": {"vertical": [{"name": "RSN1-UP"}], "vertical_acts": False}}
    assert vertical_info(SimpleNamespace(scene=up))["acted"] is False
    up["suite"]["vertical_acts"] = True
    assert vertical_info(SimpleNamespace(scene=up))["acted"] is True
    assert not vertical_info(SimpleNamespace(scene={"axes": {}}))["acted"]
    (files / "v.txt").unlink()  # the file's own copy rebuilds the scene
    sc = result_scene(read_result(out))
    assert sc.vertical is not None and sc.ground == L.GROUND_VERTICAL


@pytest.mark.parametrize("c, A_ratio, uplifts", [
    (0.5, 1.45, False), (0.5, 1.55, True), (-0.5, 0.45, False), (-0.5, 0.55, True)])
def test_a_constant_vertical_moves_a_blocks_uplift_threshold_to_one_plus_c(c, A_ratio, uplifts):
    """``w_over_p: 0`` is a constant a_v = a g sin(phase) while the pulse acts: a rigid
    block then uplifts where |a_h| > (g + a_v) tan alpha, i.e. above A_ratio = 1 + c (a
    sine pulse's peak is A)."""
    import rocksweep

    sim = rocksweep.simulate(BLOCK + f"impact: {{lam: 0.0}}\npulse: {{shape: sine, "
                             f"w_over_p: 3.0, A_ratio: {A_ratio}, vertical: {{amplitude: {c}, "
                             "w_over_p: 0, phase: 90}}")
    assert (sim.summary["uplifts"] > 0) == uplifts, sim.summary
