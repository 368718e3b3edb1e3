"""Damage states of a record-suite sweep: their words (``state=``), how several are
fitted together, and which points of a result Dataset reach each one and are counted.

States (``rocksweep.vocab.outcomes``): "overturn" (outcome 1 or 2), "mode1", "mode2",
"uplift" (uplifts > 0 or overturned), "theta:X" (max|theta|/alpha_cg >= X or overturned,
0 < X <= 1), "slide:D" (slide_max >= D or overturned, D > 0 in the units of the
Dataset's ``slide_max``: the base half-width b, for every body; a sweep of a
scene with ``body.mu``).

Two chains of nested states (a point that reaches one reaches the milder ones of its
chain): rocking, uplift < theta:X < overturn, and sliding, slide:D < overturn (slide:D1 <
slide:D2 for D1 < D2). The chains share overturning only: a body may slide without
rocking and rock without sliding. The two modes are nested with nothing.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from rocksweep.errors import AnalysisWarning, FragilityError
from rocksweep.vocab.outcomes import (
    FLAGGED,
    FLAGGED_WORDS,
    MODE1,
    MODE2,
    OUTCOME_MODE1,
    OUTCOME_MODE2,
    OUTCOME_NOT_RUN,
    OVERTURN,
    SLIDE_STATE,
    STATES,
    STATUS_BIT,
    THETA_STATE,
    UPLIFT,
)

STATE_WORDS = (*STATES, THETA_STATE, SLIDE_STATE)
#: the kinds of the threshold states (``parse_state``'s first answer): "theta", "slide"
THETA, SLIDE = (w.split(":", 1)[0] for w in (THETA_STATE, SLIDE_STATE))
#: the variable a threshold state compares with its number (``state_reached``)
THRESHOLD_VARIABLE = {THETA: "theta_max_over_alpha", SLIDE: "slide_max"}
#: the chains of nested damage states (the module docstring)
ROCKING, SLIDING = "rocking", "sliding"
_CHAINS: dict[str, frozenset[str]] = {
    UPLIFT: frozenset({ROCKING}), THETA: frozenset({ROCKING}),
    SLIDE: frozenset({SLIDING}), OVERTURN: frozenset({ROCKING, SLIDING})}


def parse_state(state: str) -> tuple[str, float]:
    """("overturn" | "mode1" | "mode2" | "uplift" | "theta" | "slide", threshold) of a state
    word; "theta:X" is max|theta|/alpha_cg >= X (0 < X <= 1) or overturned, "slide:D"
    slide_max >= D (D > 0, finite) or overturned."""
    if not isinstance(state, str):
        raise FragilityError(f"state = {state!r}: a state is a string, one of "
                             f"{', '.join(STATE_WORDS)} (or a list of them)")
    s = state.strip()
    if s in STATES:
        return s, math.nan
    kind, sep, number = s.partition(":")
    if sep and kind in (THETA, SLIDE):
        try:
            x = float(number)
        except ValueError:
            x = math.nan
        if kind == THETA and math.isfinite(x) and 0.0 < x <= 1.0:
            return THETA, x
        if kind == SLIDE and math.isfinite(x) and x > 0.0:
            return SLIDE, x
        if kind == THETA:
            raise FragilityError(f"state {state!r}: theta:X needs a number 0 < X <= 1 "
                                 "(max|theta|/alpha_cg)")
        raise FragilityError(f"state {state!r}: slide:D needs a number D > 0 (slide_max >= D: "
                             "the base's largest sliding displacement, in units of its "
                             "half-width b)")
    raise FragilityError(f"state {state!r}: expected one of {', '.join(STATE_WORDS)}")


def parse_states(state: Any) -> list[str]:
    """The list of state words of ``state`` (a word or a list/tuple of words), checked:
    each word ``parse_state``, none twice, at least one."""
    if isinstance(state, str):
        states = [state]
    elif isinstance(state, list | tuple):
        states = list(state)
    else:
        raise FragilityError(f"state = {state!r}: a state word or a list of them "
                             f"({', '.join(STATE_WORDS)})")
    if not states:
        raise FragilityError("state = []: give at least one state")
    for s in states:
        parse_state(s)
    if len({s.strip() for s in states}) != len(states):
        raise FragilityError(f"state = {states!r}: lists a state twice")
    return [s.strip() for s in states]


def severity(state: str) -> float:
    """A damage state's place in its chain (``chains``): uplift (0) < theta:X (X) <
    overturn (inf), slide:D (D) < overturn; NaN for the modes (not nested). Compare two
    states' severities only where they share a chain (``nested``)."""
    kind, x = parse_state(state)
    return {UPLIFT: 0.0, THETA: x, SLIDE: x, OVERTURN: math.inf}.get(kind, math.nan)


def chains(state: str) -> frozenset[str]:
    """The chains of nested damage states ``state`` is on (``ROCKING``, ``SLIDING``; both
    for overturn, none for the modes)."""
    return _CHAINS.get(parse_state(state)[0], frozenset())


def nested(a: str, b: str) -> bool:
    """Whether one of two states implies the other (they share a chain): the more severe
    one's curve cannot lie above the milder one's."""
    return bool(chains(a) & chains(b))


