"""Names of the settings a user picks: accuracy presets (``numerics.accuracy``), event
root finders (``numerics.root``), accuracy ladders, adaptive settings and their defaults,
the backends a sweep runs on.

The presets' values live with the numerics (``rocksweep.numerics.PRESETS``, keyed by
``PRESET_NAMES``); the ladders' descriptions here (``LADDER_HELP``), their settings with
the accuracy study (``rocksweep.analysis.accuracy.LADDERS``, keyed by ``LADDER_NAMES``).
"""

from __future__ import annotations

DRAFT, DEFAULT_PRESET, FINE, ACCURATE = "draft", "default", "fine", "accurate"
PRESET_NAMES: tuple[str, ...] = (DRAFT, DEFAULT_PRESET, FINE, ACCURATE)

BISECTION, ILLINOIS, HERMITE = "bisection", "illinois", "hermite"
#: event root finders (``numerics.root``) and the kernel's code for each (PAR_ROOT;
#: ``rocksweep.kernel.events._locate``)
ROOT_CODE: dict[str, float] = {BISECTION: 0.0, ILLINOIS: 1.0, HERMITE: 2.0}
ROOTS: tuple[str, ...] = tuple(ROOT_CODE)
DEFAULT_ROOT = HERMITE

#: the ladders of ``rocksweep accuracy --ladder`` and what each measures
LADDER_HELP: dict[str, str] = {
    "full": "steps per period 5..160, event_tol 1e-4..1e-8, presets",
    "short": "a quick check",
    "candidates": "the cheap settings the default preset is chosen from",
    "presets": "the presets alone: their tails on a scene of your own",
    "roots": "every preset with every event root finder",
}
LADDER_NAMES: tuple[str, ...] = tuple(LADDER_HELP)
DEFAULT_LADDER = "full"
#: the seed of the accuracy study's stratified sample when a caller gives none
DEFAULT_SAMPLE_SEED = 0

#: the settings of an adaptive sweep a user gives (the scene's ``refine:`` section, the
#: keywords of ``rocksweep.run``, the sweep command's options; their ranges:
#: ``rocksweep.schema``; ``rocksweep.compute.adaptive`` explains each)
ADAPTIVE_SETTINGS: tuple[str, ...] = ("coarse", "audit", "margin", "final_margin", "seed",
                                      "threshold")
#: the adaptive settings that decide a result (the diagram's axes too, the default coarse
#: level resolved): what a result file records and a resume compares
ADAPTIVE_RESOLVED: tuple[str, ...] = ("axes", "coarse", "margin", "final_margin", "audit",
                                      "seed", "threshold")
# The defaults. Default coarse level: the largest k whose coarse lattice keeps >=
# MIN_COARSE_CELLS cells along both diagram axes (80: k = 2, 400: k = 4, 1000: k = 5).
MIN_COARSE_CELLS = 16
DEFAULT_MARGIN = 1
# No margin at the last level: there it caught only one-point-tall slivers (40 of 480 000
# points of Figure 4(b) at 400 x 400) for 17-27% more points computed. 0 also selects the
# light rules of the last two levels (``rocksweep.compute.adaptive``); >= 1 refines whole
# cells there.
DEFAULT_FINAL_MARGIN = 0
DEFAULT_AUDIT = 0.02
DEFAULT_SEED = 0
# A run warns when more than this share of its audit points disagree with their fill.
DEFAULT_AUDIT_THRESHOLD = 0.002

#: where a sweep's chunks run: local worker threads, or a dask.distributed cluster
BACKENDS: tuple[str, ...] = ("threads", "dask")
DEFAULT_BACKEND = "threads"
