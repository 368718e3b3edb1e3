"""``rocksweep accuracy``: sampling, bookkeeping, and the command end to end."""

from pathlib import Path

import h5py
import numpy as np
import pytest
from bodies import FIG3_YAML

from rocksweep.analysis.accuracy import (
    Sample,
    _agreement,
    _allocate,
    boundary_mask,
    flip_matrix,
    ladder,
    stratified_sample,
)
from rocksweep.cli.main import main
from rocksweep.kernel import layout as L  # noqa: N812

SCENE = """\
name: tiny accuracy scene
""" + FIG3_YAML + """impact: {lam: 0.2}
pulse: {shape: sine, w_over_p: [2.0, 5.3], A_ratio: [1.5, 3.0, 5.0]}
"""


def test_boundary_mask_marks_both_sides_of_a_change_along_the_diagram_axes():
    outcome = np.array([[0, 0, 1],
                        [0, 0, 0],
                        [2, 0, 0]])
    mask = boundary_mask(outcome, ("A_ratio", "w_over_p"))
    assert mask.tolist() == [[False, True, True],
                             [True, False, True],
                             [True, True, False]]
    # lam is not a diagram axis: a change along it alone marks nothing
    assert not boundary_mask(np.array([[0], [1]]), ("lam", "w_over_p")).any()


def test_allocate_is_equal_up_to_the_stratum_sizes():
    assert _allocate([100, 100, 100], 9) == [3, 3, 3]
    assert _allocate([1, 100, 100], 9) == [1, 4, 4]
    assert _allocate([2, 3], 10) == [2, 3]
    assert sum(_allocate([5, 7, 50, 0], 30)) == 30


def test_stratified_sample_covers_every_outcome_and_its_weights_count_the_scene():
    rng = np.random.default_rng(1)
    outcome = rng.choice([0, 0, 0, 0, 1, 2], size=(40, 50))
    outcome[:3, :3] = 2  # a small island
    bnd = boundary_mask(outcome, ("A_ratio", "w_over_p"))
    flat, stratum, weight, names, sizes = stratified_sample(outcome.ravel(), bnd.ravel(), 60)
    assert len(flat) == 60 and len(np.unique(flat)) == 60
    assert sizes.sum() == outcome.size
    assert set(outcome.ravel()[flat]) == {0, 1, 2}
    assert len(set(stratum)) == len(names)  # every stratum is sampled
    assert weight.sum() == pytest.approx(outcome.size)
    for h, name in enumerate(names):  # each point sits in the stratum it is named after
        word, part = name.split("/")
        sel = flat[stratum == h]
        assert np.all(bnd.ravel()[sel] == (part == "boundary"))
        assert np.all(outcome.ravel()[sel] == ("safe", "mode1", "mode2").index(word))
    again = stratified_sample(outcome.ravel(), bnd.ravel(), 60)
    assert np.array_equal(again[0], flat)  # the seed fixes the sample


def test_agreement_is_the_stratum_weighted_share():
    # stratum 0: 10 points in the scene, 2 sampled, 1 agrees; stratum 1: 90 points, all agree
    sample = Sample(np.arange(4), np.array([0, 0, 1, 1]), np.array([5, 5, 45, 45.0]),
                    ["a", "b"], np.array([10, 90]), 100, np.zeros(100, np.int8), 0.0)
    share, se = _agreement(np.array([True, False, True, True]), sample)
    assert share == pytest.approx(0.1 * 0.5 + 0.9 * 1.0)
    assert se == pytest.approx(0.1 * np.sqrt(0.25 / 1 * (1 - 2 / 10)))


def test_flip_matrix_counts_reference_to_kernel():
    m = flip_matrix(np.array([0, 1, 1, 2, 0]), np.array([0, 0, 1, 2, 2]))
    assert m[0, 1] == 1 and m[2, 0] == 1 and np.trace(m) == 3 and m.sum() == 5


@pytest.fixture()
def tiny_scene(tmp_path):
    path = tmp_path / "tiny.yaml"
    path.write_text(SCENE)
    return path


