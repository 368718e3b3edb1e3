"""Boundaries of a stability diagram: labelled polylines and the overturning threshold.

For every panel (a value of each non-diagram axis: shape, body keys, lam) of a diagram over
(x, y) = (w_over_p, A_ratio) by default:

- ``boundary_lines``: the lines separating two classes, as polylines in axis values,
  labelled by the pair of classes (marching squares on the class map: a line crosses each
  edge between two differing grid points at its midpoint; in a cell with three classes
  every crossing joins the cell's centre, a triple junction);
- ``a_min``: A_min(w_over_p), the smallest A_ratio that overturns, with the mode it
  overturns in: the first overturning grid value of each column, refined by bisection in
  A_ratio between it and the grid value below (single kernel runs at the sweep's numerics)
  to a relative tolerance, so the curve is not limited by the grid spacing.

Rows for CSV (``a_min_rows``, ``boundary_rows``; ``analysis.files.csv_text``) export
them; the figures are ``rocksweep.figures.a_min.a_min_figure`` and the curves of
``rocksweep plot --curves`` (``figures.panels.draw_boundaries``).
``result_curves`` does it all for a result file (``rocksweep boundaries``). Units: those
of the axes (w_over_p = omega/p, A_ratio = A/(g tan alpha_cg), eq. 2).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from rocksweep import fields
from rocksweep.analysis.bisection import bisect_thresholds
from rocksweep.analysis.tolerance import DEFAULT_RTOL
from rocksweep.compute.adaptive import make_plan
from rocksweep.compute.dispatch import run_variant
from rocksweep.errors import (
    MAX_RTOL,
    AdaptiveError,
    ApiError,
    BoundaryError,
    check_rtol,
)
from rocksweep.fields import plain
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel import warm_up
from rocksweep.numerics import MAX_POINT_STEPS
from rocksweep.physics.points import Point, kernel_kind, points_rows
from rocksweep.scene.grid import Grid
from rocksweep.scene.model import Scene
from rocksweep.vocab.axes import DIAGRAM_AXES
from rocksweep.vocab.kinds import BOUNDARIES, KIND_ATTR
from rocksweep.vocab.outcomes import OUTCOME_MODE1, OUTCOME_MODE2, outcome_word

if TYPE_CHECKING:
    from rocksweep.store.reader import SweepResult

OVERTURNED = (OUTCOME_MODE1, OUTCOME_MODE2)


# --- panels -----------------------------------------------------------------------------

@dataclass(frozen=True)
class Panel:
    """One diagram: where: value of every swept non-diagram axis (name -> value); x, y:
    the diagram axes' values (float64[nx], [ny]); classes: int8[ny, nx]; flat: the grid's
    flat index of each cell, int64[ny, nx]."""

    where: dict[str, Any]
    x: np.ndarray
    y: np.ndarray
    classes: np.ndarray
    flat: np.ndarray


def panels(scene: Scene, outcome: np.ndarray, axes: Sequence[str] = DIAGRAM_AXES
           ) -> Iterator[Panel]:
    """The panels of a result (outcome: int8 array of the grid's shape or flat), in the
    grid's order of the other axes."""
    plan = make_plan(scene, axes, coarse=0, audit=0.0)
    outcome = np.asarray(outcome)
    if outcome.size != plan.size:
        raise AdaptiveError(f"outcome has {outcome.size} points; the scene's grid has "
                            f"{plan.size}")
    cls = plan.panels(outcome.ravel())
    idx = plan.flat_index()
    grid = Grid(scene)
    others = [a for i, a in enumerate(scene.axes) if i not in (plan.x, plan.y) and a.swept]
    x = np.asarray(scene.axis(axes[0]).values, float)
    y = np.asarray(scene.axis(axes[1]).values, float)
    for p in range(cls.shape[0]):
        values = grid.index_values(idx[p, :1, 0])
        where = {a.name: plain(values[a.name][0]) for a in others}
        yield Panel(where, x, y, cls[p], idx[p])


# --- boundary lines ---------------------------------------------------------------------

@dataclass(frozen=True)
class BoundaryLine:
    """A polyline separating two classes: classes (a, b), a < b (0 safe, 1 mode 1, 2 mode
    2); xy: float64[n, 2], (x, y) in axis values; closed when its ends coincide."""

    classes: tuple[int, int]
    xy: np.ndarray

    @property
    def label(self) -> str:
        return f"{outcome_word(self.classes[0])}|{outcome_word(self.classes[1])}"


def _node_xy(node: tuple[int, int], x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """Position of a node in doubled index coordinates (2 row, 2 col): grid points are
    even/even, edge midpoints odd in one coordinate, cell centres odd/odd."""
    r, c = node

    def at(v: np.ndarray, k: int) -> float:
        return float(v[k // 2]) if k % 2 == 0 else 0.5 * float(v[k // 2] + v[k // 2 + 1])

    return at(x, c), at(y, r)


def boundary_segments(classes: np.ndarray) -> list[tuple[tuple[int, int], tuple, tuple]]:
    """Marching squares on a class map (int[ny, nx]): segments (pair, node, node), nodes in
    doubled index coordinates (see ``_node_xy``), pair = (a, b), a < b."""
    C = np.asarray(classes)
    ny, nx = C.shape
    diff_cell = np.zeros((max(ny - 1, 0), max(nx - 1, 0)), bool)
    if ny > 1 and nx > 1:
        a, b, c, d = C[:-1, :-1], C[:-1, 1:], C[1:, 1:], C[1:, :-1]
        diff_cell = (a != b) | (b != c) | (c != d) | (d != a)
    segs = []
    for i, j in zip(*np.nonzero(diff_cell), strict=True):
        i, j = int(i), int(j)
        # corners counter-clockwise from bottom-left; edge k joins corner k and k + 1
        corner = [C[i, j], C[i, j + 1], C[i + 1, j + 1], C[i + 1, j]]
        nodes = [(2 * i, 2 * j + 1), (2 * i + 1, 2 * j + 2), (2 * i + 2, 2 * j + 1),
                 (2 * i + 1, 2 * j)]
        cross = [(k, tuple(sorted((int(corner[k]), int(corner[(k + 1) % 4])))))
                 for k in range(4) if corner[k] != corner[(k + 1) % 4]]
        if len(cross) == 2:
            segs.append((cross[0][1], nodes[cross[0][0]], nodes[cross[1][0]]))
        elif len(cross) == 4 and len(set(int(v) for v in corner)) == 2:
            # saddle: cut off the bottom-left and top-right corners (a fixed choice)
            segs.append((cross[0][1], nodes[0], nodes[3]))
            segs.append((cross[1][1], nodes[1], nodes[2]))
        else:  # three or four classes meet: every crossing joins the centre
            centre = (2 * i + 1, 2 * j + 1)
            segs.extend((pair, nodes[k], centre) for k, pair in cross)
    return segs


def _chain(edges: list[tuple[tuple, tuple]]) -> list[list[tuple]]:
    """Join segments sharing ends into polylines: paths between nodes of degree != 2
    first, then the remaining cycles."""
    adj: dict[tuple, list[int]] = defaultdict(list)
    for k, (u, v) in enumerate(edges):
        adj[u].append(k)
        adj[v].append(k)
    used = [False] * len(edges)

    def walk(start: tuple, k: int) -> list[tuple]:
        path = [start]
        node = start
        while True:
            used[k] = True
            u, v = edges[k]
            node = v if u == node else u
            path.append(node)
            if len(adj[node]) != 2:
                return path
            nxt = [e for e in adj[node] if not used[e]]
            if not nxt:
                return path
            k = nxt[0]

    lines = []
    for node in sorted(adj):
        if len(adj[node]) != 2:
            for k in adj[node]:
                if not used[k]:
                    lines.append(walk(node, k))
    for k in range(len(edges)):
        if not used[k]:
            lines.append(walk(edges[k][0], k))
    return lines


def boundary_lines(classes: np.ndarray, x: np.ndarray, y: np.ndarray) -> list[BoundaryLine]:
    """The boundary polylines of one diagram. classes: int[ny, nx] (y rows, x columns);
    x: float64[nx], y: float64[ny] axis values. Sorted by classes, then by length (longest
    first)."""
    by_pair: dict[tuple[int, int], list] = defaultdict(list)
    for pair, u, v in boundary_segments(classes):
        by_pair[pair].append((u, v))
    out = []
    for pair in sorted(by_pair):
        lines = [np.array([_node_xy(n, x, y) for n in path]) for path in _chain(by_pair[pair])]
        lines.sort(key=lambda a: -len(a))
        out.extend(BoundaryLine(pair, xy) for xy in lines)
    return out


@dataclass(frozen=True)
class PanelBoundaries:
    """The boundary lines of one panel (``where``: its non-diagram axis values)."""

    where: dict[str, Any]
    lines: list[BoundaryLine]
    xname: str = DIAGRAM_AXES[0]
    yname: str = DIAGRAM_AXES[1]


def diagram_boundaries(scene: Scene, outcome: np.ndarray,
                       axes: Sequence[str] | None = None) -> list[PanelBoundaries]:
    """Boundary lines of every panel of a result (outcome: filled, no -1); axes: the
    diagram's (None: the scene's, ``default_axes``)."""
    axes = default_axes(scene) if axes is None else axes
    return [PanelBoundaries(p.where, boundary_lines(p.classes, p.x, p.y), axes[0], axes[1])
            for p in panels(scene, outcome, axes)]


def default_axes(scene: Scene) -> tuple[str, str]:
    """The diagram axes of a scene: (w_over_p, A_ratio) for a pulse, (p, A_ratio) for a
    record (its time scale is the body's p)."""
    return (scene.freq_axis, DIAGRAM_AXES[1])


# --- A_min ------------------------------------------------------------------------------

# How a column's A_min was found (``AMinCurve.method``, the Dataset's ``A_min_method``):
A_MIN_METHODS = (
    "grid+bisection",       # the first overturning grid value, bisected with the one below
    "searched below grid",  # an overturning value found by the search below (or, in a
                            # column where no grid value overturns, between) the grid values
    "first grid value",     # the lowest grid value overturns: an upper bound only
    "not found",            # nothing overturns on the grid nor in the search: NaN
)
# The search below the first overturning grid value (``_search_intervals``) scans grid
# intervals at interior values spaced (relative to A) by: NEAR_STEP from the last value
# without uplift up to NEAR_SPAN x the first uplifting value (the narrow first bands just
# above the uplift threshold at omega/p ~ 1: 0.01-0.1 wide at A ~ 1), FAR_STEP
# from there up to UPLIFT_SPAN x it, and FAR_STEP in the intervals with an end whose
# max|theta|/alpha_ref >= CLOSE (it came close to overturning), closest first; at most
# SEARCH_RUNS kernel runs a column (a grid finer than the spacing adds none).
NEAR_SPAN, NEAR_STEP = 1.3, 0.005
UPLIFT_SPAN, FAR_STEP = 2.0, 0.02
CLOSE = 0.5
SEARCH_RUNS = 128
# Bound on the RK4 evaluations the refinement of one result may cap its runs at (the sum of
# the runs' step caps, PAR_MAXSTEPS, over the search and the bisection's iterations): 1e4
# points at the largest cap a point may have (``numerics.MAX_POINT_STEPS``).
MAX_REFINE_STEPS = 1e4 * MAX_POINT_STEPS


@dataclass
class AMinCurve:
    """A_min along x for one panel.

    where: non-diagram axis values; x: float64[nx] (w_over_p); a_min: float64[nx], the
    smallest y (A_ratio) that overturns (NaN: none found); mode: int8[nx], the class at
    a_min (1, 2; 0 where NaN); lo, hi: float64[nx], the final bracket (lo does not
    overturn, hi does; lo = NaN when the column's first grid value already overturns, then
    a_min = that value and is only an upper bound); runs: kernel runs spent on the column
    (search and bisection); method: int8[nx], index into A_MIN_METHODS (how a_min was
    found); searched: kernel runs of the search below the grid's first overturning value.
    """

    where: dict[str, Any]
    x: np.ndarray
    a_min: np.ndarray
    mode: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    runs: np.ndarray
    xname: str = DIAGRAM_AXES[0]
    yname: str = DIAGRAM_AXES[1]
    target: tuple[int, ...] = field(default=OVERTURNED)
    method: np.ndarray | None = None
    searched: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = len(self.x)
        if self.method is None:
            self.method = np.full(n, A_MIN_METHODS.index("not found"), np.int8)
        if self.searched is None:
            self.searched = np.zeros(n, np.int64)

    @property
    def method_words(self) -> list[str]:
        """How each a_min was found, as words of A_MIN_METHODS."""
        return [A_MIN_METHODS[int(k)] for k in self.method]


Evaluator = Callable[[list[Point]], np.ndarray]


def kernel_rows(scene: Scene, points: list[Point]) -> np.ndarray:
    """The kernel's result rows float64[n, N_OUT] of arbitrary points, one run each
    (outcome-only kernel, the scene's sweep numerics, close calls certified as the grid's
    were: ``compute.dispatch.run_variant``), for every ground motion, each on its
    excitation's ground variant (``Point.ground``)."""
    outs = np.empty((len(points), L.N_OUT))
    # the rows of all points at once (``points.points_rows``); one kernel call per body
    # kind and excitation (whose samples ride on its rows)
    rows, excitations, which = points_rows(points, scene.numerics)
    kinds = np.array([kernel_kind(p.body) for p in points], np.int64)
    groups = np.unique(np.stack([kinds, which], 1), axis=0)
    for kind, j in groups.tolist():
        idx = np.flatnonzero((kinds == kind) & (which == j))
        ex = excitations[j]
        warm_up(kind, L.LEVEL_OUTCOME, ex.ground)
        # the close calls re-run finer, as the sweep's did (``compute.certify``)
        outs[idx] = run_variant(rows[idx], kind, L.LEVEL_OUTCOME, ex.ground,
                                scene.numerics.refine, excitation=ex)
    return outs


def kernel_evaluator(scene: Scene) -> Evaluator:
    """Classes (int8[n]) of arbitrary points, one kernel run each (``kernel_rows``)."""

    def evaluate(points: list[Point]) -> np.ndarray:
        return kernel_rows(scene, points)[:, L.OUT_OUTCOME].astype(np.int8)

    return evaluate


@dataclass
class _Column:
    """One column's A_min search: its curve and index, the grid's values of the other
    axes, the first overturning grid index (ny: none) and what the grid says of it."""

    curve: AMinCurve
    j: int
    values: dict[str, Any]
    first: int
    theta: np.ndarray  # the column's max|theta|/alpha_ref at the grid values (NaN: unknown)
    uplifts: np.ndarray  # its uplift counts (-1: unknown)
    base: Point | None = None  # the column's first grid point (its body object is shared)

    def point(self, scene: Scene, name: str, value: float) -> Point:
        """The column's point with ``name`` (the searched axis) = value: the first grid
        point with A_ratio replaced (one body object for the column: its rows are filled
        at once), else ``scene.point``."""
        if name != "A_ratio" or scene.suite is not None or scene.path is not None:
            return scene.point({**self.values, name: value})
        if self.base is None:
            self.base = scene.point(self.values)
        return replace(self.base, A_ratio=float(value))


def _search_intervals(y: np.ndarray, first: int, theta: np.ndarray, uplifts: np.ndarray
                      ) -> list[tuple[int, int]]:
    """The grid intervals (k, k + 1) of one column, k + 1 <= first, to scan below its first
    overturning value (first = len(y): none overturns), as (k, interior values), in the
    order they are scanned: near the uplift threshold, above it, then where the response
    came close (NEAR_SPAN, UPLIFT_SPAN, CLOSE), at most SEARCH_RUNS values in all.
    theta: max|theta|/alpha_ref at the grid values (NaN: unknown); uplifts (-1: unknown,
    counted as uplifted)."""
    last = min(first, len(y) - 1)  # intervals (k, k + 1) with k + 1 <= last
    if last < 1:
        return []

    def values(k: int, step: float) -> int:
        return max(0, math.ceil((y[k + 1] - y[k]) / (step * abs(y[k + 1]))) - 1)

    out: list[tuple[int, int]] = []
    lifted = np.flatnonzero(uplifts[:last + 1] != 0)
    if lifted.size:
        u = int(lifted[0])
        out = [(k, values(k, NEAR_STEP if y[k] < NEAR_SPAN * y[u] else FAR_STEP))
               for k in range(max(u - 1, 0), last) if y[k] < UPLIFT_SPAN * y[u]]
    seen = {k for k, _ in out}
    th = np.nan_to_num(theta[:last + 1], nan=0.0)
    close = sorted((-max(th[k], th[k + 1]), k) for k in range(last)
                   if k not in seen and max(th[k], th[k + 1]) >= CLOSE)
    out += [(k, values(k, FAR_STEP)) for _, k in close]
    kept, runs = [], 0
    for k, n in out:
        n = min(n, SEARCH_RUNS - runs)
        if n > 0:
            kept.append((k, n))
            runs += n
    return kept


def check_amplitudes(scene: Scene, name: str) -> np.ndarray:
    """The values (float64[ny]) of the axis A_min is searched along (``name``, A_ratio),
    or a one-line AdaptiveError naming its key and values: it needs at least two,
    increasing."""
    names = [a.name for a in scene.axes]
    if name not in names:  # a record suite's stripes: no A_ratio axis
        raise AdaptiveError(f"{name}: not an axis of the scene (axes: {', '.join(names)})")
    ax = scene.axis(name)
    yv = np.asarray(ax.values, float)
    if yv.size < 2:
        raise AdaptiveError(f"{ax.key} = {yv.tolist()}: A_min needs a sweep over at least "
                            "two values of it")
    if not np.all(np.diff(yv) > 0):
        raise AdaptiveError(f"{ax.key}: A_min needs increasing values")
    return yv


def _bisection_steps(lo: float, hi: float, rtol: float) -> int:
    """Iterations that bisect (lo, hi) to rtol (relative to lo), bounded by float64's."""
    return int(min(60, max(0, math.ceil(math.log2(max(hi - lo, 1e-300) / (rtol * abs(lo)
                                                                           or 1e-300))))))


def a_min(scene: Scene, outcome: np.ndarray, rtol: float = DEFAULT_RTOL,
          axes: Sequence[str] = DIAGRAM_AXES, mode: int | None = None,
          evaluate: Evaluator | None = None, theta: np.ndarray | None = None,
          uplifts: np.ndarray | None = None, search: bool = True) -> list[AMinCurve]:
    """A_min(x) of every panel: the smallest y (A_ratio) that overturns, to ``rtol``
    (relative), whatever the grid's spacing.

    outcome: the grid's classes (filled, grid shape or flat); y (axes[1]) must have
    increasing values, at least two. theta, uplifts: the grid's max|theta|/alpha_ref and
    uplift counts (grid shape or flat; None or NaN / -1 at a point: unknown), which say
    where to search. mode: None for any overturning (mode 1 or 2; the curve's ``mode``
    says which), 1 or 2 for the smallest y where that mode occurs. evaluate: classes of a
    list of points (default: one kernel run each at the sweep's numerics). search: False
    bisects between the grid's first overturning value and the one below only (cheaper;
    A_min then depends on the grid: every value says "grid+bisection").

    Per column: first a search below the first overturning grid value (or in the whole
    column when none overturns) for a band narrower than the grid step: the intervals
    near the uplift threshold and those whose ends came close to overturning are scanned
    at interior values (``_search_intervals``; at most SEARCH_RUNS runs); the lowest
    overturning value found (scanned or on the grid) is then bisected with the value
    below it to ``rtol``. ``method`` says how each A_min was found (A_MIN_METHODS). A band
    narrower than the scan's spacing in an interval the search does not visit stays
    unseen. Raises a one-line AdaptiveError for an rtol outside (0, MAX_RTOL], a y axis
    with fewer than two or non-increasing values, or a refinement whose
    runs' step caps would exceed MAX_REFINE_STEPS.
    """
    rtol = check_rtol(rtol, AdaptiveError)
    if mode not in (None, OUTCOME_MODE1, OUTCOME_MODE2):
        raise AdaptiveError(f"mode = {mode!r}: must be None (any), 1 or 2")
    target = OVERTURNED if mode is None else (mode,)
    yv = check_amplitudes(scene, axes[1])
    evaluate = evaluate or kernel_evaluator(scene)
    grid = Grid(scene)
    n_grid = np.asarray(outcome).size
    theta = (np.full(n_grid, np.nan) if theta is None
             else np.asarray(theta, float).ravel())
    uplifts = (np.full(n_grid, -1) if uplifts is None else np.asarray(uplifts).ravel())
    searched = A_MIN_METHODS.index("searched below grid")

    def values_at(flat: int) -> dict[str, Any]:
        return {k: plain(v[0]) for k, v in grid.index_values(np.array([flat])).items()}

    curves, cols = [], []
    for p in panels(scene, outcome, axes):
        nx = p.x.size
        hit = np.isin(p.classes, target)
        first = np.where(hit.any(axis=0), hit.argmax(axis=0), yv.size)
        c = AMinCurve(p.where, p.x, np.full(nx, np.nan), np.zeros(nx, np.int8),
                      np.full(nx, np.nan), np.full(nx, np.nan), np.zeros(nx, np.int64),
                      axes[0], axes[1], target)
        for j in range(nx):
            col = _Column(c, j, values_at(int(p.flat[0, j])), int(first[j]),
                          theta[p.flat[:, j]], uplifts[p.flat[:, j]])
            if col.first < yv.size:
                c.hi[j], c.mode[j] = yv[col.first], p.classes[col.first, j]
                c.method[j] = A_MIN_METHODS.index("grid+bisection")
                if col.first > 0:
                    c.lo[j] = yv[col.first - 1]
            cols.append(col)
        curves.append(c)

    # the search's points, and the step budget of the whole refinement
    plan: list[tuple[_Column, list[float]]] = []
    for col in cols if search else ():
        scan = []
        for k, n in _search_intervals(yv, col.first, col.theta, col.uplifts):
            scan += list(np.linspace(yv[k], yv[k + 1], n + 2)[1:-1])
        if scan:
            plan.append((col, sorted(set(scan))))
    _check_budget(scene, axes, cols, plan, yv, rtol)
    pts = [col.point(scene, axes[1], a) for col, scan in plan
           for a in scan]
    cls = evaluate(pts) if pts else np.zeros(0, np.int8)
    at = 0
    for col, scan in plan:
        c, j = col.curve, col.j
        k = cls[at:at + len(scan)]
        at += len(scan)
        c.runs[j] += len(scan)
        c.searched[j] += len(scan)
        over = np.flatnonzero(np.isin(k, target))
        if over.size == 0:  # all below the first overturning grid value: a tighter lo
            if not math.isnan(c.lo[j]):
                c.lo[j] = max([c.lo[j], *(a for a in scan if a < c.hi[j])])
            continue
        i = int(over[0])
        c.hi[j], c.mode[j] = scan[i], k[i]
        if col.first == 0 or col.first == yv.size or scan[i] < yv[col.first - 1]:
            c.method[j] = searched  # not in the bracket the grid gives
        # the largest value below it known not to overturn: a scan value or a grid value
        below = [*scan[:i], *(float(v) for v in yv if v < scan[i])]
        c.lo[j] = max(below) if below else math.nan
    for col in cols:
        c, j = col.curve, col.j
        if math.isnan(c.hi[j]):
            c.method[j] = A_MIN_METHODS.index("not found")
        elif math.isnan(c.lo[j]):
            c.method[j] = A_MIN_METHODS.index("first grid value")
    todo = [col for col in cols if not math.isnan(col.curve.lo[col.j])]
    lo, hi = (np.array([getattr(col.curve, e)[col.j] for col in todo], float)
              for e in ("lo", "hi"))
    modes = np.array([col.curve.mode[col.j] for col in todo], np.int64)

    def classify(idx: np.ndarray, mids: np.ndarray) -> np.ndarray:
        return evaluate([todo[i].point(scene, axes[1], m)
                         for i, m in zip(idx, mids, strict=True)])

    runs, _ = bisect_thresholds(lo, hi, modes, rtol, classify, target)
    for q, col in enumerate(todo):
        c, j = col.curve, col.j
        c.lo[j], c.hi[j], c.mode[j] = lo[q], hi[q], modes[q]
        c.runs[j] += runs[q]
    for c in curves:
        c.a_min[:] = c.hi
        c.mode[np.isnan(c.hi)] = 0
    return curves


def _check_budget(scene: Scene, axes: Sequence[str], cols: list[_Column],
                  plan: list[tuple[_Column, list[float]]], yv: np.ndarray, rtol: float
                  ) -> None:
    """Refuse a refinement whose runs may take more than MAX_REFINE_STEPS RK4 evaluations
    (each run counted at its step cap, PAR_MAXSTEPS, at the top of its column's search;
    the bisection at its iterations' bound for rtol): one line naming rtol."""
    scans = {id(col): scan for col, scan in plan}
    total, runs = 0.0, 0
    for col in cols:
        c, j = col.curve, col.j
        scan = scans.get(id(col), [])
        top = c.hi[j] if not math.isnan(c.hi[j]) else (max(scan) if scan else math.nan)
        if math.isnan(top):
            continue
        step = float(np.max(np.diff(yv)))
        if scan:
            step = max(step, float(np.max(np.diff([yv[0], *scan]))))
        n = len(scan) + _bisection_steps(max(top - step, yv[0]), top, rtol)
        cap = points_rows([col.point(scene, axes[1], top)], scene.numerics)[0][0, L.PAR_MAXSTEPS]
        total += n * float(cap)
        runs += n
    if total > MAX_REFINE_STEPS:
        raise AdaptiveError(
            f"rtol = {rtol:g}: refining A_min of {len(cols)} columns may take {runs} kernel "
            f"runs capped at {total:.2g} RK4 steps in all, above the budget of "
            f"{MAX_REFINE_STEPS:.0e}; use a larger rtol (at most {MAX_RTOL:g}) or fewer "
            "columns")


# --- exports ----------------------------------------------------------------------------

def a_min_rows(curves: Sequence[AMinCurve]) -> list[dict[str, Any]]:
    """One row per panel and x value with an A_min: the non-diagram axis values, x, A_min,
    mode (word), whether A_min is only an upper bound (first grid value), and how it was
    found (``method``, a word of A_MIN_METHODS)."""
    rows = []
    for c in curves:
        for j in range(c.x.size):
            if math.isnan(c.a_min[j]):
                continue
            rows.append({**c.where, c.xname: float(c.x[j]), "A_min": float(c.a_min[j]),
                         "mode": outcome_word(int(c.mode[j])),
                         "upper_bound": bool(math.isnan(c.lo[j])),
                         "method": A_MIN_METHODS[int(c.method[j])]})
    return rows


def boundary_rows(bounds: Sequence[PanelBoundaries], axes: Sequence[str] | None = None
                  ) -> list[dict[str, Any]]:
    """One row per vertex of every boundary polyline: the non-diagram axis values, line
    (number within the panel), classes (e.g. safe|mode1), x, y (named after each panel's
    diagram axes unless ``axes`` names them)."""
    rows = []
    for b in bounds:
        names = axes if axes is not None else (b.xname, b.yname)
        for n, line in enumerate(b.lines):
            for xv, yv in line.xy:
                rows.append({**b.where, "line": n, "classes": line.label,
                             names[0]: float(xv), names[1]: float(yv)})
    return rows


CURVE_SUFFIXES = (".csv", ".h5", ".hdf5")  # ``rocksweep boundaries -o``: CSV or HDF5


# --- result files -----------------------------------------------------------------------


def check_result(result: SweepResult, axes: Sequence[str] | None = None) -> Scene:
    """The scene of a complete result with the diagram axes ``axes`` (x, y; None: the
    scene's, ``default_axes``); one-line BoundaryErrors for a result that has no such
    diagram or is not finished."""
    from rocksweep.store.reader import result_scene  # lazy: h5py (+26 ms)

    sc = result_scene(result)
    axes = default_axes(sc) if axes is None else axes
    try:
        check_amplitudes(sc, axes[1])
        make_plan(sc, axes, coarse=0, audit=0.0)
    except AdaptiveError as err:
        raise BoundaryError("{path}: {err}; boundaries need a diagram over two swept axes",
                            path=result.path, err=err) from None
    result.require_complete(BoundaryError, "A_min")
    return sc


def grid_response(result: SweepResult) -> dict[str, np.ndarray | None]:
    """The grid's max|theta|/alpha_ref and uplift counts of a result (``a_min``'s
    ``theta``, ``uplifts``; None where the result was read without them; an adaptive
    result's filled points hold NaN and -1, unknown)."""
    return {"theta": result.arrays.get("theta_max_over_alpha"),
            "uplifts": result.arrays.get("uplifts")}


# the variables of a result that A_min reads (outcome) and that say where to search
RESPONSE = ("outcome", "theta_max_over_alpha", "uplifts")


def result_curves(result: SweepResult, rtol: float = DEFAULT_RTOL, mode: int | None = None,
                  axes: Sequence[str] | None = None, evaluate: Evaluator | None = None,
                  search: bool = True) -> tuple[list[AMinCurve], list[PanelBoundaries]]:
    """A_min curves (bisected to ``rtol``; ``mode``: None any, 1 or 2) and boundary lines
    of every panel of a result read with ``outcome`` (``store.read_result``); axes: the
    diagram's (None: the scene's, (p, A_ratio) for a record)."""
    sc = check_result(result, axes)
    axes = default_axes(sc) if axes is None else axes
    outcome = np.asarray(result.arrays["outcome"])
    curves = a_min(sc, outcome, rtol, axes, mode, evaluate, **grid_response(result),
                   search=search)
    return curves, diagram_boundaries(sc, outcome, axes)


# ---------------------------------------------------------------------------------------
# As xarray / pandas (rocksweep.boundaries, rocksweep.boundary_lines)
# ---------------------------------------------------------------------------------------

def _panel_index(wheres: Sequence[dict[str, Any]]) -> tuple[list[str], dict[str, list]]:
    """The other swept axes of the panels and each one's values in order of appearance."""
    keys = list(wheres[0]) if wheres else []
    values: dict[str, list] = {k: [] for k in keys}
    for w in wheres:
        for k in keys:
            if w[k] not in values[k]:
                values[k].append(w[k])
    return keys, values


def curves_dataset(curves: Sequence[AMinCurve], attrs: dict[str, Any] | None = None):
    """A_min curves as an ``xarray.Dataset``: ``A_min`` (NaN: none found), ``mode`` (1, 2;
    0 where NaN), ``A_min_method`` (how A_min was found, a word of A_MIN_METHODS),
    ``lo``/``hi`` (the final bracket), ``runs`` (kernel runs of the search and the
    bisection), each over every other swept axis (e.g. shape, lam) and the diagram's x
    axis (w_over_p or p); values in the axes' units (A_min in A_ratio)."""
    import xarray as xr  # lazy: xarray, pandas (+0.3 s)

    if not curves:
        return xr.Dataset(attrs=dict(attrs or {}))
    keys, values = _panel_index([c.where for c in curves])
    xname, yname = curves[0].xname, curves[0].yname
    shape = (*(len(values[k]) for k in keys), len(curves[0].x))
    data = {n: np.full(shape, fill, dtype) for n, fill, dtype in (
        ("A_min", np.nan, float), ("mode", 0, np.int8), ("lo", np.nan, float),
        ("hi", np.nan, float), ("runs", 0, np.int64),
        ("A_min_method", A_MIN_METHODS[-1], object))}
    for c in curves:
        idx = tuple(values[k].index(c.where[k]) for k in keys)
        for n, v in (("A_min", c.a_min), ("mode", c.mode), ("lo", c.lo), ("hi", c.hi),
                     ("runs", c.runs), ("A_min_method", c.method_words)):
            data[n][idx] = v
    data["A_min_method"] = data["A_min_method"].astype(str)
    dims = (*keys, xname)
    ymeta = fields.axis_attrs(yname)
    meta = {"A_min": {**ymeta, "long_name": f"smallest overturning {ymeta['long_name']}"},
            "mode": {"long_name": "overturning mode at A_min", "flag_values": [0, 1, 2],
                     "flag_meanings": "none mode1 mode2"},
            "lo": {**ymeta, "long_name": "bracket: largest safe value"},
            "hi": {**ymeta, "long_name": "bracket: smallest overturning value"},
            "runs": {"long_name": "kernel runs of the search and the bisection",
                     "units": "1"},
            "A_min_method": {"long_name": "how A_min was found",
                             "flag_meanings": ";".join(A_MIN_METHODS)}}
    coords = {k: (k, np.asarray(values[k]), fields.axis_attrs(k)) for k in keys}
    coords[xname] = (xname, np.asarray(curves[0].x), fields.axis_attrs(xname))
    return xr.Dataset({n: (dims, v, meta[n]) for n, v in data.items()}, coords=coords,
                      attrs={"x_axis": xname, "y_axis": yname, **(attrs or {})})


def lines_frame(bounds: Sequence[PanelBoundaries]):
    """The boundary polylines as a tidy ``pandas.DataFrame``: one row per vertex, columns:
    every other swept axis of the panel, ``line`` (its number in the panel), ``classes``
    (e.g. "safe|mode1"), ``vertex``, and the diagram axes' values (``x``, ``y``)."""
    import pandas as pd  # lazy: pandas, pyarrow (+0.2 s)

    rows = [{**b.where, "line": i, "classes": line.label, "closed": line.closed
             if hasattr(line, "closed") else bool(np.allclose(line.xy[0], line.xy[-1])),
             "vertex": j, "x": float(x), "y": float(y)}
            for b in bounds for i, line in enumerate(b.lines)
            for j, (x, y) in enumerate(line.xy)]
    return pd.DataFrame(rows)


def boundary_lines_frame(ds: Any):
    """``rocksweep.boundary_lines``: the class boundary polylines of a complete result's
    diagrams (``diagram_boundaries``) as ``lines_frame``'s DataFrame."""
    from rocksweep.store.reader import as_result  # lazy: h5py (+26 ms)

    result = as_result(ds, ["outcome"])
    return lines_frame(diagram_boundaries(check_result(result), result.arrays["outcome"]))


def check_search(search: Any) -> bool:
    """The ``search`` argument of ``a_min``'s callers: True or False (numpy's too), else an
    ApiError."""
    if not isinstance(search, bool | np.bool_):
        raise ApiError(f"search = {search!r}: must be True or False")
    return bool(search)


def boundaries_dataset(ds: Any, rtol: float = DEFAULT_RTOL, mode: int | None = None,
                       search: bool = True) -> Any:
    """``rocksweep.boundaries`` (its arguments documented there): the A_min curves of a
    complete result (``result_curves``) as a Dataset (``curves_dataset``). rtol, mode
    (None, 1 or 2) and search (a bool) are checked before the result is read: one-line
    ApiErrors."""
    from rocksweep.store.reader import as_result  # lazy: h5py (+26 ms)

    rtol = check_rtol(rtol)
    if mode not in (None, 1, 2):
        raise ApiError(f"mode = {mode!r}: must be None, 1 or 2")
    search = check_search(search)
    result = as_result(ds, list(RESPONSE))
    curves, _ = result_curves(result, rtol, mode, search=search)
    return curves_dataset(curves, {KIND_ATTR: BOUNDARIES, "kind": result.kind,
                                   "title": result.name, "rtol": rtol,
                                   "search": int(search),
                                   "mode": "any" if mode is None else f"mode{mode}"})