def state_groups(states: Sequence[str], joint: bool = False) -> list[tuple[str, list[int]]]:
    """How the states are fitted: [(kind, indices into states)]. By default every state
    alone ("single": a curve's numbers do not depend on the other states asked for); with
    ``joint`` "ordinal" for two or more nested damage states of one chain (uplift,
    theta:X, overturn; or slide:D, overturn; indices in severity order; one beta),
    "competing" for mode1 with mode2, "single" for every other one. Two chains of two or
    more states each is a FragilityError: one ordinal fit holds one chain."""
    if not joint:
        return [("single", [i]) for i in range(len(states))]
    members = {c: sorted((i for i, s in enumerate(states) if c in chains(s)),
                         key=lambda i: severity(states[i])) for c in (ROCKING, SLIDING)}
    long = [c for c, m in members.items() if len(m) >= 2]
    if len(long) == 2:
        said = " and ".join(f"{', '.join(states[i] for i in members[c])} ({c})" for c in long)
        raise FragilityError(
            f"state = {list(states)!r}: a joint fit orders one chain of nested damage "
            f"states, these form two, {said}: a body may slide without rocking and rock "
            "without sliding; fit each chain in its own call, or every state alone "
            "(joint=False)")
    chain = members[long[0]] if long else []
    modes = [states.index(s) for s in (MODE1, MODE2) if s in states]
    groups: list[tuple[str, list[int]]] = []
    if chain:
        groups.append(("ordinal", chain))
    if len(modes) == 2:
        groups.append(("competing", modes))
    groups += [("single", [i]) for i in range(len(states))
               if i not in chain and not (len(modes) == 2 and i in modes)]
    return groups


def needed_variables(state: str) -> tuple[str, ...]:
    """The result variables ``state_reached`` reads for ``state`` besides ``outcome``:
    uplifts (uplift), theta_max_over_alpha (theta:X), slide_max (slide:D), none else."""
    kind, _ = parse_state(state)
    return ("uplifts",) if kind == UPLIFT else (
        (THRESHOLD_VARIABLE[kind],) if kind in THRESHOLD_VARIABLE else ())


def required(ds: xr.Dataset, name: str, why: str) -> xr.DataArray:
    """ds[name], or a one-line FragilityError saying the Dataset lacks it and ``why`` it
    is needed."""
    if name not in ds.variables:
        raise FragilityError(f"the Dataset has no variable {name!r} ({why})")
    return ds[name]


def state_reached(ds: xr.Dataset, state: str) -> xr.DataArray:
    """bool DataArray (the outcome's dims): the point reaches ``state`` (``parse_state``)."""
    kind, x = parse_state(state)
    out = required(ds, "outcome", "outcome codes")
    over = (out == OUTCOME_MODE1) | (out == OUTCOME_MODE2)
    if kind == "overturn":
        return over
    if kind == "mode1":
        return out == OUTCOME_MODE1
    if kind == "mode2":
        return out == OUTCOME_MODE2
    if kind == "uplift":
        return (required(ds, "uplifts", f"state {state}") > 0) | over
    name = THRESHOLD_VARIABLE[kind]
    if kind == SLIDE and name not in ds.variables:
        raise FragilityError(
            f"state {state!r}: the Dataset has no variable {name!r} (the base's sliding "
            "displacement: a sweep of a scene with body.mu has it); without it the states "
            f"are {', '.join((*STATES, THETA_STATE))}")
    return (required(ds, name, f"state {state}") >= x) | over


def counted_points(ds: xr.Dataset) -> tuple[xr.DataArray, xr.DataArray, xr.DataArray]:
    """(counted, flagged, not_run) bool DataArrays: flagged = status &
    ``kernel.layout.STATUS_FLAGGED`` (horizon, step cap, event cap, non-finite: the one
    definition of a flagged point, as ``rocksweep.fields`` documents it), not_run = outcome
    -1 and not flagged; counted = neither."""
    out = required(ds, "outcome", "outcome codes")
    status = required(ds, "status", "status bit flags: flagged points are excluded")
    flagged = (status.astype(np.int64) & FLAGGED) != 0
    not_run = (out == OUTCOME_NOT_RUN) & ~flagged
    return ~flagged & ~not_run, flagged, not_run


def trust(ds: xr.Dataset, what: str, warn: bool = True, kept: bool = False) -> str:
    """The one verdict of every analysis on the points it reads: "ok", or why they cannot
    all be trusted, one clause each: "incomplete: N of M points not computed" (a file a
    sweep stopped writing or still writes: its ``complete`` attribute is 0) and "flagged:
    K of M points flagged by the kernel (airborne 3, horizon 1) left out" (each flag's
    word and count: ``vocab.outcomes.FLAGGED_WORDS``). Not-computed and flagged points are
    left out by ``counted_points``; this says so. ``kept``: the caller keeps every point
    (``table``: one row per run, the flag in ``status_words``), and says that instead. With
    ``warn``, an ``AnalysisWarning`` "<what>: <verdict>" too. A Dataset without
    outcome/status (not a sweep) is "ok"."""
    if "outcome" not in ds.variables or "status" not in ds.variables:
        return "ok"
    _, flagged, not_run = counted_points(ds)
    total = int(np.prod(ds["outcome"].shape))
    fate = ("kept (their status_words say why; the analyses leave them out)" if kept
            else "left out")
    words = []
    n = int(not_run.sum())
    if n:
        state = (" (the file is not complete: a sweep still running or stopped; a resume "
                 "finishes it)") if ds.attrs.get("complete") in (0, False) else ""
        words.append(f"incomplete: {n} of {total} points not computed, {fate}{state}")
    k = int(flagged.sum())
    if k:
        status = ds["status"].values.astype(np.int64)
        why = ", ".join(f"{w} {c}" for w in FLAGGED_WORDS
                        if (c := int(((status & STATUS_BIT[w]) != 0).sum())))
        words.append(f"flagged: {k} of {total} points flagged by the kernel ({why}), {fate}")
    verdict = "; ".join(words) or "ok"
    if warn and words:
        warnings.warn(f"{what}: {verdict}", AnalysisWarning, stacklevel=3)
    return verdict

