"""The contact phases of a base that may slide (``body.mu``; docs/sliding.md).

The body either rocks on a corner or stands flat, and its base either sticks to the ground
or slips along it: four phases, a word each (the words ``simulate``'s summary lists in
``phases``) and a code (the kernel's: 2 if rocking, plus 1 if slipping, so that the code
is ``2 * (s != 0) + (sigma != 0)`` of the corner s and the slip direction sigma).
"""

from __future__ import annotations

REST, SLIDE, ROCK, SLIDE_ROCK = "rest", "slide", "rock", "slide-rock"
PHASES: tuple[str, ...] = (REST, SLIDE, ROCK, SLIDE_ROCK)
PHASE_CODE: dict[str, int] = {REST: 0, SLIDE: 1, ROCK: 2, SLIDE_ROCK: 3}
PHASE_WORDS: dict[int, str] = {c: w for w, c in PHASE_CODE.items()}
PHASE_MEANING: dict[str, str] = {
    REST: "flat on the ground, the base stuck (theta = 0, x' = 0)",
    SLIDE: "flat on the ground, the base slipping (theta = 0, x' != 0)",
    ROCK: "rocking on a stuck corner (x' = 0): the paper's model",
    SLIDE_ROCK: "rocking on a slipping corner (x' != 0)",
}
