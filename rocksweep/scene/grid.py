"""A scene's grid: axes -> flat point index -> kernel parameter rows, one chunk at a time.

The grid is the Cartesian product of the scene's axes in ``Scene.axes`` order (shape, body
keys, lam, the impact law's keys given (law, e, e_factor), A_ratio, w_over_p or a record's
p; that one varies fastest; then the pulse's unswept options). A point is named by its flat
(C-order) index ``0 <= i < size``. Nothing here materialises all points: a chunk of flat
indices is unravelled on its own, the body-dependent part of the rows (``points.Bodies``)
is computed once per distinct body in the chunk, and each distinct excitation of the chunk
is asked of the scene (``Scene.excitation``: made once a run) and fills its points' rows
(``points.build_rows``). Result arrays have the shape of the *swept* axes
(``Grid.shape``); an unswept axis is a length-1 dimension of the full grid and vanishes
from the result shape, which leaves the flat index unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.bodies import u_cr as body_u_cr
from rocksweep.physics.ground_motion import Excitation
from rocksweep.physics.points import (
    Bodies,
    Columns,
    body_omega_rock,
    body_row,
    build_rows,
    kernel_kind,
    law_code,
    ridge_column,
)
from rocksweep.scene.model import Scene
from rocksweep.schema import FRICTION_KEYS
from rocksweep.vocab.axes import INITIAL
from rocksweep.vocab.laws import DEFAULT_LAW


@dataclass
class ChunkRows:
    """Parameter rows of one chunk of points (n points).

    rows: float64[n, N_PAR] (``points.build_rows``; the samples of an excitation are added
    by ``Excitation.with_samples`` just before the kernel runs, not kept here);
    kinds: int64[n] (``KIND_*``);
    alpha_ref [rad] and E_ref [J]: float64[n], per point, to normalise results
    (theta/alpha_ref, E/E_ref); which: int64[n], each point's excitation, an index into
    excitations, the chunk's distinct ones (``physics.ground_motion``).
    """

    rows: np.ndarray
    kinds: np.ndarray
    alpha_ref: np.ndarray
    E_ref: np.ndarray
    which: np.ndarray
    excitations: tuple[Excitation, ...]

    def with_samples(self) -> np.ndarray:
        """The rows with their samples (``Excitation.with_samples``): rows of one
        length, so of pulses or of one recorded motion (a ValueError otherwise)."""
        if all(ex.record is None for ex in self.excitations):
            return self.rows
        if len(self.excitations) != 1:
            raise ValueError("the rows of several recorded motions differ in length")
        return self.excitations[0].with_samples(self.rows)

    def batches(self, sel: np.ndarray) -> list[tuple[np.ndarray, Excitation | None]]:
        """The selected points (bool[n]) in batches that run together: (bool[n], the
        excitation whose samples their rows carry, or None: pulses, which need none, all
        in one batch)."""
        if all(ex.record is None for ex in self.excitations):
            return [(sel, None)]
        return [(sel & (self.which == j), self.excitations[int(j)])
                for j in np.unique(self.which[sel])]


@dataclass
class ChunkResult:
    """Results of the points ``start <= i < stop`` (flat indices).

    arrays: name -> array[stop - start] (``Scene.variables``); seconds: wall time of the
    chunk in its worker; cpu_seconds: CPU time of the worker thread that ran it;
    refine_evaluations: int64[stop - start], the RK4 evaluations of the certification's
    runs of each point (in its steps and event_steps too: ``fields``
    ``refine_evaluations``; not a file variable: a file keeps their total), or None.
    """

    start: int
    stop: int
    arrays: dict[str, np.ndarray]
    seconds: float
    cpu_seconds: float = 0.0
    refine_evaluations: np.ndarray | None = None


class Grid:
    """The points of a scene, addressed by flat index.

    dims: names of the swept axes (result dimensions); shape: their lengths; size: number
    of points.
    """

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.full_shape = tuple(len(a.values) for a in scene.axes)
        self.dims = tuple(a.name for a in scene.swept)
        self.shape = scene.shape
        self.size = scene.size
        names = [a.name for a in scene.axes]
        self._body_pos = [i for i, a in enumerate(scene.axes)
                          if a.key.startswith("body.") and a.key[5:] not in FRICTION_KEYS]
        self._i_mu = names.index("mu") if "mu" in names else None
        self._i_mu_s = names.index("mu_static") if "mu_static" in names else None
        self._body_shape = tuple(self.full_shape[i] for i in self._body_pos)
        self._i_shape = names.index("shape")
        self._i_lam = names.index("lam")
        self._i_w = names.index(scene.freq_axis)  # w_over_p, or p [rad/s] for a record
        suite = scene.suite
        self._i_A = names.index("A_ratio") if suite is None else None
        self._i_rec = names.index("record") if suite is not None else None
        self._i_stripe = names.index(suite.im) if suite is not None and suite.im else None
        # the impact law's axes, when the scene gives them (else eq. 1's defaults)
        self._i_law = names.index("law") if "law" in names else None
        self._i_e = names.index("e") if "e" in names else None
        self._i_ef = names.index("e_factor") if "e_factor" in names else None
        self._law_codes = (None if self._i_law is None else
                           np.array([law_code(w) for w in scene.axes[self._i_law].values]))
        # the initial state's axes, when the scene gives them (vocab.axes.INITIAL; else at rest)
        self._i_init = [names.index(k) if k in names else None for k in INITIAL]
        # the axes a point's excitation depends on (``Scene.excitation_axes``)
        self._motion_pos = [names.index(k) for k in scene.excitation_axes]
        self._motion_dims = [self.full_shape[i] for i in self._motion_pos]
        self._values = [np.asarray(a.values, float)
                        if i not in (self._i_shape, self._i_rec, self._i_law) else None
                        for i, a in enumerate(scene.axes)]

    def coords(self) -> dict[str, np.ndarray]:
        """Coordinate values of each swept dimension (strings for ``shape``)."""
        return {a.name: np.asarray(a.values) for a in self.scene.swept}

    def index_values(self, flat: np.ndarray) -> dict[str, np.ndarray]:
        """Value of every axis (by name) at the given flat indices (int64[n])."""
        multi = np.unravel_index(np.asarray(flat, np.int64), self.full_shape)
        out = {}
        for i, a in enumerate(self.scene.axes):
            vals = np.asarray(a.values) if self._values[i] is None else self._values[i]
            out[a.name] = vals[multi[i]]
        return out

    def _bodies(self, body_index: np.ndarray) -> Bodies:
        """The distinct bodies of these body indices (``points.Bodies``)."""
        multi = np.unravel_index(body_index, self._body_shape)
        axes = [self.scene.axes[i] for i in self._body_pos]
        n = len(body_index)
        rows = np.empty((n, L.N_PAR))
        omega_rock, alpha_ref, E_ref = np.empty(n), np.empty(n), np.empty(n)
        kinds = np.empty(n, np.int64)
        u_cr = np.empty(n)
        for j in range(n):
            body = self.scene.make_body(**{a.name: a.values[int(m[j])]
                                           for a, m in zip(axes, multi, strict=True)})
            rows[j] = body_row(body)
            omega_rock[j] = body_omega_rock(body)
            alpha_ref[j] = body.alpha_ref
            E_ref[j] = body.E_ref
            kinds[j] = kernel_kind(body)
            u_cr[j] = body_u_cr(body)
        rows[:, L.PAR_RIDGE] = ridge_column(rows)
        return Bodies(rows, omega_rock, alpha_ref, E_ref, u_cr, kinds)

    def rows(self, start: int, stop: int) -> ChunkRows:
        """Rows of the points with flat indices ``start <= i < stop``."""
        return self.rows_at(np.arange(start, stop, dtype=np.int64))

    def rows_at(self, flat: np.ndarray) -> ChunkRows:
        """Rows of the points with the given flat indices (int64[n])."""
        flat = np.asarray(flat, np.int64)
        if flat.size and (flat.min() < 0 or flat.max() >= self.size):
            raise IndexError(f"flat index out of range [0, {self.size})")
        multi = np.unravel_index(flat, self.full_shape)
        body_index = np.ravel_multi_index([multi[i] for i in self._body_pos], self._body_shape)
        distinct, inverse = np.unique(body_index, return_inverse=True)
        bodies = self._bodies(distinct).take(inverse)
        which, excitations = self._excitations(multi, flat.size)
        rows = build_rows(bodies, excitations, which,
                          self._columns(multi, bodies, excitations, which),
                          self.scene.numerics)
        return ChunkRows(rows, bodies.kinds, bodies.alpha_ref, bodies.E_ref, which,
                         excitations)

    def _excitations(self, multi: tuple, n: int) -> tuple[np.ndarray, tuple[Excitation, ...]]:
        """(which: int64[n], the chunk's distinct excitations): each asked of the scene
        once (``Scene.excitation``: made once a run)."""
        axes = self.scene.axes
        pos, dims = self._motion_pos, self._motion_dims
        if math.prod(dims) == 1:  # one excitation for the whole grid
            return np.zeros(n, np.int64), (self.scene.excitation(
                {axes[i].name: axes[i].values[0] for i in pos}),)
        code = np.ravel_multi_index([multi[i] for i in pos], dims)
        distinct, inv = np.unique(code, return_inverse=True)
        excitations = tuple(
            self.scene.excitation({axes[i].name: axes[i].values[int(j)]
                                   for i, j in zip(pos, np.unravel_index(c, dims),
                                                   strict=True)})
            for c in distinct.tolist())
        return inv.reshape(-1).astype(np.int64), excitations

    def _columns(self, multi: tuple, bodies: Bodies, excitations: tuple[Excitation, ...],
                 which: np.ndarray) -> Columns:
        """The points' own numbers (``points.Columns``): lam, the time scale (a pulse's
        w_over_p, a record's p, a pulse's p on a building), the kernel's A_ratio
        (``Scene.drive_ratio``), mu, the impact law, the initial state."""
        sc = self.scene
        v = self._values

        def at(i: int | None, default=np.nan):
            return default if i is None else v[i][multi[i]]

        if sc.path is not None and not sc.recorded:
            rate = np.full(bodies.alpha_ref.size, sc.path.p)
        else:
            rate = at(self._i_w)
        rec = None if self._i_rec is None else np.asarray(multi[self._i_rec], np.int64)
        stripe = None if self._i_stripe is None else np.asarray(multi[self._i_stripe])
        a_ratio = sc.drive_ratio(at(self._i_A, None), rec, stripe, bodies.alpha_ref, rate,
                                 excitations, which)
        law = (law_code(DEFAULT_LAW) if self._i_law is None
               else self._law_codes[multi[self._i_law]])
        e = np.where(law == L.LAW_CONSTANT, at(self._i_e), np.nan)  # law constant's alone
        initial = (None if all(i is None for i in self._i_init) else
                   tuple(at(i, 0.0) for i in self._i_init))
        return Columns(at(self._i_lam), rate, a_ratio, at(self._i_mu), law, e,
                       at(self._i_ef, 1.0), initial, at(self._i_mu_s))

    def kinds(self) -> list[int]:
        """The kernel kinds the grid's bodies need (each distinct body visited once)."""
        n_bodies = int(np.prod(self._body_shape, dtype=np.int64))
        found: set[int] = set()
        step = 4096
        for a in range(0, n_bodies, step):
            found.update(int(k) for k in self._bodies(np.arange(a, min(a + step, n_bodies))).kinds)
        return sorted(found)
