"""``ds.rocksweep``: the analyses as methods of a result Dataset (as rioxarray's ``.rio``).

Registered with xarray by ``register_accessor``: on ``import rocksweep`` when xarray is
already imported, and by every function of the API (``rocksweep.api``) once xarray is
loaded, so ``import xarray, rocksweep`` is enough. ``import rocksweep`` alone never
imports xarray (it stays light).
"""

from __future__ import annotations

import sys
from typing import Any

_REGISTERED = False


def _api() -> Any:
    """The facade whose functions the methods call (imported on first use: the facade
    imports this module)."""
    from rocksweep import api

    return api


class RocksweepAccessor:
    """``ds.rocksweep.<analysis>(...)`` is ``rocksweep.<analysis>(ds, ...)``."""

    def __init__(self, ds: Any) -> None:
        self._ds = ds

    def plot(self, **kwargs: Any) -> Any:
        """``rocksweep.plot(ds, ...)``: the figure of the Dataset (a sweep's stability
        diagram, an analysis's figure)."""
        return _api().plot(self._ds, **kwargs)

    def boundaries(self, **kwargs: Any) -> Any:
        """``rocksweep.boundaries(ds, ...)``: A_min as a Dataset."""
        return _api().boundaries(self._ds, **kwargs)

    def boundary_lines(self) -> Any:
        """``rocksweep.boundary_lines(ds)``: the class boundary polylines (DataFrame)."""
        return _api().boundary_lines(self._ds)

    def spectra(self, **kwargs: Any) -> Any:
        """``rocksweep.spectra(ds, ...)``: rocking and overturning spectra."""
        return _api().spectra(self._ds, **kwargs)

    def fragility(self, **kwargs: Any) -> Any:
        """``rocksweep.fragility(ds, ...)``: lognormal fragility curves of a suite."""
        return _api().fragility(self._ds, **kwargs)

    def ida(self, **kwargs: Any) -> Any:
        """``rocksweep.ida(ds, ...)``: the first overturning level of each record."""
        return _api().ida(self._ds, **kwargs)

    def risk(self, hazard: Any, years: float = 50, **kwargs: Any) -> Any:
        """``rocksweep.risk(ds, hazard, years)``: annual rate and probability per state."""
        return _api().risk(self._ds, hazard, years, **kwargs)

    def im_efficiency(self, **kwargs: Any) -> Any:
        """``rocksweep.im_efficiency(ds, ...)``: beta of the fragility in every IM."""
        return _api().im_efficiency(self._ds, **kwargs)

    def table(self) -> Any:
        """``rocksweep.table(ds)``: one row per run (a DataFrame)."""
        return _api().table(self._ds)

    def as_overrides(self, which: str = "all") -> dict[str, Any]:
        """``rocksweep.calibrated_overrides(ds, which)`` of a calibration Dataset."""
        return _api().calibrated_overrides(self._ds, which)

    def outcome_words(self) -> Any:
        """``outcome`` as words (not_run, safe, mode1, mode2), an object DataArray."""
        import numpy as np

        from rocksweep.vocab.outcomes import OUTCOME_WORDS

        o = self._ds["outcome"]
        return o.copy(data=np.vectorize(OUTCOME_WORDS.get, otypes=[object])(o.values))


def register_accessor() -> None:
    """Register ``ds.rocksweep`` with xarray, once, if xarray is imported (this never
    imports it: cheap enough for every API call)."""
    global _REGISTERED
    if _REGISTERED or "xarray" not in sys.modules:
        return
    import xarray as xr

    xr.register_dataset_accessor("rocksweep")(RocksweepAccessor)
    _REGISTERED = True
