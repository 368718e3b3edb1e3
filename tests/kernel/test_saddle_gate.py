"""The loop's saddle gate (``loop._near_saddle``) never skips a step ``loop._saddle`` takes.

The loop tests ``_near_saddle`` before every call of ``_saddle`` (the closest approach to
the overturning saddle, OUT_MARGIN, which decides what the certification re-runs), so
the margin is bit-identical to taking ``_saddle`` at every free rocking step only if the
gate is conservative: wherever it says "far", ``_saddle`` would have left the margin as
it was. Checked on body rows of the shipped scenes (flexible and rigid) at states packed
around both edges of the gate and of ``_saddle``'s own window (|x| = 1/2, |v| = 1/2),
with the top mass displaced either way, and at random rocking states; the gate must also
skip most of the latter (else it buys nothing).
"""

from pathlib import Path

import numpy as np
import pytest
from numba import njit

from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel.loop import _near_saddle, _saddle, _saddle_bounds
from rocksweep.scene.grid import Grid
from rocksweep.scene.parse import load_scene

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@njit(cache=False)
def _gate_and_full(prm, states, sides):
    """(near, margin) per state: the gate's verdict and ``_saddle``'s margin from inf."""
    n = states.shape[0]
    near = np.empty(n, np.bool_)
    margin = np.empty(n)
    bounds = _saddle_bounds(prm)
    for i in range(n):
        y = (states[i, 0], states[i, 1], states[i, 2], states[i, 3], 0.0, 0.0)
        near[i] = _near_saddle(y, sides[i], bounds)
        margin[i] = _saddle(y, sides[i], prm)
    return near, margin


def _rows(name: str, n: int) -> np.ndarray:
    grid = Grid(load_scene(CONFIGS / f"{name}.yaml"))
    take = np.linspace(0, grid.size - 1, n).astype(np.int64)
    return grid.rows_at(take).rows


def _edge_states(prm: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """States packed around |x| = 1/2 and |v| = 1/2 (relative offsets 1e-16 .. 1e-2 either
    way), u of either sign (the saddle theta_s moves with u) or 0, on both corners."""
    a = prm[L.PAR_ALPHA_REF]
    b, hcg, m, mtot = prm[L.PAR_B], prm[L.PAR_HCG], prm[L.PAR_M], prm[L.PAR_MTOT]
    eps = np.concatenate([[0.0], np.logspace(-16, -2, 29)])
    offs = np.concatenate([-eps, eps])
    us = [0.0, 0.3 * b, -0.3 * b, 0.02 * b, -0.02 * b] if m > 0.0 else [0.0]
    states, sides = [], []
    for s in (1, -1):
        for u in us:
            th_s = np.arctan((b - s * m * u / mtot) / hcg)
            for k in (-0.5, 0.5):
                for o in offs:
                    theta = s * (th_s + k * a * (1.0 + o))
                    for w in (0.0, 0.5 * a * (1.0 - 1e-12), 0.5 * a * (1.0 + 1e-12)):
                        for sw in (1.0, -1.0):
                            states.append((theta, sw * w, u, rng.normal()))
                            sides.append(s)
            for o in offs:  # |v| = 1/2 at the saddle itself
                for sw in (1.0, -1.0):
                    states.append((s * th_s, sw * 0.5 * a * (1.0 + o), u, 0.0))
                    sides.append(s)
    return np.array(states), np.array(sides, np.int64)


def _rocking_states(prm: np.ndarray, rng: np.random.Generator,
                    n: int) -> tuple[np.ndarray, np.ndarray]:
    """Random rocking states: |theta| up to 1.3 alpha_ref, |theta'| up to alpha_ref."""
    a, b = prm[L.PAR_ALPHA_REF], prm[L.PAR_B]
    sides = rng.choice(np.array([1, -1]), n)
    theta = sides * rng.uniform(0.0, 1.3 * a, n)
    states = np.column_stack([theta, rng.uniform(-a, a, n),
                              rng.normal(0.0, 0.05 * b, n) if prm[L.PAR_M] > 0 else np.zeros(n),
                              np.zeros(n)])
    return states, sides


@pytest.mark.parametrize("name", ["fig3a", "fig4b", "fig4a-rigid", "block"])
def test_the_gate_never_skips_a_step_the_saddle_test_takes(name):
    rng = np.random.default_rng(7)
    skipped_share = []
    for prm in _rows(name, 6):
        for states, sides in (_edge_states(prm, rng), _rocking_states(prm, rng, 4000)):
            near, margin = _gate_and_full(prm, np.ascontiguousarray(states), sides)
            # "far" only where the full test finds nothing (margin stays inf)
            assert np.all(np.isinf(margin[~near])), states[~near & np.isfinite(margin)][:3]
        # the full test does take some of these states: the check above is not vacuous
        assert np.isfinite(margin).any()
        skipped_share.append(np.mean(~near))
    assert min(skipped_share) > 0.5  # most rocking states are skipped


def test_a_row_without_a_body_takes_the_full_test_everywhere():
    prm = np.zeros(L.N_PAR)  # warm_up's row: h_cg = 0 (no gate, no division)
    prm[L.PAR_ALPHA_REF] = 0.2
    bounds = _saddle_bounds(prm)
    assert np.isnan(bounds[1])
    for state in ((0.0, 0.0, 0.0, 0.0, 0.0, 0.0), (1.0, 0.05, 0.0, 0.0, 0.0, 0.0)):
        assert _near_saddle(state, 1, bounds)
