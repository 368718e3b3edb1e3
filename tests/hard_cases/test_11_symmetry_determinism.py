"""Hard case 11: A -> -A mirrors the run; a point's result is bit-identical wherever it runs."""

import math
import subprocess
import sys
import tempfile

import numpy as np
import pytest
from hardkit import BASE, run
from hardkit import table3_body as body
from joblib import Parallel, delayed

from rocksweep.kernel import chunk_kernel
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.bodies import BlockBody
from rocksweep.physics.points import Point, point_row

pytestmark = pytest.mark.hard

MIRROR_CASES = {
    "flexible, sine, chatters": Point(body(), 0.2, "sine", 4.0, 1.05),
    "flexible, cosine, uplift at t = 0": Point(body(), 0.2, "cosine", 6.0, 6.2),
    "undamped, sine, mode 1": Point(body(zeta=0.0), 0.2, "sine", 5.3, 5.0),
    "stiff, cosine": Point(body(wn_over_p=50.0), 0.4, "cosine", 4.0, 2.0),
    "welded, sine": Point(body(wn_over_p=math.inf), 0.2, "sine", 2.0, 1.5),
    "block, cosine": Point(BlockBody(alpha=0.2), 0.0, "cosine", 3.0, 2.5),
}
ODD = ("theta", "theta_dot", "u", "u_dot", "phase", "xg")
EVEN = ("t", "E", "W_in", "D_damp", "E_impact")


@pytest.mark.parametrize("name", list(MIRROR_CASES))
def test_negative_amplitude_mirrors_the_run_exactly(name):
    """Guards against a left/right asymmetry in the equations, the events or the impact map."""
    # Exact, not to round-off: under theta, u, s, xg'' -> -(...) every operation of the
    # kernel maps to itself or to its negative (sin is odd, cos even, a = u - s b flips,
    # products and sums of flipped operands flip), IEEE-754 rounding is symmetric in sign,
    # and the event functions (s theta, M g b - s Q) and energies are unchanged: both runs
    # take the same steps and make the same decisions, bit for bit.
    p = MIRROR_CASES[name]
    q = Point(p.body, p.lam, p.shape, p.w_over_p, -p.A_ratio)
    a, b = run(p), run(q)
    assert a.uplifts >= 1  # the case does rock
    for key in ODD:
        assert np.array_equal(b.history[key], -a.history[key]), key
    for key in EVEN:
        assert np.array_equal(b.history[key], a.history[key]), key
    assert np.array_equal(a.out, b.out, equal_nan=True)  # same outcome, counts, times


def _rows() -> np.ndarray:
    """Parameter rows of flexible damped points of all outcomes (one kernel variant)."""
    pts = [Point(body(), lam, shape, w, a) for lam in (0.0, 0.4) for shape in ("sine", "cosine")
           for w, a in ((4.0, 1.05), (2.0, 3.0), (5.3, 5.0), (3.0, 2.0), (0.5, 0.4))]
    return np.array([point_row(p, BASE) for p in pts])


def _chunk(rows: np.ndarray) -> np.ndarray:
    outs = np.empty((rows.shape[0], L.N_OUT))
    chunk_kernel(L.KIND_FLEXIBLE, L.LEVEL_OUTCOME)(rows, outs)
    return outs


def test_same_point_gives_bit_identical_results_alone_in_a_chunk_and_elsewhere():
    """Guards against results that depend on the chunk, its order, the worker or the process."""
    rows = _rows()
    assert len({int(o) for o in _chunk(rows)[:, L.OUT_OUTCOME]}) == 3  # all outcomes present
    alone = np.array([_chunk(rows[i:i + 1])[0] for i in range(len(rows))])
    in_chunk = _chunk(rows)
    perm = np.random.default_rng(5).permutation(len(rows))
    shuffled = np.empty_like(in_chunk)
    shuffled[perm] = _chunk(rows[perm])
    # two worker threads at once, outside the GIL (the sweep's local workers)
    halves = Parallel(n_jobs=2, backend="threading")(
        delayed(_chunk)(part) for part in np.array_split(rows, 2))
    workers = np.concatenate(halves)
    # and a fresh interpreter, fed the rows through a file
    code = ("import numpy as np, sys; from rocksweep.kernel import chunk_kernel; "
            "from rocksweep.kernel import layout as L; r = np.load(sys.argv[1]); "
            "o = np.empty((r.shape[0], L.N_OUT)); "
            "chunk_kernel(L.KIND_FLEXIBLE, L.LEVEL_OUTCOME)(r, o); np.save(sys.argv[2], o)")
    with tempfile.TemporaryDirectory() as d:
        np.save(f"{d}/rows.npy", rows)
        subprocess.run([sys.executable, "-c", code, f"{d}/rows.npy", f"{d}/outs.npy"],
                       check=True)
        other = np.load(f"{d}/outs.npy")
    for res in (in_chunk, shuffled, workers, other):
        assert res.tobytes() == alone.tobytes()  # bit-identical, NaNs included
