"""Incremental dynamic analysis (IDA) per record of a scaled record suite.

A scaled suite's sweep runs every record at every stripe of its intensity measure (IM:
PGA, PGV, Sa, PGA_ratio or PGV_ratio). Its stripes say, per record, the first level that
overturns the body; ``ida`` refines that level: between the last stripe below it (which
does not overturn) and it, the record's scale is bisected to a relative tolerance with
single kernel runs at the sweep's numerics (``compute.single.run_point``: each run
certified as a single run is). The scaled record's peak, and so the kernel's amplitude,
is linear in the IM, so a level x between stripes is the stripe's point with its amplitude times
x / stripe. Overturning means outcome 1 or 2 (mode 1, mode 2).

"Resurrection" (Vamvatsikos & Cornell 2002): a stripe above the first overturning level
where the record does not overturn.

Points the kernel flagged undecided (horizon, step or event cap, non-finite: status &
STATUS_FLAGGED) are neither safe nor overturning: the bracket's bottom is the highest
stripe below the first overturning one that is decided safe (a flagged stripe between
them lies inside the bracket and the bisection decides it), and a bisection run that comes
back flagged stops that record's bisection with its bracket as it is (``unresolved`` = 1).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import xarray as xr

from rocksweep import fields
from rocksweep.analysis.bisection import UNDECIDED, bisect_thresholds
from rocksweep.analysis.tolerance import DEFAULT_RTOL_MANY
from rocksweep.compute.single import run_point
from rocksweep.errors import IdaError, check_rtol
from rocksweep.fields import plain
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.store.reader import as_result, result_scene
from rocksweep.vocab.kinds import IDA, KIND_ATTR
from rocksweep.vocab.outcomes import FLAGGED, OUTCOME_MODE1, OUTCOME_MODE2

# Bisection steps at most (a relative tolerance of 1e-12 takes ~40 from a stripe gap).
MAX_ITER = 60
OVERTURNED = (OUTCOME_MODE1, OUTCOME_MODE2)


def ida(ds: Any, rtol: float = DEFAULT_RTOL_MANY) -> Any:
    """The smallest IM that overturns each record, bisected to ``rtol`` between stripes.

    ds: a complete sweep of a scaled record suite (what ``rocksweep.run`` or
    ``rocksweep.open`` returns; the stripe dimension is named by ``ds.attrs["scale_im"]``).
    Returns an ``xarray.Dataset`` over the other swept keys (lam, p, ...) and ``record``:
    ``ida_lo``/``ida_hi`` [IM units] (the final bracket: lo is decided safe, hi
    overturns; NaN hi: no stripe overturns the record; NaN lo: no stripe below hi is
    decided safe, ``upper_bound`` = 1), ``ida_im`` (the estimate of the smallest
    overturning level: the bracket's geometric middle, within rtol / 2 of both ends;
    ida_hi where lo is NaN), ``mode`` (1 or 2 at ida_hi; 0 where NaN), ``runs`` (kernel
    runs of the bisection), ``resurrection`` (1: a higher decided stripe is safe again),
    ``n_flagged`` (flagged stripe points of the record: neither safe nor overturning),
    ``unresolved`` (1: a bisection run came back flagged; the bracket is wider than
    rtol).
    """
    check_rtol(rtol, IdaError)
    result = as_result(ds, ["outcome", "status"])
    s = _stripes(result)
    b = _brackets(s)
    scene = result_scene(result)
    # the point at each bracket's top stripe: its amplitude scales with the level
    base = {a.name: a.values[0] for a in scene.axes}
    points = {}
    for i in np.flatnonzero(np.isfinite(b.lo)):
        values = dict(base)
        for d, k in zip([*s.others, "record"], np.unravel_index(i, s.lead), strict=True):
            values[d] = result.coords[d][k]
        values[s.im] = s.levels[b.first[i]]
        points[i] = scene.point({k: plain(v) for k, v in values.items()})

    def classify(idx: np.ndarray, mids: np.ndarray) -> list[int]:
        classes = []
        for i, mid in zip(idx, mids, strict=True):
            pt = dataclasses.replace(points[i],
                                     A_ratio=points[i].A_ratio * mid / s.levels[b.first[i]])
            out = run_point(pt, scene.numerics, history=False).out
            flagged = int(out[L.OUT_STATUS]) & FLAGGED
            classes.append(UNDECIDED if flagged else int(out[L.OUT_OUTCOME]))
        return classes

    runs, unresolved = bisect_thresholds(b.lo, b.hi, b.mode, rtol, classify, OVERTURNED,
                                         max_iter=MAX_ITER)
    return _dataset(result, s, b, runs, unresolved.astype(np.int8), rtol)


@dataclasses.dataclass(frozen=True)
class _Stripes:
    """A scaled suite's stripes: ``im`` the stripe dimension, ``levels`` (S,) increasing;
    over (others..., record) flattened to n rows: ``over``, ``safe``, ``flagged`` bool
    (n, S) and the outcome codes ``modes`` (n, S); ``lead`` the unflattened shape."""

    im: str
    levels: np.ndarray
    others: list[str]
    lead: tuple[int, ...]
    over: np.ndarray
    safe: np.ndarray
    flagged: np.ndarray
    modes: np.ndarray


def _stripes(result: Any) -> _Stripes:
    """The stripes of a complete scaled record suite (one-line IdaErrors otherwise)."""
    im = result.attrs.get("scale_im")
    if not im or im not in result.dims or "record" not in result.dims:
        raise IdaError(f"{result.path}: IDA needs a scaled record suite (ground.records with "
                       "ground.scale stripes)")
    result.require_complete(IdaError, "IDA")
    outcome = np.asarray(result.arrays["outcome"])
    dims = list(result.dims)
    others = [d for d in dims if d not in (im, "record")]
    perm = [dims.index(d) for d in [*others, "record", im]]
    flagged = np.transpose((np.asarray(result.arrays["status"]) & FLAGGED) != 0,
                           perm)
    modes = np.transpose(outcome, perm)
    over = np.isin(modes, OVERTURNED) & ~flagged
    levels = np.asarray(result.coords[im], float)
    if not np.all(np.diff(levels) > 0):
        raise IdaError(f"{result.path}: the {im} stripes must increase")
    return _Stripes(im, levels, others, over.shape[:-1], over.reshape(-1, levels.size),
                    (~over & ~flagged).reshape(-1, levels.size),
                    flagged.reshape(-1, levels.size), modes.reshape(-1, levels.size))


@dataclasses.dataclass(frozen=True)
class _Brackets:
    """Per row: ``first`` overturning stripe (-1: none), ``bottom`` the highest stripe
    below it decided safe (-1: none), the bracket ``lo``/``hi`` [IM units] and the
    ``mode`` at hi (bisected in place), ``safe_above`` (a resurrection)."""

    first: np.ndarray
    bottom: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    mode: np.ndarray
    safe_above: np.ndarray


def _brackets(s: _Stripes) -> _Brackets:
    n, S = s.over.shape
    first = np.where(s.over.any(-1), s.over.argmax(-1), -1)
    safe_above = np.array([j >= 0 and bool(s.safe[i, j:].any())
                           for i, j in enumerate(first)])
    # the bracket's bottom: the highest stripe below the first overturning one decided safe
    below = s.safe & (np.arange(S)[None, :] < np.where(first >= 0, first, 0)[:, None])
    bottom = np.where(below.any(-1), S - 1 - below[:, ::-1].argmax(-1), -1)
    lo = np.full(n, np.nan)
    hi = np.full(n, np.nan)
    mode = np.zeros(n, np.int8)
    has = first >= 0
    hi[has] = s.levels[first[has]]
    mode[has] = s.modes[has, first[has]]
    inner = np.flatnonzero(has & (bottom >= 0))
    lo[inner] = s.levels[bottom[inner]]
    return _Brackets(first, bottom, lo, hi, mode, safe_above)


def _dataset(result: Any, s: _Stripes, b: _Brackets, runs: np.ndarray,
             unresolved: np.ndarray, rtol: float) -> Any:
    im, shape = s.im, s.lead
    lo, hi = b.lo, b.hi
    est = np.where(np.isfinite(lo), np.sqrt(lo * hi), hi)
    n_flag = s.flagged.sum(-1)
    has = b.first >= 0
    unit = fields.axis_attrs(im).get("units", "1")
    coords = {d: (d, np.asarray(result.coords[d]), fields.axis_attrs(d))
              for d in [*s.others, "record"]}
    dims_out = [*s.others, "record"]
    data = {
        "ida_im": (dims_out, est.reshape(shape),
                   {"long_name": f"smallest {im} that overturns the record (the bracket's "
                                 "geometric middle; ida_hi where ida_lo is NaN)",
                    "units": unit}),
        "ida_lo": (dims_out, lo.reshape(shape),
                   {"long_name": "bracket: largest level decided safe", "units": unit}),
        "ida_hi": (dims_out, hi.reshape(shape),
                   {"long_name": "bracket: smallest level that overturns", "units": unit}),
        "upper_bound": (dims_out, (has & (b.bottom < 0)).astype(np.int8).reshape(shape),
                        {"long_name": "1: no stripe below ida_hi is decided safe (ida_im is "
                                      "an upper bound)"}),
        "mode": (dims_out, b.mode.reshape(shape),
                 {"long_name": "overturning mode at ida_hi", "flag_values": [0, 1, 2],
                  "flag_meanings": "none mode1 mode2"}),
        "runs": (dims_out, runs.reshape(shape), {"long_name": "kernel runs of the bisection"}),
        "resurrection": (dims_out, b.safe_above.astype(np.int8).reshape(shape),
                         {"long_name": "1: a stripe above ida_hi is decided safe"}),
        "n_flagged": (dims_out, n_flag.reshape(shape),
                      {"long_name": "flagged stripe points (status & STATUS_FLAGGED): "
                                    "neither safe nor overturning"}),
        "unresolved": (dims_out, unresolved.reshape(shape),
                       {"long_name": "1: a bisection run came back flagged; the bracket "
                                     "is wider than rtol"}),
    }
    return xr.Dataset(data, coords=coords,
                      attrs={"im": im, "im_units": unit, "rtol": float(rtol),
                             "title": result.name})


def ida_dataset(ds: Any, rtol: float = DEFAULT_RTOL_MANY) -> Any:
    """``rocksweep.ida``: ``ida`` with the IDA curves on the stripes
    (``theta_max_over_alpha`` against the IM, per record, NaN where a point overturned:
    what the figure draws) and its kind for ``rocksweep.plot`` (``analysis.kinds``)."""
    out = ida(ds, rtol)
    out.attrs[KIND_ATTR] = IDA
    im = out.attrs.get("im")
    if hasattr(ds, "data_vars") and "theta_max_over_alpha" in ds.data_vars and im in ds.dims:
        theta = ds["theta_max_over_alpha"].where(ds["outcome"] == 0)
        out["theta_max_over_alpha"] = theta.drop_vars(
            [c for c in theta.coords if c not in theta.dims])
    return out
