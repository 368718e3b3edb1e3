"""Which rocksweep Dataset is this? The one place that tells a sweep from an analysis's
result (``rocksweep.plot``, ``rocksweep.table``, ``rocksweep.open`` and the command line
dispatch on it).

A Dataset says its kind in ``attrs["rocksweep_kind"]`` (``vocab.kinds``): every analysis
sets it, and every file ``rocksweep.analysis.files`` writes carries it. Datasets without
it (a sweep result, or an analysis's file written before the attribute was set) are known
by the variables that only they hold.
"""

from __future__ import annotations

from typing import Any

from rocksweep.vocab.kinds import (
    BOUNDARIES,
    CALIBRATION,
    FLOOR_SPECTRUM,
    FRAGILITY,
    IDA,
    IM_EFFICIENCY,
    KIND_ATTR,
    KIND_NAMES,
    RISK,
    SPECTRA,
    SWEEP,
)

#: kind -> the variables that identify it (all of them present), checked in this order:
#: the fallback for a Dataset without ``rocksweep_kind``
SIGNATURES: tuple[tuple[str, tuple[str, ...]], ...] = (
    (RISK, ("annual_rate",)),
    (IM_EFFICIENCY, ("beta", "exponent")),
    (FRAGILITY, ("im_median", "beta")),
    (FRAGILITY, ("median", "beta")),
    (IDA, ("ida_im",)),
    (CALIBRATION, ("estimate", "measured_theta")),
    (FLOOR_SPECTRUM, ("p_overturn", "n_counted")),
    (SWEEP, ("outcome", "status")),
    (SPECTRA, ("A_min", "theta_max_over_alpha", "outcome")),
    (BOUNDARIES, ("A_min",)),
)
KINDS = KIND_NAMES


def dataset_kind(ds: Any) -> str | None:
    """A kind of ``vocab.kinds`` ("sweep", "fragility", "calibration", ...); None for a
    Dataset rocksweep did not make."""
    kind = getattr(ds, "attrs", {}).get(KIND_ATTR)
    if kind in KINDS:
        return str(kind)
    names = set(getattr(ds, "variables", ()))
    for kind, needs in SIGNATURES:
        if all(n in names for n in needs):
            return kind
    return None
