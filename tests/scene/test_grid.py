"""The grid: flat index -> point -> kernel parameter rows, chunk by chunk."""

import math
import tracemalloc
from itertools import product

import numpy as np
import pytest
from bodies import body_yaml, table3

import rocksweep.scene.grid as grid_mod
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.points import kernel_kind, point_row
from rocksweep.scene.grid import Grid
from rocksweep.scene.parse import parse_scene

BODY = body_yaml(table3(wn_over_p="%s", zeta="%s"))


def scene(wn="2.43", zeta="0.05", lam="[0.0, 0.4]", shape="[sine, cosine]",
          w="{start: 0.5, stop: 6, num: 4}", A="{start: 1, stop: 8, num: 3}"):
    return parse_scene(BODY % (wn, zeta) + f"impact: {{lam: {lam}}}\n"
                       f"pulse: {{shape: {shape}, w_over_p: {w}, A_ratio: {A}}}\n")


def all_points(sc):
    """Every point in C order, enumerated independently of Grid (itertools.product)."""
    names = [a.name for a in sc.axes]
    return [dict(zip(names, combo, strict=True))
            for combo in product(*(a.values for a in sc.axes))]


def test_dims_and_shape_follow_the_swept_axes():
    sc = scene(zeta="[0.02, 0.05, 0.1]")
    g = Grid(sc)
    assert g.dims == ("shape", "zeta", "lam", "A_ratio", "w_over_p")
    assert g.shape == (2, 3, 2, 3, 4)
    assert g.size == 2 * 3 * 2 * 3 * 4
    np.testing.assert_array_equal(g.coords()["w_over_p"], np.linspace(0.5, 6, 4))


def test_rows_equal_point_rows_in_product_order():
    sc = scene(zeta="[0.02, 0.05]")
    g = Grid(sc)
    pts = all_points(sc)
    assert len(pts) == g.size
    cr = g.rows(0, g.size)
    for i, values in enumerate(pts):
        expected = point_row(sc.point(values), sc.numerics)
        np.testing.assert_array_equal(cr.rows[i], expected)
        body = sc.point(values).body
        assert cr.alpha_ref[i] == body.alpha_ref
        assert cr.E_ref[i] == body.E_ref


def test_index_values_match_product_order():
    sc = scene()
    g = Grid(sc)
    pts = all_points(sc)
    idx = np.array([0, 5, 17, g.size - 1])
    vals = g.index_values(idx)
    for j, i in enumerate(idx):
        for name, v in pts[i].items():
            assert vals[name][j] == v


def test_rows_do_not_depend_on_the_chunk():
    """A point's row is the same whichever chunk it is built in (bit for bit)."""
    sc = scene(zeta="[0.0, 0.05]", wn="[2.43, 9.82]")
    g = Grid(sc)
    whole = g.rows(0, g.size).rows
    rng = np.random.default_rng(3)
    for _ in range(5):
        a = int(rng.integers(0, g.size))
        b = int(rng.integers(a + 1, g.size + 1))
        np.testing.assert_array_equal(g.rows(a, b).rows, whole[a:b])
    pick = rng.permutation(g.size)[:7]
    np.testing.assert_array_equal(g.rows_at(pick).rows, whole[pick])


def test_kinds_follow_each_points_body():
    """zeta = 0 needs the undamped variant, wn/p = inf the rigid one, within one grid."""
    sc = scene(zeta="[0.0, 0.05]", wn="[2.43, .inf]")
    g = Grid(sc)
    cr = g.rows(0, g.size)
    expected = [kernel_kind(sc.point(v).body) for v in all_points(sc)]
    np.testing.assert_array_equal(cr.kinds, expected)
    assert set(cr.kinds.tolist()) == {L.KIND_FLEXIBLE, L.KIND_FLEXIBLE_UNDAMPED, L.KIND_RIGID}
    assert g.kinds() == sorted({L.KIND_FLEXIBLE, L.KIND_FLEXIBLE_UNDAMPED, L.KIND_RIGID})
    # a rigid body has no spring: no damper either, whatever zeta says
    rigid = cr.kinds == L.KIND_RIGID
    assert np.all(cr.rows[rigid, L.PAR_C] == 0.0)


def test_body_quantities_computed_once_per_distinct_body(monkeypatch):
    calls = []
    real = grid_mod.body_row
    monkeypatch.setattr(grid_mod, "body_row", lambda body: calls.append(body) or real(body))
    sc = scene(zeta="[0.02, 0.05, 0.1]", w="{start: 0.5, stop: 6, num: 50}")
    g = Grid(sc)
    g.rows(0, g.size)  # 3 bodies, 1800 points
    assert len(calls) == 3
    calls.clear()
    n_per_body = g.size // 3
    g.rows(n_per_body // 2, n_per_body // 2 + 10)  # inside the first body's block
    assert len(calls) == 1


def test_huge_grid_is_never_materialised():
    """10^8 points: rows of a chunk at the end cost memory of the chunk only."""
    sc = scene(lam="0.2", shape="sine", w="{start: 0.1, stop: 6, num: 10000}",
               A="{start: 0.1, stop: 8, num: 10000}")
    g = Grid(sc)
    assert g.size == 10**8
    tracemalloc.start()
    cr = g.rows(g.size - 500, g.size)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert cr.rows.shape == (500, L.N_PAR)
    assert peak < 2_000_000  # bytes; all points' rows would be 20.8 GB
    last = point_row(sc.point({a.name: a.values[-1] for a in sc.axes}), sc.numerics)
    np.testing.assert_array_equal(cr.rows[-1], last)
    assert cr.rows[-1, L.PAR_OMEGA] == 6.0
    assert math.isclose(cr.rows[-1, L.PAR_AMP], 8 * 9.81 * math.tan(0.15))


def test_out_of_range_indices_are_refused():
    g = Grid(scene())
    with pytest.raises(IndexError):
        g.rows(g.size - 1, g.size + 1)
