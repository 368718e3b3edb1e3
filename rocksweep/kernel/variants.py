"""The compiled variants: one small jitted entry point per effect set (jitted).

Each entry point fixes the compile-time flags of ``loop.simulate_point`` as literals
(FLEX: the top mass moves on its spring; DAMPED: the spring has a damper; ENERGY: energy
accounting; CONTACT: ground reactions, friction demand and impulses, True or None), so
every variant is assembled from the same functions with the branches it does not need
removed. Each calls ``simulate_point`` itself (no shared chunk loop in between: every level
of calls is one more LLVM optimisation of the whole kernel at compile time).

  chunk_*: prms float64[n, N_PAR] -> outs float64[n, N_OUT] (filled in place); they
      release the GIL, so threads of one process run chunks in parallel
  chunk_*_contact: with energy accounting and the ground reactions (``LEVEL_CONTACT``:
      scenes with ``outputs: {contact: true}``, with or without energy)
  point_*: one point with energy accounting, the ground reactions and a history buffer
      float64[n, N_HIST] (the reactions cost a single run ~nothing: no variant without)

``chunk_kernel(kind, level, ground)`` and ``point_kernel(kind, ground)`` pick one by
``KIND_*``, ``LEVEL_*`` and ``GROUND_*`` (``layout``); ``warm_up`` compiles (or loads) one
now.
"""

import numpy as np
from numba import njit

from rocksweep.kernel._cache import ENTRY, loads_fast
from rocksweep.kernel.layout import (
    GROUND_PULSE,
    GROUND_VERTICAL,
    KIND_FLEXIBLE,
    KIND_FLEXIBLE_UNDAMPED,
    KIND_RIGID,
    LEVEL_CONTACT,
    LEVEL_ENERGY,
    LEVEL_OUTCOME,
    N_HIST,
    N_OUT,
    N_PAR,
    PAR_B,
    PAR_G,
    PAR_M,
    PAR_MTOT,
    PAR_T_AIR,
    PAR_TEND,
    PAR_TPULSE,
)
from rocksweep.kernel.loop import simulate_point


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, True, False, None, False)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_undamped(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, False, False, None, False)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_rigid(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, False, False, False, None, False)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_energy(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, True, True, None, False)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_undamped_energy(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, False, True, None, False)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_rigid_energy(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, False, False, True, None, False)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_contact(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, True, True, True, False)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_undamped_contact(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, False, True, True, False)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_rigid_contact(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, False, False, True, True, False)


@njit(cache=True, **ENTRY)
def point_flexible_history(prm, out, hist):
    simulate_point(prm, out, hist, True, True, True, True, False)


@njit(cache=True, **ENTRY)
def point_flexible_undamped_history(prm, out, hist):
    simulate_point(prm, out, hist, True, False, True, True, False)


@njit(cache=True, **ENTRY)
def point_rigid_history(prm, out, hist):
    simulate_point(prm, out, hist, False, False, True, True, False)


# GROUND = 1 (an int, not True: its type selects the code, ``loop._acting``): the Ricker
# and MP pulses and records (``equations.ground_acc``), compiled only when a scene asks.
@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_ground(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, True, False, None, 1)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_undamped_ground(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, False, False, None, 1)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_rigid_ground(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, False, False, False, None, 1)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_energy_ground(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, True, True, None, 1)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_undamped_energy_ground(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, False, True, None, 1)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_rigid_energy_ground(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, False, False, True, None, 1)


@njit(cache=True, **ENTRY)
def point_flexible_history_ground(prm, out, hist):
    simulate_point(prm, out, hist, True, True, True, True, 1)


@njit(cache=True, **ENTRY)
def point_flexible_undamped_history_ground(prm, out, hist):
    simulate_point(prm, out, hist, True, False, True, True, 1)


@njit(cache=True, **ENTRY)
def point_rigid_history_ground(prm, out, hist):
    simulate_point(prm, out, hist, False, False, True, True, 1)


# GROUND = 2 (GROUND_VERTICAL): every ground motion with a vertical component (``on`` a
# float: gravity g + a_v, ``equations.ground_gravity``); compiled only when a scene asks.
@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_vertical(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, True, False, None, 2)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_undamped_vertical(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, False, False, None, 2)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_rigid_vertical(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, False, False, False, None, 2)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_energy_vertical(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, True, True, None, 2)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_flexible_undamped_energy_vertical(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, True, False, True, None, 2)


@njit(cache=True, nogil=True, **ENTRY)
def chunk_rigid_energy_vertical(prms, outs):
    for i in range(prms.shape[0]):
        simulate_point(prms[i], outs[i], None, False, False, True, None, 2)


@njit(cache=True, **ENTRY)
def point_flexible_history_vertical(prm, out, hist):
    simulate_point(prm, out, hist, True, True, True, True, 2)


@njit(cache=True, **ENTRY)
def point_flexible_undamped_history_vertical(prm, out, hist):
    simulate_point(prm, out, hist, True, False, True, True, 2)


@njit(cache=True, **ENTRY)
def point_rigid_history_vertical(prm, out, hist):
    simulate_point(prm, out, hist, False, False, True, True, 2)


