"""A folder suite's verticals act on the body (``ground.vertical: true|false``, default:
when the folder has UP files): each record run with its UP file equals the single-record
scene ``ground.record`` + ``ground.vertical`` of the same files at the same scale, and a
suite with the vertical switched off equals one without UP files."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import yaml
from helpers import one_line_error
from test_peer_folders import folder, scene

import rocksweep
from rocksweep.errors import SceneError
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.suite import RecordWarning
from rocksweep.scene.parse import parse_scene

# H1's peak set to these multiples of g tan(alpha); at 3.0 the second record's UP
# (5/3 of H1, factor 1.37) reaches -1 g: that run ends airborne
STRIPES = [1.5, 3.0]
RUN_VARS = ("outcome", "status", "impacts", "uplifts", "theta_max_over_alpha", "steps")


def run(spec: dict):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordWarning)
        return rocksweep.run(spec)


def suite_run(d, **ground):
    return run(scene(d, scale={"im": "PGA_ratio", "values": STRIPES}, **ground))


def single_runs(d, vertical: bool) -> dict[str, np.ndarray]:
    """Each record's H1 (and its UP) run as one record at A_ratio = the stripes:
    {variable: [record, stripe]}."""
    h1s = sorted(p for p in d.iterdir() if p.stem.endswith("000"))
    out: dict[str, list] = {k: [] for k in RUN_VARS}
    for h1 in h1s:
        g = {"record": str(h1), "A_ratio": STRIPES, "p": 2.0}
        if vertical:
            g["vertical"] = str(h1.with_name(h1.name.replace("000", "-UP")))
        ds = run({"body": scene(d)["body"], "ground": g})
        for k in RUN_VARS:
            out[k].append(ds[k].values)
    return {k: np.array(v) for k, v in out.items()}


def assert_same_runs(ds, want: dict[str, np.ndarray]) -> None:
    for k in RUN_VARS:
        got = ds[k].transpose("record", "PGA_ratio").values
        assert np.array_equal(got, want[k]), k


def test_suite_verticals_act_as_each_records_ground_vertical(tmp_path):
    d = folder(tmp_path, n=2)
    ds = suite_run(d)
    assert_same_runs(ds, single_runs(d, vertical=True))
    # the vertical changed the runs, and one ended airborne (a flagged status)
    off = single_runs(d, vertical=False)
    assert not np.array_equal(ds["theta_max_over_alpha"].values, off["theta_max_over_alpha"])
    status = ds["status"].values
    assert (status & L.STATUS_AIRBORNE).any() and not (off["status"] & L.STATUS_AIRBORNE).any()


def test_suite_with_the_vertical_off_equals_the_suite_without_up_files(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    with_up = folder(tmp_path / "a", n=2)
    without = folder(tmp_path / "b", n=2, up=False)
    ds = suite_run(with_up, vertical=False)
    base = suite_run(without)
    for k in RUN_VARS:
        assert np.array_equal(ds[k].values, base[k].values), k
    assert_same_runs(ds, single_runs(without, vertical=False))
    # the UP files still give the records' vertical IMs
    assert np.all(ds["record_pga_v"].values > 0)


def test_suite_vertical_keys_refused_in_one_line(tmp_path):
    d = folder(tmp_path, n=2, up=False)
    with pytest.raises(SceneError) as err:
        parse_scene(yaml.safe_dump(scene(d, vertical=True)))
    assert "ground.vertical = true" in str(err.value) and "no vertical (UP)" in str(err.value)
    with pytest.raises(SceneError) as err:
        parse_scene(yaml.safe_dump(scene(d, vertical="x-UP.AT2")))
    assert "with ground.records, true or false" in str(err.value)
    assert "\n" not in str(err.value)


def test_sweep_file_states_the_acting_verticals_and_resume_refuses_a_change(tmp_path, cli):
    from rocksweep.cli.main import main
    from rocksweep.scene.model import Scene
    from rocksweep.store.reader import read_result, result_scene

    d = folder(tmp_path, n=2)
    spec = scene(d, scale={"im": "PGA_ratio", "values": [1.5]})
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(spec))
    out = tmp_path / "out.h5"
    res = cli.invoke(main, ["sweep", str(path), "-o", str(out), "--quiet"])
    assert res.exit_code == 0, res.output
    sc: Scene = result_scene(read_result(out))
    assert sc.suite.vertical_acts and sc.ground == L.GROUND_VERTICAL
    spec["ground"]["vertical"] = False
    path.write_text(yaml.safe_dump(spec))
    line = one_line_error(cli.invoke(main, ["sweep", str(path), "-o", str(out), "--resume",
                                            "--quiet"]), 2)
    assert "ground.vertical" in line


def test_rotated_suite_carries_each_records_vertical(tmp_path):
    """With an angle axis (the excitation path) the body at angle 0 feels H1 alone and
    its record's vertical: the runs of the suite without the axis."""
    d = folder(tmp_path, n=2)
    ds = suite_run(d, angle=[0.0, 90.0])
    plain = suite_run(d)
    for k in RUN_VARS:
        assert np.array_equal(ds[k].sel(angle=0.0).values, plain[k].values), k


