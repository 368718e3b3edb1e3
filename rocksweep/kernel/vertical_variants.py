"""The vertical ground acceleration's compiled variants (jitted; docs/vertical.md).

GROUND = 2 (``layout.GROUND_VERTICAL``): every ground motion with a vertical component
(``on`` a float: gravity g + a_v, ``equations.ground_gravity``), one entry point per body
kind and level as ``variants``' own. A module apart, imported by ``variants._tables`` the
first time a scene asks for one: a run without a vertical neither imports nor compiles
these (their decorators and cache objects cost every start-up a few ms otherwise).
"""

from numba import njit

from rocksweep.kernel._cache import ENTRY, loads_fast
from rocksweep.kernel.layout import (
    KIND_FLEXIBLE,
    KIND_FLEXIBLE_UNDAMPED,
    KIND_RIGID,
    LEVEL_ENERGY,
    LEVEL_OUTCOME,
)
from rocksweep.kernel.loop import simulate_point


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


CHUNK = {
    (KIND_FLEXIBLE, LEVEL_OUTCOME): chunk_flexible_vertical,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_OUTCOME): chunk_flexible_undamped_vertical,
    (KIND_RIGID, LEVEL_OUTCOME): chunk_rigid_vertical,
    (KIND_FLEXIBLE, LEVEL_ENERGY): chunk_flexible_energy_vertical,
    (KIND_FLEXIBLE_UNDAMPED, LEVEL_ENERGY): chunk_flexible_undamped_energy_vertical,
    (KIND_RIGID, LEVEL_ENERGY): chunk_rigid_energy_vertical,
}
POINT = {
    KIND_FLEXIBLE: point_flexible_history_vertical,
    KIND_FLEXIBLE_UNDAMPED: point_flexible_undamped_history_vertical,
    KIND_RIGID: point_rigid_history_vertical,
}
for _entry in (*CHUNK.values(), *POINT.values()):
    loads_fast(_entry)  # a cached variant loads in ~5 ms (_cache.EntryCache)
