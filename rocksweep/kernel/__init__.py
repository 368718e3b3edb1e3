"""The jitted kernel: plain float64 arrays in, plain float64 arrays out (numba only).

``chunk_kernel(kind, level, ground, contact)`` and ``point_kernel(kind, ground, contact)``
pick the compiled variant of an effect set, a row of one table (``variants``);
``warm_up`` compiles one now. One idea per module:

- ``layout``: the arrays' index constants (parameter row, result row, history, state)
  and the variants' codes; plain Python, importable without numba;
- ``eq1``: eq. (1), the coefficient of restitution, written once; plain Python (the
  physics evaluates it on arrays), compiled by ``equations``;
- ``spring``: the top mass's spring rate while rocking (the step-size rule's input); plain
  Python, importable without numba;
- ``ridge``: the least potential energy over the top mass's u at a tilt, whose peak a
  decided flexible run's energy is below (``transitions.flexible_bounded``); plain
  Python, compiled by ``equations``;
- ``equations``: the physics, pure formulas (also called by ``rocksweep.physics.reference``);
- ``ground``: the ground's motion as the body feels it, one row per ground kind;
- ``stepping``: the right-hand side on the state and one RK4 step;
- ``events``: event functions, detection inside a step and location of the root;
- ``transitions``: uplift, the impact map, the rest, rigid-bound and flexible-bound early
  exits;
- ``contact``: the ground's reactions, friction demand and impact impulses (where the
  model holds), and their bookkeeping as the loop calls it (outputs.contact);
- ``loop``: ``simulate_point``, one point from start to outcome (the no-slip contact
  model);
- ``variants``: the table of variants and the entry points made from it on first use;
- ``_static``: choices a variant's flags make while typing (the others not compiled);
- ``_cache``: where numba caches them, stamped by the hash of these sources (imported
  by every module that defines a jitted function, before its first ``@njit(cache=True)``),
  and how an entry point loads from it (``EntryCache``: no refresh of numba's registries).

The package is lazy (PEP 562): ``from rocksweep.kernel import layout`` (or ``eq1``) loads
no numba; the entry points load the variants (and numba) on first access.
"""

from __future__ import annotations

from typing import Any

__all__ = ["chunk_kernel", "point_kernel", "warm_up"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from rocksweep.kernel import variants  # lazy: numba, scipy (+0.3 s)

        return getattr(variants, name)
    raise AttributeError(f"module 'rocksweep.kernel' has no attribute {name!r}")
