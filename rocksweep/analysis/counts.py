"""What a fragility fit reads from a record-suite result Dataset: its IM (stripes, the
levels of the sweep's ``scale_im``, or a cloud, an IM per record) and, per curve (every
combination of the other swept keys), the points counted, flagged, not run and reaching
each state (``analysis.states``)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr

from rocksweep.analysis.states import counted_points, parse_state, required, state_reached
from rocksweep.compute.adaptive import FILLED
from rocksweep.errors import Arg, FragilityError
from rocksweep.vocab.ground import CLOUD_IMS as CLOUD_IM_VARIABLES
from rocksweep.vocab.ground import SCALE_IMS
from rocksweep.vocab.outcomes import MODE1, MODE2, OVERTURN, UPLIFT

#: the coordinate along ``record`` naming the record each sample was drawn from (a
#: sample per (record, angle): ``floors.each_orientation``); the bootstrap resamples
#: records, each with all its samples
RECORD_OF = "record_of"
#: stripe dimension names (the sweep's ``scale_im``) and their units
STRIPE_IMS = SCALE_IMS
#: cloud IMs and the per-record variables they come from
CLOUD_IMS = {im: (var, SCALE_IMS[im]) for im, var in CLOUD_IM_VARIABLES.items()}


def cloud_im(ds: xr.Dataset, im: str | None, period: float | None
              ) -> tuple[np.ndarray, str, str, float]:
    name = "PGA" if im is None else str(im)
    if name not in CLOUD_IMS:
        raise FragilityError(f"im = {im!r}: a cloud (no stripe dimension) takes one of "
                             f"{', '.join(CLOUD_IMS)}")
    var, unit = CLOUD_IMS[name]
    da = required(ds, var, f"the per-record {name} of a cloud")
    per = math.nan
    if name == "Sa":
        if "period" not in da.dims:
            raise FragilityError(f"{var} has no 'period' dimension")
        periods = np.asarray(da["period"].values, dtype=np.float64)
        if period is None:
            if periods.size != 1:
                raise FragilityError(f"im = 'Sa' needs period= (one of "
                                     f"{', '.join(f'{p:g}' for p in periods)} s)")
            period = float(periods[0])
        hit = np.flatnonzero(np.isclose(periods, float(period), rtol=1e-9, atol=0.0))
        if hit.size == 0:
            raise FragilityError(f"period = {period!r}: {var} holds periods "
                                 f"{', '.join(f'{p:g}' for p in periods)} s")
        da = da.isel(period=int(hit[0]))
        per = float(periods[hit[0]])
    if set(da.dims) != {"record"}:
        raise FragilityError(f"{var} must lie along 'record' only, has {da.dims}")
    x = np.asarray(da.transpose("record").values, dtype=np.float64)
    if "scale_factor" in ds.variables:
        x = x * np.asarray(ds["scale_factor"].transpose("record").values, dtype=np.float64)
    if np.any(~np.isfinite(x) | (x <= 0.0)):
        bad = ds["record"].values[~np.isfinite(x) | (x <= 0.0)][0]
        raise FragilityError(f"record {bad}: {name} must be finite and > 0 for a cloud fit")
    return x, name, unit, per


def refuse_filled(ds: xr.Dataset, states: Sequence[str], counted: xr.DataArray) -> None:
    """An adaptive sweep's filled points carry only the class: refuse states that need
    more (uplift, theta:X)."""
    if "computed" not in ds.variables:
        return
    filled = (ds["computed"] == FILLED) & counted
    n = int(filled.sum())
    need = [s for s in states if parse_state(s)[0] in (UPLIFT, "theta")]
    if n and need:
        raise FragilityError(
            f"state {need[0]!r}: {n} points of this adaptive sweep were filled from the class "
            "around them, not computed, so their uplift and theta are unknown; only "
            f"{OVERTURN}, {MODE1} and {MODE2} can be fitted (a sweep that computes every "
            "point can give it)")


@dataclass(frozen=True)
class IMAxis:
    """The IM of a fit: stripes (``stripe`` the dimension, ``x`` its levels (S,)) or a
    cloud (``stripe`` None, ``x`` the records' IMs (R,)); [unit] each."""

    stripe: str | None
    x: np.ndarray
    im_name: str
    unit: str
    period: float  # Sa's period [s], NaN for other IMs
    method: str  # "stripes-mle" | "cloud-mle"

    @property
    def stripes(self) -> bool:
        return self.stripe is not None


def im_axis(ds: xr.Dataset, out_da: xr.DataArray, im: str | None, period: float | None
             ) -> IMAxis:
    """Stripes if the outcome lies along the sweep's ``scale_im``, else a cloud."""
    scale_im = ds.attrs.get("scale_im")
    stripe = str(scale_im) if scale_im is not None and str(scale_im) in out_da.dims else None
    if scale_im not in (None, "", "none") and stripe is None:
        raise FragilityError(f"scale_im = {scale_im!r} but outcome has no such dimension")
    if stripe is None:
        if period is not None and (im is None or str(im) != "Sa"):
            raise FragilityError("{period}: only with {im}", period=Arg("period", period),
                                 im=Arg("im", "Sa"))
        rec_im, im_name, unit, per = cloud_im(ds, im, period)
        return IMAxis(None, rec_im, im_name, unit, per, "cloud-mle")
    if stripe not in STRIPE_IMS:
        raise FragilityError(f"scale_im = {stripe!r}: one of {', '.join(STRIPE_IMS)}")
    if im is not None and str(im) != stripe:
        raise FragilityError(f"im = {im!r}: the stripes are levels of {stripe}; a "
                             "stripe fit uses that IM")
    levels = np.asarray(ds[stripe].values, dtype=np.float64)
    if np.any(~np.isfinite(levels) | (levels <= 0.0)):
        raise FragilityError(f"{stripe}: every stripe level must be finite and > 0")
    per = float(ds.attrs.get("scale_period", math.nan)) if stripe == "Sa" else math.nan
    if period is not None and not (stripe == "Sa" and math.isclose(
            float(period), per, rel_tol=1e-9)):
        raise FragilityError(f"period = {period!r}: the stripes are {stripe}"
                             + (f" at T = {per:g} s" if stripe == "Sa" else "")
                             + "; leave period out")
    return IMAxis(stripe, levels, stripe, STRIPE_IMS[stripe], per, "stripes-mle")


@dataclass(frozen=True)
class Counts:
    """The points of every curve: the other dims (``others``, sizes ``shape_o``) flattened
    to n_o curves; bool arrays over (n_o, R[, S]) (records, stripes), ``hits`` over
    (states, n_o, R[, S])."""

    others: list[str]
    shape_o: tuple[int, ...]
    names: list[str]  # the records
    counted: np.ndarray
    flagged: np.ndarray
    not_run: np.ndarray
    hits: np.ndarray  # the point reaches the state
    over_all: np.ndarray  # the point overturns (either mode)
    # the record each sample of the record dimension was drawn from (int[R], 0..G-1):
    # every (record, angle) pair of an ``each`` orientation answer is a sample of its
    # record (``floors.each_orientation``'s ``RECORD_OF``); None: each sample a record
    groups: np.ndarray | None = None

    @property
    def n_o(self) -> int:
        return self.counted.shape[0]

    @property
    def R(self) -> int:
        return self.counted.shape[1]

    @property
    def n_groups(self) -> int:
        """The records the samples come from (R when each sample is a record)."""
        return self.R if self.groups is None else int(self.groups.max()) + 1

    def records_counted(self) -> np.ndarray:
        """int[n_o]: the records with at least one counted point (a record whose samples
        are its orientations counts once)."""
        per = self.counted.reshape(self.n_o, self.R, -1).any(-1)
        if self.groups is None:
            return per.sum(-1)
        return np.stack([per[:, self.groups == g].any(-1)
                         for g in range(self.n_groups)], -1).sum(-1)

    def onehot(self, kind: str, idxs: list[int], o: int, mask: np.ndarray) -> np.ndarray:
        """(C, R[, S]) float: each point of ``mask`` in its category of the group."""
        h = self.hits[idxs, o] & mask[None]
        if kind == "single":
            cat = h[0].astype(np.int64)
        else:  # ordinal: the most severe reached; competing: 1 mode 1, 2 mode 2
            cat = np.max(np.stack([(j + 1) * h[j] for j in range(len(idxs))]), 0)
        C = len(idxs) + 1
        return np.stack([(cat == c) & mask for c in range(C)]).astype(np.float64)


def count_points(ds: xr.Dataset, states: list[str], axis: IMAxis, out_da: xr.DataArray
           ) -> Counts:
    """Which points are counted, flagged, not run, and reach each state."""
    others = [d for d in out_da.dims if d not in ("record", axis.stripe)]
    order = others + ["record"] + ([axis.stripe] if axis.stripes else [])
    counted_da, flagged_da, not_run_da = counted_points(ds)
    refuse_filled(ds, states, counted_da)
    shape_o = tuple(ds.sizes[d] for d in others)
    n_o = int(np.prod(shape_o)) if shape_o else 1
    R = ds.sizes["record"]
    tail = (R, ds.sizes[axis.stripe]) if axis.stripes else (R,)

    def flat(da: xr.DataArray) -> np.ndarray:
        return da.transpose(*order).values.reshape((n_o,) + tail)

    hits = np.stack([state_reached(ds, s).transpose(*order).values for s in states])
    groups = None
    if RECORD_OF in ds.coords and ds[RECORD_OF].dims == ("record",):
        of = [str(v) for v in ds[RECORD_OF].values]
        first = {name: g for g, name in enumerate(dict.fromkeys(of))}  # records in order
        groups = np.array([first[name] for name in of], np.int64)
    return Counts(others, shape_o, [str(r) for r in ds["record"].values],
                   flat(counted_da), flat(flagged_da), flat(not_run_da),
                   hits.reshape((len(states), n_o) + tail),
                   flat(state_reached(ds, OVERTURN)), groups)