def test_accuracy_runs_end_to_end_and_writes_its_table_and_plot(cli, tiny_scene, tmp_path):
    report, fig = tmp_path / "report.h5", tmp_path / "wp.png"
    res = cli.invoke(main, ["accuracy", str(tiny_scene), "-o", str(report), "--plot", str(fig),
                            "--points", "4", "--ladder", "short", "--repeat", "1", "-q"])
    assert res.exit_code == 0, res.output
    settings = ladder("short")
    for s in settings:
        assert f" {s.name} " in res.output
    assert "stratified sample of 4 of 6 points" in res.output
    with h5py.File(report) as f:
        names = [n.decode() if isinstance(n, bytes) else n for n in f["table/setting"][:]]
        assert names == [s.name for s in settings]
        agree = dict(zip(names, f["table/agreement"][:], strict=True))
        assert all(0.0 <= a <= 1.0 for a in agree.values())
        assert agree["fine"] == 1.0  # the fine preset classifies like the reference
        assert f["flips"].shape == (len(settings), 3, 3)
        assert f["sample/flat_index"].shape == (4,)
        assert f["reference/anomalies"][:].sum() == 0
        assert np.all(np.isfinite(f["table/median_us"][:]))
        assert f.attrs["command"].startswith("rocksweep accuracy")
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and fig.stat().st_size > 20_000


def test_accuracy_takes_every_point_of_a_small_scene(cli, tiny_scene):
    res = cli.invoke(main, ["accuracy", str(tiny_scene), "--points", "50", "--ladder", "short",
                            "--repeat", "1", "-q"])
    assert res.exit_code == 0, res.output
    assert "every point" in res.output and "all 6/6" in res.output


def test_accuracy_rejects_bad_input_in_one_line_without_output(cli, tiny_scene, tmp_path):
    res = cli.invoke(main, ["accuracy", str(tiny_scene), "--points", "0"])
    assert res.exit_code != 0 and "--points" in res.output and "Traceback" not in res.output
    missing = tmp_path / "nowhere" / "r.h5"
    res = cli.invoke(main, ["accuracy", str(tiny_scene), "-o", str(missing)])
    assert res.exit_code != 0
    assert res.output.strip().count("\n") == 0 and "does not exist" in res.output
    assert not missing.exists()
    res = cli.invoke(main, ["accuracy", str(tmp_path / "none.yaml")])
    assert res.exit_code != 0 and "no such scene file" in res.output


def test_roots_ladder_prices_every_root_finder_on_the_same_points(cli, tiny_scene, tmp_path):
    """Every preset with every event root finder: same outcomes, and the Hermite-seeded
    finder needs fewer RK4 re-integrations than bisection (2-4 trials per event, not
    log2(step/event_tol) ~ 20)."""
    report = tmp_path / "roots.h5"
    res = cli.invoke(main, ["accuracy", str(tiny_scene), "-o", str(report), "--points", "6",
                            "--ladder", "roots", "--repeat", "1", "-q"])
    assert res.exit_code == 0, res.output
    with h5py.File(report) as f:
        names = [n.decode() for n in f["table/setting"][:]]
        roots = [r.decode() for r in f["table/root"][:]]
        evals = f["table/evals_per_point"][:]
        assert sorted(set(roots)) == ["bisection", "hermite", "illinois"]
        by = {(n.split("-")[0], r): i for i, (n, r) in enumerate(zip(names, roots, strict=True))}
        for preset in ("draft", "default", "fine"):
            b, h = by[preset, "bisection"], by[preset, "hermite"]
            ev_b, ev_h = (f[f"kernel/{names[i]}/event_steps"][:].sum() for i in (b, h))
            assert ev_h < 0.5 * ev_b, (preset, ev_h, ev_b)  # the re-integrations ...
            assert evals[h] < evals[b], (preset, evals[h], evals[b])  # ... and in all
            for r in ("illinois", "hermite"):
                np.testing.assert_array_equal(
                    f[f"kernel/{names[by[preset, r]]}/outcome"][:],
                    f[f"kernel/{names[b]}/outcome"][:])


