"""Which rocksweep Dataset is this? The one place that tells a sweep from an analysis's
result (``rocksweep.plot``, ``rocksweep.table`` and the command line dispatch on it).

A Dataset says its kind in ``attrs["rocksweep_kind"]`` when the analysis that made it sets
it (risk, im_efficiency); the others are known by the variables that only they hold.
"""

from __future__ import annotations

from typing import Any

#: kind -> the variables that identify it (all of them present), checked in this order
SIGNATURES: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("risk", ("annual_rate",)),
    ("im_efficiency", ("beta", "exponent")),
    ("fragility", ("im_median", "beta")),
    ("fragility", ("median", "beta")),
    ("ida", ("ida_im",)),
    ("floor_spectrum", ("p_overturn", "n_counted")),
    ("sweep", ("outcome", "status")),
    ("spectra", ("A_min", "theta_max_over_alpha", "outcome")),
    ("boundaries", ("A_min",)),
)
KINDS = tuple(dict.fromkeys(k for k, _ in SIGNATURES))


def dataset_kind(ds: Any) -> str | None:
    """"sweep", "fragility", "ida", "spectra", "boundaries", "risk" or "im_efficiency";
    None for a Dataset rocksweep did not make."""
    kind = getattr(ds, "attrs", {}).get("rocksweep_kind")
    if kind in KINDS:
        return str(kind)
    names = set(getattr(ds, "variables", ()))
    for kind, needs in SIGNATURES:
        if all(n in names for n in needs):
            return kind
    return None
