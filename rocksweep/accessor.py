"""``ds.rocksweep``: the analyses as methods of a result Dataset (as rioxarray's ``.rio``),
registered when ``run`` or ``open`` first imports xarray (``import rocksweep`` stays light).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

# the facade's functions the methods call (``rocksweep.api`` hands them over when it
# registers the accessor: the accessor imports nothing of the facade)
_ANALYSES: dict[str, Callable[..., Any]] = {}
_REGISTERED = False


class RocksweepAccessor:
    """``ds.rocksweep.<analysis>(...)`` is ``rocksweep.<analysis>(ds, ...)``."""

    def __init__(self, ds: Any) -> None:
        self._ds = ds
        self._fn = _ANALYSES

    def plot(self, *args: Any, **kwargs: Any) -> Any:
        """``rocksweep.plot(ds, ...)``: the stability diagram (categorical outcome)."""
        return self._fn["plot"](self._ds, *args, **kwargs)

    def boundaries(self, **kwargs: Any) -> Any:
        """``rocksweep.boundaries(ds, ...)``: A_min as a Dataset."""
        return self._fn["boundaries"](self._ds, **kwargs)

    def boundary_lines(self) -> Any:
        """``rocksweep.boundary_lines(ds)``: the class boundary polylines (DataFrame)."""
        return self._fn["boundary_lines"](self._ds)

    def spectra(self, **kwargs: Any) -> Any:
        """``rocksweep.spectra(ds, ...)``: rocking and overturning spectra."""
        return self._fn["spectra"](self._ds, **kwargs)

    def fragility(self, **kwargs: Any) -> Any:
        """``rocksweep.fragility(ds, ...)``: lognormal fragility curves of a suite."""
        return self._fn["fragility"](self._ds, **kwargs)

    def ida(self, **kwargs: Any) -> Any:
        """``rocksweep.ida(ds, ...)``: the first overturning level of each record."""
        return self._fn["ida"](self._ds, **kwargs)

    def risk(self, hazard: Any, years: float = 50, **kwargs: Any) -> Any:
        """``rocksweep.risk(ds, hazard, years)``: annual rate and probability per state."""
        return self._fn["risk"](self._ds, hazard, years, **kwargs)

    def im_efficiency(self, **kwargs: Any) -> Any:
        """``rocksweep.im_efficiency(ds, ...)``: beta of the fragility in every IM."""
        return self._fn["im_efficiency"](self._ds, **kwargs)

    def table(self) -> Any:
        """``rocksweep.table(ds)``: one row per run (a DataFrame)."""
        return self._fn["table"](self._ds)

    def as_overrides(self, which: str = "all") -> dict[str, Any]:
        """``rocksweep.calibrated_overrides(ds, which)`` of a calibration Dataset."""
        return self._fn["calibrated_overrides"](self._ds, which)

    def outcome_words(self) -> Any:
        """``outcome`` as words (not_run, safe, mode1, mode2), an object DataArray."""
        import numpy as np

        from rocksweep.outcomes import OUTCOME_WORDS

        o = self._ds["outcome"]
        return o.copy(data=np.vectorize(OUTCOME_WORDS.get, otypes=[object])(o.values))


def register_accessor(analyses: Mapping[str, Callable[..., Any]]) -> None:
    """Register ``ds.rocksweep`` with xarray (once), its methods calling ``analyses``
    (name -> the facade's function: plot, boundaries, ...)."""
    global _REGISTERED
    _ANALYSES.update(analyses)
    if _REGISTERED:
        return
    import xarray as xr

    xr.register_dataset_accessor("rocksweep")(RocksweepAccessor)
    _REGISTERED = True
