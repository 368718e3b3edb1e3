"""The kinds of Dataset rocksweep writes and reads back (``rocksweep.open`` says which).

A file an analysis writes carries its kind in the attribute ``KIND_ATTR``
(``rocksweep.analysis.files``); a Dataset in memory carries it in ``attrs`` when the
analysis that made it sets it. A sweep result is known by its own format.
"""

from __future__ import annotations

#: the attribute that names a Dataset's (or a file's) kind
KIND_ATTR = "rocksweep_kind"

SWEEP = "sweep"
FRAGILITY = "fragility"
IDA = "ida"
SPECTRA = "spectra"
BOUNDARIES = "boundaries"
RISK = "risk"
IM_EFFICIENCY = "im_efficiency"
CALIBRATION = "calibration"
ACCURACY = "accuracy"
FLOOR_SPECTRUM = "floor_spectrum"

#: every kind, with what it holds
KINDS: dict[str, str] = {
    SWEEP: "a sweep result: outcomes and fields over the swept axes",
    FRAGILITY: "lognormal fragility curves of a record suite, with verdicts",
    IDA: "each record's first overturning level, bisected",
    SPECTRA: "A_min and the peak rotation per record and period",
    BOUNDARIES: "A_min curves and the boundary lines of a stability diagram",
    RISK: "annual rate and probability of a state over a hazard curve",
    IM_EFFICIENCY: "the dispersion of each IM's fragility (which IM predicts best)",
    CALIBRATION: "scene parameters fitted to a measured rocking history",
    ACCURACY: "the accuracy study of a ladder of numerical settings",
    FLOOR_SPECTRUM: "P(overturn) or A_min against a building's period (floor spectra)",
}
KIND_NAMES: tuple[str, ...] = tuple(KINDS)
