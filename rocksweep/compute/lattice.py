"""The refinement's geometry: lattices over the two diagram axes, the cells between
their points, and the points the refinement rules mark in them (``compute.adaptive``, its
module docstring, says which rules and why).

Arrays are per panel (panels, ny, nx), the diagram axes last (``Plan.panels``); a stride-s
lattice is every s-th index of both axes plus each axis's last index (``axis_lattice``),
and its cells are the closed squares between neighbouring lattice points (a shorter last
cell spans up to the axis's end). ``known`` is an int8 panel array: the class where
computed, -1 elsewhere. ``index`` is the grid's flat index of every panel cell,
int64[panels, ny, nx] (``adaptive.Plan.flat_index``): what the functions return is in it.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

NO_CLASS = np.int8(127)  # above every class, for minima over computed points


@functools.lru_cache(maxsize=256)
def axis_lattice(n: int, s: int) -> np.ndarray:
    """Indices of the stride-s lattice of an axis of length n: 0, s, 2s, ... and n - 1
    (int64, read-only: one per (n, s), asked for ~2000 times by an adaptive sweep's
    planning passes, ~0.1 ms each when built)."""
    out = np.arange(0, n, s)
    if out[-1] != n - 1:
        out = np.append(out, n - 1)
    out.flags.writeable = False
    return out


def on_lattice(a: np.ndarray, s: int) -> np.ndarray:
    """The values of panels a (P, ny, nx) at the stride-s lattice's points."""
    _, ny, nx = a.shape
    return a[:, axis_lattice(ny, s)][:, :, axis_lattice(nx, s)]


def lattice_points(index: np.ndarray, s: int) -> np.ndarray:
    """Flat indices of the stride-s lattice's points, panel by panel."""
    return on_lattice(index, s).ravel()


def ncells(n: int, s: int) -> int:
    return max(1, math.ceil((n - 1) / s))


def pad(a: np.ndarray, s: int) -> np.ndarray:
    """Pad panels (P, ny, nx) by repeating the last row/column to (P, cy s + 1, cx s + 1):
    the last, shorter cell then spans exactly up to index n - 1."""
    _, ny, nx = a.shape
    py, px = ncells(ny, s) * s + 1 - ny, ncells(nx, s) * s + 1 - nx
    return pad_edge(a, ny + py, nx + px)


def pad_edge(a: np.ndarray, ny: int, nx: int) -> np.ndarray:
    """Panels a (P, ay, ax) padded to (P, ny, nx) (ny >= ay, nx >= ax) by repeating the
    last row and column: ``np.pad(mode="edge")`` without its ~0.2 ms of Python a call (the
    planning passes pad ~500 times)."""
    P, ay, ax = a.shape
    if (ay, ax) == (ny, nx):
        return a
    out = np.empty((P, ny, nx), a.dtype)
    out[:, :ay, :ax] = a
    out[:, :ay, ax:] = a[:, :, ax - 1:ax]
    out[:, ay:, :] = out[:, ay - 1:ay, :]
    return out


def cell_blocks(cells: np.ndarray, s: int, ny: int, nx: int) -> np.ndarray:
    """Per-cell values of the stride-s cells (P, cy, cx) at every point (P, ny, nx): point
    (y, x) gets its cell's (y // s, x // s), the axis's last index the last cell's (a
    block copy each: ~4 ms at 1000 x 1000 x 3, against ~15 ms of fancy indexing)."""
    big = np.repeat(np.repeat(cells, s, axis=1), s, axis=2)
    return pad_edge(big, max(ny, big.shape[1]), max(nx, big.shape[2]))[:, :ny, :nx]


@dataclass
class CellStats:
    """Per stride-s cell of every panel (P, cy, cx): lo/hi class among its computed points
    (127/-1 when none), and whether its four corners are computed."""

    lo: np.ndarray
    hi: np.ndarray
    corners: np.ndarray

    @property
    def mixed(self) -> np.ndarray:
        return (self.hi >= 0) & (self.lo < self.hi)

    @property
    def uniform_class(self) -> np.ndarray:
        """Class of uniform cells with computed corners, -1 elsewhere."""
        ok = self.corners & (self.lo == self.hi)
        return np.where(ok, self.hi, -1).astype(np.int8)


