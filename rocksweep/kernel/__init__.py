"""The jitted kernel: plain float64 arrays in, plain float64 arrays out (numba only).

``chunk_kernel(kind, level)`` and ``point_kernel(kind)`` pick the compiled variant for an
effect set; ``warm_up`` compiles one now. One idea per module:

- ``layout``: the arrays' index constants (parameter row, result row, history, state);
- ``equations``: the physics, pure formulas (also called by ``rocksweep.reference``);
- ``stepping``: the right-hand side on the state and one RK4 step;
- ``events``: event functions, detection inside a step and location of the root;
- ``transitions``: uplift, the impact map, the rest and rigid-bound early exits;
- ``loop``: ``simulate_point``, one point from start to outcome;
- ``variants``: the compiled entry points and their tables;
- ``_cache``: where numba caches them, stamped by the hash of these sources.
"""

from rocksweep.kernel import _cache  # noqa: F401  (must precede every @njit(cache=True))
from rocksweep.kernel.variants import chunk_kernel, point_kernel, warm_up

__all__ = ["chunk_kernel", "point_kernel", "warm_up"]
