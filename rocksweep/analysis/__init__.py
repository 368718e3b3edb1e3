"""Analyses of results: each takes an ``xarray.Dataset`` (what ``rocksweep.run`` and
``rocksweep.open`` return) and returns a Dataset or plain data. ``summary`` (counts,
provenance), ``boundaries`` (A_min curves, class boundary lines), ``spectrum`` (rocking
and overturning spectra), ``restitution`` (the eq. 1 map), ``accuracy`` (the
work-precision study against the reference).
"""

# the public modules
__all__ = ["accuracy", "boundaries", "fragility", "restitution", "spectrum", "summary"]
