"""Analyses over the excitation path's axes: the two answers of an ``angle`` axis, and
the floor spectrum over ``floor.period``.

Orientation. A sweep over ``angle`` answers two questions (``ORIENTATIONS``):

- ``each``: every orientation is a sample of the demand: the (record, angle) pairs are the
  samples along ``record`` (``each_orientation``: the record coordinate becomes "name@angle
  deg", ``record_of`` names the record); a fit pools them, but they are not independent
  records: ``n_records`` counts records and the bootstrap resamples records, each with all
  its angles (a cluster bootstrap), so the intervals are those of the records at hand;
- ``worst``: the worst orientation per record (``worst_orientation``): at every other
  point of the grid, the angle whose run overturned (any angle) or, none overturning,
  rotated the most (largest max|theta|/alpha_ref); its variables are that run's,
  ``worst_angle`` [deg] names it, a point not computed at some angle is not computed.

``by_orientation(ds, analysis)`` runs an analysis of a sweep Dataset (e.g. fragility) on
both and stacks the results along an ``orientation`` dimension.

Floor spectrum (``floor_spectrum``): the body's response against the building's period
``floor.period``:

- a record suite: P(overturn) = the share of the counted records (run, not flagged) that
  overturned, at every stripe, floor period and value of the other swept keys (with an
  angle axis, for each orientation answer);
- one record or a pulse: A_min, the smallest A_ratio that overturns at each floor period,
  bisected to ``rtol`` with kernel runs (``boundaries.a_min`` along (floor.period,
  A_ratio)).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import xarray as xr

from rocksweep.analysis.counts import RECORD_OF
from rocksweep.analysis.states import counted_points, state_reached
from rocksweep.analysis.tolerance import DEFAULT_RTOL_MANY
from rocksweep.errors import FloorError, check_rtol
from rocksweep.vocab.ground import ORIENTATIONS
from rocksweep.vocab.kinds import FLOOR_SPECTRUM, KIND_ATTR
from rocksweep.vocab.outcomes import OVERTURN

FLOOR_X = "floor.period"


def _where(ds) -> str:
    """A Dataset as messages name it: its file, else its title."""
    source = ds.encoding.get("source")
    return str(source) if source else f"result in memory ({ds.attrs.get('title') or 'untitled'})"


def worst_orientation(ds):
    """The sweep Dataset (or a result file's path) with its ``angle`` dimension reduced to
    the worst orientation (module docstring): the same variables, ``worst_angle`` [deg];
    attrs ``orientation`` says how it was chosen."""
    from rocksweep.analysis.files import as_dataset  # lazy: h5py (+26 ms)

    ds = as_dataset(ds, "ds")
    if "angle" not in ds.dims or "outcome" not in ds.data_vars:
        raise FloorError(f"{_where(ds)}: worst orientation: not a sweep over angle (no "
                         "angle dimension and outcome)")
    out = ds["outcome"]
    theta = ds["theta_max_over_alpha"].fillna(-1.0)
    key = xr.where(out > 0, np.inf, theta)
    idx = key.argmax("angle")
    angle_vars = [k for k, v in ds.data_vars.items() if "angle" in v.dims]
    worst = ds[angle_vars].isel(angle=idx)
    res = ds.drop_vars(angle_vars).drop_dims("angle")
    for k in angle_vars:
        res[k] = worst[k].drop_vars("angle", errors="ignore")
    res["outcome"] = xr.where((out < 0).any("angle"), np.int8(-1),
                              res["outcome"]).astype(np.int8)
    if "status" in ds:  # every angle's flags: a flagged run at any angle flags the worst
        st = ds["status"].values
        res["status"] = (res["status"].dims, np.bitwise_or.reduce(
            st, axis=ds["status"].dims.index("angle")).astype(st.dtype),
            ds["status"].attrs)
    res["worst_angle"] = ds["angle"].isel(angle=idx).drop_vars("angle").astype(float)
    res["worst_angle"].attrs = {"long_name": "worst orientation", "units": "degree"}
    for k in ds.data_vars:
        if k in res:
            res[k].attrs = ds[k].attrs
    res.attrs = {**ds.attrs, "orientation": (
        f"worst of {ds.sizes['angle']} angles per record: overturns at any angle, else the "
        "largest max|theta|/alpha_ref (worst_angle)")}
    return res


def each_orientation(ds):
    """The sweep Dataset with every (record, angle) pair a sample "name@angle deg" along
    ``record`` (the orientations as samples of the demand), ``record_of`` naming its record
    (``counts.RECORD_OF``: a fit counts records and its bootstrap resamples records, each
    with all its angles); per-record variables repeat over the angles."""
    if "angle" not in ds.dims or "record" not in ds.dims:
        raise FloorError("each orientation: the Dataset needs record and angle dimensions")
    names = [f"{r}@{float(a):g}deg" for r in ds["record"].values for a in ds["angle"].values]
    of = [str(r) for r in ds["record"].values for _ in ds["angle"].values]
    st = ds.stack(_sample=("record", "angle"))
    st = st.drop_vars(["record", "angle", "_sample"]).rename({"_sample": "record"})
    st = st.assign_coords(record=("record", np.array(names, dtype=object)),
                          **{RECORD_OF: ("record", np.array(of, dtype=object),
                                         {"long_name": "the record the sample is of"})})
    dims = [d for d in ds["outcome"].dims if d not in ("record", "angle")]
    order = list(ds["outcome"].dims)
    pos = order.index("record")
    dims.insert(min(pos, len(dims)), "record")
    for k, v in st.data_vars.items():
        if "record" in v.dims:
            st[k] = v.transpose(*[d for d in dims if d in v.dims],
                                *[d for d in v.dims if d not in dims])
    st.attrs = {**ds.attrs, "orientation": (
        f"each of {ds.sizes['angle']} angles a sample (record@angle)")}
    return st


def by_orientation(ds, analysis: Callable[[Any], Any]):
    """``analysis`` (a function of a sweep Dataset returning a Dataset) on each and on the
    worst orientation, stacked along ``orientation`` (``ORIENTATIONS``); the Dataset itself
    without an angle dimension."""
    if "angle" not in ds.dims:
        return analysis(ds)
    parts = [analysis(each_orientation(ds)), analysis(worst_orientation(ds))]
    # the answers' record dimensions differ (the samples of each, the records of worst):
    # joined outer, NaN where an answer has no such sample
    out = xr.concat(parts, dim="orientation", coords="minimal", compat="override",
                    combine_attrs="override", join="outer")
    out = out.assign_coords(orientation=("orientation", list(ORIENTATIONS)))
    out.attrs["orientation"] = ("each: every (record, angle) a sample, records resampled "
                                "with all their angles; worst: the worst angle per record "
                                "(overturns at any angle, else the largest "
                                "max|theta|/alpha_ref)")
    return out


def worst_ida(ida):
    """An IDA Dataset with, when it runs over ``angle``, each record's worst orientation:
    ``ida_im_worst`` (the least ``ida_im`` over the angles: the IM that overturns the
    record at some angle; NaN where no angle overturns) and ``worst_angle`` [deg]."""
    if "angle" not in ida.get("ida_im", xr.DataArray()).dims:
        return ida
    im = ida["ida_im"]
    found = im.notnull().any("angle")
    idx = im.fillna(np.inf).argmin("angle")
    ida["ida_im_worst"] = im.min("angle", skipna=True)
    state = ida.attrs.get("state", OVERTURN)
    ida["ida_im_worst"].attrs = {**im.attrs, "long_name": f"least IM at which the record "
                                 f"reaches {state} at any angle (its worst orientation)"}
    ida["worst_angle"] = xr.where(found, ida["angle"].isel(angle=idx).drop_vars("angle"),
                                  np.nan)
    ida["worst_angle"].attrs = {"long_name": "worst orientation", "units": "degree"}
    return ida


def _p_overturn(ds):
    """P(overturn) over records of a suite sweep Dataset: (p_overturn, n_counted)."""
    counted = counted_points(ds)[0]
    hit = state_reached(ds, OVERTURN) & counted
    n = counted.sum("record")
    p = (hit.sum("record") / n.where(n > 0)).astype(float)
    p.attrs = {"long_name": "probability of overturning",
               "description": "share of the counted records (run, not flagged) that "
                              "overturned", "units": "1"}
    n.attrs = {"long_name": "records counted", "units": "1"}
    return p, n


def floor_spectrum(ds, rtol: float = DEFAULT_RTOL_MANY, search: bool = True):
    """The floor spectrum of a complete sweep over ``floor.period`` (module docstring) as a
    Dataset (attrs rocksweep_kind "floor_spectrum", the building's ``floor`` line): a
    suite's ``p_overturn`` and ``n_counted`` over (floor.period, stripe, others[,
    orientation]); one record's or a pulse's ``A_min``, ``mode``, ``A_min_method`` over
    (others, floor.period). ds: a sweep Dataset or a result file's path; rtol (in (0,
    MAX_RTOL]) and search (a bool) are checked first, as ``spectra`` checks them; an
    incomplete result (an interrupted sweep) is refused in one line."""
    # lazy: numba, scipy (+0.2 s)
    from rocksweep.analysis.boundaries import check_search
    from rocksweep.analysis.files import as_dataset
    from rocksweep.store.reader import as_result

    rtol = check_rtol(rtol)
    search = check_search(search)
    ds = as_dataset(ds, "ds")
    if "outcome" in ds.data_vars and FLOOR_X not in ds.dims:
        raise FloorError(f"{_where(ds)}: floor spectrum: the sweep has no {FLOOR_X} "
                         "dimension (sweep floor.period in the scene's floor section)")
    as_result(ds, ["outcome"]).require_complete(FloorError, "a floor spectrum")
    attrs = {KIND_ATTR: FLOOR_SPECTRUM, "title": ds.attrs.get("title", ""),
             "floor": ds.attrs.get("floor", ""), "scale_im": ds.attrs.get("scale_im", "")}
    if "record" in ds["outcome"].dims:
        def one(d):
            p, n = _p_overturn(d)
            return xr.Dataset({"p_overturn": p, "n_counted": n})

        out = by_orientation(ds, one)
        out.attrs = {**out.attrs, **attrs, "method": "share of records"}
        return out
    # lazy: numba, scipy (+0.2 s)
    from rocksweep.analysis.boundaries import (
        A_MIN_METHODS,
        a_min,
        grid_response,
        kernel_evaluator,
    )
    from rocksweep.store.reader import result_scene

    result = as_result(ds, ["outcome", "theta_max_over_alpha", "uplifts", "status"])
    if "A_ratio" not in result.dims:
        raise FloorError(f"{_where(ds)}: floor spectrum: one record's or a pulse's needs "
                         "A_ratio swept (A_min is searched along it)")
    scene = result_scene(result)
    curves = a_min(scene, result.arrays["outcome"], rtol, axes=(FLOOR_X, "A_ratio"),
                   evaluate=kernel_evaluator(scene), **grid_response(result), search=search)
    others = [d for d in result.dims if d not in (FLOOR_X, "A_ratio")]
    shape = tuple(len(result.coords[d]) for d in others)
    x = np.asarray(result.coords[FLOOR_X], float)
    amin = np.array([c.a_min for c in curves], float).reshape(*shape, x.size)
    mode = np.array([c.mode for c in curves], np.int8).reshape(amin.shape)
    method = np.array([c.method_words for c in curves], str).reshape(amin.shape)
    dims = (*others, FLOOR_X)
    coords = {d: (d, np.asarray(result.coords[d])) for d in dims}
    out = xr.Dataset(
        {"A_min": (dims, amin, {"long_name": "smallest overturning amplitude ratio "
                                "(of the ground motion)", "units": "1"}),
         "mode": (dims, mode, {"long_name": "overturning mode at A_min"}),
         "A_min_method": (dims, method, {"long_name": "how A_min was found",
                                         "flag_meanings": ";".join(A_MIN_METHODS)})},
        coords=coords)
    out[FLOOR_X].attrs = {"long_name": "period of the building's mode", "units": "s"}
    out.attrs = {**attrs, "method": "A_min", "rtol": rtol, "kind": result.kind,
                 "runs": int(sum(c.runs.sum() for c in curves))}
    return out
