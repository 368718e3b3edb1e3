"""The compiled entry points, made from one table of (kind, level, ground, contact) (jitted).

A variant is one row of four columns, each a small table here or in ``ground``:

- kind (``KINDS``, ``layout.KIND_*``): the body: FLEX (the top mass moves on its spring)
  and DAMPED (the spring has a damper);
- level (``LEVELS``, ``layout.LEVEL_*``; ``HISTORY`` for a single run): what the run
  accounts besides its outcome: ENERGY (energy accounting) and REACTIONS (the ground
  reactions' bookkeeping, ``contact``: outputs.contact; every single run keeps both);
- ground (``ground.GROUNDS``, ``layout.GROUND_*``): the ground kind: the paper's pulses,
  every shape and records, those with a vertical component;
- contact (``CONTACTS``, ``layout.CONTACT_*``): the contact model, the loop that runs a
  point with its state, phases and transitions: the no-slip rocking of the paper
  (``loop.simulate_point``), or the base that may slide (``slide_loop.simulate_sliding``,
  where a scene gives body.mu).

REACTIONS (a level's bookkeeping of what the ground does) and the contact model (what the
ground lets the body do) are separate columns: any level runs under any model.

An entry point fixes a row's flags as literals of ``simulate_point`` (numba compiles one
specialisation per row, the branches a row does not need removed) and calls it itself (no
shared chunk loop in between: every level of calls is one more LLVM optimisation of the
whole kernel at compile time):

  chunk entry: prms float64[n, N_PAR] -> outs float64[n, N_OUT] (filled in place); it
      releases the GIL, so threads of one process run chunks in parallel
  point entry: one point with energy accounting, the ground reactions and a history
      buffer float64[n, N_HIST] (the reactions cost a single run ~nothing)

``chunk_kernel(kind, level, ground, contact)`` and ``point_kernel(kind, ground, contact)``
make a row's entry point the first time it is asked for (a jitted closure of the row's
flags, named after the row: ``chunk_flexible_energy_ground``), so nothing is decorated,
compiled or loaded for a row no scene asks for; ``warm_up`` compiles (or loads) one now.
numba's on-disk cache keys each made entry point by its name and its flags' values (the
closure's cells are part of the cache index key), so each row is cached on its own, in
the shared per-user cache of these kernel sources (``_cache``), and loads in ~5 ms
(``_cache.EntryCache``).

A new ground kind is a row of ``ground.GROUNDS``; a new contact model a row of
``CONTACTS`` (the two entry bodies calling its loop, which takes ``simulate_point``'s
arguments); the entry points of every combination follow.
"""

import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit

