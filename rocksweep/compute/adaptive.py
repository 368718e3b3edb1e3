"""Adaptive stability diagrams: compute only where the class can change.

A stability diagram is large uniform regions (safe, mode 1, mode 2) separated by thin
boundaries. Over the two *diagram axes* (by default x = w_over_p, y = A_ratio; any two
swept axes with at least 2 values), for every value of the other axes (a *panel*):

1. coarse pass: the lattice L_s0, s0 = 2**coarse, i.e. every s0-th index of both diagram
   axes plus each axis's last index;
2. refinement, stride s = s0, s0/2, ..., 2: a cell of the stride-s lattice is *mixed* when
   the computed points inside it (closed: edges and corners included, at any resolution)
   hold more than one class. Mixed cells, dilated by ``margin`` cells across their edges
   (so a boundary that bends between samples is not lost; ``final_margin`` at the last
   level, s = 2, where a bend between samples is a one-point feature), get every point of
   the stride-s/2 lattice inside them computed. With ``final_margin`` = 0 (the default)
   the last two levels are lighter, where a bend between samples is one or two points:
   at s = 4 the margin cells get only their centre computed (a probe: if it differs, the
   cell is mixed and refined whole); at s = 2 a mixed cell whose corners differ gets its
   centre and the midpoints of the edges a boundary crosses (ends differ, or a one-point
   sliver through the centre runs on across the edge; see ``lattice.edge_points``), and the
   other edge midpoints are filled from their two agreeing ends. Measured on Figure 3(a)
   at 1000 x 1000 x 3 lam (``scripts/bench_adaptive.py --fine``): 3.77% of the points
   computed instead of 4.46%, 99.9990% of the outcomes equal to the full grid instead of
   99.9997%. What it misses are one-point specks on a boundary and one-point slivers
   (at 400 x 400, 0-70 cells of a scene instead of 0-44, docs/adaptive.md's table);
3. audit: a fixed pseudo-random share ``audit`` of all points (seeded, independent of the
   state) is computed once refinement has converged, i.e. a Bernoulli sample of the points
   that would be filled. An audit point whose class differs from its fill makes its cells
   mixed, so step 2 refines around it down to the final resolution;
4. fill: every point not computed takes the class of a uniform cell (all four corners
   computed, one class inside) that contains it (all such cells agree: nested or
   neighbouring cells share computed points), or else, in a mixed stride-2 cell, the
   class of the two agreeing ends of the edge it is the midpoint of.

The computed set is the least fixed point of step 2 above the coarse lattice (and, after
the audit, above the audit points): adding points only adds mixed cells, and every rule
of step 2 that reads classes (edge ends, a centre) only fires once those points are
computed and then holds for good, so the order in which batches are computed does not
matter. ``next_batch`` is therefore a pure function of
(outcome, computed): ``run_plan`` (the loop, written once, that the sweep driver
``rocksweep.compute.driver`` runs) calls it, computes the batch it returns (any workers, any
chunking; a point's result depends only on the point), stores the results and calls it
again, until it returns an empty batch; after a refine or audit batch it tells it which
points that batch held, so that it looks only at windows around them, with the same
result (``next_batch``'s ``near``). An interrupted sweep resumes from the file.

Per point, the state is two arrays over the grid's flat indices (``rocksweep.scene.grid``):
``outcome`` (int8, the kernel's class; read only where computed > 0) and ``computed``
(int8, the flags below). Filled points keep the "not computed" fill values of every other
variable (``rocksweep.compute.sweep.VARIABLES``).
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from rocksweep.compute import sweep as sw
from rocksweep.compute.lattice import (
    cell_blocks,
    cell_stats,
    centres,
    dilate,
    edge_fill,
    edge_points,
    lattice_points,
    points_of_cells,
)
from rocksweep.errors import AdaptiveError, ApiError, Arg, flag
from rocksweep.scene.grid import ChunkRows, Grid
from rocksweep.scene.model import Scene
from rocksweep.schema import check_option
from rocksweep.vocab import outcomes as _out
from rocksweep.vocab.axes import DIAGRAM_AXES
from rocksweep.vocab.settings import (
    ADAPTIVE_RESOLVED,
    ADAPTIVE_SETTINGS,
    DEFAULT_AUDIT,
    DEFAULT_AUDIT_THRESHOLD,
    DEFAULT_FINAL_MARGIN,
    DEFAULT_MARGIN,
    DEFAULT_SEED,
    MIN_COARSE_CELLS,
)

# ``computed`` flags (int8 per point).
# (codes, words and meanings: ``rocksweep.vocab.outcomes``)
FILLED = _out.COMPUTED_CODE[_out.FILLED]  # not computed: the class filled from its cell
COMPUTED = _out.COMPUTED_CODE[_out.COMPUTED]  # computed by the coarse pass or a refinement
AUDIT = _out.COMPUTED_CODE[_out.AUDIT_AGREED]  # an audit point; its class equals the fill
AUDIT_MISS = _out.COMPUTED_CODE[_out.AUDIT_DISAGREED]  # an audit point; differs (refined)
COMPUTED_MEANING = _out.COMPUTED_MEANING

# The settings' defaults (MIN_COARSE_CELLS, DEFAULT_MARGIN, ...): rocksweep.vocab.settings


@dataclass(frozen=True)
class Plan:
    """Where and how a grid is refined.

    full_shape: the grid's full shape (``Grid.full_shape``; flat indices are C-order in it);
    x, y: positions in full_shape of the two diagram axes; names: their names (x, y);
    coarse: the coarse pass takes every 2**coarse-th index; margin: cells [>= 0] refined
    around each mixed cell (across edges) at strides >= 4 (at stride 4, with final_margin
    0, only probed at their centre); final_margin: the same at the last level (stride 2),
    0 for the light last levels of the module docstring; audit: share in [0, 1] of all
    points that are audit candidates; seed: of the audit sample.
    """

    full_shape: tuple[int, ...]
    x: int
    y: int
    names: tuple[str, str] = DIAGRAM_AXES
    coarse: int | None = None  # None: default_coarse(ny, nx)
    margin: int = DEFAULT_MARGIN
    audit: float = DEFAULT_AUDIT
    seed: int = DEFAULT_SEED
    final_margin: int = DEFAULT_FINAL_MARGIN

    def __post_init__(self) -> None:
        if self.coarse is None:
            object.__setattr__(self, "coarse", default_coarse(self.full_shape[self.y],
                                                              self.full_shape[self.x]))
        # the ranges of the scene's refine: section (rocksweep.schema), as Options
        check_settings({n: getattr(self, n) for n in ("coarse", "margin", "final_margin",
                                                      "audit", "seed")})
        if self.x == self.y:
            raise AdaptiveError(f"diagram axes {self.names}: must be two different axes")
        for pos, name in zip((self.x, self.y), self.names, strict=True):
            if self.full_shape[pos] < 2:
                raise AdaptiveError(f"diagram axis {name} has {self.full_shape[pos]} value: "
                                    "the adaptive sweep needs >= 2 values on both axes")

    @property
    def size(self) -> int:
        return int(np.prod(self.full_shape, dtype=np.int64))

    @property
    def panel_shape(self) -> tuple[int, int, int]:
        """(panels, ny, nx): panels = product of the other axes' lengths."""
        ny, nx = self.full_shape[self.y], self.full_shape[self.x]
        return self.size // (nx * ny), ny, nx

    @property
    def strides(self) -> list[int]:
        """Cell sizes of the refinement levels, coarse to fine: 2**coarse, ..., 2."""
        return [2**k for k in range(self.coarse, 0, -1)]

    @property
    def in_order(self) -> bool:
        """The diagram axes are the grid's last two, y before x: the panels are the flat
        grid reshaped (``panels`` is a view, ``flat_index`` counts up)."""
        n = len(self.full_shape)
        return (self.y, self.x) == (n - 2, n - 1)

    def panels(self, a: np.ndarray) -> np.ndarray:
        """A flat per-point array (size,) as panels (panels, ny, nx), diagram axes last."""
        full = np.asarray(a).reshape(self.full_shape)
        return np.moveaxis(full, (self.y, self.x), (-2, -1)).reshape(self.panel_shape)

    def flat_index(self) -> np.ndarray:
        """int64[panels, ny, nx]: the flat grid index of every panel cell (read-only: one
        per plan, kept, ``_flat_index``)."""
        return _flat_index(self)


