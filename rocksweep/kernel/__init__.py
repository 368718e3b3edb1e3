"""The jitted kernel: plain float64 arrays in, plain float64 arrays out (numba only).

``chunk_kernel(kind, level)`` and ``point_kernel(kind)`` pick the compiled variant for an
effect set; see ``integrate`` for how the variants are built and ``layout`` for the arrays.
"""

from rocksweep.kernel import _cache  # noqa: F401  (must precede every @njit(cache=True))
from rocksweep.kernel import integrate as _k
from rocksweep.kernel.layout import (
    KIND_FLEXIBLE,
    KIND_FLEXIBLE_UNDAMPED,
    KIND_RIGID,
    LEVEL_ENERGY,
    LEVEL_OUTCOME,
)

_CHUNK = {
    (KIND_FLEXIBLE, LEVEL_OUTCOME): _k.chunk_flexible,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_OUTCOME): _k.chunk_flexible_undamped,
    (KIND_RIGID, LEVEL_OUTCOME): _k.chunk_rigid,
    (KIND_FLEXIBLE, LEVEL_ENERGY): _k.chunk_flexible_energy,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_ENERGY): _k.chunk_flexible_undamped_energy,
    (KIND_RIGID, LEVEL_ENERGY): _k.chunk_rigid_energy,
}
_POINT = {
    KIND_FLEXIBLE: _k.point_flexible_history,
    KIND_FLEXIBLE_UNDAMPED: _k.point_flexible_undamped_history,
    KIND_RIGID: _k.point_rigid_history,
}


def chunk_kernel(kind: int, level: int):
    """Jitted ``f(prms[n, N_PAR], outs[n, N_OUT])`` for a kernel kind and bookkeeping level."""
    return _CHUNK[(kind, level)]


def point_kernel(kind: int):
    """Jitted ``f(prm[N_PAR], out[N_OUT], hist[n, N_HIST])`` with energy and history."""
    return _POINT[kind]


def warm_up(kind: int, level: int | None = None) -> None:
    """Compile (or load from numba's cache) a variant now, so timings exclude compilation.

    ``level=None`` warms the single-run (history) variant of ``kind``.
    """
    import numpy as np

    from rocksweep.kernel.layout import N_HIST, N_OUT, N_PAR, PAR_TEND

    prm = np.zeros((1, N_PAR))
    prm[0, PAR_TEND] = -1.0  # the loop stops before its first step
    out = np.empty((1, N_OUT))
    if level is None:
        point_kernel(kind)(prm[0], out[0], np.empty((1, N_HIST)))
    else:
        chunk_kernel(kind, level)(prm, out)