from rocksweep.kernel._cache import ENTRY, loads_fast
from rocksweep.kernel.ground import GROUNDS
from rocksweep.kernel.layout import (
    CONTACT_NOSLIP,
    CONTACT_SLIDE,
    GROUND_PULSE,
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


@dataclass(frozen=True)
class Kind:
    name: str
    flex: bool  # FLEX: the top mass moves on its spring
    damped: bool  # DAMPED: the spring has a damper


@dataclass(frozen=True)
class Level:
    name: str  # the entry point's suffix
    energy: bool  # ENERGY: energy accounting (outputs.energy)
    reactions: bool  # REACTIONS: the ground reactions' bookkeeping (outputs.contact)


@dataclass(frozen=True)
class ContactModel:
    """A contact model: how the body touches the ground, as the two entry points' bodies
    made from a row's flags, ``chunk(FLEX, DAMPED, ENERGY, REACTIONS, GROUND)`` -> a Python
    ``f(prms, outs)`` and ``point(...)`` -> ``f(prm, out, hist)``, each calling the model's
    loop (for the paper's: ``simulate_point``) with the flags. A function of the model's
    own module, so that the loop is a global name of the entry point: a closure cell
    holding it would put numba's per-process dispatcher id into the cache key, and a
    selection in between one more compiled function."""

    name: str  # the entry points' suffix ("" for the paper's)
    chunk: Callable
    point: Callable


KINDS: dict[int, Kind] = {
    KIND_FLEXIBLE: Kind("flexible", flex=True, damped=True),
    KIND_FLEXIBLE_UNDAMPED: Kind("flexible_undamped", flex=True, damped=False),
    KIND_RIGID: Kind("rigid", flex=False, damped=False),
}
LEVELS: dict[int, Level] = {
    LEVEL_OUTCOME: Level("", energy=False, reactions=False),
    LEVEL_ENERGY: Level("_energy", energy=True, reactions=False),
    LEVEL_CONTACT: Level("_contact", energy=True, reactions=True),
}
HISTORY = Level("_history", energy=True, reactions=True)  # the single runs (point entries)


def _noslip_chunk(FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    def chunk(prms, outs):
        for i in range(prms.shape[0]):
            simulate_point(prms[i], outs[i], None, FLEX, DAMPED, ENERGY, REACTIONS, GROUND)
    return chunk


def _noslip_point(FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    def point(prm, out, hist):
        simulate_point(prm, out, hist, FLEX, DAMPED, ENERGY, REACTIONS, GROUND)
    return point


def _slide_chunk(FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    # imported here: a scene without body.mu imports none of the sliding base (20-35 ms
    # of the kernel's ~350 ms import, measured with python -X importtime)
    from rocksweep.kernel import slide_loop

    return slide_loop.chunk_entry(FLEX, DAMPED, ENERGY, REACTIONS, GROUND)


def _slide_point(FLEX, DAMPED, ENERGY, REACTIONS, GROUND):
    from rocksweep.kernel import slide_loop  # (as _slide_chunk's)

    return slide_loop.point_entry(FLEX, DAMPED, ENERGY, REACTIONS, GROUND)


CONTACTS: dict[int, ContactModel] = {
    # the paper's: rocking on a corner or in full contact, never sliding
    CONTACT_NOSLIP: ContactModel("", _noslip_chunk, _noslip_point),
    # the base that may slide on Coulomb friction (a scene's body.mu; docs/sliding.md)
    CONTACT_SLIDE: ContactModel("_slide", _slide_chunk, _slide_point),
}


_MADE: dict[tuple, Callable] = {}  # (kind, level or None, ground, contact) -> entry point
_MAKING = threading.Lock()  # a sweep's threads may ask for the same row at once


def _row(kind, level, ground, contact) -> tuple[int, int | None, int, int]:
    """The table's key of a variant, as plain ints (numpy ints, bools: the same row, the
    same closure cells, the same cache entry); ValueError for a row no table has."""
    row = (int(kind), None if level is None else int(level), int(ground), int(contact))
    if not (row[0] in KINDS and (level is None or row[1] in LEVELS) and row[2] in GROUNDS
            and row[3] in CONTACTS):
        raise ValueError(f"no kernel variant for kind {kind}, level {level}, ground "
                         f"{ground}, contact {contact}")
    return row


def _entry(kind, level, ground, contact):
    row = _row(kind, level, ground, contact)
    fn = _MADE.get(row)
    if fn is not None:
        return fn
    with _MAKING:
        fn = _MADE.get(row)
        if fn is None:
            k, lvl = KINDS[row[0]], (HISTORY if level is None else LEVELS[row[1]])
            g, c = GROUNDS[row[2]], CONTACTS[row[3]]
            flags = (k.flex, k.damped, lvl.energy, lvl.reactions, row[2])
            py = (c.point if level is None else c.chunk)(*flags)
            # the name numba caches it under (module, name): one cache entry per row
            name = ("point" if level is None else "chunk") + "_" + k.name
            py.__name__ = py.__qualname__ = name + lvl.name + g.name + c.name
            fn = _MADE[row] = loads_fast(njit(cache=True, nogil=level is not None,
                                              **ENTRY)(py))
    return fn


def chunk_kernel(kind: int, level: int, ground: int = GROUND_PULSE,
                 contact: int = CONTACT_NOSLIP):
    """Jitted ``f(prms[n, N_PAR], outs[n, N_OUT])`` of a kernel kind, bookkeeping level,
    ground kind (``layout.GROUND_*``: GROUND_PULSE the paper's sine and cosine only,
    GROUND_ANY every shape and records (rows of a record carry its samples,
    ``points.with_record``), GROUND_VERTICAL the same with a vertical component (rows with
    PAR_V_*)) and contact model (``layout.CONTACT_*``)."""
    return _entry(kind, level, ground, contact)


def point_kernel(kind: int, ground: int = GROUND_PULSE, contact: int = CONTACT_NOSLIP):
    """Jitted ``f(prm[N_PAR], out[N_OUT], hist[n, N_HIST])`` with energy, ground reactions
    and history; ``ground``, ``contact``: as ``chunk_kernel``'s."""
    return _entry(kind, None, ground, contact)


def warm_up(kind: int, level: int | None = None, ground: int = GROUND_PULSE,
            contact: int = CONTACT_NOSLIP) -> None:
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
        point_kernel(kind, ground, contact)(prm[0], out[0], np.empty((1, N_HIST)))
    else:
        chunk_kernel(kind, level, ground, contact)(prm, out)