# A planning pass asked for the whole grid's index several times: ~4 ms each at 1000 x 1000
# x 3, 8% of a tail pass (a plan is a frozen, hashable value: one index per plan, the last
# few kept)
@functools.lru_cache(maxsize=4)
def _flat_index(plan: Plan) -> np.ndarray:
    idx = plan.panels(np.arange(plan.size, dtype=np.int64))
    idx.flags.writeable = False
    return idx


def make_plan(grid_or_scene: Grid | Scene, axes: Sequence[str] = DIAGRAM_AXES,
              coarse: int | None = None, margin: int = DEFAULT_MARGIN,
              audit: float = DEFAULT_AUDIT, seed: int = DEFAULT_SEED,
              final_margin: int = DEFAULT_FINAL_MARGIN) -> Plan:
    """The plan of a scene's grid. axes: (x, y) names of two swept axes; coarse: None for
    ``default_coarse`` of the grid. Raises AdaptiveError naming a bad axis."""
    given = grid_or_scene
    scene = given.scene if isinstance(given, Grid) else given
    names = [a.name for a in scene.axes]
    if isinstance(axes, str) or len(axes) != 2:
        raise AdaptiveError(f"axes = {axes!r}: give two axis names (x, y)")
    by_key = {a.key: a.name for a in scene.axes}
    # a dotted scene key (pulse.w_over_p) names its axis, as in refine.axes and plot's x
    axes = [by_key.get(a, a) if isinstance(a, str) else a for a in axes]
    pos = []
    for name in axes:
        if name not in names:
            raise AdaptiveError(f"axis {name!r}: not an axis of the scene (axes: "
                                f"{', '.join(names)})")
        ax = scene.axis(name)
        if name in ("shape", "law") or len(ax.values) < 2:  # word axes: no order
            raise AdaptiveError(f"axis {name} ({ax.key}): a diagram axis must be a swept "
                                f"numeric axis with >= 2 values (has {len(ax.values)})")
        pos.append(names.index(name))
    full_shape = tuple(len(a.values) for a in scene.axes)
    return Plan(full_shape, pos[0], pos[1], (str(axes[0]), str(axes[1])),
                None if coarse is None else _checked("coarse", coarse, int),
                _checked("margin", margin, int), _checked("audit", audit, float),
                _checked("seed", seed, int), _checked("final_margin", final_margin, int))



