"""Every rocksweep Dataset to and from disk: the one reader (``open_any``, behind
``rocksweep.open``) and the writers of every analysis's file, each marked with its kind.

Writers (each onto the path it is given; the command line publishes through
``rocksweep.outputs.write_atomic``, the one publish rule):

- ``to_netcdf``: a Dataset (fragility, risk, IM efficiency, calibration, ...) as netCDF-4
  (h5netcdf), list and dict attributes as JSON text, text variables as fixed strings, and
  its kind in the attribute ``rocksweep_kind`` (``vocab.kinds``);
- ``csv_text``: rows (dicts) or a DataFrame as CSV text: a float as its shortest repr
  (read back exactly), None and NaN as an empty field, "\\n" line ends;
- ``write_curves_h5``: the A_min curves and boundary lines of ``rocksweep boundaries``
  (HDF5 groups, one per panel);
- ``write_report``: the accuracy study of ``rocksweep accuracy --report``.

``open_any(path)`` opens any of these (and a sweep result, ``store.dataset.open_result``)
as a Dataset whose ``attrs["rocksweep_kind"]`` says its kind (a sweep is known by its
format, ``analysis.kinds.dataset_kind``); a file written before the kind attribute
existed is known by its variables. A boundaries file opens as its A_min curves (as
``rocksweep.boundaries`` gives them), an accuracy report as its table (one entry per
setting).
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

import h5py
import numpy as np

from rocksweep import fields
from rocksweep.analysis.kinds import dataset_kind
from rocksweep.errors import ApiError
from rocksweep.outputs import input_problem, shown, write_atomic
from rocksweep.store.dataset import open_result
from rocksweep.vocab.axes import DIAGRAM_AXES
from rocksweep.vocab.kinds import ACCURACY, BOUNDARIES, KIND_ATTR, KIND_NAMES, SWEEP

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr

    from rocksweep.analysis.accuracy import Study
    from rocksweep.analysis.boundaries import AMinCurve, PanelBoundaries


# ---------------------------------------------------------------------------------------
# writers
# ---------------------------------------------------------------------------------------


def _field(v: Any) -> Any:
    if v is None or (isinstance(v, float | np.floating) and math.isnan(v)):
        return ""
    if isinstance(v, float | np.floating):
        return repr(float(v))
    return v


def csv_text(rows: Sequence[Mapping[str, Any]] | pd.DataFrame) -> str:
    """CSV text of rows (the keys of the first row as the header) or of a DataFrame (its
    columns, no index): a float as its shortest repr, None and NaN as empty fields."""
    if hasattr(rows, "to_csv"):  # a DataFrame: pandas writes floats by the same rule
        return rows.to_csv(index=False, lineterminator="\n", na_rep="")
    buf = io.StringIO()
    if rows:
        w = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: _field(v) for k, v in r.items()})
    return buf.getvalue()


def to_netcdf(ds: xr.Dataset, path: str | Path, kind: str) -> None:
    """The Dataset as netCDF-4 (h5netcdf) at ``path`` (truncated): attributes plain (lists
    and dicts as JSON text), text variables as fixed strings, ``rocksweep_kind`` = kind
    (a name of ``vocab.kinds``)."""
    if kind not in KIND_NAMES:
        raise ValueError(f"kind = {kind!r}: one of {', '.join(KIND_NAMES)}")
    out = ds.copy()
    out.attrs = {k: (json.dumps(v) if isinstance(v, list | dict) else v)
                 for k, v in ds.attrs.items()}
    out.attrs[KIND_ATTR] = kind
    for name in list(out.variables):
        if out[name].dtype.kind in ("U", "O"):
            out[name] = out[name].astype(str)
    out.to_netcdf(path, engine="h5netcdf")


def write_dataset(ds: xr.Dataset, path: str | Path, kind: str, *,
                  overwrite: bool = False) -> None:
    """``to_netcdf`` published at ``path`` by the one publish rule
    (``outputs.write_atomic``: complete or absent, never over a file it was not told to
    replace)."""
    write_atomic(path, lambda tmp: to_netcdf(ds, tmp, kind), overwrite=overwrite)


#: version of the layout ``write_curves_h5`` writes
H5_FORMAT = 1


def _h5_attr(v: Any) -> Any:
    """An attribute value h5py stores and netCDF readers understand (no bool, no None)."""
    if isinstance(v, bool | np.bool_):
        return np.int8(v)
    if isinstance(v, str):
        return v
    if isinstance(v, int | np.integer):
        return np.int64(v)
    return np.float64(v)


def write_curves_h5(path: str | Path, curves: Sequence[AMinCurve],
                    bounds: Sequence[PanelBoundaries], attrs: dict[str, Any] | None = None
                    ) -> None:
    """Write A_min curves and boundary lines to a new HDF5 file at ``path`` (meant for the
    temporary path of ``rocksweep.outputs.write_atomic``; an existing file at ``path`` is
    truncated).

    Layout (h5py; every ``a_min`` panel group also opens with
    ``xarray.open_dataset(path, group="a_min/panel_0", engine="h5netcdf")``):

    - root attributes: ``rocksweep_kind`` ("boundaries"), ``title``, ``format``
      (``H5_FORMAT``), ``x_axis``, ``y_axis`` (diagram axis names), ``panels`` (count) and
      ``attrs`` (e.g. ``source``, ``rtol``);
    - ``a_min/panel_<i>``, one group per panel in the grid's order, with the panel's
      value of every other swept axis as attributes (e.g. ``lam`` = 0.2, ``shape`` =
      "sine"; their names, in order, in ``where``): ``<x_axis>`` float64[nx], the
      dimension scale, and over it ``A_min`` float64[nx] (NaN: no value of the column
      overturns), ``mode`` int8[nx] (1, 2; 0 where A_min is NaN), ``lo``/``hi``
      float64[nx] (the final bisection bracket, lo = NaN when the first grid value
      already overturns), ``upper_bound`` int8[nx] (1: A_min is that first grid value,
      only an upper bound), ``runs`` int64[nx] (kernel runs of the search and the
      bisection), ``A_min_method`` int8[nx] (how A_min was found: an index into the
      attribute ``flag_meanings``, the words of ``A_MIN_METHODS`` joined by ";"). Units
      those of the axes (w_over_p = omega/p, A_ratio = A/(g tan alpha_cg));
    - ``lines/panel_<i>``: the same attributes, one dataset ``line_<n>`` per boundary
      polyline (n as the ``line`` column of the CSV), float64[vertices, 2], columns
      (x_axis, y_axis) in axis values, attributes ``classes`` (e.g. "safe|mode1"),
      ``class_a`` < ``class_b`` (int8 outcome codes), ``closed`` (int8 0/1).

    The rows of ``a_min_rows`` / ``boundary_rows`` (what the CSV files hold) are these
    arrays' entries: A_min rows where A_min is not NaN, line rows one per vertex.
    """
    # analysis.boundaries (numba, 0.6 s): this file's writer only
    from rocksweep.analysis.boundaries import A_MIN_METHODS

    xname = curves[0].xname if curves else DIAGRAM_AXES[0]
    yname = curves[0].yname if curves else DIAGRAM_AXES[1]
    with h5py.File(path, "w") as f:
        f.attrs[KIND_ATTR] = BOUNDARIES
        f.attrs["title"] = "rocksweep boundaries: A_min curves and boundary lines"
        f.attrs["format"] = np.int64(H5_FORMAT)
        f.attrs["x_axis"], f.attrs["y_axis"] = xname, yname
        f.attrs["panels"] = np.int64(len(curves))
        for k, v in (attrs or {}).items():
            f.attrs[k] = _h5_attr(v)

        def panel_group(parent: str, i: int, where: dict[str, Any]) -> h5py.Group:
            g = f.require_group(parent).create_group(f"panel_{i}")
            for k, v in where.items():
                g.attrs[k] = _h5_attr(v)
            g.attrs["where"] = " ".join(where)
            return g

        for i, c in enumerate(curves):
            g = panel_group("a_min", i, c.where)
            xs = g.create_dataset(c.xname, data=np.asarray(c.x, float))
            xs.make_scale(c.xname)
            xs.attrs["units"] = "1"
            data = {"A_min": (c.a_min, f"smallest {c.yname} that overturns (bisected)"),
                    "mode": (c.mode.astype(np.int8), "overturning mode at A_min (0: none)"),
                    "lo": (c.lo, f"largest {c.yname} known not to overturn"),
                    "hi": (c.hi, f"smallest {c.yname} known to overturn"),
                    "upper_bound": (np.isnan(c.lo) & ~np.isnan(c.a_min),
                                    "1: A_min is the first grid value, an upper bound"),
                    "runs": (c.runs.astype(np.int64),
                             "kernel runs of the search and the bisection"),
                    "A_min_method": (c.method.astype(np.int8), "how A_min was found")}
            for name, (v, text) in data.items():
                arr = np.asarray(v)
                ds = g.create_dataset(name, data=arr.astype(np.int8) if arr.dtype == bool
                                      else arr)
                ds.attrs["long_name"] = text
                if name == "A_min_method":
                    ds.attrs["flag_values"] = np.arange(len(A_MIN_METHODS), dtype=np.int8)
                    ds.attrs["flag_meanings"] = ";".join(A_MIN_METHODS)
                ds.dims[0].attach_scale(xs)
        for i, b in enumerate(bounds):
            g = panel_group("lines", i, b.where)
            for n, line in enumerate(b.lines):
                ds = g.create_dataset(f"line_{n}", data=np.asarray(line.xy, float))
                ds.attrs["classes"] = line.label
                ds.attrs["class_a"], ds.attrs["class_b"] = (np.int8(c) for c in line.classes)
                ds.attrs["closed"] = np.int8(len(line.xy) > 2
                                             and np.array_equal(line.xy[0], line.xy[-1]))
                ds.attrs["columns"] = f"{xname} {yname}"


def write_report(study: Study, path: str | Path, command: str = "", *,
                 overwrite: bool = False) -> None:
    """Write an accuracy study (``analysis.accuracy``) to HDF5, published by the one
    publish rule (``outputs.write_atomic``).

    Layout: attrs (``rocksweep_kind`` "accuracy", scene name and YAML, sample description,
    reference tolerances, command, observed orders); /table: one dataset per column, one
    entry per setting; /flips: int64[settings, 3, 3] (reference outcome, kernel outcome);
    /sample: flat index, stratum, weight and axis values per point, stratum names and
    sizes; /reference and /kernel/<setting>: per point, every result field of the
    outcome-level kernel (``REPORT_FIELDS``: outcome, impacts, uplifts,
    theta_max_over_alpha, t_overturn, status, steps (regular RK4 steps), event_steps,
    t_end, t_first_impact, e_max, returns_to_contact, each with ``units``) and seconds
    (with ``check``, also the ``fields.CHECK_FIELDS`` of the half-step reruns). In
    /reference, steps are DOP853's steps and event_steps 0 (``reference.result_row``).
    """
    write_atomic(path, lambda tmp: _write_study(study, tmp, command), overwrite=overwrite)


def _write_study(study: Study, path: Path, command: str) -> None:
    # the accuracy study (numba, 0.6 s): its report's writer only
    from rocksweep.analysis.accuracy import OUTCOMES, reference_words

    with h5py.File(path, "w") as f:
        f.attrs[KIND_ATTR] = ACCURACY
        f.attrs["format"] = "rocksweep-accuracy-1"
        f.attrs["scene_name"] = study.scene.name
        f.attrs["scene_yaml"] = study.scene.text
        f.attrs["numerics"] = study.scene.numerics.describe()
        f.attrs["command"] = command
        f.attrs["reference"] = reference_words(study.scene)
        f.attrs["points_in_scene"] = study.sample.size
        f.attrs["points_sampled"] = len(study.sample.flat)
        f.attrs["classify_seconds"] = study.sample.classify_seconds
        f.attrs["wall_seconds"] = study.wall_seconds
        f.attrs["time_per_point"] = ("median: each point timed as a 1-row chunk; mean: "
                                     "weighted by stratum (scene estimate); total_s: one "
                                     "call on the sample, best of repeats")
        for m, orders in study.orders.items():
            f.attrs[f"observed_order_{m}"] = np.array(
                [(a, b, p) for a, b, p in orders], float).reshape(-1, 3)
        table = study.table()
        g = f.create_group("table")
        for key in table[0]:
            col = [d[key] for d in table]
            if isinstance(col[0], str):
                g.create_dataset(key, data=np.array(col, dtype=h5py.string_dtype()))
            else:
                g.create_dataset(key, data=np.asarray(col))
        f.create_dataset("flips", data=np.stack([r.flips for r in study.results]))
        f["flips"].attrs["axes"] = "setting, reference outcome, kernel outcome"
        f["flips"].attrs["outcomes"] = ", ".join(OUTCOMES)
        s = f.create_group("sample")
        s.create_dataset("flat_index", data=study.sample.flat)
        s.create_dataset("stratum", data=study.sample.stratum)
        s.create_dataset("weight", data=study.sample.weight)
        s.create_dataset("strata", data=np.array(study.sample.strata,
                                                 dtype=h5py.string_dtype()))
        s.create_dataset("stratum_size", data=study.sample.stratum_size)
        for k, v in study.values.items():
            v = np.asarray(v)
            s.create_dataset(k, data=v.astype(h5py.string_dtype()) if v.dtype.kind in "US"
                             else v)
        g = f.create_group("reference")
        _write_runs(g, study, study.reference, study.reference_seconds)
        if study.reference_anomalies is not None:
            g.create_dataset("anomalies", data=study.reference_anomalies)
        k = f.create_group("kernel")
        for r in study.results:
            g = k.create_group(r.setting.name)
            _write_runs(g, study, r.outs, r.seconds)
            if r.half is not None:  # the per-point estimates, as a sweep stores them
                for name, arr in fields.convert_check(r.outs, r.half,
                                                      study.alpha_ref).items():
                    g.create_dataset(name, data=arr).attrs["units"] = fields.UNITS[name]


def _write_runs(g: Any, study: Study, outs: np.ndarray, seconds: np.ndarray) -> None:
    # every field the outcome-level kernel reports (rocksweep.fields), in its unit; the
    # sliding base's (in units of b) where the scene gives body.mu
    from rocksweep.analysis.accuracy import REPORT_FIELDS

    b = np.nan if study.b is None else study.b
    report = tuple(f for f in REPORT_FIELDS if study.scene.slides or not f.slide)
    for name, arr in fields.convert(outs, study.alpha_ref, np.nan, report, b).items():
        ds = g.create_dataset(name, data=arr)
        ds.attrs["units"] = fields.UNITS[name]
    g.create_dataset("seconds", data=seconds)


# ---------------------------------------------------------------------------------------
# the reader
# ---------------------------------------------------------------------------------------


def file_kind(path: str | Path) -> str | None:
    """The kind of a readable HDF5 file rocksweep wrote (its ``rocksweep_kind``, else
    guessed from its top-level variables); None for anything else (damaged, foreign,
    missing: ``open_result`` says why in one line)."""
    if input_problem(path) is not None:
        return None
    try:
        with h5py.File(path, "r") as f:
            attrs = {KIND_ATTR: f.attrs[KIND_ATTR]} if KIND_ATTR in f.attrs else {}
            if isinstance(attrs.get(KIND_ATTR), bytes):
                attrs[KIND_ATTR] = attrs[KIND_ATTR].decode()
            return dataset_kind(SimpleNamespace(variables=list(f.keys()), attrs=attrs))
    except (OSError, RuntimeError, ValueError, KeyError, TypeError):
        return None  # damaged, foreign, locked: open's one-line error says which


def open_any(path: str | Path) -> xr.Dataset:
    """Any rocksweep file as a Dataset loaded in memory (the module docstring): a sweep
    result (``store.dataset.open_result``), or what an analysis wrote, its JSON
    attributes decoded and ``attrs["rocksweep_kind"]`` its kind. Any other file gets
    ``open_result``'s one-line errors."""
    path = Path(path)
    kind = file_kind(path)
    if kind in (None, SWEEP):  # a sweep, or rocksweep.open's one-line error for the rest
        return open_result(path)
    try:
        ds = (_open_boundaries(path) if kind == BOUNDARIES else
              _open_accuracy(path) if kind == ACCURACY else _open_netcdf(path))
    except (ValueError, TypeError, KeyError, OSError, RuntimeError, MemoryError, IndexError,
            AttributeError, OverflowError) as err:  # HDF5's errors of a damaged file too
        why = (str(err).strip().splitlines() or [type(err).__name__])[0][:160]
        raise ApiError(f"{shown(path)}: cannot be read as a {kind} Dataset ({why})") from None
    ds.attrs[KIND_ATTR] = kind
    return ds


