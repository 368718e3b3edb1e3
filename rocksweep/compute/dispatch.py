"""Parameter rows through one compiled kernel variant: the one dispatch of every run.

Sweeps (``compute.sweep.run_rows``, one call per body kind and record of a chunk), the
A_min searches of ``analysis.boundaries``, single runs (``compute.single.run_point``) and
the accuracy study (``analysis.accuracy.run_kernel``) all run their rows through
``run_variant``: the kernel variant of (body kind, bookkeeping level, ground), an
excitation's samples riding on the rows, and the close calls certified
(``compute.certify``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from rocksweep import kernel  # its variants looked up at each call (kernel.chunk_kernel)
from rocksweep.compute.certify import certify
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.ground_motion import Excitation
from rocksweep.physics.points import kernel_contact


def history_capacity(row: np.ndarray) -> int:
    """Rows a full history of this point can need: every step plus 3 rows per event (a
    record's steps on its samples counted on top)."""
    t_pulse = min(row[L.PAR_TPULSE], row[L.PAR_TEND])
    steps = math.ceil(t_pulse / row[L.PAR_DT_ON]) + math.ceil(
        (row[L.PAR_TEND] - t_pulse) / row[L.PAR_DT])
    if row[L.PAR_REC_H] > 0.0:
        steps += math.ceil(row[L.PAR_TPULSE] / row[L.PAR_REC_H]) + 1
    return int(steps + 3 * row[L.PAR_MAXEVENTS] + 16)


def run_variant(rows: np.ndarray, kind: int, level: int, ground: int, refine: int = 0,
                excitation: Excitation | None = None, histories: list | None = None,
                out: np.ndarray | None = None) -> np.ndarray:
    """Result rows float64[n, N_OUT] of parameter rows float64[n, N_PAR (+ samples)] run
    through the kernel variant of body ``kind`` (``physics.points.kernel_kind``),
    bookkeeping ``level`` (``kernel.layout.LEVEL_*``), ``ground``
    (``kernel.layout.GROUND_*``: the variants of Ricker, MP and samples, and of a moving
    gravity g + a_v; ``ground_motion.shared_ground``) and the contact model the rows'
    friction calls for (``physics.points.kernel_contact``: the sliding base where a row
    gives PAR_MU; rows with and without it run apart, in their places).

    refine: close calls re-run finer, up to this many refinements (``compute.certify``,
    ``Numerics.refine``; 0: none). excitation: the excitation all rows share, whose
    samples are written once into one wide row (``run_record``), or None (the rows carry
    their samples, ``Excitation.with_samples``, or need none). histories: a list of n
    entries to receive each run's history (float64[capacity, N_HIST], the finest run's
    when certified): the energy-accounting point kernel runs instead (``level`` unused).
    out: where to write the result rows (float64[n, N_OUT]; default a new array).
    Returns the result rows."""
    n = rows.shape[0]
    outs = np.empty((n, L.N_OUT)) if out is None else out
    given = np.isfinite(rows[:, L.PAR_MU])
    if given.any() and not given.all():  # each contact model on its own rows
        for part in (given, ~given):
            idx = np.flatnonzero(part)
            sub_h = None if histories is None else [None] * idx.size
            outs[idx] = run_variant(np.ascontiguousarray(rows[idx]), kind, level, ground,
                                    refine, excitation, sub_h)
            if histories is not None:
                for j, i in enumerate(idx.tolist()):
                    histories[i] = sub_h[j]
        return outs
    contact = kernel_contact(rows[:, L.PAR_MU]) if n else L.CONTACT_NOSLIP
    if excitation is not None and excitation.record is None:
        excitation = None  # a pulse: nothing rides on its rows
    if histories is not None:
        fn = kernel.point_kernel(kind, ground, contact)

        def call(sub: np.ndarray, res: np.ndarray, idx: Sequence[int],
                 keep: bool = True) -> None:
            wide = sub if excitation is None else excitation.with_samples(sub)
            for j, i in enumerate(idx):
                hist = np.empty((history_capacity(wide[j]), L.N_HIST))
                fn(wide[j], res[j], hist)
                if keep:  # a probe's (``certify``) is not the point's history
                    histories[int(i)] = hist
    else:
        fn = kernel.chunk_kernel(kind, level, ground, contact)

        def call(sub: np.ndarray, res: np.ndarray, idx: Sequence[int],
                 keep: bool = True) -> None:
            if excitation is None:
                fn(sub, res)
            else:
                run_record(fn, sub, np.ones(sub.shape[0], bool), res, excitation)

    call(rows, outs, range(n))  # idx: the rows' places in ``histories``
    if refine > 0:
        def rerun(sub: np.ndarray, idx: np.ndarray, keep: bool = True) -> np.ndarray:
            res = np.empty((sub.shape[0], L.N_OUT))
            call(np.ascontiguousarray(sub), res, idx, keep)
            return res

        certify(rows, outs, rerun, refine)
    return outs


def run_record(kernel_fn, rows: np.ndarray, sel: np.ndarray, outs: np.ndarray,
               excitation: Excitation) -> None:
    """Run the selected rows (float64[n, N_PAR]), all driven by the samples of
    ``excitation``.

    The GROUND chunk kernel reads the ground motion from the row after the parameters
    (``kernel.ground.ground_acc``, ``Excitation.with_samples``). The runs share one
    wide row: the samples are written into it once, and each point's N_PAR parameters are
    copied in before its kernel call (one call a point, ~1 us of dispatch against the
    milliseconds a run of a record takes), so no point copies the samples. Each point's
    result is the one a row of its own gives (the kernel runs every row alone), bit for
    bit."""
    idx = np.flatnonzero(sel)
    if idx.size == 0:
        return
    wide = excitation.with_samples(rows[idx[:1], :L.N_PAR])  # float64[1, N_PAR + samples]
    res = np.empty((1, L.N_OUT))
    head = wide[0, :L.N_PAR]
    for i in idx.tolist():
        head[:] = rows[i, :L.N_PAR]
        kernel_fn(wide, res)
        outs[i] = res[0]
