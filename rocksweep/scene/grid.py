"""A scene's grid: axes -> flat point index -> kernel parameter rows, one chunk at a time.

The grid is the Cartesian product of the scene's axes in ``Scene.axes`` order (shape, body
keys, lam, the impact law's keys given (law, e, e_factor), A_ratio, w_over_p or a record's
p; that one varies fastest; then the pulse's unswept options). A point is named by its flat
(C-order) index ``0 <= i < size``. Nothing here materialises all points: a chunk of flat
indices is unravelled on its own, and the body-dependent part of the rows (``body_row``,
the spring frequency, alpha_ref, E_ref, the kernel kind) is computed once per distinct
body in the chunk. Result arrays have the shape of the *swept* axes (``Grid.shape``); an
unswept axis is a length-1 dimension of the full grid and vanishes from the result shape,
which leaves the flat index unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.bodies import u_cr as body_u_cr
from rocksweep.physics.points import (
    body_omega_rock,
    body_row,
    fill_rows,
    kernel_kind,
    law_code,
    shape_code,
)
from rocksweep.physics.records import vertical_samples
from rocksweep.scene.model import FLOOR_AXES, Scene
from rocksweep.schema import VERTICAL_KEYS
from rocksweep.vocab.axes import INITIAL
from rocksweep.vocab.ground import RECORD


@dataclass
class ChunkRows:
    """Parameter rows of one chunk of points (n points).

    rows: float64[n, N_PAR] (``points.fill_rows``; a record's samples are added by
    ``points.with_record`` just before the kernel runs, not kept here);
    kinds: int64[n] (``KIND_*``);
    alpha_ref [rad] and E_ref [J]: float64[n], per point, to normalise results
    (theta/alpha_ref, E/E_ref).
    """

    rows: np.ndarray
    kinds: np.ndarray
    alpha_ref: np.ndarray
    E_ref: np.ndarray
    # a suite's points: the index of each point's record (int64[n], into
    # ``Scene.suite.records``), None otherwise
    record_index: np.ndarray | None = None
    # the records the points run, indexed by ``record_index`` (a suite's records, or the
    # motions of an excitation path, ``physics.path``), None otherwise
    records: tuple | None = None
    # each of ``records``' vertical component on its samples [g] (None: none)
    verticals: tuple | None = None


@dataclass
class ChunkResult:
    """Results of the points ``start <= i < stop`` (flat indices).

    arrays: name -> array[stop - start] (``Scene.variables``); seconds: wall time of the
    chunk in its worker; cpu_seconds: CPU time of the worker thread that ran it.
    """

    start: int
    stop: int
    arrays: dict[str, np.ndarray]
    seconds: float
    cpu_seconds: float = 0.0


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
                          if a.key.startswith("body.") and a.key != "body.mu"]
        self._i_mu = names.index("mu") if "mu" in names else None
        self._body_shape = tuple(self.full_shape[i] for i in self._body_pos)
        self._i_shape = names.index("shape")
        self._i_lam = names.index("lam")
        self._i_w = names.index(scene.freq_axis)  # w_over_p, or p [rad/s] for a record
        suite = scene.suite
        self._i_A = names.index("A_ratio") if suite is None else None
        self._i_rec = names.index("record") if suite is not None else None
        self._i_stripe = names.index(suite.im) if suite is not None and suite.im else None
        self._shape_codes = np.array([shape_code(s) for s in scene.axes[self._i_shape].values])
        # the impact law's axes, when the scene gives them (else eq. 1's defaults)
        self._i_law = names.index("law") if "law" in names else None
        self._i_e = names.index("e") if "e" in names else None
        self._i_ef = names.index("e_factor") if "e_factor" in names else None
        self._law_codes = (None if self._i_law is None else
                           np.array([law_code(w) for w in scene.axes[self._i_law].values]))
        # the initial state's axes, when the scene gives them (vocab.axes.INITIAL; else at rest)
        self._i_init = [names.index(k) if k in names else None for k in INITIAL]
        # the axes an excitation path's motion depends on (``physics.path``)
        self._path_pos = ([] if scene.path is None else
                          [names.index(k) for k in ("record", "angle", *FLOOR_AXES)
                           if k in names]
                          + ([] if scene.recorded else [self._i_shape, self._i_w]))
        # a pulse's vertical harmonic (pulse.vertical: amplitude, w_over_p, phase), or None
        self._i_vert = ([names.index(f"vertical.{k}") for k in VERTICAL_KEYS]
                        if "vertical.amplitude" in names else None)
        self._vertical = scene.vertical_samples()  # a record's vertical component, or None
        # a folder suite's acting verticals, each on its record's samples (None: none act)
        self._suite_verticals = (
            tuple(vertical_samples(v, h) for v, h in zip(suite.vertical, suite.records,
                                                          strict=True))
            if suite is not None and suite.vertical_acts else None)
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

    def _bodies(self, body_index: np.ndarray) -> tuple[np.ndarray, ...]:
        """Per distinct body index: body rows, omega_rock, alpha_ref, E_ref, kind, u_cr."""
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
        return rows, omega_rock, alpha_ref, E_ref, kinds, u_cr

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
        b_rows, b_omega, b_alpha, b_E, b_kind, b_ucr = self._bodies(distinct)
        n = flat.size
        rows = np.empty((n, L.N_PAR))
        alpha_ref = b_alpha[inverse]
        law = (L.LAW_EQ1 if self._i_law is None
               else self._law_codes[multi[self._i_law]])
        e = np.nan if self._i_e is None else self._values[self._i_e][multi[self._i_e]]
        e = np.where(law == L.LAW_CONSTANT, e, np.nan)  # e is law constant's alone
        e_factor = 1.0 if self._i_ef is None else self._values[self._i_ef][multi[self._i_ef]]
        initial = (None if all(i is None for i in self._i_init) else
                   tuple(0.0 if i is None else self._values[i][multi[i]] for i in self._i_init))
        u_cr = b_ucr[inverse]
        if self.scene.path is not None:
            return self._path_rows(multi, rows, b_rows[inverse], b_omega[inverse], alpha_ref,
                                   b_kind[inverse], b_E[inverse], (law, e, e_factor),
                                   initial, u_cr)
        if self.scene.suite is not None:
            return self._suite_rows(multi, rows, b_rows[inverse], b_omega[inverse], alpha_ref,
                                    b_kind[inverse], b_E[inverse], (law, e, e_factor),
                                    initial, u_cr)
        fill_rows(rows, b_rows[inverse], b_omega[inverse], alpha_ref,
                  self._values[self._i_lam][multi[self._i_lam]],
                  self._shape_codes[multi[self._i_shape]],
                  self._values[self._i_w][multi[self._i_w]],
                  self._values[self._i_A][multi[self._i_A]], self.scene.numerics,
                  self.scene.option("cycles"), self.scene.option("gamma"),
                  self.scene.option("nu"), self.scene.record,
                  np.nan if self._i_mu is None else self._values[self._i_mu][multi[self._i_mu]],
                  law, e, e_factor, initial, u_cr, self._vertical,
                  None if self._i_vert is None else
                  tuple(self._values[i][multi[i]] for i in self._i_vert))
        return ChunkRows(rows, b_kind[inverse], alpha_ref, b_E[inverse])

    def _suite_rows(self, multi, rows, body_rows, omega_rock, alpha_ref, kinds, E_ref,
                    impact: tuple, initial: tuple | None = None, u_cr=0.0) -> ChunkRows:
        """Rows of a suite's points: each point's record scaled to its stripe (the peak
        as A_ratio, ``Suite.peak_ratio``), filled record by record (each record has its
        own DT and length)."""
        su = self.scene.suite
        rec = np.asarray(multi[self._i_rec], np.int64)
        stripe = None if self._i_stripe is None else np.asarray(multi[self._i_stripe])
        lam = self._values[self._i_lam][multi[self._i_lam]]
        p = self._values[self._i_w][multi[self._i_w]]
        a_ratio = su.peak_ratio(rec, stripe, alpha_ref, p)
        code = self._shape_codes[multi[self._i_shape]]
        law, e, e_factor = (np.broadcast_to(np.asarray(v, float), lam.shape) for v in impact)
        if initial is not None:
            initial = tuple(np.broadcast_to(np.asarray(v, float), lam.shape) for v in initial)
        u_cr = np.broadcast_to(np.asarray(u_cr, float), lam.shape)
        for r in np.unique(rec):
            sel = rec == r
            part = np.empty((int(sel.sum()), L.N_PAR))
            fill_rows(part, body_rows[sel], omega_rock[sel], alpha_ref[sel], lam[sel],
                      code[sel], p[sel], a_ratio[sel], self.scene.numerics,
                      record=su.records[int(r)], law=law[sel], e=e[sel],
                      e_factor=e_factor[sel],
                      initial=None if initial is None else tuple(v[sel] for v in initial),
                      u_cr=u_cr[sel], vertical=None if self._suite_verticals is None
                      else self._suite_verticals[int(r)])
            rows[sel] = part
        return ChunkRows(rows, kinds, alpha_ref, E_ref, rec, su.records,
                         self._suite_verticals)

    def _path_rows(self, multi, rows, body_rows, omega_rock, alpha_ref, kinds, E_ref,
                   impact: tuple, initial: tuple | None = None, u_cr=0.0) -> ChunkRows:
        """Rows of a scene with an excitation path: each distinct motion of the chunk
        computed once (``Scene.path_motion``), the kernel's A_ratio the ground's times the
        motion's gain (``Scene._path_point``, vectorised), filled motion by motion."""
        sc = self.scene
        n = alpha_ref.size
        key = (np.stack([np.asarray(multi[i], np.int64) for i in self._path_pos], 1)
               if self._path_pos else np.zeros((n, 1), np.int64))
        distinct, inv = np.unique(key, axis=0, return_inverse=True)
        inv = inv.reshape(-1)
        motions, peaks, verticals = [], [], []
        for row in distinct:
            values = {sc.axes[i].name: sc.axes[i].values[int(j)]
                      for i, j in zip(self._path_pos, row, strict=True)}
            m, peak, r = sc.path_motion(values)
            motions.append(m)
            peaks.append(peak)
            # the record's vertical reaches the floor unfiltered: on the motion's samples
            verticals.append(sc.path_vertical(m, r))
        m_pga = np.array([m.pga for m in motions])[inv]
        lam = self._values[self._i_lam][multi[self._i_lam]]
        if sc.suite is not None:
            su = sc.suite
            stripe = None if self._i_stripe is None else np.asarray(multi[self._i_stripe])
            p = self._values[self._i_w][multi[self._i_w]]
            rec = np.asarray(multi[self._i_rec], np.int64)
            a_ratio = su.factors(rec, stripe, alpha_ref, p) * m_pga / np.tan(alpha_ref)
        else:
            p = (self._values[self._i_w][multi[self._i_w]] if sc.recorded
                 else np.full(n, sc.path.p))
            a_ratio = (self._values[self._i_A][multi[self._i_A]] * m_pga
                       / np.array(peaks)[inv])
        mu = np.nan if self._i_mu is None else self._values[self._i_mu][multi[self._i_mu]]
        law, e, e_factor, mu = (np.broadcast_to(np.asarray(v, float), lam.shape)
                                for v in (*impact, mu))
        if initial is not None:
            initial = tuple(np.broadcast_to(np.asarray(v, float), lam.shape) for v in initial)
        u_cr = np.broadcast_to(np.asarray(u_cr, float), lam.shape)
        code = np.full(n, shape_code(RECORD))
        for j, motion in enumerate(motions):
            sel = inv == j
            part = np.empty((int(sel.sum()), L.N_PAR))
            fill_rows(part, body_rows[sel], omega_rock[sel], alpha_ref[sel], lam[sel],
                      code[sel], p[sel], a_ratio[sel], sc.numerics, record=motion,
                      mu=mu[sel], law=law[sel], e=e[sel], e_factor=e_factor[sel],
                      initial=None if initial is None else tuple(v[sel] for v in initial),
                      u_cr=u_cr[sel], vertical=verticals[j])
            rows[sel] = part
        return ChunkRows(rows, kinds, alpha_ref, E_ref, inv, tuple(motions), tuple(verticals))

    def kinds(self) -> list[int]:
        """The kernel kinds the grid's bodies need (each distinct body visited once)."""
        n_bodies = int(np.prod(self._body_shape, dtype=np.int64))
        found: set[int] = set()
        step = 4096
        for a in range(0, n_bodies, step):
            found.update(int(k) for k in self._bodies(np.arange(a, min(a + step, n_bodies)))[4])
        return sorted(found)
