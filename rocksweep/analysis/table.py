"""A tidy table of a rocksweep Dataset: one row per run (a sweep) or per curve (an
analysis), never duplicated.

``ds.to_dataframe()`` takes the union of every variable's dims as the index, so a suite's
``record_sa`` (record, period) repeats every run once per Sa period. Here the rows are the
runs: the dims of ``outcome`` (for an analysis, of its main variable, ``ROW_VARIABLE``).
Columns, in order: the row dims' coordinates; the unswept scene values (scalar
coordinates: wn_over_p, alpha_cg, p, ...); every variable over (a subset of) the row dims,
broadcast (the result fields, per-record variables, ``scale_factor``); a variable with one
more short dimension (``record_sa`` over ``period``) as one column per value,
``record_sa(0.2)``; and for a record suite the IMs of the ground motion each run saw, the
record's IM times scale_factor^n (``physics.suite.RECORD_IMS``): ``pga`` [g], ``pgv``
[m/s], ``arias`` [m/s], ``cav`` [m/s], ``d5_95`` [s], ``pgv_over_pga`` [s], ``avgsa`` [g],
``sa(T)`` [g], and PGA/(g tan alpha) ``pga_ratio``, PGV p/(g tan alpha) ``pgv_ratio``. A
sweep's ``outcome`` and ``status`` codes are also given in words: ``outcome_word``,
``status_words`` (the status bits' words joined by ","). The units of every column are
in ``DataFrame.attrs["units"]`` (``rocksweep table`` writes them into the CSV header,
``name [unit]`` for every column with a dimension, and into Parquet's field metadata,
``units``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from rocksweep.analysis.kinds import dataset_kind
from rocksweep.analysis.states import trust
from rocksweep.errors import TableError
from rocksweep.physics.bodies import G
from rocksweep.vocab.axes import ALPHA_KEYS
from rocksweep.vocab.ground import RECORD_IMS, SA, SCALE_IMS
from rocksweep.vocab.kinds import (
    BOUNDARIES,
    FLOOR_SPECTRUM,
    FRAGILITY,
    IDA,
    IM_EFFICIENCY,
    RISK,
    SPECTRA,
    SWEEP,
)
from rocksweep.vocab.outcomes import OUTCOME_WORDS, status_words

__all__ = ["ROW_VARIABLE", "table", "units_of"]

#: the variable whose dims are a kind's rows
ROW_VARIABLE = {SWEEP: "outcome", FRAGILITY: ("im_median", "median"), IDA: "ida_im",
                RISK: "annual_rate", IM_EFFICIENCY: "beta",
                SPECTRA: "theta_max_over_alpha", BOUNDARIES: "A_min",
                FLOOR_SPECTRUM: ("p_overturn", "A_min")}
MAX_SPREAD = 32  # an extra dimension at most this long becomes columns
SKIP = ("record_sha256",)  # identity, not data: in the file, not in every row



def units_of(da: xr.DataArray) -> str:
    """A variable's unit as a reader says it: its scale (``rocksweep_units``, e.g. "b"
    where the CF ``units`` say "1"), else its ``units``, else ""."""
    return str(da.attrs.get("rocksweep_units") or da.attrs.get("units") or "")


def table(ds: xr.Dataset) -> Any:
    """The tidy ``pandas.DataFrame`` of a rocksweep Dataset (module docstring): one row
    per run of a sweep (prod of outcome's dim sizes rows), or per entry of an analysis's
    main variable. ``.attrs["units"]``: column -> units."""
    kind = dataset_kind(ds)
    if kind is None:
        raise TableError("not a rocksweep Dataset (a sweep or an analysis's result)")
    if kind == SWEEP:  # every row is written; a partial file's are said to be missing
        trust(ds, "table", kept=True)
    main = ROW_VARIABLE[kind]
    main = next((m for m in (main if isinstance(main, tuple) else (main,)) if m in ds),
                None)
    if main is None:
        raise TableError(f"a {kind} Dataset without its main variable")
    dims = list(ds[main].dims)
    sizes = tuple(ds.sizes[d] for d in dims)
    n = int(np.prod(sizes)) if sizes else 1
    grids = np.meshgrid(*(np.arange(s) for s in sizes), indexing="ij") if dims else []
    cols: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    for d, g in zip(dims, grids, strict=True):
        vals = ds[d].values if d in ds.coords else np.arange(ds.sizes[d])
        cols[d] = np.asarray(vals)[g.ravel()]
        units[d] = units_of(ds[d]) if d in ds.coords else ""
    for name, c in ds.coords.items():
        if c.ndim == 0 and name not in cols:
            cols[str(name)] = np.repeat(c.values, n)
            units[str(name)] = units_of(c)
    frame = xr.Dataset(coords={d: np.arange(ds.sizes[d]) for d in dims})

    def flat(da: xr.DataArray) -> np.ndarray:
        da = da.drop_vars([c for c in da.coords if c not in da.dims])
        da = da.assign_coords({d: np.arange(da.sizes[d]) for d in da.dims})
        return np.asarray(da.broadcast_like(frame).transpose(*dims).values).reshape(n)

    for name, da in ds.data_vars.items():
        name = str(name)
        if name in SKIP:
            continue
        extra = [d for d in da.dims if d not in dims]
        if not extra:
            cols[name] = flat(da)
            units[name] = units_of(da)
        elif (kind == SWEEP and len(extra) == 1 and ds.sizes[extra[0]] <= MAX_SPREAD):
            e = extra[0]
            for i, v in enumerate(ds[e].values if e in ds.coords else range(ds.sizes[e])):
                label = f"{name}({v:g})" if isinstance(v, float | np.floating) else \
                    f"{name}({v})"
                cols[label] = flat(da.isel({e: i}))
                units[label] = units_of(da)
    if kind == SWEEP and "scale_factor" in ds.data_vars and "record" in dims:
        f = flat(ds["scale_factor"])
        for im, (var, unit, k) in RECORD_IMS.items():
            if var in ds.data_vars:
                label = im.lower()
                cols[label] = flat(ds[var]) * f ** k
                units[label] = unit
        alpha = next((cols[a] for a in ALPHA_KEYS if a in cols), None)
        if alpha is not None and "pga" in cols:  # the dimensionless ones of the run
            tan = np.tan(np.asarray(alpha, np.float64))
            cols["pga_ratio"], units["pga_ratio"] = cols["pga"] / tan, "1"
            if "pgv" in cols and "p" in cols:
                cols["pgv_ratio"] = cols["pgv"] * np.asarray(cols["p"], np.float64) / (
                    G * tan)
                units["pgv_ratio"] = "1"
        if "record_sa" in ds.data_vars and "period" in ds["record_sa"].dims:
            for i, T in enumerate(ds["period"].values):
                label = f"sa({float(T):g})"
                cols[label] = flat(ds["record_sa"].isel(period=i)) * f
                units[label] = SCALE_IMS[SA]
    if kind == SWEEP and "status" in cols:  # the codes in words, beside the codes
        cols["outcome_word"] = np.array([OUTCOME_WORDS.get(int(c), str(c))
                                         for c in cols["outcome"]], dtype=object)
        cols["status_words"] = np.array([",".join(status_words(int(b))) for b in
                                         cols["status"]], dtype=object)
        units["outcome_word"] = units["status_words"] = ""
    out = pd.DataFrame(cols)
    for c in out.columns:  # words as plain strings (parquet, csv)
        if out[c].dtype == object or out[c].dtype.kind in "US":
            out[c] = out[c].astype(str)
    out.attrs["units"] = units
    out.attrs["kind"] = kind
    return out