def cell_stats(known: np.ndarray, strides: Sequence[int]) -> dict[int, CellStats]:
    """Cell statistics at every stride (powers of 2 >= 2). known: int8 panels, the class
    where computed, -1 elsewhere.

    Stride 2 is reduced from the points (closed windows of 3); each coarser stride from
    the one below, since a closed 2s-cell is the union of its four closed s-subcells
    (a missing last subcell beyond the padded edge repeats the last one, which holds the
    same points of the edge).
    """
    out: dict[int, CellStats] = {}
    if not strides:
        return out
    kp = pad(known, 2)
    lo_src = np.where(kp < 0, NO_CLASS, kp)

    def closed3(a: np.ndarray, op: Callable) -> np.ndarray:
        a = op(op(a[:, :, 0:-1:2], a[:, :, 1::2]), a[:, :, 2::2])
        return op(op(a[:, 0:-1:2], a[:, 1::2]), a[:, 2::2])

    hi, lo = closed3(kp, np.maximum), closed3(lo_src, np.minimum)
    _, ny, nx = known.shape
    s = 2
    while True:
        if s in strides:
            c = on_lattice(known, s) >= 0
            corners = c[:, :-1, :-1] & c[:, 1:, :-1] & c[:, :-1, 1:] & c[:, 1:, 1:]
            out[s] = CellStats(lo, hi, corners)
        if s >= max(strides):
            return out
        s *= 2
        cy, cx = ncells(ny, s), ncells(nx, s)

        def up(a: np.ndarray, op: Callable, cy: int = cy, cx: int = cx) -> np.ndarray:
            a = pad_edge(a, 2 * cy, 2 * cx)
            a = op(a[:, 0::2], a[:, 1::2])
            return op(a[:, :, 0::2], a[:, :, 1::2])

        hi, lo = up(hi, np.maximum), up(lo, np.minimum)


def dilate(mask: np.ndarray, m: int) -> np.ndarray:
    """Cells within m steps across cell edges (4-neighbourhood, per panel) of a marked
    cell: a boundary enters a cell through an edge, so its edge neighbours are the cells it
    can bend into between samples (the 8-neighbourhood cost 13-18% more points at 400 x 400
    for the same outcomes on the study scenes)."""
    out = mask.copy()
    for _ in range(m):
        cur = out.copy()
        out[:, 1:, :] |= cur[:, :-1, :]
        out[:, :-1, :] |= cur[:, 1:, :]
        out[:, :, 1:] |= cur[:, :, :-1]
        out[:, :, :-1] |= cur[:, :, 1:]
    return out


def points_of_cells(index: np.ndarray, cells: np.ndarray, s: int,
                     known: np.ndarray | None = None) -> np.ndarray:
    """Flat indices (increasing) of the stride-s/2 lattice points inside the marked
    stride-s cells (bool[P, cy, cx]; closed), each once; with ``known`` (int8 panels, -1:
    not computed) only those not computed yet.

    The cells' 3 x 3 points are marked on the lattice itself (no index per cell and
    point, and no sort of them to remove the points that neighbouring cells share: that
    was a sixth of a planning pass's time)."""
    P, cy, cx = cells.shape
    _, ny, nx = index.shape
    h = s // 2
    ys, xs = axis_lattice(ny, h), axis_lattice(nx, h)
    lat = np.zeros((P, 2 * cy + 1, 2 * cx + 1), bool)
    for dy in range(3):
        for dx in range(3):
            lat[:, dy:dy + 2 * cy:2, dx:dx + 2 * cx:2] |= cells
    # 2 cy + 1 is len(ys) or one more: that last row lies past the axis's end (clipped, it
    # is the lattice's last point), and only the last cell marks it, which marks the row
    # before it too: the lattice's last one
    lat = lat[:, :ys.size, :xs.size]
    if known is not None:
        lat &= on_lattice(known, h) < 0
    p, jj, ii = np.nonzero(lat)
    return np.sort(index[p, ys[jj], xs[ii]])


