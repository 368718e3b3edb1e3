"""Names of the accuracy settings a user picks (``numerics.accuracy``, ``numerics.root``,
``--ladder``).

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

#: the settings of an adaptive sweep a user gives (the scene's ``refine:`` section, the
#: keywords of ``rocksweep.run``; their ranges: ``rocksweep.schema``)
ADAPTIVE_SETTINGS: tuple[str, ...] = ("coarse", "audit", "margin", "final_margin", "seed",
                                      "threshold")
#: the adaptive settings that decide a result (the diagram's axes too, the default coarse
#: level resolved): what a result file records and a resume compares
ADAPTIVE_RESOLVED: tuple[str, ...] = ("axes", "coarse", "margin", "final_margin", "audit",
                                      "seed", "threshold")
