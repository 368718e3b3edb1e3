"""Analyses of results: each takes an ``xarray.Dataset`` (what ``rocksweep.run`` and
``rocksweep.open`` return) and returns a Dataset or plain data. ``summary`` (counts,
provenance), ``boundaries`` (A_min curves, class boundary lines), ``spectrum`` (rocking
and overturning spectra), ``floors`` (the orientation answers and the floor spectrum),
``restitution`` (the eq. 1 map), ``accuracy`` (the work-precision study against the
reference), ``fragility`` (curves and verdicts) over ``likelihood``, ``joint_models``,
``states`` and ``counts``, ``ida``, ``efficiency`` (beta per IM), ``risk``, ``table`` (one
row per run), ``calibrate`` over ``peaks``; shared: ``bisection`` (the one threshold
bisection), ``tolerance`` and ``resampling`` (the rtol and bootstrap rules), ``kinds``
(which Dataset is this), ``files`` (every analysis's file written and read back).
"""

# the public modules
__all__ = ["accuracy", "bisection", "boundaries", "calibrate", "counts", "efficiency", "files",
           "floors", "fragility", "ida", "joint_models", "kinds", "likelihood", "peaks",
           "resampling", "restitution", "risk", "spectrum", "states", "summary", "table",
           "tolerance"]