def check_settings(values: dict[str, Any]) -> None:
    """An ``AdaptiveError`` naming the first setting of ``values`` (name -> value; None:
    not given) outside its ``refine.<name>`` range (``rocksweep.schema``), ``margin = 9:
    must be an integer in [0, 8]``. The one check of the adaptive settings: the command
    line, ``Options``, ``make_plan`` and ``Plan`` call it."""
    for name, v in values.items():
        allowed = check_option(f"refine.{name}", v)
        if allowed is not None:
            raise AdaptiveError("{arg}: {allowed}", arg=Arg(name, v), allowed=allowed)


def _checked(name: str, v: Any, kind: type) -> Any:
    check_settings({name: v})
    return kind(v)


@dataclass(frozen=True)
class Options:
    """Settings of an adaptive sweep as a user gives them (``rocksweep.run(...,
    adaptive=True)``, the sweep command's adaptive options). axes: (x, y) diagram axis
    names; coarse: None for ``default_coarse``; audit: share of points audited, in [0, 1];
    threshold: share of disagreeing audit points above which a run warns, in [0, 1];
    margin, final_margin, seed: see ``Plan``."""

    axes: tuple[str, str] = DIAGRAM_AXES
    coarse: int | None = None
    audit: float = DEFAULT_AUDIT
    margin: int = DEFAULT_MARGIN
    final_margin: int = DEFAULT_FINAL_MARGIN
    seed: int = DEFAULT_SEED
    threshold: float = DEFAULT_AUDIT_THRESHOLD

    def __post_init__(self) -> None:
        check_settings({n: getattr(self, n) for n in ADAPTIVE_SETTINGS})

    def plan(self, grid_or_scene: Grid | Scene) -> Plan:
        """The plan of a grid (AdaptiveError for bad axes or settings)."""
        return make_plan(grid_or_scene, self.axes, self.coarse, self.margin, self.audit,
                         self.seed, self.final_margin)

    def resolved(self, grid_or_scene: Grid | Scene) -> dict[str, Any]:
        """The settings that decide the result, the default coarse level resolved: what a
        result file records and a resume compares (plain JSON values)."""
        p = self.plan(grid_or_scene)
        return {"axes": list(p.names), "coarse": int(p.coarse), "margin": int(p.margin),
                "final_margin": int(p.final_margin), "audit": float(p.audit),
                "seed": int(p.seed), "threshold": float(self.threshold)}

    @classmethod
    def from_resolved(cls, d: dict[str, Any]) -> Options:
        """Options from ``resolved`` (as read from a result file)."""
        return cls(tuple(d["axes"]), int(d["coarse"]), float(d["audit"]),
                   int(d["margin"]), int(d["final_margin"]), int(d["seed"]),
                   float(d["threshold"]))


def default_coarse(ny: int, nx: int) -> int:
    """Default coarse level of a ny x nx diagram: the largest k whose lattice (every
    2**k-th index) keeps at least MIN_COARSE_CELLS cells along both axes.

    A class region is sure to be sampled by the coarse pass only if it holds a whole
    coarse cell; smaller regions are found through the boundary they touch (refinement and
    margin) or by the audit. Measured (``scripts/bench_adaptive.py --study``, replaying
    every coarse level on the full grids): on the four figures, configs/block.yaml and two
    held-out scenes, at 80 x 80 and 400 x 400, every level from 1 to 7 (down to 3 cells per
    axis) gives the same outcomes: each region is either large or a speck (<= 8 points)
    on a boundary (the same few one-point specks and tips that the light last levels fill
    wrong at every level: 0-70 points of a scene at 400 x 400, 0 at 80 x 80 but one point
    of the block). Beyond 16 cells per axis a coarser lattice saves < 0.2% of the points
    (Figure 3(a) at 400 x 400: 6.12% computed at k = 4, 5.98% at k = 5), so 16 keeps
    every region with an extent above 1/8 of both axes sampled at almost no cost: k = 2
    at 80, 4 at 400, 5 at 1000.
    """
    k = 0
    while (min(ny, nx) - 1) / 2 ** (k + 1) >= MIN_COARSE_CELLS:
        k += 1
    return k


# --- the coarse lattice, the known classes, the audit sample ----------------------------

def plan_coarse(shape: Sequence[int], axes: tuple[int, int], level: int) -> np.ndarray:
    """Flat indices (int64, increasing) of the coarse lattice: every 2**level-th index of
    the axes at positions ``axes`` (x, y) of ``shape`` plus their last index, for every
    value of the other axes."""
    plan = Plan(tuple(shape), axes[0], axes[1], coarse=level, audit=0.0)
    return np.sort(lattice_points(plan.flat_index(), 2**level))


def _known(plan: Plan, outcome: np.ndarray, computed: np.ndarray,
           done: np.ndarray | None = None,
           window: tuple[int, slice, slice] | None = None) -> np.ndarray:
    """int8 panels: the class where computed, -1 elsewhere. done: computed > FILLED
    (bool[size]) where the caller has it; window: (panel, rows, columns), that part of
    the panels alone (int8[1, rows, columns])."""
    if window is not None:
        p, ys, xs = window
        c = plan.panels(computed)[p:p + 1, ys, xs] > FILLED
        return np.where(c, plan.panels(np.asarray(outcome, np.int8))[p:p + 1, ys, xs],
                        np.int8(-1))
    c = np.asarray(computed).ravel() > FILLED if done is None else done
    return plan.panels(np.where(c, np.asarray(outcome, np.int8).ravel(), np.int8(-1)))


