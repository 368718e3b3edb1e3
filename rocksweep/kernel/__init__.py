"""The jitted kernel: plain float64 arrays in, plain float64 arrays out (numba only).

``chunk_kernel(kind, level)`` and ``point_kernel(kind)`` pick the compiled variant for an
effect set; ``warm_up`` compiles one now. One idea per module:

- ``layout``: the arrays' index constants (parameter row, result row, history, state);
  plain Python, importable without numba;
- ``equations``: the physics, pure formulas (also called by ``rocksweep.physics.reference``);
- ``spring``: the top mass's spring rate while rocking (the step-size rule's input); plain
  Python, importable without numba;
- ``stepping``: the right-hand side on the state and one RK4 step;
- ``events``: event functions, detection inside a step and location of the root;
- ``transitions``: uplift, the impact map, the rest and rigid-bound early exits;
- ``contact``: the ground's reactions, friction demand and impact impulses (where the
  model holds; the contact variants);
- ``loop``: ``simulate_point``, one point from start to outcome;
- ``variants``: the compiled entry points and their tables;
- ``vertical_variants``: the entry points of a vertical ground acceleration (imported on
  first use);
- ``_static``: calls that a variant's flags make dead, left out while typing;
- ``_cache``: where numba caches them, stamped by the hash of these sources (imported
  by every module that defines a jitted function, before its first ``@njit(cache=True)``),
  and how an entry point loads from it (``EntryCache``: no refresh of numba's registries).

The package is lazy (PEP 562): ``from rocksweep.kernel import layout`` loads no numba;
the entry points load the variants (and numba) on first access.
"""

from __future__ import annotations

from typing import Any

__all__ = ["chunk_kernel", "point_kernel", "warm_up"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from rocksweep.kernel import variants

        return getattr(variants, name)
    raise AttributeError(f"module 'rocksweep.kernel' has no attribute {name!r}")
