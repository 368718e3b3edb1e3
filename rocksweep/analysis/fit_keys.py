"""What a calibration (``rocksweep.analysis.calibrate``) may fit: the keys of a scene a
fit may set (``fittable``: its numeric axes and the optional impact.e_factor and initial
state), a fit key checked against the scene (``check_fit_key``: impact.e only under law
constant, impact.lam never under it), its search bounds (``check_bounds``: given, inside
the key's admissible range, or ``DEFAULT_BOUNDS``) and the scene's one point the other
keys keep (``single_values``). Every refusal is a one-line CalibrationError."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from rocksweep.errors import BodyError, CalibrationError, set_key
from rocksweep.schema import KEYS, fmt
from rocksweep.vocab.axes import INITIAL, axis_name
from rocksweep.vocab.laws import CONSTANT, LAWS

# practical default bounds of a fitted key (inside the key's admissible range)
DEFAULT_BOUNDS = {"impact.lam": (0.0, 2.0), "impact.e": (0.02, 1.0),
                  "impact.e_factor": (0.2, 2.0), "body.zeta": (0.0, 0.5)}
# keys of a scene's point a fit may set although the scene does not give them
OPTIONAL_NAMES = ("e_factor", *INITIAL)


def fittable(scene: Any) -> list[str]:
    """The keys of a scene that a fit may set: its numeric axes (body, impact, pulse,
    ground, initial) and the optional impact.e_factor and initial state."""
    out = [a.key for a in scene.axes if KEYS.get(a.key) is not None
           and KEYS[a.key].kind == "axis" and a.key != "body.mu"]
    out += [f"impact.{n}" if n == "e_factor" else f"initial.{n}" for n in OPTIONAL_NAMES]
    values = {a.name: a.values[0] for a in scene.axes}
    try:
        rigid = scene.make_body(**{a.name: values[a.name] for a in scene.body_axes()}).rigid
    except (BodyError, ValueError):
        rigid = False
    return list(dict.fromkeys(
        k for k in out if not (scene.free and k.startswith("pulse."))
        # a rigid body has no top mass: its displacement and rate mean nothing
        and not (rigid and k in ("initial.u_over_ucr", "initial.udot_over_pucr"))))


def check_fit_key(scene: Any, key: Any) -> str:
    """The axis name a fit key sets, or a one-line CalibrationError."""
    if not isinstance(key, str):
        raise CalibrationError(f"fit key {key!r}: must be a dotted scene key such as "
                               "impact.lam")
    if key == "impact.e" and "e" not in {a.name for a in scene.axes}:
        raise CalibrationError("fit impact.e: only law constant uses e; give impact: "
                               "{law: constant, e: ...} in the scene (or fit impact.e_factor)")
    laws = {str(v) for a in scene.axes if a.name == "law" for v in a.values}
    if key == "impact.lam" and laws and laws <= {CONSTANT}:
        others = " or ".join(law for law in LAWS if law != CONSTANT)
        raise CalibrationError(f"fit impact.lam: law {CONSTANT} does not use lam (its e is "
                               "impact.e), so no lam changes a run; fit impact.e or "
                               f"impact.e_factor, or use law {others}")
    allowed = fittable(scene)
    if key not in allowed:
        raise CalibrationError(f"fit {key}: not a number of this scene (fit one of "
                               f"{', '.join(allowed)})")
    return axis_name(key)


def check_bounds(key: str, given: Any) -> tuple[float, float]:
    """(lo, hi) of a fit key: given, or DEFAULT_BOUNDS / the key's admissible range;
    a one-line CalibrationError outside the admissible range."""
    spec = KEYS[key]
    lo_ok = spec.lo + (0.0 if spec.lo_in else 1e-9 * max(1.0, abs(spec.lo)))
    hi_ok = spec.hi - (0.0 if spec.hi_in else 1e-9 * max(1.0, abs(spec.hi)))
    if given is None:
        lo, hi = DEFAULT_BOUNDS.get(key, (max(lo_ok, -10.0), min(hi_ok, 10.0)))
        return float(lo), float(hi)
    try:
        lo, hi = (float(v) for v in given)
    except (TypeError, ValueError):
        raise CalibrationError(f"bounds {key} = {fmt(given)}: give two numbers (lo, hi)"
                               ) from None
    allowed = spec.allowed.removeprefix("must be ")
    for v in (lo, hi):
        if not math.isfinite(v) or (v < spec.lo or (v == spec.lo and not spec.lo_in)
                                    or v > spec.hi or (v == spec.hi and not spec.hi_in)):
            raise CalibrationError(f"bounds {key} = ({fmt(lo)}, {fmt(hi)}): {fmt(v)} is "
                                   f"outside the key's admissible range ({allowed})")
    if not lo < hi:
        raise CalibrationError(f"bounds {key} = ({fmt(lo)}, {fmt(hi)}): lo must be below hi")
    return lo, hi


def single_values(scene: Any, fitted: Sequence[str]) -> dict[str, Any]:
    """The scene's one value of every axis; a swept axis that is not fitted is refused."""
    for a in scene.axes:
        if len(a.values) != 1 and a.name not in fitted:
            raise CalibrationError(f"{a.key} has {len(a.values)} values: a calibration "
                                   "fits one point; pick one with {fix}",
                                   fix=set_key(a.key, "set_fix"))
    return {a.name: a.values[0] for a in scene.axes}
