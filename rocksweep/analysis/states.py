"""Damage states of a record-suite sweep: their words (``state=``), how several are
fitted together, and which points of a result Dataset reach each one and are counted.

States (``rocksweep.vocab.outcomes``): "overturn" (outcome 1 or 2), "mode1", "mode2",
"uplift" (uplifts > 0 or overturned), "theta:X" (max|theta|/alpha_cg >= X or overturned,
0 < X <= 1). uplift < theta:X < overturn are nested (a point that reaches one reaches the
milder ones); the two modes are not.
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
    STATES,
    STATUS_BIT,
    THETA_STATE,
    UPLIFT,
)

STATE_WORDS = (*STATES, THETA_STATE)


def parse_state(state: str) -> tuple[str, float]:
    """("overturn" | "mode1" | "mode2" | "uplift" | "theta", threshold) of a state word;
    "theta:X" is max|theta|/alpha_cg >= X (0 < X <= 1) or overturned."""
    if not isinstance(state, str):
        raise FragilityError(f"state = {state!r}: a state is a string, one of "
                             f"{', '.join(STATE_WORDS)} (or a list of them)")
    s = state.strip()
    if s in STATES:
        return s, math.nan
    if s.startswith("theta:"):
        try:
            x = float(s[6:])
        except ValueError:
            x = math.nan
        if math.isfinite(x) and 0.0 < x <= 1.0:
            return "theta", x
        raise FragilityError(f"state {state!r}: theta:X needs a number 0 < X <= 1 "
                             "(max|theta|/alpha_cg)")
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
    """Order of the nested damage states: uplift (0) < theta:X (X) < overturn (inf); NaN
    for the modes (not nested)."""
    kind, x = parse_state(state)
    return {UPLIFT: 0.0, "theta": x, OVERTURN: math.inf}.get(kind, math.nan)


def state_groups(states: Sequence[str], joint: bool = False) -> list[tuple[str, list[int]]]:
    """How the states are fitted: [(kind, indices into states)]. By default every state
    alone ("single": a curve's numbers do not depend on the other states asked for); with
    ``joint`` "ordinal" for two or more nested damage states (uplift, theta:X, overturn;
    indices in severity order; one beta), "competing" for mode1 with mode2, "single" for
    every other one."""
    if not joint:
        return [("single", [i]) for i in range(len(states))]
    nested = sorted((i for i, s in enumerate(states) if not math.isnan(severity(s))),
                    key=lambda i: severity(states[i]))
    modes = [states.index(s) for s in (MODE1, MODE2) if s in states]
    groups: list[tuple[str, list[int]]] = []
    if len(nested) >= 2:
        groups.append(("ordinal", nested))
    else:
        groups += [("single", [i]) for i in nested]
    if len(modes) == 2:
        groups.append(("competing", modes))
    else:
        groups += [("single", [i]) for i in modes]
    return groups


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
    return (required(ds, "theta_max_over_alpha", f"state {state}") >= x) | over


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

