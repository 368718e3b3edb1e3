"""``ds.rocksweep``: the analyses as methods of a result Dataset (as rioxarray's ``.rio``).

Registered when ``rocksweep.run`` or ``rocksweep.open`` first imports xarray (importing
rocksweep stays light), so every Dataset they return has it:

    ds = rocksweep.run("configs/fig3a.yaml")
    ds.rocksweep.plot()             # the stability diagram, outcome as categories
    ds.rocksweep.boundaries()       # A_min over w_over_p, lam, ...
"""

from __future__ import annotations

from typing import Any

_REGISTERED = False


class RocksweepAccessor:
    """``ds.rocksweep.<analysis>(...)`` is ``rocksweep.<analysis>(ds, ...)``."""

    def __init__(self, ds: Any) -> None:
        self._ds = ds

    def plot(self, *args: Any, **kwargs: Any) -> Any:
        """``rocksweep.plot(ds, ...)``: the stability diagram (categorical outcome)."""
        from rocksweep.api import plot

        return plot(self._ds, *args, **kwargs)

    def boundaries(self, **kwargs: Any) -> Any:
        """``rocksweep.boundaries(ds, ...)``: A_min as a Dataset."""
        from rocksweep.api import boundaries

        return boundaries(self._ds, **kwargs)

    def boundary_lines(self) -> Any:
        """``rocksweep.boundary_lines(ds)``: the class boundary polylines (DataFrame)."""
        from rocksweep.api import boundary_lines

        return boundary_lines(self._ds)

    def spectra(self, **kwargs: Any) -> Any:
        """``rocksweep.spectra(ds, ...)``: rocking and overturning spectra."""
        from rocksweep.api import spectra

        return spectra(self._ds, **kwargs)

    def fragility(self, **kwargs: Any) -> Any:
        """``rocksweep.fragility(ds, ...)``: lognormal fragility curves of a suite."""
        from rocksweep.api import fragility

        return fragility(self._ds, **kwargs)

    def ida(self, **kwargs: Any) -> Any:
        """``rocksweep.ida(ds, ...)``: the first overturning level of each record."""
        from rocksweep.api import ida

        return ida(self._ds, **kwargs)

    def outcome_words(self) -> Any:
        """``outcome`` as words (not_run, safe, mode1, mode2), an object DataArray."""
        import numpy as np

        from rocksweep.outcomes import OUTCOME_WORDS

        o = self._ds["outcome"]
        return o.copy(data=np.vectorize(OUTCOME_WORDS.get, otypes=[object])(o.values))


def register() -> None:
    """Register ``ds.rocksweep`` with xarray (once)."""
    global _REGISTERED
    if _REGISTERED:
        return
    import xarray as xr

    xr.register_dataset_accessor("rocksweep")(RocksweepAccessor)
    _REGISTERED = True
