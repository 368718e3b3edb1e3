"""What a run ends in, as codes (the kernel's integers, stored in files) and as words.

- outcome classes (``outcome``, int8): not_run, safe, mode1 (overturned after one or more
  impacts), mode2 (overturned without impact);
- status bits (``status``, a bit set): how the run ended and what it met on the way; a run
  with any ``FLAGGED`` bit is not a reliable classification;
- fragility states (``state=``): overturn (either mode), mode1, mode2, uplift, theta:X,
  slide:D;
- ``computed`` flags of an adaptive sweep (int8): filled, computed, audit agreed/disagreed.
"""

from __future__ import annotations

NOT_RUN, SAFE, MODE1, MODE2 = "not_run", "safe", "mode1", "mode2"
OUTCOME_CODE: dict[str, int] = {NOT_RUN: -1, SAFE: 0, MODE1: 1, MODE2: 2}
#: the codes by name (the kernel's ``layout.OUTCOME_*`` are these)
OUTCOME_NOT_RUN, OUTCOME_SAFE = OUTCOME_CODE[NOT_RUN], OUTCOME_CODE[SAFE]
OUTCOME_MODE1, OUTCOME_MODE2 = OUTCOME_CODE[MODE1], OUTCOME_CODE[MODE2]
OUTCOME_WORDS: dict[int, str] = {c: w for w, c in OUTCOME_CODE.items()}
#: the classes of a run that ran, in code order (0, 1, 2)
CLASSES: tuple[str, ...] = (SAFE, MODE1, MODE2)
#: words of an overturning-mode variable (0: none, 1, 2)
MODE_WORDS: tuple[str, ...] = ("none", MODE1, MODE2)

SLIDES, LIFTS_OFF = "slides", "lifts_off"  # the contact status words (outputs.contact)
AIRBORNE = "airborne"  # the ground falls faster than gravity: the body leaves it
SLID = "slid"  # the base slipped along the ground (a scene with body.mu: docs/sliding.md)
#: the bits of a run's ``status``: word -> bit (what each means: docs/diagrams.md, "Status
#: words")
STATUS_BIT: dict[str, int] = {
    "rest": 1,
    "horizon": 2,
    "step_cap": 4,
    "event_cap": 8,
    "nonfinite": 16,
    "history_full": 32,
    "energy_gain": 64,
    "settled": 128,
    "overturned": 256,
    "e_above_1": 512,
    "bounded": 1024,
    SLIDES: 2048,
    LIFTS_OFF: 4096,
    # set after the kernel by the certification of close calls (rocksweep.compute.certify)
    "refined": 8192,
    "uncertified": 16384,
    # g + a_v <= 0 (a vertical ground acceleration): the body leaves the ground; the run
    # stops there (kernel)
    AIRBORNE: 32768,
    # the base slipped (the sliding base, a scene that gives body.mu; kernel)
    SLID: 65536,
}
STATUS_WORDS: dict[int, str] = {b: w for w, b in STATUS_BIT.items()}
#: the bits that make a run's class unreliable ("flagged")
FLAGGED_WORDS: tuple[str, ...] = ("horizon", "step_cap", "event_cap", "nonfinite",
                                   "uncertified", AIRBORNE)
FLAGGED = 0
for _w in FLAGGED_WORDS:
    FLAGGED |= STATUS_BIT[_w]

#: the limit states a fragility curve can count (besides "theta:X" and "slide:D")
OVERTURN, UPLIFT = "overturn", "uplift"
STATES: tuple[str, ...] = (OVERTURN, MODE1, MODE2, UPLIFT)
THETA_STATE = "theta:X"  # max|theta|/alpha_cg >= X, or overturned
#: slide_max >= D (the base's largest sliding displacement, in the units of the Dataset's
#: slide_max: the base half-width b), or overturned
SLIDE_STATE = "slide:D"

#: ``computed`` flags of an adaptive sweep (int8 per point): word -> code
FILLED, COMPUTED, AUDIT_AGREED, AUDIT_DISAGREED = (
    "filled", "computed", "audit_agreed", "audit_disagreed")
COMPUTED_CODE: dict[str, int] = {FILLED: 0, COMPUTED: 1, AUDIT_AGREED: 2, AUDIT_DISAGREED: 3}
COMPUTED_FLAGS: dict[int, str] = {c: w for w, c in COMPUTED_CODE.items()}
COMPUTED_MEANING: dict[int, str] = {
    0: "filled (not computed; outcome from the uniform cell around it)",
    1: "computed (coarse pass or refinement)",
    2: "computed as an audit point, agreed with its fill",
    3: "computed as an audit point, disagreed with its fill (region refined)",
}


def outcome_word(code: int) -> str:
    return OUTCOME_WORDS[int(code)]


def status_words(bits: int) -> list[str]:
    return [w for b, w in STATUS_WORDS.items() if int(bits) & b]


def flag_attrs(words: tuple[str, ...] | dict[int, str], start: int = 0) -> dict:
    """CF ``flag_values``/``flag_meanings`` of a coded variable: ``words`` in code order
    from ``start``, or a code -> word dict."""
    pairs = (list(words.items()) if isinstance(words, dict)
             else list(enumerate(words, start)))
    return {"flag_values": [c for c, _ in pairs],
            "flag_meanings": " ".join(w for _, w in pairs)}
