"""Adaptive sweeps (rocksweep.compute.adaptive): same outcomes as the full grid where the diagram is
resolved, islands caught by the audit, results independent of workers, chunking and
interruptions."""

import numpy as np
import pytest

import rocksweep.compute.adaptive as ad
from rocksweep.compute import lattice
from rocksweep.compute.driver import sweep_arrays
from rocksweep.errors import RocksweepError
from rocksweep.scene.parse import load_scene, parse_scene

# A rigid block under long pulses (omega/p <= 0.6): below A = g tan(alpha) (A_ratio < 1)
# the ground cannot lift it (the inertial moment M A h_cg stays below the restoring
# moment M g b), so it never rocks and is safe; above, the pulse lasts long enough to tip
# it over. The diagram is two large regions and one boundary near A_ratio = 1.
BLOCK_LONG = """body: {kind: block, alpha: 0.2, inertia: 1.3333333333333333}
pulse: {shape: sine, w_over_p: {start: 0.05, stop: 0.6, num: 33},
        A_ratio: {start: 0.5, stop: 2.5, num: 33}}
"""


def assert_same(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for k in a:
        assert a[k].dtype == b[k].dtype, k
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def synthetic(plan: ad.Plan, truth: np.ndarray):
    """An evaluator that looks classes up in a planted map (flat int8[size])."""
    calls = []

    def evaluate(flat, batch):
        calls.append((batch.kind, flat.copy()))
        return truth[flat]

    return evaluate, calls


def adaptive(sc, **kw):
    """An adaptive sweep in memory at the default settings: (arrays, stats)."""
    arrays, report = sweep_arrays(sc, adaptive=ad.Options(), **kw)
    return arrays, report.adaptive


@pytest.fixture(scope="module")
def block_long():
    sc = parse_scene(BLOCK_LONG)
    return sc, sweep_arrays(sc, jobs=1)[0]


# --- against the full grid, real kernel -------------------------------------------------

def test_block_long_pulse_equals_full_grid(block_long):
    sc, full = block_long
    A = np.asarray(sc.axis("A_ratio").values)
    assert (full["outcome"][A < 1] == 0).all()  # no uplift below g tan(alpha)
    assert (full["outcome"][A > 1.2] > 0).all()  # a boundary to find
    arr, st = adaptive(sc, jobs=1)
    np.testing.assert_array_equal(arr["outcome"], full["outcome"])
    assert st.computed < 0.5 * st.points
    c = arr["computed"] > 0
    # computed points hold the kernel's results, filled ones the "not computed" values
    for k, (_, fv, _) in sc.variables().items():
        np.testing.assert_array_equal(arr[k][c], full[k][c], err_msg=k)
        if k != "outcome":
            np.testing.assert_array_equal(arr[k][~c], np.full((~c).sum(), fv), err_msg=k)
    assert set(np.unique(arr["computed"])) <= {ad.FILLED, ad.COMPUTED, ad.AUDIT,
                                               ad.AUDIT_MISS}
    assert (~c).any()


def test_figure_3a_two_lam_equals_full_grid():
    """The paper's Figure 3(a) at its shipped 80 x 80, lam = 0 and 0.4."""
    sc = load_scene("configs/fig3a.yaml", ["impact.lam=[0.0, 0.4]"])
    full = sweep_arrays(sc, jobs=2)[0]
    arr, st = adaptive(sc, jobs=2)
    np.testing.assert_array_equal(arr["outcome"], full["outcome"])
    assert st.audit_misses == 0 and not st.suspicious
    assert st.computed_share < 0.5


def test_same_results_whatever_jobs_and_chunks(block_long):
    sc, _ = block_long
    a, sa = adaptive(sc, jobs=1, chunk_size=7)
    b, sb = adaptive(sc, jobs=2, chunk_size=64)
    c, _ = adaptive(sc, jobs=2)
    assert_same(a, b)
    assert_same(a, c)
    assert sa.batches == sb.batches



def test_spare_workers_compute_the_audit_early_without_changing_anything(block_long,
                                                                         monkeypatch):
    """The worker threads take the audit candidates and the next batch's points that the
    results so far show (``adaptive.Ahead``) while batches leave them idle
    (``compute.overlap.Runner``): the sweep equals the one that runs each batch alone
    (``run_batch`` without a runner, the dask backend's way), and a point computed early
    is not computed again when its batch asks for it."""
    import rocksweep.compute.overlap as ov
    from rocksweep.compute import sweep as sw

    sc, _ = block_long
    runs, runners = [], []
    real, real_runner = sw.run_chunk, ov.Runner

    def counted(grid, start, stop, level):
        runs.extend(grid.flat[start:stop].tolist())
        return real(grid, start, stop, level)

    def kept(*args, **kw):
        runners.append(real_runner(*args, **kw))
        return runners[-1]

    monkeypatch.setattr(sw, "run_chunk", counted)
    monkeypatch.setattr(ov, "Runner", kept)
    monkeypatch.setattr(ov, "AHEAD_SECONDS", 0.0)  # look ahead whatever is left
    a, ra = sweep_arrays(sc, jobs=2, chunk_size=5, adaptive=ad.Options())
    assert sorted(runs) == sorted(set(runs))  # every point once
    assert len(runs) == ra.adaptive.computed
    assert runners[0].ahead_points > 0  # some computed before their batch was planned
    monkeypatch.setattr(ov, "Runner", lambda *args, **kw: None)  # each batch alone
    b, rb = sweep_arrays(sc, jobs=2, chunk_size=5, adaptive=ad.Options())
    assert_same(a, b)
    assert ra.adaptive.batches == rb.adaptive.batches
    assert ra.refine_evaluations == rb.refine_evaluations

def test_a_batch_s_chunks_go_ahead_of_queued_spare_chunks():
    """``overlap.Pool``: a worker that comes free takes a batch's chunk (``BATCH``) before
    the spare chunks (``SPARE``) queued ahead of it, in submission order within one
    priority (a first-in, first-out executor would run the spares first, and the next
    batch, on the sweep's critical path, would wait for them)."""
    import threading

    from rocksweep.compute.overlap import BATCH, SPARE, Pool

    pool, gate, order = Pool(1), threading.Event(), []
    busy = pool.submit(BATCH, gate.wait)  # holds the only worker while the rest queue
    spares = [pool.submit(SPARE, order.append, f"spare {i}") for i in range(2)]
    batch = [pool.submit(BATCH, order.append, f"batch {i}") for i in range(2)]
    dropped = pool.submit(SPARE, order.append, "cancelled")
    assert dropped.cancel()
    gate.set()
    for f in [busy, *spares, *batch]:
        f.result(timeout=10)
    pool.shutdown()
    assert order == ["batch 0", "batch 1", "spare 0", "spare 1"]


def test_the_audit_sample_is_one_draw_of_the_seed_s_stream():
    """``audit_mask``, drawn a block at a time, is the Bernoulli(audit) sample of one draw
    of ``size`` doubles from the plan's seed, across block edges (65 536 doubles)."""
    for shape, audit, seed in (((3, 210, 211), 0.02, 0), ((1, 2, 65537), 0.3, 5),
                               ((1, 2, 3), 0.5, 1)):
        plan = ad.Plan(shape, 2, 1, audit=audit, seed=seed)
        u = np.random.default_rng(seed).random(int(np.prod(shape)))
        np.testing.assert_array_equal(ad.audit_mask(plan), u < audit)


# --- planted maps (synthetic classifier) --------------------------------------------------

def disc_map(shape, cx, cy, r):
    """Class 2 inside a disc, class 1 above the line y = 0.3 ny + 0.2 x, else 0."""
    P, ny, nx = shape
    y, x = np.mgrid[0:ny, 0:nx]
    m = np.where(y > 0.3 * ny + 0.2 * x, 1, 0)
    m = np.where((x - cx) ** 2 + (y - cy) ** 2 < r * r, 2, m)
    return np.broadcast_to(m, shape).astype(np.int8).copy()


def test_smooth_planted_map_recovered_exactly_and_cheaply():
    shape = (2, 257, 257)
    truth = disc_map(shape, 150.3, 60.7, 30.0)
    plan = ad.Plan(shape, 2, 1, audit=0.0)
    evaluate, _ = synthetic(plan, truth.ravel())
    out, comp, st = ad.run_on_function(plan, evaluate)
    np.testing.assert_array_equal(out, truth.ravel())
    assert st.computed_share < 0.15
    assert (comp[out != truth.ravel()] > 0).all()


def sliver_map(shape):
    """Class 2 left of x = 41, else 0, with two one-point-tall slivers of class 1 leaving
    the boundary: along row 61 (odd: through the centres of the stride-2 cells) and along
    row 90 (even: on their edges), the latter with a speck of class 0 at x = 71."""
    m = np.zeros(shape[1:], np.int8)
    m[:, :41] = 2
    m[61, 41:100] = 1
    m[90, 41:120] = 1
    m[90, 71] = 0
    return np.broadcast_to(m, shape).copy()


def test_one_point_slivers_and_specks_recovered_by_the_last_level():
    """The last level computes only the edge midpoints a boundary crosses, yet follows a
    one-point sliver through cells whose corners all agree, and looks inside a one-point
    band lying on the cells' edges (no audit here to help)."""
    shape = (2, 129, 129)
    truth = sliver_map(shape).ravel()
    plan = ad.Plan(shape, 2, 1, coarse=4, audit=0.0)
    out, comp, st = ad.run_on_function(plan, synthetic(plan, truth)[0])
    np.testing.assert_array_equal(out, truth)
    assert comp.reshape(shape)[0, 90, 71] == ad.COMPUTED  # the speck was looked at
    assert st.computed_share < 0.35
    # the edges along the straight boundary x = 41 that no boundary crosses (rows 2j + 1
    # at x = 42: ends (2j, 42), (2j + 2, 42) both 0) are filled, not computed
    c = comp.reshape(shape)[0]
    assert (c[101:127:2, 42] == ad.FILLED).all()
    # any order of computation ends with the same points computed
    rng = np.random.default_rng(5)
    outcome = np.full(plan.size, -1, np.int8)
    computed = np.zeros(plan.size, np.int8)
    for _ in range(2000):
        b = ad.next_batch(plan, outcome, computed)
        if b.kind == "done":
            break
        part = b.flat[rng.random(len(b)) < 0.3] if len(b) > 1 else b.flat
        outcome[part], computed[part] = truth[part], ad.COMPUTED
    np.testing.assert_array_equal(computed, comp)


def test_audit_catches_planted_island():
    shape = (1, 129, 129)
    base = np.zeros(shape, np.int8)
    plan = ad.Plan(shape, 2, 1, coarse=5, audit=0.05, seed=3)
    # plant a 3 x 3 island of class 1 on an audit candidate far from every coarse sample
    cand = ad.audit_mask(plan).reshape(shape)[0]
    ys, xs = np.nonzero(cand)
    far = (np.abs((ys + 16) % 32 - 16) >= 8) & (np.abs((xs + 16) % 32 - 16) >= 8)
    y0, x0 = ys[far][0], xs[far][0]
    truth = base.copy()
    truth[0, y0 - 1:y0 + 2, x0 - 1:x0 + 2] = 1
    t = truth.ravel()
    # without an audit the island is missed: it lies inside one uniform coarse cell
    out0, _, st0 = ad.run_on_function(ad.Plan(shape, 2, 1, coarse=5, audit=0.0),
                                      synthetic(plan, t)[0])
    assert (out0 == 0).all() and st0.audited == 0
    # with it, the audit point disagrees, the region is refined and the island recovered
    out, comp, st = ad.run_on_function(plan, synthetic(plan, t)[0], threshold=0.0)
    np.testing.assert_array_equal(out, t)
    assert st.audit_misses >= 1 and comp.reshape(shape)[0, y0, x0] == ad.AUDIT_MISS
    assert st.suspicious and "audit points" in st.warning()
    # the audit share: about 5% of the points that would otherwise have been filled
    filled0 = int((ad.run_on_function(ad.Plan(shape, 2, 1, coarse=5, audit=0.0),
                            synthetic(plan, base.ravel())[0])[1] == 0).sum())
    _, _, st_clean = ad.run_on_function(plan, synthetic(plan, base.ravel())[0], threshold=0.0)
    assert 0.03 * filled0 < st_clean.audited < 0.07 * filled0
    assert st_clean.audit_misses == 0 and not st_clean.suspicious


def planted_with_specks(rng, shape):
    """Two planted diagrams (int8 panels): a disc and a winding boundary, each with 25
    one-point specks of class 2 anywhere."""
    y, x = np.mgrid[0:shape[1], 0:shape[2]]
    wave = np.where(y > 60 + 25 * np.sin(x / 9.0) + 0.1 * x, 1, 0)  # a winding boundary
    for truth in (disc_map(shape, 70.3, 41.7, 9.0), np.broadcast_to(wave, shape).copy()):
        truth = truth.astype(np.int8)
        specks = rng.integers(0, [shape[0], shape[1], shape[2]], size=(25, 3))
        truth[specks[:, 0], specks[:, 1], specks[:, 2]] = 2
        yield truth


def check_against_whole_grid(monkeypatch, seen):
    """Make every ``next_batch`` given a hint (near or prior) also plan over the whole grid
    and assert both batches equal; seen(batch, near, prior) is told of each. Windows are
    forced whatever their size."""
    real = ad.next_batch

    def both(plan, outcome, computed, near=None, prior=None):
        b = real(plan, outcome, computed, near, prior)
        if near is not None or prior is not None:
            w = real(plan, outcome, computed)
            assert (b.kind, b.stride) == (w.kind, w.stride)
            np.testing.assert_array_equal(b.flat, w.flat)
            seen(b, plan, near, prior)
        return b

    monkeypatch.setattr(ad, "next_batch", both)
    monkeypatch.setattr(ad, "WINDOWS_SHARE", np.inf)


@pytest.mark.parametrize("coarse, margin, final_margin", [(4, 1, 0), (3, 2, 1), (2, 0, 3)])
def test_windowed_planning_equals_the_whole_grid(monkeypatch, coarse, margin, final_margin):
    """After a refine or audit batch, ``next_batch`` looks only at windows around its
    points (``adaptive._windows``, their size from ``reach``): at every step of a run over
    planted diagrams with specks, islands and winding boundaries, the windowed batch (the
    windows forced whatever their size) equals the one planned over the whole grid."""
    seen = []

    def windowed(b, plan, near, prior):
        assert ad._windows(plan, near) is not None
        seen.append(b.kind)

    check_against_whole_grid(monkeypatch, windowed)
    rng = np.random.default_rng(11)
    shape = (2, 161, 137)
    for truth in planted_with_specks(rng, shape):
        plan = ad.Plan(shape, 2, 1, coarse=coarse, margin=margin,
                       final_margin=final_margin, audit=0.05, seed=4)
        t = truth.ravel()
        ad.run_on_function(plan, lambda flat, batch, t=t: t[flat])
    assert seen.count("refine") >= 3 and "audit" in seen and "done" in seen


@pytest.mark.parametrize("coarse, margin, final_margin", [(4, 1, 0), (3, 2, 1)])
def test_a_look_ahead_wants_only_next_batch_points_and_plans_it_as_the_whole_grid(
        monkeypatch, coarse, margin, final_margin):
    """While a batch runs, ``Ahead`` (asked after some of its results, at random) wants
    only points of this batch or the next (a runner computes them early, none in vain),
    and the next batch planned from what it saw (``next_batch``'s near and prior: the
    windows around the points computed since) equals the one planned over the whole grid,
    on planted diagrams with specks and a winding boundary."""
    from_prior = []

    def planned_from_prior(b, plan, near, prior):
        if prior is not None:
            from_prior.append(b.kind)

    check_against_whole_grid(monkeypatch, planned_from_prior)
    rng = np.random.default_rng(7)
    shape = (2, 161, 137)
    for truth in planted_with_specks(rng, shape):
        t = truth.ravel()
        plan = ad.Plan(shape, 2, 1, coarse=coarse, margin=margin,
                       final_margin=final_margin, audit=0.05, seed=4)
        looked, flats = [], []  # (batch number, points wanted ahead); each batch's points

        def run(b, t=t, looked=looked, flats=flats):
            flats.append(b.flat)
            # in chunks of neighbouring points, as a runner's, in any order
            parts = np.array_split(b.flat, min(len(b), int(rng.integers(2, 9))))
            for i in rng.permutation(len(parts)):
                part = parts[i]
                yield ad.BatchResult(part, {"outcome": t[part]}, 0.0, 0.0)
                if b.ahead is not None and rng.random() < 0.7:
                    looked.append((len(flats) - 1, b.ahead()))

        outcome = np.full(plan.size, -1, np.int8)
        computed = np.zeros(plan.size, np.int8)
        for _ in ad.run_plan(plan, outcome, computed, run):
            pass
        ref_out, ref_comp, _ = ad.run_on_function(plan, lambda flat, batch, t=t: t[flat])
        np.testing.assert_array_equal(computed, ref_comp)
        assert sum(p.size for _, p in looked) > 0
        for k, pts in looked:  # this batch's or the next one's, never in vain
            later = np.concatenate(flats[k:k + 2])
            assert np.isin(pts, later).all()
    assert from_prior.count("refine") >= 3 and "done" in from_prior


def test_interrupted_run_resumes_to_the_same_result():
    """The next batch is a function of the state: computing any part of a batch, then
    asking again, ends with the same outcomes and computed set as an uninterrupted run."""
    shape = (3, 97, 65)
    truth = disc_map(shape, 40.2, 50.5, 12.0).ravel()
    plan = ad.Plan(shape, 2, 1, coarse=3, audit=0.1, seed=1)
    ref_out, ref_comp, _ = ad.run_on_function(plan, synthetic(plan, truth)[0])
    outcome = np.full(plan.size, -1, np.int8)
    computed = np.zeros(plan.size, np.int8)
    rng = np.random.default_rng(0)
    for _ in range(1000):
        b = ad.next_batch(plan, outcome, computed)
        if b.kind == "done":
            break
        part = b.flat[rng.random(len(b)) < 0.4] if len(b) > 1 else b.flat  # "killed"
        outcome[part] = truth[part]
        computed[part] = ad.AUDIT if b.kind == "audit" else ad.COMPUTED
    else:
        raise AssertionError("no convergence")
    np.testing.assert_array_equal(ad.fill(plan, outcome, computed), ref_out)
    np.testing.assert_array_equal(computed > 0, ref_comp > 0)
    # a finished file asks for nothing more, even with filled classes in outcome
    filled = ad.fill(plan, outcome, computed)
    assert ad.next_batch(plan, filled, computed).kind == "done"


def test_other_diagram_axes_equal_transposed_default():
    shape = (2, 65, 81)
    truth = disc_map(shape, 30.5, 20.2, 9.0)
    plan = ad.Plan(shape, 2, 1, audit=0.02)
    out, comp, _ = ad.run_on_function(plan, synthetic(plan, truth.ravel())[0])
    # the same map with the diagram axes first and the "other" axis last, y and x swapped
    moved = np.ascontiguousarray(np.transpose(truth, (2, 1, 0)))  # (x, y, panel)
    plan_t = ad.Plan(moved.shape, 0, 1, audit=0.0)
    out_t, comp_t, _ = ad.run_on_function(plan_t, synthetic(plan_t, moved.ravel())[0])
    np.testing.assert_array_equal(out_t.reshape(moved.shape), moved)
    np.testing.assert_array_equal(out.reshape(shape), truth)


# --- pieces ------------------------------------------------------------------------------

def test_plan_coarse_takes_every_2k_th_index_and_the_last():
    shape = (9, 3, 17)
    flat = ad.plan_coarse(shape, (0, 2), 2)  # x = axis 0 (9), y = axis 2 (17), stride 4
    i, j, k = np.unravel_index(flat, shape)
    assert sorted(set(i.tolist())) == [0, 4, 8]
    assert sorted(set(k.tolist())) == [0, 4, 8, 12, 16]
    assert sorted(set(j.tolist())) == [0, 1, 2]
    assert flat.size == 3 * 3 * 5 and np.all(np.diff(flat) > 0)
    flat = ad.plan_coarse((1, 10, 10), (2, 1), 2)  # last index 9 is not a multiple of 4
    _, y, x = np.unravel_index(flat, (1, 10, 10))
    assert sorted(set(y.tolist())) == sorted(set(x.tolist())) == [0, 4, 8, 9]


def test_default_coarse_keeps_16_cells_per_axis():
    assert ad.default_coarse(80, 80) == 2      # 79 / 4 = 19.75 cells
    assert ad.default_coarse(400, 400) == 4    # 399 / 16 = 24.9
    assert ad.default_coarse(1000, 1000) == 5  # 999 / 32 = 31.2
    assert ad.default_coarse(10, 400) == 0     # too few points for a coarse pass
    assert ad.Plan((1, 400, 80), 2, 1).coarse == 2


def test_stats_from_flags_alone():
    flags = np.array([0, 0, 1, 1, 1, 2, 2, 3], np.int8)
    st = ad.stats_of(flags, threshold=0.1)
    assert (st.points, st.computed, st.audited, st.audit_misses) == (8, 6, 3, 1)
    assert st.suspicious and st.warning()
    assert not ad.stats_of(flags[:-1]).suspicious


@pytest.mark.parametrize("kwargs, word", [
    ({"axes": ("w_over_p", "speed")}, "speed"),
    ({"axes": ("w_over_p", "lam")}, "lam"),
    ({"axes": ("w_over_p",)}, "two axis names"),
    ({"audit": 1.5}, "audit = 1.5"),
    ({"margin": -1}, "margin = -1"),
    ({"coarse": -2}, "coarse = -2"),
])
def test_bad_settings_are_one_line_errors(block_long, kwargs, word):
    sc, _ = block_long
    with pytest.raises(RocksweepError) as err:
        ad.make_plan(sc, **kwargs)
    assert word in str(err.value) and "\n" not in str(err.value)


def test_interrupted_audit_resumes_to_the_same_flags():
    """``next_step`` finishes a begun audit batch before refining around its misses, and
    compares its points with the fill of the points computed before the audit: however a
    run is cut (any part of any batch, audit included), the flags equal an uninterrupted
    run's, audit misses included."""
    shape = (2, 129, 129)
    truth = disc_map(shape, 70.3, 40.1, 14.0)
    # specks of class 1 on audit candidates inside uniform coarse cells: audit misses
    plan = ad.Plan(shape, 2, 1, coarse=4, audit=0.05, seed=2)
    cand = ad.audit_mask(plan).reshape(shape)
    for p in range(2):
        ys, xs = np.nonzero(cand[p])
        far = ((np.abs((ys + 8) % 16 - 8) >= 4) & (np.abs((xs + 8) % 16 - 8) >= 4)
               & (ys > 0.3 * 129 + 0.2 * xs + 20))
        for y0, x0 in list(zip(ys[far], xs[far], strict=True))[:3]:
            truth[p, y0, x0] = 2
    t = truth.ravel()
    ref_out, ref_comp, ref_st = ad.run_on_function(plan, synthetic(plan, t)[0])
    assert ref_st.audit_misses >= 2  # the audit batch matters here
    for seed in range(4):
        rng = np.random.default_rng(seed)
        outcome = np.full(plan.size, -1, np.int8)
        computed = np.zeros(plan.size, np.int8)
        for _ in range(2000):
            step = ad.next_step(plan, outcome, computed)
            b = step.batch
            if b.kind == "done":
                break
            part = b.flat[rng.random(len(b)) < 0.3] if len(b) > 1 else b.flat  # "killed"
            outcome[part] = t[part]
            computed[part] = step.flags(part, t[part])
        else:
            raise AssertionError("no convergence")
        np.testing.assert_array_equal(computed, ref_comp)
        np.testing.assert_array_equal(ad.fill(plan, outcome, computed), ref_out)


def _edge_points_every_cell(plan, mixed, known):
    """The last level's rules (``lattice.edge_points``) evaluated on every cell of the
    panels, as they were written before the planner evaluated them on the cells they can
    fire at only."""
    c = lattice.corner_classes(known)
    a, b = c[:, :-1, :-1], c[:, :-1, 1:]  # corners (y, x), (y, x + 1)
    d, e = c[:, 1:, :-1], c[:, 1:, 1:]  # (y + 1, x), (y + 1, x + 1)
    ok = mixed & (a >= 0) & (b >= 0) & (d >= 0) & (e >= 0)
    same = (a == b) & (a == d) & (a == e)
    split, whole = ok & ~same, ok & same
    P, cy, cx = mixed.shape
    _, ny, nx = plan.panel_shape
    m = lattice.centre_classes(known)
    lat = np.zeros((P, 2 * cy + 1, 2 * cx + 1), bool)  # stride-1 lattice, as points_of_cells
    lat[:, 1::2, 1::2] |= split  # centres

    def crossed(p: np.ndarray, q: np.ndarray, r: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Edge (p, q) of a split cell crossed; (r, t): the opposite edge's ends."""
        return (p != q) | ((m >= 0) & (p != m) & ~((r == m) & (t == m)))

    lat[:, 0:-1:2, 1::2] |= split & crossed(a, b, d, e)  # lower edges
    lat[:, 2::2, 1::2] |= split & crossed(d, e, a, b)  # upper edges
    lat[:, 1::2, 0:-1:2] |= split & crossed(a, d, b, e)  # left edges
    lat[:, 1::2, 2::2] |= split & crossed(b, e, a, d)  # right edges

    def band(p: np.ndarray, q: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Edge (p, q) with agreeing ends between centres u, v of another class."""
        return (p >= 0) & (p == q) & (u >= 0) & (v >= 0) & (u != p) & (v != p)

    no = np.full((P, 1, cx), -1, np.int8)  # beyond the panel: no centre
    lat[:, 0::2, 1::2] |= band(c[:, :, :-1], c[:, :, 1:], np.concatenate([no, m], 1),
                               np.concatenate([m, no], 1))  # edges along x
    no = np.full((P, cy, 1), -1, np.int8)
    lat[:, 1::2, 0::2] |= band(c[:, :-1, :], c[:, 1:, :], np.concatenate([no, m], 2),
                               np.concatenate([m, no], 2))  # edges along y
    for dy in range(3):
        for dx in range(3):
            lat[:, dy:dy + 2 * cy:2, dx:dx + 2 * cx:2] |= whole
    p, jj, ii = np.nonzero(lat)
    return np.unique(plan.flat_index()[p, np.minimum(jj, ny - 1), np.minimum(ii, nx - 1)])


def test_the_last_levels_rules_on_their_cells_equal_them_on_every_cell():
    """``edge_points`` looks only at mixed cells and cells with a computed centre; on
    random states (classes, computed sets, mixed cells; panels of 1-3, odd and even axis
    lengths, the diagram axes in either order) it picks exactly the points the rules
    evaluated on every cell pick."""
    rng = np.random.default_rng(1)
    picked = 0
    for _ in range(600):
        n_p, ny, nx = (int(v) for v in rng.integers((1, 2, 2), (4, 14, 14)))
        plan = (ad.Plan((n_p, ny, nx), 2, 1) if rng.random() < 0.5
                else ad.Plan((ny, n_p, nx), 2, 0))
        shape = plan.panel_shape
        known = rng.integers(-1, int(rng.integers(1, 4)), size=shape).astype(np.int8)
        if rng.random() < 0.5:
            known[rng.random(shape) < 0.6] = -1
        cells = (shape[0], lattice.ncells(shape[1], 2), lattice.ncells(shape[2], 2))
        mixed = rng.random(cells) < rng.uniform(0, 1)
        got = lattice.edge_points(plan.flat_index(), mixed, known)
        np.testing.assert_array_equal(got, _edge_points_every_cell(plan, mixed, known))
        picked += got.size
    assert picked > 1000  # the rules fired


def test_the_points_of_marked_cells_are_those_of_their_closed_lattice():
    """``points_of_cells`` (the stride-s/2 points inside the marked stride-s cells, edges
    and corners included; with ``known``, those not computed) against each marked cell's
    3 x 3 points listed one by one, a shorter last cell's clipped to the axis's end."""
    rng = np.random.default_rng(2)
    for _ in range(300):
        n_p, ny, nx = (int(v) for v in rng.integers((1, 2, 2), (4, 40, 40)))
        plan = (ad.Plan((n_p, ny, nx), 2, 1) if rng.random() < 0.5
                else ad.Plan((ny, n_p, nx), 2, 0))
        s = int(2 ** rng.integers(1, 5))
        h = s // 2
        cy, cx = lattice.ncells(ny, s), lattice.ncells(nx, s)
        cells = rng.random((n_p, cy, cx)) < rng.uniform(0, 0.5)
        known = rng.integers(-1, 2, size=(n_p, ny, nx)).astype(np.int8)
        idx = plan.flat_index()
        pts = {(p, min((2 * j + dy) * h, ny - 1), min((2 * i + dx) * h, nx - 1))
               for p, j, i in zip(*np.nonzero(cells), strict=True)
               for dy in range(3) for dx in range(3)}
        want = sorted(int(idx[q]) for q in pts)
        np.testing.assert_array_equal(lattice.points_of_cells(idx, cells, s), want)
        todo = sorted(int(idx[q]) for q in pts if known[q] < 0)
        np.testing.assert_array_equal(lattice.points_of_cells(idx, cells, s, known), todo)


def test_lattice_blocks_pads_and_axes_against_their_definitions():
    """The block copies ``fill`` is built of: ``cell_blocks`` gives point (y, x) its cell's
    value (min(y // s, cy - 1), min(x // s, cx - 1)), ``pad_edge`` equals numpy's edge
    pad, ``axis_lattice`` is 0, s, 2s, ... and n - 1; on random shapes, odd and even
    axis lengths, strides up to beyond the axis."""
    rng = np.random.default_rng(3)
    for _ in range(300):
        n_p, ny, nx = (int(v) for v in rng.integers((1, 2, 2), (4, 40, 40)))
        s = int(2 ** rng.integers(1, 6))
        cy, cx = lattice.ncells(ny, s), lattice.ncells(nx, s)
        cells = rng.integers(-1, 3, size=(n_p, cy, cx)).astype(np.int8)
        y, x = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
        want = cells[:, np.minimum(y // s, cy - 1), np.minimum(x // s, cx - 1)]
        np.testing.assert_array_equal(lattice.cell_blocks(cells, s, ny, nx), want)
        a = rng.integers(0, 9, size=(n_p, ny, nx))
        py, px = (int(v) for v in rng.integers(0, 4, 2))
        np.testing.assert_array_equal(lattice.pad_edge(a, ny + py, nx + px),
                                      np.pad(a, ((0, 0), (0, py), (0, px)), mode="edge"))
        want_axis = sorted(set(range(0, ny, s)) | {ny - 1})
        np.testing.assert_array_equal(lattice.axis_lattice(ny, s), want_axis)
