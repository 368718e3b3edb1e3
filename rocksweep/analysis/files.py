"""Any rocksweep Dataset from a file: a sweep result, or what an analysis wrote with
``-o .h5`` (fragility, risk, IM efficiency: netCDF-4), its JSON attributes decoded."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from rocksweep.errors import ApiError

if TYPE_CHECKING:
    import xarray as xr

def open_any(path: str | Path) -> xr.Dataset:
    """Any rocksweep Dataset from a file: a sweep result (``open``) or what an analysis
    wrote with ``-o .h5`` (fragility, risk, IM efficiency: netCDF-4), its JSON attributes
    (lists) decoded. Any other file gets ``open``'s one-line errors."""
    import json
    from types import SimpleNamespace

    import xarray as xr

    from rocksweep.analysis.kinds import dataset_kind
    from rocksweep.outputs import input_problem, shown

    path = Path(path)
    kind = None
    if input_problem(path) is None:
        try:
            import h5py

            with h5py.File(path, "r") as f:
                kind = dataset_kind(SimpleNamespace(
                    variables=list(f.keys()), attrs={k: v for k, v in f.attrs.items()
                                                     if k == "rocksweep_kind"}))
        except (OSError, RuntimeError, ValueError, KeyError, TypeError):
            kind = None  # damaged, foreign, locked: open's one-line error says which
    if kind in (None, "sweep"):  # a sweep, or rocksweep.open's one-line error for the rest
        from rocksweep.store.dataset import open_result

        return open_result(path)
    try:
        with xr.open_dataset(path, engine="h5netcdf", phony_dims="sort") as ds:
            ds = ds.load()
    except (ValueError, TypeError, KeyError, OSError, RuntimeError, MemoryError, IndexError,
            AttributeError, OverflowError) as err:  # HDF5's errors of a damaged file too
        why = (str(err).strip().splitlines() or [type(err).__name__])[0][:160]
        raise ApiError(f"{shown(path)}: cannot be read as a {kind} Dataset ({why})") from None
    for k, v in list(ds.attrs.items()):
        if isinstance(v, str) and v[:1] in "[{":
            try:
                ds.attrs[k] = json.loads(v)
            except ValueError:
                pass
        elif hasattr(v, "item") and getattr(v, "size", 2) == 1:
            ds.attrs[k] = v.item()

    return ds


def _as_dataset(ds: Any, what: str) -> xr.Dataset:
    """A Dataset argument, or a path to one (``open_any``)."""
    import xarray as xr

    if isinstance(ds, str | Path):
        return open_any(ds)
    if not isinstance(ds, xr.Dataset):
        raise ApiError(f"{what} = {type(ds).__name__}: must be an xarray Dataset "
                       "(rocksweep.run, rocksweep.open or an analysis) or a path to one")
    return ds
