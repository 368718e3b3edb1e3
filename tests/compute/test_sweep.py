"""Sweeps: chunking, workers, determinism, kernel dispatch, the paper's lam claim."""

import numpy as np
import pytest
from bodies import FIG3_YAML, body_yaml, table3

import rocksweep.compute.sweep as sw
from rocksweep import fields
from rocksweep.compute.driver import sweep_arrays
from rocksweep.compute.single import run_point
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.scene.grid import ChunkResult, Grid
from rocksweep.scene.parse import parse_scene

BODY3 = FIG3_YAML


def small_scene(extra: str = "") -> object:
    return parse_scene(BODY3 + "impact: {lam: [0.0, 0.4]}\n"
                       "pulse: {shape: [sine, cosine], w_over_p: {start: 0.6, stop: 6, num: 5},"
                       " A_ratio: {start: 1, stop: 7, num: 4}}\n" + extra)


def assert_same(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for k in a:
        assert a[k].dtype == b[k].dtype, k
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)  # NaN == NaN here


@pytest.fixture(scope="module")
def reference():
    sc = small_scene()
    return sc, sweep_arrays(sc, jobs=1, chunk_size=1000)[0]


# --- chunk planning ---------------------------------------------------------------------

@pytest.mark.parametrize("seed", range(6))
def test_plan_covers_each_todo_point_once(seed):
    rng = np.random.default_rng(seed)
    todo = rng.random(int(rng.integers(1, 400))) < rng.random()
    size = int(rng.integers(1, 50))
    chunks = sw.plan_chunks(todo, size)
    covered = np.zeros(todo.size, int)
    for a, b in chunks:
        assert 0 < b - a <= size
        covered[a:b] += 1
    np.testing.assert_array_equal(covered, todo.astype(int))


def test_auto_chunks_keep_every_worker_busy():
    # many chunks per worker, so the last chunk is a small part of a worker's load
    assert len(sw.plan_chunks(np.ones(19200, bool), sw.auto_chunk_size(19200, 2))) >= 64
    assert sw.auto_chunk_size(10**6, 2) == sw.MAX_CHUNK
    assert sw.auto_chunk_size(5, 8) >= 1


# --- results ----------------------------------------------------------------------------

def test_sweep_equals_single_runs(reference):
    """Each grid cell holds the result of its own point (indexing and normalisation)."""
    sc, ref = reference
    g = Grid(sc)
    rng = np.random.default_rng(0)
    for flat in rng.choice(g.size, 6, replace=False):
        values = {k: v[0] for k, v in g.index_values(np.array([flat])).items()}
        run = run_point(sc.point(values), sc.numerics, history=False)
        idx = np.unravel_index(flat, g.shape)
        assert ref["outcome"][idx] == run.out[L.OUT_OUTCOME]
        assert ref["impacts"][idx] == run.impacts
        assert ref["uplifts"][idx] == run.uplifts
        assert ref["status"][idx] == run.out[L.OUT_STATUS]
        assert ref["steps"][idx] == run.out[L.OUT_STEPS]
        assert ref["theta_max_over_alpha"][idx] == run.theta_max_over_alpha
        t = run.t_overturn
        assert (np.isnan(ref["t_overturn"][idx]) if t is None else ref["t_overturn"][idx] == t)


def test_outcomes_are_consistent(reference):
    _, ref = reference
    o = ref["outcome"]
    assert set(np.unique(o).tolist()) <= {0, 1, 2} and (o >= 0).all()  # all computed
    over = o > 0
    assert np.isfinite(ref["t_overturn"][over]).all()
    assert np.isnan(ref["t_overturn"][~over]).all()
    assert (ref["theta_max_over_alpha"][over] >= np.pi / 2 / 0.15 * 0.999).all()
    assert (ref["impacts"][o == L.OUTCOME_MODE2] == 0).all()  # mode 2: no impact
    assert (ref["impacts"][o == L.OUTCOME_MODE1] >= 1).all()
    assert (ref["steps"] > 0).all()


def test_bit_for_bit_whatever_jobs_and_chunks(reference):
    sc, ref = reference
    assert_same(ref, sweep_arrays(sc, jobs=1, chunk_size=7)[0])
    assert_same(ref, sweep_arrays(sc, jobs=2, chunk_size=5)[0])
    assert_same(ref, sweep_arrays(sc, jobs=2, chunk_size=64)[0])


def test_merge_contiguous_joins_neighbours_in_any_order():
    rng = np.random.default_rng(3)
    bounds = [(0, 5), (5, 9), (9, 20), (30, 33), (33, 40), (50, 51)]
    full = {"x": rng.random(51), "n": np.arange(51)}
    results = [ChunkResult(a, b, {k: v[a:b] for k, v in full.items()}, 1.0, 0.5)
               for a, b in bounds]
    merged = sw.merge_contiguous([results[i] for i in rng.permutation(len(results))])
    assert [(m.start, m.stop) for m in merged] == [(0, 20), (30, 40), (50, 51)]
    for m in merged:
        for k, v in full.items():
            np.testing.assert_array_equal(m.arrays[k], v[m.start:m.stop])
    assert [m.seconds for m in merged] == [3.0, 2.0, 1.0]
    assert [m.cpu_seconds for m in merged] == [1.5, 1.0, 0.5]