def _open_netcdf(path: Path) -> xr.Dataset:
    # xarray (0.4-1.5 s): not for the HDF5 files the command line writes
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf", phony_dims="sort") as ds:
        ds = ds.load()
    for k, v in list(ds.attrs.items()):
        if isinstance(v, str) and v[:1] in "[{":
            try:
                ds.attrs[k] = json.loads(v)
            except ValueError:
                pass
        elif hasattr(v, "item") and getattr(v, "size", 2) == 1:
            ds.attrs[k] = v.item()
    return ds


def _plain_attr(v: Any) -> Any:
    if isinstance(v, bytes):
        return v.decode()
    if hasattr(v, "item") and getattr(v, "size", 2) == 1:
        return v.item()
    return v


def _open_boundaries(path: Path) -> xr.Dataset:
    """The A_min curves of a ``write_curves_h5`` file as ``boundaries.curves_dataset``
    gives them (the boundary lines stay in the file's ``lines`` groups)."""
    # analysis.boundaries (numba, 0.6 s): this file's reader only
    from rocksweep.analysis.boundaries import AMinCurve, curves_dataset

    with h5py.File(path, "r") as f:
        attrs = {k: _plain_attr(v) for k, v in f.attrs.items()
                 if k not in ("title", "format", "panels", "x_axis", "y_axis")}
        xname, yname = str(_plain_attr(f.attrs["x_axis"])), str(_plain_attr(f.attrs["y_axis"]))
        curves = []
        for i in range(int(f.attrs["panels"])):
            g = f[f"a_min/panel_{i}"]
            keys = str(_plain_attr(g.attrs["where"])).split()
            where = {k: _plain_attr(g.attrs[k]) for k in keys}
            curves.append(AMinCurve(where, g[xname][()], g["A_min"][()], g["mode"][()],
                                    g["lo"][()], g["hi"][()], g["runs"][()], xname, yname,
                                    method=g["A_min_method"][()]))
    return curves_dataset(curves, attrs)


def _open_accuracy(path: Path) -> xr.Dataset:
    """An accuracy report's table (one entry per setting) and its attributes (the sample,
    the reference and the kernel's runs stay in the file's groups)."""
    # xarray: this file's reader only
    import xarray as xr

    with h5py.File(path, "r") as f:
        attrs = {k: _plain_attr(v) for k, v in f.attrs.items()}
        table = {k: np.asarray(f["table"][k][()]) for k in f["table"]}
        flips = f["flips"][()]
    data = {k: ("setting", v.astype(str) if v.dtype.kind in "OS" else v)
            for k, v in table.items()}
    data["flips"] = (("setting", "reference_outcome", "kernel_outcome"), flips)
    return xr.Dataset(data, attrs=attrs)


def as_dataset(ds: Any, what: str) -> xr.Dataset:
    """A Dataset argument, or a path to one (``open_any``)."""
    # xarray (0.4-1.5 s): not for the HDF5 files the command line writes
    import xarray as xr

    if isinstance(ds, str | Path):
        return open_any(ds)
    if not isinstance(ds, xr.Dataset):
        raise ApiError(f"{what} = {type(ds).__name__}: must be an xarray Dataset "
                       "(rocksweep.run, rocksweep.open or an analysis) or a path to one")
    return ds
