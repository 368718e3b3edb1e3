"""``rocksweep.plot(ds)`` for any rocksweep Dataset: the figure of its kind
(``rocksweep.analysis.kinds.dataset_kind``), in this one place."""

from __future__ import annotations

from typing import Any

from rocksweep.analysis.kinds import dataset_kind
from rocksweep.errors import PlotError, RocksweepError  # noqa: F401 (re-exported)


def plot_analysis(ds: Any, *, ax: Any = None, width: str | None = None) -> Any:
    """The figure of a fragility, IDA, spectra, risk or IM-efficiency Dataset (a sweep's
    diagram is ``rocksweep.figures.diagrams``)."""
    from rocksweep.figures import results
    from rocksweep.figures.fragility import fragility_figure

    kind = dataset_kind(ds)
    if kind == "fragility":
        return fragility_figure(ds, ax=ax, width=width or "single")
    draw = {"risk": results.risk_figure, "ida": results.ida_figure,
            "spectra": results.spectra_dataset_figure,
            "im_efficiency": results.efficiency_figure}.get(kind or "")
    if draw is None:
        raise PlotError(f"a {kind or 'foreign'} Dataset has no figure (rocksweep.plot draws "
                        "sweeps, fragility, IDA, spectra, risk and IM-efficiency Datasets)")
    return draw(ds, ax=ax, width=width)