@functools.lru_cache(maxsize=4)
def audit_mask(plan: Plan) -> np.ndarray:
    """bool[size]: the audit candidates, a fixed Bernoulli(audit) sample of all points
    (``seed``); those still filled once refinement has converged are computed. Read-only,
    one per plan (drawing it took ~20 ms at 1000 x 1000 x 3, asked for by every pass of
    the audit)."""
    mask = np.zeros(plan.size, bool)
    if plan.audit > 0:
        # drawn a block at a time: the same stream as one draw of them all (a double per
        # draw, in order), without its float64 temporary of 8 bytes a point, whose fresh
        # pages were most of the ~60 ms this took before an adaptive figure's first chunk
        rng, block = np.random.default_rng(plan.seed), np.empty(min(plan.size, 1 << 16))
        for i in range(0, plan.size, block.size):
            u = block[:min(block.size, plan.size - i)]
            rng.random(out=u)
            np.less(u, plan.audit, out=mask[i:i + u.size])
    mask.flags.writeable = False
    return mask


# --- the state machine --------------------------------------------------------------------

@dataclass(frozen=True)
class Batch:
    """Points to compute next: flat: int64[n], increasing; kind: "coarse" | "refine" |
    "audit" | "done" (flat empty); stride: the lattice the points complete (1 for audit).
    ahead: while the batch runs, the points (flat, int64[k], increasing) the next batch
    will want that the results so far already show (``Ahead``, set by ``run_plan``), for a
    runner to compute early (``compute.overlap.Runner``); None: not known."""

    flat: np.ndarray
    kind: str
    stride: int
    ahead: Callable[[], np.ndarray] | None = field(default=None, compare=False, repr=False)

    def __len__(self) -> int:
        return int(self.flat.size)


def next_batch(plan: Plan, outcome: np.ndarray, computed: np.ndarray,
               near: np.ndarray | None = None,
               prior: dict[int, np.ndarray] | None = None) -> Batch:
    """The next batch of points to compute, from the state alone (see module docstring).

    outcome, computed: int8[size] (or the grid's shape); outcome is read only where
    computed > 0. Order: the coarse lattice; then, at every level at once, the points of
    the refined cells not computed yet (all belong to the final computed set, whatever is
    computed later, so batching them together changes nothing but the number of rounds;
    stride: the coarsest level among them); once refinement has converged, the audit
    points not yet computed; then "done".

    near: the points (flat, int64[k]) of the last batch, where every point the refinement
    wanted before it is computed now (``run_plan`` after a refine or audit batch); the
    rules are then evaluated only in windows around them (``_windows``): the same batch,
    without a pass over the whole grid for each of the few points a boundary's last
    cells add (Figure 3(b) at 1000 x 1000 x 3 lam: 31 passes, 20 of them of 1-100
    points, at ~60 ms a pass on the sweep's critical path). None: the whole grid.
    prior: stride -> the points the refinement wanted at an earlier state (``Ahead``)
    where near holds every point computed since; those not computed yet are still wanted
    at the same level (the wants only grow), and every other want comes from near.
    """
    done = np.asarray(computed).ravel() > FILLED
    s0 = 2**plan.coarse
    coarse = lattice_points(plan.flat_index(), s0)
    missing = coarse[~done[coarse]]
    if missing.size:
        return Batch(np.sort(missing), "coarse", s0)
    wanted = _wanted_near(plan, outcome, computed, done, near)
    if prior is not None:
        wanted = _merged(wanted, prior, done)
    parts = [wanted[s] for s in plan.strides if s in wanted]
    if parts:
        stride = next(s for s in plan.strides if s in wanted) // 2
        return Batch(np.unique(np.concatenate(parts)), "refine", stride)
    missing = np.flatnonzero(audit_mask(plan) & ~done)
    if missing.size:
        return Batch(missing.astype(np.int64), "audit", 1)
    return Batch(np.empty(0, np.int64), "done", 0)


def _wanted_near(plan: Plan, outcome: np.ndarray, computed: np.ndarray, done: np.ndarray,
                 near: np.ndarray | None) -> dict[int, np.ndarray]:
    """``_wanted`` of the whole grid, or of the windows around the points ``near`` (flat,
    int64[k]; ``_windows``) where they are a small part of it (``next_batch``)."""
    windows = None if near is None else _windows(plan, near)
    if windows is None:
        return _wanted(plan, plan.flat_index(), _known(plan, outcome, computed, done), done)
    wanted: dict[int, list[np.ndarray]] = {}
    for p, ys, xs in windows:
        known = _known(plan, outcome, computed, window=(p, ys, xs))
        index = plan.flat_index()[p:p + 1, ys, xs]
        for s, pts in _wanted(plan, index, known, done).items():
            wanted.setdefault(s, []).append(pts)
    return {s: np.concatenate(v) for s, v in wanted.items()}


def _merged(wanted: dict[int, np.ndarray], prior: dict[int, np.ndarray], done: np.ndarray
            ) -> dict[int, np.ndarray]:
    """Stride -> wanted points: ``wanted``'s with ``prior``'s not computed yet (``done``,
    bool[size]) added, level by level (duplicates are left to the caller's unique)."""
    out = dict(wanted)
    for s, pts in prior.items():
        keep = pts[~done[pts]]
        if keep.size:
            out[s] = np.concatenate([out[s], keep]) if s in out else keep
    return out


