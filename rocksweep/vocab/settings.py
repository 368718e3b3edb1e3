"""Names of the settings a user picks: accuracy presets (``numerics.accuracy``), accuracy
ladders, the backends a sweep runs on.

The presets' values live with the numerics (``rocksweep.numerics.PRESETS``, keyed by
``PRESET_NAMES``); the ladders' settings with the accuracy study
(``rocksweep.analysis.accuracy.LADDERS``, keyed by ``LADDER_NAMES``).
"""

from __future__ import annotations

PRESET_NAMES: tuple[str, ...] = ("draft", "default", "fine", "accurate")
DEFAULT_PRESET = "default"
#: the ladders of ``rocksweep accuracy --ladder`` and what each measures
LADDERS: dict[str, str] = {
    "full": "steps per period 5..160, event_tol 1e-4..1e-8, presets",
    "short": "a quick check",
    "candidates": "the cheap settings the default preset is chosen from",
    "presets": "the presets alone: their tails on a scene of your own",
    "roots": "every preset with every event root finder",
}
LADDER_NAMES: tuple[str, ...] = tuple(LADDERS)
DEFAULT_LADDER = "full"

#: where a sweep's chunks run: local worker threads, or a dask.distributed cluster
BACKENDS: tuple[str, ...] = ("threads", "dask")
DEFAULT_BACKEND = "threads"
