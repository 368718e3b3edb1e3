"""A result file (or its bytes in memory) as the loaded xarray Dataset that
``rocksweep.open`` and ``rocksweep.run`` return: CF decoding, units and flag attributes."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from rocksweep import fields
from rocksweep.errors import StoreError
from rocksweep.outputs import shown
from rocksweep.store.reader import READER_LOCKING, opened_here, read_result
from rocksweep.vocab.outcomes import OUTCOME_WORDS, STATUS_WORDS

if TYPE_CHECKING:
    import xarray as xr

def open_result(path: str | Path) -> xr.Dataset:
    """A sweep result file as the loaded Dataset (``rocksweep.open``): a file that is not
    a rocksweep result, or is damaged, is a one-line error (``reader.read_result``) before
    ``result_dataset`` reads it."""
    path = Path(path)
    read_result(path, ["outcome"])
    return result_dataset(path)


def result_dataset(source: Path | Any) -> xr.Dataset:
    """A result file (a path, or a file object holding the bytes of one in memory) as the
    loaded Dataset that ``open`` and ``run`` return, with the accessor registered; a
    damaged variable attribute is a one-line StoreError."""
    # xarray (0.4-1.5 s): rocksweep info and sweep read results without it
    import xarray as xr

    kwds = {"driver_kwds": {"locking": False}} if isinstance(source, Path) else {}
    try:
        try:
            with xr.open_dataset(source, engine="h5netcdf", **kwds) as ds:
                ds = ds.load()
        except OSError as err:  # open here through another handle: take its lock flags
            if not (kwds and opened_here(err)):
                raise
            for locking in READER_LOCKING:
                try:
                    with xr.open_dataset(source, engine="h5netcdf",
                                         driver_kwds={"locking": locking}) as ds:
                        ds = ds.load()
                    break
                except OSError:
                    continue
            else:
                raise
    except (ValueError, TypeError, KeyError, OSError, OverflowError, AttributeError,
            IndexError, RuntimeError, MemoryError) as err:
        # xarray's CF decoding of a damaged attribute; HDF5's of damaged dimension scales
        # (H5DSget_num_scales: RuntimeError), a damaged shape's allocation
        where = shown(source) if isinstance(source, Path) else "result in memory"
        why = (str(err).strip().splitlines() or [type(err).__name__])[0]
        why = why if len(why) <= 160 else why[:157] + "..."
        raise StoreError(f"{where}: damaged rocksweep result (its variables or their "
                         f"attributes cannot be decoded: {why})") from None
    for name, var in ds.data_vars.items():  # files of format 1 have neither
        f = fields.BY_NAME.get(str(name))
        if f is not None:
            var.attrs.setdefault("rocksweep_units", f.unit)
            var.attrs.setdefault("description", f.meaning)
    if "outcome" in ds:
        ds["outcome"].attrs.setdefault("flag_values", list(OUTCOME_WORDS))
        ds["outcome"].attrs.setdefault("flag_meanings", " ".join(OUTCOME_WORDS.values()))
    if "status" in ds:
        ds["status"].attrs.setdefault("flag_masks", list(STATUS_WORDS))
        ds["status"].attrs.setdefault("flag_meanings", " ".join(STATUS_WORDS.values()))
    ds.attrs = {k: (v.item() if hasattr(v, "item") and getattr(v, "size", 1) == 1 else v)
                for k, v in ds.attrs.items()}
    return ds