def centres(index: np.ndarray, cells: np.ndarray, s: int) -> np.ndarray:
    """Flat indices of the centres of the marked stride-s cells (bool[P, cy, cx]), a
    shorter last cell's clipped to the axis's last index (then a corner)."""
    _, ny, nx = index.shape
    p, j, i = np.nonzero(cells)
    return index[p, np.minimum(j * s + s // 2, ny - 1), np.minimum(i * s + s // 2, nx - 1)]


def corner_classes(known: np.ndarray) -> np.ndarray:
    """int8[P, cy + 1, cx + 1]: the classes (-1: not computed) at the stride-2 lattice
    points, i.e. the corners of the stride-2 cells."""
    return on_lattice(known, 2)


def centre_classes(known: np.ndarray) -> np.ndarray:
    """int8[P, cy, cx]: the classes at the centres of the stride-2 cells (-1: not
    computed, or a last cell one index long: no centre)."""
    P, ny, nx = known.shape
    cy, cx = ncells(ny, 2), ncells(nx, 2)
    m = np.full((P, cy, cx), -1, np.int8)
    cen = known[:, 1::2, 1::2][:, :cy, :cx]
    m[:, :cen.shape[1], :cen.shape[2]] = cen
    if (ny - 1) % 2:
        m[:, -1] = -1
    if (nx - 1) % 2:
        m[:, :, -1] = -1
    return m


def edge_points(index: np.ndarray, mixed: np.ndarray, known: np.ndarray) -> np.ndarray:
    """Flat indices of the points the last level (stride 2 -> 1) computes in the mixed
    stride-2 cells ``mixed`` (bool[P, cy, cx]) whose four corners are computed.

    Where the corners differ: the centre, and the midpoint of each edge that a boundary
    crosses: its two ends differ; or they agree, the computed centre differs from them and
    the opposite edge's ends do not both side with the centre (a one-point sliver through
    the centre that runs on across the edge, not a boundary between the centre and the
    edge). Any edge whose ends agree and whose two computed neighbouring centres are both
    of another class (a one-point band lying along the edge, in which a speck can hide).
    Where the corners agree (an audit point inside made the cell mixed): all its points.
    The other edge midpoints are filled from their two agreeing ends (``edge_fill``).

    Each rule fires only once the points it reads are computed and then holds for good
    (classes do not change), so the wanted set only grows with the computed set: the
    least fixed point, and so the result, does not depend on the batch order. Measured on
    Figure 3(a) at 1000 x 1000 x 3 lam: whole mixed cells at this level are 0.91% of the
    grid, these points 0.46%.

    The rules are evaluated on the few cells they can fire at (mixed cells; cells with a
    computed centre), not on every cell: they were 2/3 of a planning pass's time, ~80 ms
    a pass at 1000 x 1000 x 3, on the sweep's critical path.
    """
    c, m = corner_classes(known), centre_classes(known)
    _, cy, cx = mixed.shape
    _, ny, nx = index.shape
    pts: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []  # (p, jj, ii) lattice points

    p, j, i = np.nonzero(mixed)
    a, b, d, e = c[p, j, i], c[p, j, i + 1], c[p, j + 1, i], c[p, j + 1, i + 1]
    ok = (a >= 0) & (b >= 0) & (d >= 0) & (e >= 0)
    same = (a == b) & (a == d) & (a == e)
    split, whole = ok & ~same, ok & same
    mc = m[p, j, i]

    def crossed(p_: np.ndarray, q: np.ndarray, r: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Edge (p_, q) of a split cell crossed; (r, t): the opposite edge's ends."""
        return (p_ != q) | ((mc >= 0) & (p_ != mc) & ~((r == mc) & (t == mc)))

    jj, ii = 2 * j + 1, 2 * i + 1
    for sel, dy, dx in ((split, 0, 0),  # centres
                        (split & crossed(a, b, d, e), -1, 0),  # lower edges
                        (split & crossed(d, e, a, b), 1, 0),  # upper edges
                        (split & crossed(a, d, b, e), 0, -1),  # left edges
                        (split & crossed(b, e, a, d), 0, 1)):  # right edges
        pts.append((p[sel], jj[sel] + dy, ii[sel] + dx))
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            pts.append((p[whole], jj[whole] + dy, ii[whole] + dx))

    # one-point bands along an edge: both neighbouring centres computed, of another class
    # than the edge's agreeing ends
    pc, jc, ic = np.nonzero(m >= 0)
    up = jc + 1 < cy  # the edge between cell (jc, ic) and the one above it, along x
    pu, ju, iu = pc[up], jc[up], ic[up]
    u, v, e0, e1 = m[pu, ju, iu], m[pu, ju + 1, iu], c[pu, ju + 1, iu], c[pu, ju + 1, iu + 1]
    band = (v >= 0) & (e0 >= 0) & (e0 == e1) & (u != e0) & (v != e0)
    pts.append((pu[band], 2 * ju[band] + 2, 2 * iu[band] + 1))
    right = ic + 1 < cx  # the edge between cell (jc, ic) and the one right of it, along y
    pr, jr, ir = pc[right], jc[right], ic[right]
    u, v, e0, e1 = m[pr, jr, ir], m[pr, jr, ir + 1], c[pr, jr, ir + 1], c[pr, jr + 1, ir + 1]
    band = (v >= 0) & (e0 >= 0) & (e0 == e1) & (u != e0) & (v != e0)
    pts.append((pr[band], 2 * jr[band] + 1, 2 * ir[band] + 2))

    pp = np.concatenate([q[0] for q in pts])
    yy = np.minimum(np.concatenate([q[1] for q in pts]), ny - 1)
    xx = np.minimum(np.concatenate([q[2] for q in pts]), nx - 1)
    return np.unique(index[pp, yy, xx])


def edge_fill(known: np.ndarray) -> np.ndarray:
    """int8 panels: at the midpoints of stride-2 edges whose two ends are computed and
    agree, their class; -1 elsewhere (what the last level leaves uncomputed, see
    ``edge_points``)."""
    _, ny, nx = known.shape
    c = corner_classes(known)
    lat = np.full((c.shape[0], 2 * c.shape[1] - 1, 2 * c.shape[2] - 1), -1, np.int8)
    h = np.where(c[:, :, :-1] == c[:, :, 1:], c[:, :, :-1], -1)  # edges along x
    v = np.where(c[:, :-1, :] == c[:, 1:, :], c[:, :-1, :], -1)  # edges along y
    lat[:, 0::2, 1::2] = h
    lat[:, 1::2, 0::2] = v
    # lattice index k is grid index k up to the axis's end; past it (a last cell one index
    # long) it is clipped onto the end, whose own value is the lattice's earlier point
    return np.ascontiguousarray(lat[:, :ny, :nx])
