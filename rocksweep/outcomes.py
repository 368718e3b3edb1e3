"""Outcome and status codes (integers in the kernel and files) <-> words at the boundary."""

from __future__ import annotations

from rocksweep.kernel import layout as L

OUTCOME_WORDS = {
    L.OUTCOME_NOT_RUN: "not_run",
    L.OUTCOME_SAFE: "safe",
    L.OUTCOME_MODE1: "mode1",
    L.OUTCOME_MODE2: "mode2",
}

STATUS_WORDS = {
    L.STATUS_REST: "rest",
    L.STATUS_HORIZON: "horizon",
    L.STATUS_STEP_CAP: "step_cap",
    L.STATUS_EVENT_CAP: "event_cap",
    L.STATUS_NONFINITE: "nonfinite",
    L.STATUS_HIST_FULL: "history_full",
    L.STATUS_ENERGY_GAIN: "energy_gain",
    L.STATUS_SETTLED: "settled",
    L.STATUS_OVERTURNED: "overturned",
    L.STATUS_E_ABOVE_1: "e_above_1",
    L.STATUS_BOUNDED: "bounded",
    L.STATUS_SLIDES: "slides",
    L.STATUS_LIFTS_OFF: "lifts_off",
    L.STATUS_REFINED: "refined",
    L.STATUS_UNCERTIFIED: "uncertified",
}

STATUS_MEANING = {
    "rest": "rest proven after the pulse (early exit); never after the rest-rate rule "
            "ended a chattering sequence (then: settled)",
    "horizon": "horizon reached before the outcome was decided (flagged)",
    "step_cap": "RK4 step cap reached (flagged)",
    "event_cap": "impact/uplift cap reached (flagged)",
    "nonfinite": "state became NaN or infinite (flagged)",
    "history_full": "history buffer full; later steps not recorded",
    "energy_gain": "at least one impact gained energy",
    "settled": "a chattering sequence ended in full contact by the rest-rate rule (not a "
               "proof: the run ends without 'rest')",
    "overturned": "the body reached |theta| = pi/2",
    "e_above_1": "at least one impact had e > 1",
    "bounded": "rigid body below its overturning energy after the pulse, |e| <= 1: "
               "safe proven (early exit)",
    "slides": "friction demand mu_required above body.mu: the base would slide "
              "(outputs.contact)",
    "lifts_off": "normal reaction below zero: the body would leave the ground "
                 "(outputs.contact)",
    "refined": "a close call (the free rocking came near the overturning saddle): re-run "
               "with 2, 4, ... times the steps until its outcome was stable; the finest "
               "run's result is kept (rocksweep.compute.certify)",
    "uncertified": "a close call whose outcome still changed at the last refinement "
                   "(numerics.refine) (flagged)",
}


def outcome_word(code: int) -> str:
    return OUTCOME_WORDS[int(code)]


def status_words(bits: int) -> list[str]:
    return [w for b, w in STATUS_WORDS.items() if int(bits) & b]
