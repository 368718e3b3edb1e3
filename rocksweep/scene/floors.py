"""The scene keys of the excitation path: a record's second horizontal component and the
body's orientation (``ground.h2``, ``ground.angle``) and the building under the body
(``floor:``), parsed into a ``physics.path.GroundPath`` and the axes they sweep (docs/
floors.md). Called by ``scene.parse``; the section and axis forms are ``scene.sections``'."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from rocksweep.errors import SceneError
from rocksweep.physics.floor import Mode
from rocksweep.physics.path import GroundPath, check_pair
from rocksweep.physics.records import GroundRecord
from rocksweep.physics.suite import Suite
from rocksweep.scene.ground import ground_record
from rocksweep.scene.model import FLOOR_AXES
from rocksweep.scene.sections import axis_spec, axis_values, section
from rocksweep.schema import KEYS, as_float, check_values, fmt, is_number


def modes(spec: Any) -> tuple[Mode, ...]:
    """The building's modes of ``floor.modes`` (numbers, each checked as the one-mode
    form's keys)."""
    key = "floor.modes"
    if not (isinstance(spec, list) and spec):
        raise SceneError(f"{key} = {fmt(spec)}: {KEYS[key].allowed}")
    out = []
    for i, m in enumerate(spec):
        where = f"{key}[{i}]"
        if not isinstance(m, dict):
            raise SceneError(f"{where} = {fmt(m)}: {KEYS[key].allowed}")
        for k in m:
            if f"floor.{k}" not in FLOOR_AXES:
                raise SceneError(f"{where}.{k}: unknown key (allowed: period, damping, "
                                 "participation)")
        vals = []
        for k in FLOOR_AXES:
            short = k.split(".")[1]
            v = m.get(short)
            if v is None:
                raise SceneError(f"{where}.{short}: missing required key "
                                 f"({KEYS[k].allowed.removeprefix('must be ')})")
            x = as_float(v) if is_number(v) else math.nan
            if check_values(k, np.array([x])) is not None or (
                    k == "floor.participation" and x == 0.0):
                raise SceneError(f"{where}.{short} = {fmt(v)}: {KEYS[k].allowed}")
            vals.append(x)
        out.append(Mode(*vals))
    return tuple(out)


def excitation_path(raw: dict, ground: dict, kind: str, free: bool,
                     record: GroundRecord | None, suite: Suite | None, base: Path | None,
                     physical: dict | None, given_h2: GroundRecord | None = None
                     ) -> tuple[GroundPath | None, list[tuple[str, str, str, Any]],
                                tuple[str, ...]]:
    """A scene's excitation path (``physics.path``): the second horizontal component
    (``ground.h2``, or a suite's paired H2 files) with the ``angle`` axis, and the
    ``floor`` section's building (its one-mode keys as axes named ``floor.period``,
    ``floor.damping``, ``floor.participation``, or ``floor.modes``). Returns (the path,
    None without those keys; the axes' specs (name, key, form, spec); files read)."""
    specs: list[tuple[str, str, str, Any]] = []
    inputs: tuple[str, ...] = ()
    h2: tuple = ()
    if ground.get("h2") is not None:
        if suite is not None:
            raise SceneError("ground.h2: not with ground.records (a folder of PEER "
                             "downloads pairs each record's components by name)")
        second = ground_record(ground, base, "h2") if given_h2 is None else given_h2
        why = check_pair(record, second)
        if why is not None:
            raise SceneError(f"ground.h2: {second.name}: {why}")
        h2 = (second,)
        inputs = (str(second.source),) if given_h2 is None else ()
    elif suite is not None and any(r is not None for r in suite.h2):
        h2 = suite.h2
    if ground.get("angle") is not None and not h2:
        raise SceneError(f"ground.angle = {fmt(ground['angle'])}: needs the second "
                         "horizontal component (ground.h2, or a suite of PEER folders with "
                         "both horizontals)")
    if h2:
        specs.append(("angle", "ground.angle",
                      *axis_spec("ground.angle", ground.get("angle", 0.0))[:2]))
    building = None
    if raw.get("floor") is not None:
        if free:
            raise SceneError(f"floor = {fmt(raw['floor'])}: a free-rocking scene (no pulse "
                             "or ground section) has no ground motion for a building to "
                             "carry; give a pulse or a ground motion")
        sec = section(raw, "floor", kind, required=False)
        if sec.get("modes") is not None:
            for k in FLOOR_AXES:
                if sec.get(k.split(".")[1]) is not None:
                    raise SceneError(f"{k}: not with floor.modes (give one mode's keys or "
                                     "the list of modes)")
            building = modes(sec["modes"])
        else:
            for k in FLOOR_AXES:
                short = k.split(".")[1]
                if sec.get(short) is None:
                    raise SceneError(f"{k}: missing required key ({AXIS_HINT}; or give "
                                     "floor.modes)")
                form, spec, _ = axis_spec(k, sec[short])
                if k == "floor.participation" and np.any(axis_values(k, form, spec) == 0):
                    raise SceneError(f"{k} = 0.0: {KEYS[k].allowed}")
                specs.append((k, k, form, spec))
    if not h2 and raw.get("floor") is None:
        return None, specs, inputs
    p = float(physical["p"]) if physical is not None else 1.0
    return (GroundPath(h2=h2, modes=building, floor=raw.get("floor") is not None, p=p),
            specs, inputs)


AXIS_HINT = "a number, a list of numbers or a range {start, stop, num}"
