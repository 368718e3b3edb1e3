"""The bootstrap's settings, shared by ``rocksweep.fragility``, the analysis
(``rocksweep.analysis.fragility``) and ``rocksweep fragility`` (one definition; this module
imports nothing, so the command line reads it at start-up)."""

#: resamples over records when a caller gives none
DEFAULT_BOOTSTRAP = 200
#: at most this many resamples (each resample's fit is kept, 16 bytes a curve)
MAX_BOOTSTRAP = 100_000
