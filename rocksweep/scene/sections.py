"""The forms every scene section shares: a section's keys, an axis given as a number, a list
or a range ``{start, stop, num}``, and word axes (``pulse.shape``, ``impact.law``).

Used by ``scene.parse`` and the sections parsed beside it (``scene.ground``,
``scene.floors``); every refusal is one ``SceneError`` line naming the key and value.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from rocksweep.errors import SceneError
from rocksweep.schema import (
    BODY_KEYS,
    KEYS,
    as_float,
    check_values,
    fmt,
    is_number,
    section_keys,
)

# Values per axis: an axis is kept as a tuple of Python floats (~32 bytes a value; 1e6
# values are 32 MB and 0.1 s to build); a figure's axis needs a few thousand at most.
MAX_AXIS_VALUES = 1_000_000


def section(raw: dict, name: str, kind: str, required: bool) -> dict:
    """The mapping of a section, with its keys checked against the table."""
    sec = raw.get(name)
    if name == "body" and isinstance(sec, dict):
        kind = sec.get("kind", "flexible")
        if not (isinstance(kind, str) and kind in BODY_KEYS):
            raise SceneError(f"body.kind = {fmt(kind)}: {KEYS['body.kind'].allowed}")
    allowed = section_keys(name, kind)
    if sec is None and name in raw:  # ``pulse:`` or ``pulse: null`` is no absent section
        raise SceneError(f"{name} = null: must be a mapping with keys {', '.join(allowed)}, "
                         "or leave the section out")
    if sec is None:
        if required:
            needed = ", ".join(k for k in allowed if KEYS[f"{name}.{k}"].required)
            raise SceneError(f"{name}: missing required section ({name}: {{{needed}}})")
        return {}
    if not isinstance(sec, dict):
        if name == "body":
            what = (f"keys {', '.join(BODY_KEYS['flexible'])} (a flexible body), "
                    f"or kind: block, {', '.join(BODY_KEYS['block'])}")
        else:
            what = f"keys {', '.join(allowed)}"
        raise SceneError(f"{name} = {fmt(sec)}: must be a mapping with {what}")
    for k in sec:
        if k not in allowed:
            what = f" for a {kind} body" if name == "body" else ""
            raise SceneError(f"{name}.{k}: unknown key{what} (allowed: {', '.join(allowed)})")
    for k, v in sec.items():  # a number left empty is not its default
        if v is None and KEYS[f"{name}.{k}"].kind == "axis":
            raise SceneError(f"{name}.{k} = null: {KEYS[f'{name}.{k}'].allowed}, or leave "
                             "the key out")
    for k in allowed:
        spec = KEYS[f"{name}.{k}"]
        if spec.required and sec.get(k) is None:
            hint = {"axis": "a number, a list of numbers or a range {start, stop, num}",
                    "choices": spec.allowed.removeprefix("must be ")}.get(
                        spec.kind, spec.allowed.removeprefix("must be "))
            raise SceneError(f"{name}.{k}: missing required key ({hint})")
    return sec


def axis_spec(key: str, spec: Any) -> tuple[str, Any, int]:
    """Check an axis's form, without building its values: (form, spec, length)."""
    if is_number(spec):
        return "scalar", as_float(spec), 1
    if isinstance(spec, list):
        if not spec:
            raise SceneError(f"{key} = []: an empty list; give at least one value")
        for v in spec:
            if not is_number(v):
                raise SceneError(f"{key} = {fmt(v)}: each value must be a number")
        if len(spec) > MAX_AXIS_VALUES:
            raise SceneError(f"{key}: {len(spec):,} values; at most {MAX_AXIS_VALUES:,} "
                             "per axis")
        return "list", [as_float(v) for v in spec], len(spec)
    if isinstance(spec, dict):
        for k in spec:
            if k not in ("start", "stop", "num"):
                raise SceneError(f"{key}.{k}: unknown key in a range (allowed: start, stop, "
                                 "num)")
        for k in ("start", "stop", "num"):
            if k not in spec:
                raise SceneError(f"{key}.{k}: missing (a range is {{start, stop, num}}, "
                                 "num values from start to stop inclusive)")
        num = spec["num"]
        if not (isinstance(num, int) and not isinstance(num, bool) and num >= 1):
            raise SceneError(f"{key}.num = {fmt(num)}: must be an integer >= 1")
        if num > MAX_AXIS_VALUES:
            raise SceneError(f"{key}.num = {num}: at most {MAX_AXIS_VALUES:,} values per axis")
        for k in ("start", "stop"):
            v = spec[k]
            if not (is_number(v) and math.isfinite(as_float(v))):
                raise SceneError(f"{key}.{k} = {fmt(v)}: must be a finite number")
        return "range", {**spec, "start": float(spec["start"]), "stop": float(spec["stop"])}, num
    raise SceneError(f"{key} = {fmt(spec)}: must be a number, a list of numbers or a range "
                     "{start, stop, num}")


def axis_values(key: str, form: str, spec: Any) -> np.ndarray:
    """The values of a checked axis spec (float64[n]), each admissible and distinct."""
    if form == "range":
        values = np.linspace(float(spec["start"]), float(spec["stop"]), spec["num"])
    else:
        values = np.array(spec if form == "list" else [spec], dtype=float)
    msg = check_values(key, values)
    if msg is not None:
        raise SceneError(msg)
    if values.size > 1:
        ordered = np.sort(values)
        same = ordered[1:] == ordered[:-1]
        if same.any():
            dup = float(ordered[1:][same][0])
            if form == "range":
                why = ("start = stop" if spec["start"] == spec["stop"]
                       else "its step is below float64's resolution")
                raise SceneError(
                    f"{key} = {{start: {fmt(spec['start'])}, stop: {fmt(spec['stop'])}, "
                    f"num: {spec['num']}}}: {why}, so the value {fmt(dup)} repeats; the "
                    "values of an axis must differ (they label the result's coordinates)")
            raise SceneError(f"{key}: the value {fmt(dup)} is given twice; the values of an "
                             "axis must differ (they label the result's coordinates)")
    return values


def words(key: str, spec: Any) -> tuple[tuple[str, ...], bool]:
    """A word axis (``pulse.shape``, ``impact.law``): one of the key's choices or a list of
    them (a swept axis). Returns (values, swept)."""
    allowed = KEYS[key]
    words = ", ".join(allowed.choices)
    if isinstance(spec, list):
        if not spec:
            raise SceneError(f"{key} = []: an empty list; give one or more of {words}")
        for v in spec:
            if not (isinstance(v, str) and v in allowed.choices):
                raise SceneError(f"{key} = {fmt(v)}: {allowed.allowed}")
        if len(set(spec)) < len(spec):
            noun = key.split(".")[1]  # shape, law
            raise SceneError(f"{key} = {fmt(spec)}: a {noun} is given twice; the values "
                             "of an axis must differ")
        return tuple(spec), True
    if not (isinstance(spec, str) and spec in allowed.choices):
        raise SceneError(f"{key} = {fmt(spec)}: {allowed.allowed}")
    return (spec,), False


def choice(key: str, value: Any) -> str:
    """The word of a ``choice`` key (one word, not swept): the schema's default when not
    given (None), else one of its choices; a one-line SceneError otherwise. The choices and
    the default are the schema's alone (``KEYS[key]``)."""
    spec = KEYS[key]
    if value is None:
        return spec.default
    if not (isinstance(value, str) and value in spec.choices):
        raise SceneError(f"{key} = {fmt(value)}: {spec.allowed}")
    return value


def shape_words(spec: Any) -> tuple[tuple[str, ...], bool]:
    return words("pulse.shape", spec)