_CHUNK = {
    (KIND_FLEXIBLE, LEVEL_OUTCOME): chunk_flexible,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_OUTCOME): chunk_flexible_undamped,
    (KIND_RIGID, LEVEL_OUTCOME): chunk_rigid,
    (KIND_FLEXIBLE, LEVEL_ENERGY): chunk_flexible_energy,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_ENERGY): chunk_flexible_undamped_energy,
    (KIND_RIGID, LEVEL_ENERGY): chunk_rigid_energy,
    (KIND_FLEXIBLE, LEVEL_CONTACT): chunk_flexible_contact,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_CONTACT): chunk_flexible_undamped_contact,
    (KIND_RIGID, LEVEL_CONTACT): chunk_rigid_contact,
}
_POINT = {
    KIND_FLEXIBLE: point_flexible_history,
    KIND_FLEXIBLE_UNDAMPED: point_flexible_undamped_history,
    KIND_RIGID: point_rigid_history,
}
_CHUNK_GROUND = {
    (KIND_FLEXIBLE, LEVEL_OUTCOME): chunk_flexible_ground,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_OUTCOME): chunk_flexible_undamped_ground,
    (KIND_RIGID, LEVEL_OUTCOME): chunk_rigid_ground,
    (KIND_FLEXIBLE, LEVEL_ENERGY): chunk_flexible_energy_ground,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_ENERGY): chunk_flexible_undamped_energy_ground,
    (KIND_RIGID, LEVEL_ENERGY): chunk_rigid_energy_ground,
}
_POINT_GROUND = {
    KIND_FLEXIBLE: point_flexible_history_ground,
    KIND_FLEXIBLE_UNDAMPED: point_flexible_undamped_history_ground,
    KIND_RIGID: point_rigid_history_ground,
}
_CHUNK_VERTICAL = {
    (KIND_FLEXIBLE, LEVEL_OUTCOME): chunk_flexible_vertical,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_OUTCOME): chunk_flexible_undamped_vertical,
    (KIND_RIGID, LEVEL_OUTCOME): chunk_rigid_vertical,
    (KIND_FLEXIBLE, LEVEL_ENERGY): chunk_flexible_energy_vertical,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_ENERGY): chunk_flexible_undamped_energy_vertical,
    (KIND_RIGID, LEVEL_ENERGY): chunk_rigid_energy_vertical,
}
_POINT_VERTICAL = {
    KIND_FLEXIBLE: point_flexible_history_vertical,
    KIND_FLEXIBLE_UNDAMPED: point_flexible_undamped_history_vertical,
    KIND_RIGID: point_rigid_history_vertical,
}
for _entry in (*_CHUNK.values(), *_CHUNK_GROUND.values(), *_POINT.values(),
               *_POINT_GROUND.values(), *_CHUNK_VERTICAL.values(), *_POINT_VERTICAL.values()):
    loads_fast(_entry)  # a cached variant loads in ~5 ms, not ~0.25 s (_cache.EntryCache)


def _tables(ground: int) -> tuple[dict, dict]:
    """(chunk table, point table) of a ground code (``layout.GROUND_*``; True is GROUND_ANY)."""
    if ground == GROUND_VERTICAL:
        return _CHUNK_VERTICAL, _POINT_VERTICAL
    return (_CHUNK_GROUND, _POINT_GROUND) if ground else (_CHUNK, _POINT)


def chunk_kernel(kind: int, level: int, ground: int = GROUND_PULSE):
    """Jitted ``f(prms[n, N_PAR], outs[n, N_OUT])`` for a kernel kind and bookkeeping level;
    ``ground`` (``layout.GROUND_*``): GROUND_ANY (or True) the variant for every ground
    motion (Ricker, MP, records; rows of a record carry its samples,
    ``points.with_record``), GROUND_VERTICAL the same with a vertical component (rows with
    PAR_V_*), else sine and cosine pulses only."""
    table = _tables(ground)[0]
    if (kind, level) not in table:  # the scene refuses this combination first
        raise ValueError(f"no kernel variant for kind {kind}, level {level}, ground {ground}")
    return table[(kind, level)]


def point_kernel(kind: int, ground: int = GROUND_PULSE):
    """Jitted ``f(prm[N_PAR], out[N_OUT], hist[n, N_HIST])`` with energy, ground reactions
    and history; ``ground``: as ``chunk_kernel``'s."""
    return _tables(ground)[1][kind]


def warm_up(kind: int, level: int | None = None, ground: int = GROUND_PULSE) -> None:
    """Compile (or load from numba's cache) a variant now, so timings exclude compilation.

    ``level=None`` warms the single-run (history) variant of ``kind``.
    """
    prm = np.zeros((1, N_PAR))
    prm[0, PAR_TEND] = -1.0  # the loop stops before its first step
    # a body at rest in full contact: the contact variants evaluate the reactions at t = 0
    prm[0, PAR_M] = prm[0, PAR_MTOT] = prm[0, PAR_G] = prm[0, PAR_B] = 1.0
    prm[0, PAR_TPULSE] = 1.0  # pulse on: no rest test (it divides by k)
    out = np.empty((1, N_OUT))
    prm[0, PAR_T_AIR] = np.inf
    if level is None:
        point_kernel(kind, ground)(prm[0], out[0], np.empty((1, N_HIST)))
    else:
        chunk_kernel(kind, level, ground)(prm, out)