def test_up_file_at_another_dt_is_resampled_as_ground_vertical_is(tmp_path):
    """An UP file sampled at DT/2 is resampled onto H1's samples (not refused): the suite's
    runs are those of ``ground.record`` + ``ground.vertical`` of the same files."""
    from rocksweep.physics.records import read_record, write_at2

    d = folder(tmp_path, n=2)
    up = d / "RSN101_EVENT_STA-UP.AT2"
    r = read_record(up)
    fine = np.interp(np.arange(2 * r.npts - 1) * r.dt / 2, r.times(), r.acc)
    up.unlink()
    write_at2(up, 0.9 * fine, r.dt / 2, "RSN101")
    assert_same_runs(suite_run(d), single_runs(d, vertical=True))


def test_a_vertical_below_minus_g_at_the_start_is_refused(tmp_path):
    """A record's UP starting at -1 g, scaled by its factor (> 1 at this stripe), gives
    g + a_v <= 0 at t = 0: one line naming the file."""
    from rocksweep.physics.records import read_record, write_at2

    d = folder(tmp_path, n=2)
    up = d / "RSN100_EVENT_STA-UP.AT2"
    r = read_record(up)
    up.unlink()
    write_at2(up, np.where(np.arange(r.npts) == 0, -1.0, r.acc), r.dt, "RSN100")
    spec = yaml.safe_dump(scene(d, scale={"im": "PGA_ratio", "values": [3.0]}))
    with pytest.raises(SceneError) as err:
        parse_scene(spec)
    assert "RSN100_EVENT_STA-UP.AT2" in str(err.value) and "g + a_v <= 0" in str(err.value)
    assert "\n" not in str(err.value)
    # switched off, the same folder runs
    parse_scene(yaml.safe_dump(scene(d, scale={"im": "PGA_ratio", "values": [3.0]},
                                     vertical=False)))


def test_a_floor_suite_with_verticals_equals_each_records_floor_run_and_fits(tmp_path):
    """Under ``floor:`` each record's UP acts too (unfiltered, on the floor motion's
    samples): the suite equals the single-record floor runs of ``ground.record`` +
    ``ground.vertical``; and fragility reads such a file (airborne runs are flagged points,
    said by its verdict, not counted as safe)."""
    d = folder(tmp_path, n=2)
    building = {"period": 0.3, "damping": 0.05, "participation": 1.3}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordWarning)
        ds = rocksweep.run({**scene(d, scale={"im": "PGA_ratio", "values": STRIPES}),
                            "floor": building})
        h1s = sorted(p for p in d.iterdir() if p.stem.endswith("000"))
        want = {k: [] for k in RUN_VARS}
        for h1 in h1s:
            g = {"record": str(h1), "A_ratio": STRIPES, "p": 2.0,
                 "vertical": str(h1.with_name(h1.name.replace("000", "-UP")))}
            one = rocksweep.run({"body": scene(d)["body"], "ground": g, "floor": building})
            for k in RUN_VARS:
                want[k].append(one[k].values)
    assert_same_runs(ds, {k: np.array(v) for k, v in want.items()})
    assert (ds["floor_pfa"].values > 0).all()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fr = rocksweep.fragility(ds, bootstrap=0)
    assert (ds["status"].values & L.STATUS_AIRBORNE).any()  # the second record, at 3.0
    assert "flagged" in str(fr["reason"].values.ravel()[0]).split(",")
