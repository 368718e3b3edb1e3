"""``ds.rocksweep``: the API's functions of a Dataset as its methods, as rioxarray's ``.rio``.

``ds.rocksweep.<analysis>(...)`` is ``rocksweep.<analysis>(ds, ...)`` for every function the
API marks ``@analysis`` (``rocksweep.api.ANALYSES``): the class is made from that list, so
a new analysis is a method without a line here. A method takes the function's required
arguments after the Dataset by position (``ds.rocksweep.risk(hazard)``), the others as
keywords. Two more: ``as_overrides`` (``rocksweep.calibrated_overrides`` of a calibration)
and ``outcome_words``.

Registered with xarray once per process, without importing it: ``import rocksweep`` never
loads xarray (with pandas 1.3 G instructions, 0.4-1.5 s; the command line's start-up would
pay it: docs/performance.md).
``watch()`` (called by ``import rocksweep``) registers at once if xarray is loaded, else
when it is: a finder first on ``sys.meta_path`` lets the real finders find xarray and
registers the accessor when the module has run (the post-import hook of ``wrapt`` and
``importlib``'s lazy loader), then leaves ``sys.meta_path``.
"""

from __future__ import annotations

import functools
import importlib.util
import inspect
import sys
from collections.abc import Callable
from typing import Any

from rocksweep.vocab.outcomes import OUTCOME_WORDS


def _method(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` as a method of the accessor: ``fn(ds, *required, **keywords)``."""
    params = list(inspect.signature(fn).parameters.values())[1:]
    required = [p for p in params
                if p.default is p.empty and p.kind is p.POSITIONAL_OR_KEYWORD]

    def method(self: Any, *args: Any, **kwargs: Any) -> Any:
        if len(args) > len(required):
            names = ", ".join(p.name for p in required) or "no argument"
            raise TypeError(f"ds.rocksweep.{fn.__name__}() takes {names} by position, the "
                            f"others as keywords ({len(args)} given by position)")
        return fn(self._ds, *args, **kwargs)

    method.__name__ = method.__qualname__ = fn.__name__
    method.__doc__ = f"``rocksweep.{fn.__name__}(ds, ...)`` as a method.\n\n{fn.__doc__}"
    method.__signature__ = inspect.Signature(  # type: ignore[attr-defined]
        [inspect.Parameter("self", inspect.Parameter.POSITIONAL_OR_KEYWORD), *required,
         inspect.Parameter("kwargs", inspect.Parameter.VAR_KEYWORD)])
    return method


class _Accessor:
    """``ds.rocksweep.<analysis>(...)`` is ``rocksweep.<analysis>(ds, ...)``."""

    def __init__(self, ds: Any) -> None:
        self._ds = ds

    def as_overrides(self, which: str = "all") -> dict[str, Any]:
        """``rocksweep.calibrated_overrides(ds, which)`` of a calibration Dataset."""
        # rocksweep.api on first use: import rocksweep does not load it
        from rocksweep.api import calibrated_overrides

        return calibrated_overrides(self._ds, which)

    def outcome_words(self) -> Any:
        """``outcome`` as words (not_run, safe, mode1, mode2), an object DataArray."""
        # numpy: import rocksweep loads none
        import numpy as np

        o = self._ds["outcome"]
        return o.copy(data=np.vectorize(OUTCOME_WORDS.get, otypes=[object])(o.values))


@functools.cache
def accessor_class() -> type:
    """``RocksweepAccessor``: ``_Accessor`` with a method per ``rocksweep.api.ANALYSES``
    (made once, on first use)."""
    # rocksweep.api on first use: import rocksweep does not load it
    from rocksweep.api import ANALYSES

    methods = {fn.__name__: _method(fn) for fn in ANALYSES}
    return type("RocksweepAccessor", (_Accessor,), {**methods, "__module__": __name__})


def register() -> None:
    """Register ``ds.rocksweep`` with xarray (loaded by now), once."""
    # loaded by now: watch() registers once xarray is imported
    import xarray as xr

    if getattr(xr.Dataset, "rocksweep", None) is not accessor_class():
        xr.register_dataset_accessor("rocksweep")(accessor_class())


class _XarrayWatch:
    """A finder that finds nothing itself: when xarray is imported it has the other finders
    find it and registers the accessor after the module has run."""

    def find_spec(self, name: str, path: Any = None, target: Any = None) -> Any:
        if name != "xarray":
            return None
        sys.meta_path.remove(self)  # once: the finders below find the real module
        spec = importlib.util.find_spec(name)
        if spec is None or not hasattr(spec.loader, "exec_module"):
            return spec
        run = spec.loader.exec_module

        def exec_module(module: Any) -> None:
            run(module)
            register()

        spec.loader.exec_module = exec_module  # type: ignore[union-attr]
        return spec


def watch() -> None:
    """``ds.rocksweep`` now if xarray is loaded, else as soon as it is."""
    if "xarray" in sys.modules:
        register()
    elif not any(isinstance(f, _XarrayWatch) for f in sys.meta_path):
        sys.meta_path.insert(0, _XarrayWatch())