class Ahead:
    """While a batch runs: the points (flat, int64[k], increasing) the refinement wants
    from the state as it stands, some of the batch's results in (``__call__``). All of them
    belong to the next batch, or to this one (the wants only grow with the computed set,
    module docstring), so a runner may compute them early (``compute.overlap.Runner``);
    and the next batch is planned from them (``next_batch``'s ``prior``) and the windows
    around the points computed since (``late``), not from the whole batch again.

    The first call looks in windows around the whole batch (a point wanted now and not
    when the batch was planned is wanted because of one of its points); each later one
    around the points computed since the one before, its wants added.
    """

    def __init__(self, plan: Plan, outcome: np.ndarray, computed: np.ndarray,
                 flat: np.ndarray) -> None:
        self.plan, self.outcome, self.computed = plan, outcome, computed
        self.late: list[np.ndarray] = [flat]  # computed since the last call (at first: all)
        self.wanted: dict[int, np.ndarray] | None = None  # at the last call

    def arrived(self, flat: np.ndarray) -> None:
        """The points ``flat`` (int64[n]) are in the state now."""
        if self.wanted is not None:
            self.late.append(flat)

    def __call__(self) -> np.ndarray:
        done = np.asarray(self.computed).ravel() > FILLED
        w = _wanted_near(self.plan, self.outcome, self.computed, done,
                         np.concatenate(self.late))
        if self.wanted is not None:
            w = _merged(w, self.wanted, done)
        self.wanted, self.late = w, []
        return np.unique(np.concatenate(list(w.values()))) if w else np.empty(0, np.int64)

    def next_hint(self, flat: np.ndarray) -> tuple[np.ndarray, dict[int, np.ndarray] | None]:
        """(near, prior) for ``next_batch`` once the batch ``flat`` is computed: the points
        computed since the last call and its wants, or the batch alone if never called."""
        if self.wanted is None:
            return flat, None
        return np.concatenate(self.late) if self.late else np.empty(0, np.int64), self.wanted


def _wanted(plan: Plan, index: np.ndarray, known: np.ndarray, done: np.ndarray
            ) -> dict[int, np.ndarray]:
    """Stride -> the points (flat, int64) not computed yet that the refinement rules of
    that level want in panels ``known`` (int8[P, ny, nx], -1: not computed) whose flat
    indices are ``index`` (int64[P, ny, nx]: whole panels, or windows of them cut on the
    coarse lattice, ``_windows``); levels that want none are left out."""
    out = {}
    cells = cell_stats(known, plan.strides)
    light = plan.final_margin == 0  # the last two levels' lighter rules (module docstring)
    for s in plan.strides:
        mixed = cells[s].mixed
        refine = dilate(mixed, plan.margin if s > 2 else plan.final_margin)
        if not refine.any():
            continue
        if s == 2 and light:
            want = edge_points(index, mixed, known)
            missing = want[~done[want]]
        elif s == 4 and light:
            probes = centres(index, refine, s)
            missing = np.concatenate([points_of_cells(index, mixed, s, known),
                                      probes[~done[probes]]])
        else:
            missing = points_of_cells(index, refine, s, known)
        if missing.size:
            out[s] = missing
    return out


def reach(plan: Plan) -> int:
    """How far [indices, along either diagram axis] a point the refinement wants lies from
    the points whose classes decide it: a level-s cell is mixed by the points in it, and
    its points are wanted up to ``margin`` cells (``final_margin`` at s = 2) across its
    edges; an edge midpoint of the last level reads the centres of the two cells beside
    it (``lattice.edge_points``)."""
    far = [(plan.margin + 1) * s if s > 2 else (plan.final_margin + 1) * s
           for s in plan.strides]
    return max(far + [4])


# Windows covering more than this share of the grid: the whole grid instead, one pass of
# numpy over all panels at once (the windows go one panel at a time)
WINDOWS_SHARE = 0.5