def test_cli_ladder_choices_are_the_ladders():
    """The command's --ladder choices (kept literal so --help loads no numerics) name
    exactly the ladders the study knows."""
    from rocksweep.analysis.accuracy import LADDERS
    from rocksweep.cli.accuracy import accuracy as command

    opt = next(p for p in command.params if p.name == "ladder_name")
    assert list(opt.type.choices) == list(LADDERS)


ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("name, sets", [
    ("ricker.yaml", ["pulse.w_over_p={start: 1, stop: 6, num: 3}",
                     "pulse.A_ratio={start: 1, stop: 8, num: 3}", "impact.lam=0.2"]),
    ("record-demo.yaml", ["ground.A_ratio=[1.0, 4.0]", "ground.p=[1.0, 3.0]",
                          "impact.lam=0.2"]),
])
def test_energy_and_half_step_runs_use_the_scene_ground_motion(name, sets):
    """The accuracy study's energy runs (and half-step reruns) must run
    the Ricker pulse and the record, not the sine/cosine variant: they equal the sweep's
    own energy outputs and check reruns of the same points."""
    from rocksweep import fields
    from rocksweep.analysis.accuracy import run_energy, run_half
    from rocksweep.compute.driver import sweep_arrays
    from rocksweep.scene.parse import load_scene

    sc = load_scene(ROOT / "configs" / name, [*sets, "outputs.energy=true",
                                              "outputs.check=true"])
    flat = np.arange(sc.size)
    swept = sweep_arrays(sc, jobs=1)[0]
    energy = run_energy(sc, flat, sc.numerics)
    w_in = energy[:, L.OUT_W_IN] / np.array([sc.point(v).body.E_ref for v in _values(sc)])
    np.testing.assert_array_equal(w_in, swept["work_in_over_Eref"].ravel())
    assert np.all(np.abs(w_in) > 0)  # the ground did work: a ground motion was applied
    half = run_half(sc, flat, sc.numerics)
    np.testing.assert_array_equal(half[:, L.OUT_OUTCOME].astype(np.int8),
                                  swept["check_outcome"].ravel())
    assert fields.BY_NAME["check_outcome"].slot == L.OUT_OUTCOME


def _values(sc):
    from rocksweep.scene.grid import Grid

    vals = Grid(sc).index_values(np.arange(sc.size))
    return [{k: v[i] for k, v in vals.items()} for i in range(sc.size)]


SLIDING = """\
name: a block that can only slide
body: {kind: block, alpha: 0.3, mu: 0.2}
impact: {lam: 0.0}
pulse: {shape: sine, w_over_p: 2.0, A_ratio: [1.5, 2.5]}
"""


def test_a_sliding_scene_is_measured_against_the_sliding_reference(tmp_path, monkeypatch):
    """body.mu = 0.2 < tan(alpha): the block only slides (a base held to the ground would
    uplift: A_ratio > 1). The reference is the sliding one (its slide_max the closed-form
    rigid-plastic block's, no uplift), and the table reports slide_max's error beside
    theta_max's. The energy runs are left out: no other test compiles the sliding
    energy chunk (~18 s), and the energy balance is not what this checks."""
    from rocksweep.analysis import accuracy as acc
    from rocksweep.errors import SceneError
    from rocksweep.physics import friction
    from rocksweep.scene.parse import load_scene

    path = tmp_path / "slide.yaml"
    path.write_text(SLIDING)
    sc = load_scene(path)
    monkeypatch.setattr(acc, "run_energy", lambda scene, flat, numerics:
                        np.full((len(flat), L.N_OUT), np.nan))
    study = acc.accuracy_study(sc, None, ladder("presets")[:1], repeat=1)
    ref = study.reference
    assert np.all(ref[:, L.OUT_UPLIFTS] == 0) and np.all(ref[:, L.OUT_THETA_MAX] == 0)
    for i, a_ratio in enumerate(study.values["A_ratio"]):
        pt = sc.point({k: v[i] for k, v in study.values.items()})
        closed = friction.sliding_block(pt.A, pt.omega, 0.2, shape="sine")["slide_max"]
        assert ref[i, L.OUT_SLIDE_MAX] == pytest.approx(closed, rel=1e-6), a_ratio
    row = study.table()[0]
    assert 0 < row["max_err_slide_max"] < 1e-3  # rel. error; the target: 2% at default
    text = acc.format_table(study)
    assert "sliding reference" in text and "slide_max (rel)" in text
    assert f"{row['err_slide_max']:.1e}" in text
    # the sliding reference has no vertical ground motion: refused in one line
    with pytest.raises(SceneError, match=r"^pulse\.vertical: .*body\.mu"):
        acc.accuracy_study(load_scene(path, ["pulse.vertical={amplitude: 0.2, "
                                             "w_over_p: 2.0}"]), 2)