def test_chunk_kernels_release_the_gil():
    """Local workers are threads: a chunk kernel that held the GIL would run them one at a
    time (the sweep would still be right, only as slow as one worker)."""
    from rocksweep.kernel import chunk_kernel

    for kind in (L.KIND_FLEXIBLE, L.KIND_FLEXIBLE_UNDAMPED, L.KIND_RIGID):
        for lvl in (L.LEVEL_OUTCOME, L.LEVEL_ENERGY):
            assert chunk_kernel(kind, lvl).targetoptions.get("nogil") is True, (kind, lvl)


def test_dask_backend_on_a_local_cluster(reference):
    distributed = pytest.importorskip("distributed")  # in the test extra: never skipped in CI
    sc, ref = reference
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        got = sweep_arrays(sc, chunk_size=9, backend="dask", scheduler=cluster.scheduler_address)[0]
    assert_same(ref, got)


def test_each_point_goes_to_its_kernel_variant(monkeypatch):
    """A body axis crossing zeta = 0 and wn/p = inf: each point to the right variant."""
    seen = []

    def fake_kernel(kind, level, ground=False, contact=L.CONTACT_NOSLIP):
        def run(rows, outs):
            seen.append((kind, level, rows.copy()))
            outs[:] = 0.0
            outs[:, L.OUT_MARGIN] = np.inf  # never near the saddle: no close call to refine
            # nor near the other mode, nor an impact it did not make, nor a lift-off
            outs[:, [L.OUT_GRAZE, L.OUT_MODE_GRAZE, L.OUT_LIFT_GRAZE,
                     L.OUT_LIFT_ANGLE]] = np.inf
            outs[:, L.OUT_OUTCOME] = kind  # mark which variant computed the point
        return run

    monkeypatch.setattr(sw.kernel, "chunk_kernel", fake_kernel)
    sc = parse_scene(body_yaml(table3(wn_over_p="[2.43, .inf]", zeta="[0.0, 0.05]"))
                     + "impact: {lam: 0.2}\n"
                     "pulse: {shape: sine, w_over_p: [1.0, 2.0], A_ratio: 3.0}\n")
    g = Grid(sc)
    res = sw.run_chunk(g, 0, g.size, L.LEVEL_OUTCOME)
    wn = g.index_values(np.arange(g.size))["wn_over_p"]
    zeta = g.index_values(np.arange(g.size))["zeta"]
    expected = np.where(np.isinf(wn), L.KIND_RIGID,
                        np.where(zeta > 0, L.KIND_FLEXIBLE, L.KIND_FLEXIBLE_UNDAMPED))
    np.testing.assert_array_equal(res.arrays["outcome"], expected)
    assert len(seen) == 3  # one call per variant, not per point
    for kind, level, rows in seen:
        assert level == L.LEVEL_OUTCOME
        if kind == L.KIND_FLEXIBLE:
            assert (rows[:, L.PAR_C] > 0).all()
        else:
            assert (rows[:, L.PAR_C] == 0).all()


def test_energy_outputs_match_the_single_run_bookkeeping():
    sc = parse_scene(BODY3 + "impact: {lam: 0.2}\npulse: {shape: sine, w_over_p: [2.0, 5.3], "
                     "A_ratio: [2.0, 5.0]}\noutputs: {energy: true}\n")
    res = sweep_arrays(sc, jobs=1)[0]
    assert {f.name for f in fields.ENERGY_FIELDS} <= res.keys()
    g = Grid(sc)
    for flat in range(g.size):
        values = {k: v[0] for k, v in g.index_values(np.array([flat])).items()}
        s = run_point(sc.point(values), sc.numerics, history=True).summary()
        idx = np.unravel_index(flat, g.shape)
        for name, key in (("work_in_over_Eref", "work_in_over_Eref"),
                          ("damper_loss_over_Eref", "damper_loss_over_Eref"),
                          ("impact_loss_over_Eref", "impact_loss_over_Eref")):
            assert res[name][idx] == pytest.approx(s[key], rel=1e-9, abs=1e-12), name
        assert res["damper_loss_over_Eref"][idx] >= 0.0  # a damper only dissipates


def test_raising_lam_grows_mode1_area():
    """The paper (Sec. 3.3): an increase in lam expands the mode 1 area; lam acts only at
    impacts, so mode 2 (no impact) cannot depend on it."""
    sc = parse_scene(BODY3 + "impact: {lam: [0.0, 0.2, 0.4]}\n"
                     "pulse: {shape: sine, w_over_p: {start: 3.0, stop: 5.7, num: 10},"
                     " A_ratio: {start: 1.5, stop: 6.5, num: 10}}\n")
    res = sweep_arrays(sc, jobs=1)[0]
    o = res["outcome"]  # [lam, A, w]
    mode1 = (o == L.OUTCOME_MODE1).sum(axis=(1, 2))
    assert np.all(np.diff(mode1) >= 0), mode1
    safe_to_mode1 = (o[0] == L.OUTCOME_SAFE) & (o[-1] == L.OUTCOME_MODE1)
    assert safe_to_mode1.sum() >= 3
    m2 = o == L.OUTCOME_MODE2
    assert m2[0].any()
    np.testing.assert_array_equal(m2[0], m2[1])
    np.testing.assert_array_equal(m2[0], m2[2])