def _windows(plan: Plan, near: np.ndarray) -> list[tuple[int, slice, slice]] | None:
    """Where the rules need evaluating once the points ``near`` (flat, int64[k]) are
    computed and every point wanted before them is: per panel, the box around its points
    of ``near`` widened by twice ``reach`` and cut on the coarse lattice, as (panel, rows,
    columns). A point wanted now and not before is wanted because of one of them, so it
    lies within ``reach`` of it and every point it depends on within twice that: inside
    the box, whose cells are the grid's own (cut on the coarse lattice, or at the axis's
    end). What the box cuts off (cells beyond it) only hides wants that were wanted
    before, and are computed. None where the boxes would cover most of the grid (the
    whole grid is then no slower) or there is no refinement."""
    if not plan.strides or near.size == 0:
        return None
    P, ny, nx = plan.panel_shape
    near = np.asarray(near, np.int64)
    # (diagram axes last: a flat index is its own position; building the identity map of
    # 3M points took ~65 ms of the main thread, on the sweep's critical path)
    pos = near if plan.in_order else _panel_position(plan)[near]
    p, r = np.divmod(pos, ny * nx)
    y, x = np.divmod(r, nx)
    s0, w = 2**plan.coarse, 2 * reach(plan)
    out, area = [], 0
    for q in np.unique(p):
        m = p == q
        y0, y1 = (max(0, (int(y[m].min()) - w) // s0 * s0),
                  min(ny - 1, -(-(int(y[m].max()) + w) // s0) * s0))
        x0, x1 = (max(0, (int(x[m].min()) - w) // s0 * s0),
                  min(nx - 1, -(-(int(x[m].max()) + w) // s0) * s0))
        out.append((int(q), slice(y0, y1 + 1), slice(x0, x1 + 1)))
        area += (y1 - y0 + 1) * (x1 - x0 + 1)
    return None if area > WINDOWS_SHARE * plan.size else out


@functools.lru_cache(maxsize=4)
def _panel_position(plan: Plan) -> np.ndarray:
    """int64[size]: each flat index's position in the panels (p ny nx + y nx + x); the
    inverse of ``Plan.flat_index``, one per plan, read-only; for a plan not ``in_order``
    (in order, each index is its own position)."""
    pos = np.empty(plan.size, np.int64)
    pos[plan.flat_index().ravel()] = np.arange(plan.size, dtype=np.int64)
    pos.flags.writeable = False
    return pos


def fill(plan: Plan, outcome: np.ndarray, computed: np.ndarray) -> np.ndarray:
    """int8[size]: the computed class where computed > 0; elsewhere the class of the uniform
    cell (four corners computed, one class inside) around the point, coarsest first; -1
    where no such cell exists yet (never, once ``next_batch`` says "done")."""
    known = _known(plan, outcome, computed)
    out = known.copy()
    _, ny, nx = plan.panel_shape
    cells = cell_stats(known, plan.strides)
    for s in plan.strides:
        np.copyto(out, cell_blocks(cells[s].uniform_class, s, ny, nx), where=out < 0)
    if plan.strides and plan.final_margin == 0:
        np.copyto(out, edge_fill(known), where=out < 0)
    if plan.in_order:
        return out.reshape(-1)
    flat = np.empty(plan.size, np.int8)
    flat[plan.flat_index().ravel()] = out.ravel()
    return flat


def audit_before(plan: Plan, outcome: np.ndarray, computed: np.ndarray) -> np.ndarray:
    """int8[size]: the fill that audit points are compared with: ``fill`` of the state
    before the audit batch, i.e. of the points computed with flag COMPUTED alone.

    Before the audit batch every computed point has flag COMPUTED, so this is ``fill`` of
    the state; during the batch (a resumed sweep) the audit points already computed
    (AUDIT, AUDIT_MISS) are left out, so the flags of an interrupted and resumed audit
    equal those of an uninterrupted one.
    """
    base = (np.asarray(computed).ravel() == COMPUTED).astype(np.int8)
    return fill(plan, outcome, base)


@dataclass(frozen=True)
class Step:
    """What to compute next: the batch, and for an audit batch the fill its points are
    compared with (``audit_before``, int8[size]; None otherwise)."""

    batch: Batch
    before: np.ndarray | None = None

    def flags(self, flat: np.ndarray, classes: np.ndarray) -> np.ndarray:
        """int8[n]: the ``computed`` flags of the points ``flat`` (a subset of the batch)
        computed with ``classes``."""
        if self.before is None:
            return np.full(np.shape(flat), COMPUTED, np.int8)
        return audit_flags(self.before[flat], classes)


def next_step(plan: Plan, outcome: np.ndarray, computed: np.ndarray,
              near: np.ndarray | None = None,
              prior: dict[int, np.ndarray] | None = None) -> Step:
    """``next_batch``, except that an audit batch, once begun (some point flagged AUDIT or
    AUDIT_MISS while audit candidates are still filled), is finished before refinement
    resumes: the audit is one batch whatever interrupted it, so a resumed sweep computes
    the same points with the same flags as an uninterrupted one. Pure function of the
    state, like ``next_batch`` (near, prior: see there; an audit begun is finished in the
    batch after it began, or at a resume, with no prior)."""
    c = np.asarray(computed).ravel()
    if plan.audit > 0 and np.any(c >= AUDIT):
        missing = np.flatnonzero(audit_mask(plan) & (c == FILLED))
        if missing.size:
            return Step(Batch(missing.astype(np.int64), "audit", 1),
                        audit_before(plan, outcome, c))
    b = next_batch(plan, outcome, c, near, prior)
    return Step(b, audit_before(plan, outcome, c) if b.kind == "audit" else None)


def audit_flags(filled_before: np.ndarray, outcome: np.ndarray) -> np.ndarray:
    """int8[n]: AUDIT where the computed class equals the fill it replaces, else
    AUDIT_MISS. filled_before: ``fill(...)`` of the state before the audit batch, at the
    batch's points; outcome: the computed classes there."""
    same = np.asarray(filled_before) == np.asarray(outcome)
    return np.where(same, AUDIT, AUDIT_MISS).astype(np.int8)


# --- driving it -------------------------------------------------------------------------

@dataclass
class AdaptiveStats:
    """What an adaptive run did. points: grid size; computed: points computed (audit
    included); audited / audit_misses: audit points and those that disagreed with their
    fill; batches: (kind, stride, points) in order; threshold: warning level of the audit
    miss share; seconds: wall time."""

    points: int
    computed: int
    audited: int
    audit_misses: int
    batches: list[tuple[str, int, int]] = field(default_factory=list)
    threshold: float = DEFAULT_AUDIT_THRESHOLD
    seconds: float = 0.0

    @property
    def computed_share(self) -> float:
        return self.computed / self.points if self.points else 0.0

    @property
    def audit_miss_share(self) -> float:
        return self.audit_misses / self.audited if self.audited else 0.0

    @property
    def suspicious(self) -> bool:
        """More audit points disagreed than the threshold allows: features smaller than
        the coarse cell are likely missed; rerun with a lower coarse level."""
        return self.audit_miss_share > self.threshold

    def warning(self) -> str | None:
        if not self.suspicious:
            return None
        return (f"{self.audit_misses} of {self.audited} audit points "
                f"({100 * self.audit_miss_share:.2f}%) disagreed with the filled class "
                f"(threshold {100 * self.threshold:.2f}%): the diagram has features finer "
                "than the coarse cells; use a lower coarse level")


def stats_of(outcome_computed: np.ndarray, threshold: float = DEFAULT_AUDIT_THRESHOLD
             ) -> AdaptiveStats:
    """Counts from a ``computed`` flag array alone (what ``rocksweep info`` can print)."""
    c = np.asarray(outcome_computed).ravel()
    # a count per flag, not a bincount of an int64 copy (~10-50 ms at 3M points, at the
    # end of an adaptive sweep, its workers idle)
    n = {f: int(np.count_nonzero(c == f)) for f in (FILLED, AUDIT, AUDIT_MISS)}
    return AdaptiveStats(points=int(c.size), computed=int(c.size) - n[FILLED],
                         audited=n[AUDIT] + n[AUDIT_MISS], audit_misses=n[AUDIT_MISS],
                         threshold=threshold)


def run_plan(plan: Plan, outcome: np.ndarray, computed: np.ndarray,
             run: Callable[[Batch], Iterable[BatchResult]]
             ) -> Iterator[tuple[Batch, BatchResult, np.ndarray]]:
    """The adaptive loop, written once: plan a batch from the state (``next_step``), run it,
    record its classes and flags, until the plan says "done".

    outcome, computed: the state (flat, int8[size]), updated in place. run(batch): the
    batch's points' results, in chunks of any size and order (``BatchResult``: ``flat``
    and at least ``arrays["outcome"]``). Yields (batch, result, flags) for each result
    once it is in the state: the sweep driver (``compute.driver.adaptive_loop``) writes
    them to its sink; ``run_on_function`` only counts them.
    """
    # after a refine or audit batch: the batch (every point wanted before it is computed
    # now), or what ``Ahead`` saw while it ran (``next_batch``'s near and prior)
    near, prior = None, None
    while True:
        step = next_step(plan, outcome, computed, near=near, prior=prior)
        b = step.batch
        if b.kind == "done":
            return
        # (a coarse batch is planned before refinement has looked)
        ahead = None if b.kind == "coarse" else Ahead(plan, outcome, computed, b.flat)
        for res in run(b if ahead is None else replace(b, ahead=ahead)):
            cls = res.arrays["outcome"]
            flags = step.flags(res.flat, cls)
            outcome[res.flat] = cls
            computed[res.flat] = flags
            if ahead is not None:
                ahead.arrived(res.flat)
            yield b, res, flags
        # a refine batch is everything refinement wanted; an audit comes once it wants
        # nothing
        near, prior = (None, None) if ahead is None else ahead.next_hint(b.flat)


def run_on_function(plan: Plan, evaluate: Callable[[np.ndarray, Batch], np.ndarray],
                    outcome: np.ndarray | None = None, computed: np.ndarray | None = None,
                    threshold: float = DEFAULT_AUDIT_THRESHOLD
                    ) -> tuple[np.ndarray, np.ndarray, AdaptiveStats]:
    """The plan run over a class function instead of the kernel, ``evaluate(flat, batch) ->
    int8[n]`` (``run_plan``): how the planner is tested and benchmarked on a known diagram.
    Sweeps go through the sweep driver (``compute.driver``).

    outcome, computed: a state to resume from (flat, int8[size]); default: nothing
    computed. Returns the filled outcome (int8[size]), the computed flags (int8[size]) and
    the stats (with ``batches``: (kind, stride, points) per batch, and ``seconds``).
    """
    t0 = time.perf_counter()
    size = plan.size
    outcome = (np.full(size, -1, np.int8) if outcome is None
               else np.asarray(outcome, np.int8).ravel().copy())
    computed = (np.zeros(size, np.int8) if computed is None
                else np.asarray(computed, np.int8).ravel().copy())

    def run(b: Batch) -> list[BatchResult]:
        cls = np.asarray(evaluate(b.flat, b), np.int8)
        return [BatchResult(b.flat, {"outcome": cls}, 0.0, 0.0)]

    batches = [(b.kind, b.stride, len(b))
               for b, _res, _flags in run_plan(plan, outcome, computed, run)]
    filled = fill(plan, outcome, computed)
    st = stats_of(computed, threshold)
    st.batches, st.seconds = batches, time.perf_counter() - t0
    return filled, computed, st


@dataclass
class BatchResult:
    """Results of some points of a batch: flat: int64[n] (increasing), arrays: name ->
    array[n] (``rocksweep.compute.sweep.VARIABLES``), seconds / cpu_seconds of the chunk,
    refine_evaluations: int64[n], the RK4 evaluations of each point's certification, or
    None (``ChunkResult``)."""

    flat: np.ndarray
    arrays: dict[str, np.ndarray]
    seconds: float
    cpu_seconds: float
    refine_evaluations: np.ndarray | None = None

    @property
    def refine_total(self) -> int:
        """The RK4 evaluations of the certification of its points (0: none counted)."""
        r = self.refine_evaluations
        return 0 if r is None else int(r.sum())


class Subset:
    """A grid seen through a list of flat indices: what ``rocksweep.compute.sweep.run_chunk`` needs
    (``rows(start, stop)`` over positions in the list, ``kinds()``), so a batch runs through
    the chunk machinery (threads or dask) unchanged."""

    def __init__(self, grid: Grid, flat: np.ndarray) -> None:
        self.grid = grid
        self.scene = grid.scene
        self.flat = np.asarray(flat, np.int64)

    def rows(self, start: int, stop: int) -> ChunkRows:
        return self.grid.rows_at(self.flat[start:stop])

    def kinds(self) -> list[int]:
        return self.grid.kinds()


def run_batch(grid: Grid, flat: np.ndarray, jobs: int = 1, chunk_size: int | None = None,
              backend: str = "threads", scheduler: str | None = None,
              runner: Any = None, ahead: Callable[[], np.ndarray] | None = None
              ) -> Iterator[BatchResult]:
    """Compute the points ``flat`` (int64[n]) through ``rocksweep.compute.sweep.run_chunks``; yield
    each chunk's results as it finishes (any order). Results depend only on the point.
    runner: a sweep's ``compute.overlap.Runner`` (its worker threads, kept busy between
    batches), which then runs them instead, and computes the points ``ahead`` gives
    (``Batch.ahead``) early."""
    flat = np.asarray(flat, np.int64)
    if flat.size == 0:
        return
    if runner is not None:
        yield from runner.run(flat, ahead)
        return
    n_workers = sw.effective_jobs(jobs) if backend == "threads" else 1
    size = chunk_size or sw.auto_chunk_size(flat.size, n_workers)
    sub = Subset(grid, flat)
    chunks = sw.plan_chunks(np.ones(flat.size, bool), size)
    for r in sw.run_chunks(sub, chunks, sw.level(grid.scene), jobs, backend,  # type: ignore[arg-type]
                           scheduler):
        yield BatchResult(flat[r.start:r.stop], r.arrays, r.seconds, r.cpu_seconds,
                          r.refine_evaluations)


@dataclass
class Validation:
    """A check of a finished adaptive sweep against a coarse full grid: stride: of the
    lattice (every stride-th index of both diagram axes from stride // 2: an odd stride,
    so the lattice is not one the refinement computes); points: lattice points;
    checked: those that were filled (computed now; the others are kernel results
    already); differ: flat indices (int64, increasing) of the checked points whose
    kernel class differs from the fill, classes: those kernel classes."""

    stride: int
    points: int
    checked: int
    differ: np.ndarray
    classes: np.ndarray


def validate(grid: Grid, plan: Plan, outcome: np.ndarray, computed: np.ndarray,
             stride: int | None = None, jobs: int = 1, chunk_size: int | None = None,
             backend: str = "threads", scheduler: str | None = None) -> Validation:
    """Compute the filled points of a uniform lattice (default stride: half a coarse
    cell plus one, at least 3) and compare them with their fill (``--validate``).
    outcome: the filled classes, computed: the flags (int8[size] each). Nothing is
    written: the file keeps the adaptive result."""
    s = max(3, 2 ** (plan.coarse - 1) + 1) if stride is None else int(stride)
    if s < 1:
        raise AdaptiveError(f"validate stride = {s}: must be >= 1")
    _, ny, nx = plan.panel_shape
    ys, xs = np.arange(s // 2, ny, s), np.arange(s // 2, nx, s)
    lattice = np.sort(plan.flat_index()[:, ys][:, :, xs].ravel())
    filled = lattice[np.asarray(computed).ravel()[lattice] == FILLED]
    cls = np.full(filled.size, -1, np.int8)
    for res in run_batch(grid, filled, jobs, chunk_size, backend, scheduler):
        cls[np.searchsorted(filled, res.flat)] = res.arrays["outcome"]
    bad = cls != np.asarray(outcome).ravel()[filled]
    return Validation(s, int(lattice.size), int(filled.size), filled[bad], cls[bad])


def adaptive_options(adaptive: bool, base: dict | None = None,
                     **settings: Any) -> Options | None:
    """``Options`` from the API's keyword settings (None values: the defaults);
    None when not ``adaptive``, then any setting given is an ApiError. base: a scene's
    ``refine`` section (``Scene.refine``): it turns adaptive on, and the keyword settings
    override its values."""
    given = {k: v for k, v in settings.items() if v is not None}
    if base is not None:
        adaptive = True
        given = {**base, **given}
    known = set(ADAPTIVE_RESOLVED)
    unknown = sorted(set(given) - known)
    if unknown:
        raise AdaptiveError(f"{unknown[0]} = {given[unknown[0]]!r}: not a setting of an adaptive "
                       f"sweep (settings: {', '.join(sorted(known))})")
    if not adaptive:
        if given:
            k = sorted(given)[0]
            raise ApiError("{setting}: an adaptive setting; add {adaptive}",
                           setting=Arg(k, given[k]), adaptive=flag("adaptive"))
        return None
    if "axes" in given:
        axes = given["axes"]
        if isinstance(axes, str):
            axes = [a.strip() for a in axes.split(",")]
        given["axes"] = tuple(axes)
    return Options(**given)
