"""A scene: YAML -> validated study (body, impact, pulse, numerics, outputs).

Any Pi-group value may be a scalar, a list, or a range ``{start, stop, num}`` (inclusive,
like ``numpy.linspace``); ``pulse.shape`` may be a list. Lists and ranges are swept axes.
Every problem is a ``SceneError`` with one line naming the key, the value and what is
allowed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import product
from pathlib import Path
from typing import Any, Literal

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, ValidationError

from rocksweep.errors import RocksweepError
from rocksweep.model import BlockBody, Body, BodyError, FlexibleBody
from rocksweep.numerics import PRESETS, ROOTS, Numerics
from rocksweep.points import Point


class SceneError(RocksweepError, ValueError):
    """A scene that cannot be run; ``str()`` is one line for the user."""


# ---------------------------------------------------------------------------------------
# Schema (structure and types; pydantic). Values are checked per key below.
# ---------------------------------------------------------------------------------------

_STRICT = ConfigDict(extra="forbid", strict=True)


class RangeSpec(BaseModel):
    model_config = _STRICT
    start: float | int
    stop: float | int
    num: int


AxisSpec = float | int | list[float | int] | RangeSpec


class FlexibleSpec(BaseModel):
    model_config = _STRICT
    kind: Literal["flexible"] = "flexible"
    wn_over_p: AxisSpec
    zeta: AxisSpec
    alpha_cg: AxisSpec
    alpha_A: AxisSpec
    mA_over_m: AxisSpec
    IA_ratio: AxisSpec


class BlockSpec(BaseModel):
    model_config = _STRICT
    kind: Literal["block"]
    alpha: AxisSpec
    inertia: AxisSpec = 4.0 / 3.0


class ImpactSpec(BaseModel):
    model_config = _STRICT
    lam: AxisSpec


class PulseSpec(BaseModel):
    model_config = _STRICT
    shape: Literal["sine", "cosine"] | list[Literal["sine", "cosine"]]
    w_over_p: AxisSpec
    A_ratio: AxisSpec


class NumericsSpec(BaseModel):
    model_config = _STRICT
    accuracy: Literal["draft", "default", "fine"] | None = None
    steps_per_period: int | None = None
    event_tol: float | None = None
    horizon: float | int | None = None
    rest_rate: float | None = None
    max_events: int | None = None
    root: Literal[ROOTS] | None = None  # type: ignore[valid-type]


class OutputsSpec(BaseModel):
    model_config = _STRICT
    energy: bool = False  # sweeps: store energy metrics (runs the energy-accounting kernel)


class SceneSpec(BaseModel):
    model_config = _STRICT
    name: str | None = None
    body: FlexibleSpec | BlockSpec
    impact: ImpactSpec | None = None
    pulse: PulseSpec
    numerics: NumericsSpec = NumericsSpec()
    outputs: OutputsSpec = OutputsSpec()


# ---------------------------------------------------------------------------------------
# Per-key admissible values: (low, high, low inclusive, high inclusive, inf allowed, text)
# ---------------------------------------------------------------------------------------

_HALF_PI = math.pi / 2
_LIMITS: dict[str, tuple[float, float, bool, bool, bool, str]] = {
    "body.wn_over_p": (0, math.inf, False, True, True, "must be > 0 (.inf for a rigid body)"),
    "body.zeta": (0, math.inf, True, False, False, "must be >= 0"),
    "body.alpha_cg": (0, _HALF_PI, False, False, False, "must be in (0, pi/2) rad"),
    "body.alpha_A": (0, _HALF_PI, False, False, False, "must be in (0, pi/2) rad"),
    "body.mA_over_m": (0, math.inf, False, False, False, "must be > 0"),
    "body.IA_ratio": (0, math.inf, True, False, False, "must be >= 0"),
    "body.alpha": (0, _HALF_PI, False, False, False, "must be in (0, pi/2) rad"),
    "body.inertia": (1, math.inf, True, False, False, "must be >= 1 (I_O >= M R^2)"),
    "impact.lam": (0, 2, True, True, False, "must be in [0, 2]"),
    "pulse.w_over_p": (0, math.inf, False, False, False,
                       "must be > 0 and finite (the pulse lasts 2 pi/omega)"),
    "pulse.A_ratio": (-math.inf, math.inf, False, False, False,
                      "must be a finite number (negative: a pulse in the other direction)"),
}

BODY_KEYS = {"flexible": ("wn_over_p", "zeta", "alpha_cg", "alpha_A", "mA_over_m", "IA_ratio"),
             "block": ("alpha", "inertia")}
# Order of the grid's dimensions: shape, body keys, lam, A_ratio, w_over_p (x last).
PULSE_AXES = ("A_ratio", "w_over_p")


@dataclass(frozen=True)
class Axis:
    """One parameter of a scene: its name (the dimension name), values and whether swept."""

    name: str
    key: str  # dotted scene key, e.g. "pulse.A_ratio"
    values: tuple
    swept: bool


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else str(v)
    return repr(v)


def _axis_values(key: str, spec: Any) -> tuple[tuple, bool]:
    if isinstance(spec, RangeSpec):
        if spec.num < 1:
            raise SceneError(f"{key}.num = {spec.num}: must be an integer >= 1")
        for part in ("start", "stop"):
            v = float(getattr(spec, part))
            if not math.isfinite(v):
                raise SceneError(f"{key}.{part} = {_fmt(v)}: must be finite")
        values = tuple(float(x) for x in np.linspace(spec.start, spec.stop, spec.num))
        swept = True
    elif isinstance(spec, list):
        if not spec:
            raise SceneError(f"{key} = []: an empty list; give at least one value")
        values, swept = tuple(float(x) for x in spec), True
    else:
        values, swept = (float(spec),), False
    lo, hi, lo_in, hi_in, inf_ok, text = _LIMITS[key]
    for v in values:
        ok = not math.isnan(v)
        ok = ok and (v > lo or (lo_in and v == lo)) and (v < hi or (hi_in and v == hi))
        if ok and math.isinf(v) and not inf_ok:
            ok = False
        if not ok:
            raise SceneError(f"{key} = {_fmt(v)}: {text}")
    return values, swept


@dataclass(frozen=True)
class Scene:
    """A validated scene. ``axes`` in the grid's dimension order; ``text`` the YAML verbatim."""

    name: str
    kind: str  # "flexible" | "block"
    axes: tuple[Axis, ...]
    numerics: Numerics  # sweeps: the `default` preset unless the scene names one
    single_numerics: Numerics  # single runs (simulate): `fine` unless the scene names one
    energy: bool
    text: str = field(repr=False)

    def axis(self, name: str) -> Axis:
        for a in self.axes:
            if a.name == name:
                return a
        raise KeyError(name)

    @property
    def swept(self) -> tuple[Axis, ...]:
        return tuple(a for a in self.axes if a.swept)

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of the result arrays: one dimension per swept axis."""
        return tuple(len(a.values) for a in self.swept)

    @property
    def size(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64))

    def body_axes(self) -> tuple[Axis, ...]:
        return tuple(a for a in self.axes if a.key.startswith("body."))

    def make_body(self, **values: float) -> Body:
        """A body from values of the body keys (as in ``body_axes``)."""
        if self.kind == "block":
            return BlockBody(**values)
        return FlexibleBody(**values)

    def point(self, values: dict[str, Any]) -> Point:
        """The point with the given value of every axis (by name)."""
        body = self.make_body(**{a.name: values[a.name] for a in self.body_axes()})
        return Point(body, float(values["lam"]), str(values["shape"]),
                     float(values["w_over_p"]), float(values["A_ratio"]))

    def single_point(self) -> Point:
        """The scene's only point; a SceneError names the first swept key otherwise."""
        for a in self.axes:
            if len(a.values) != 1:
                raise SceneError(
                    f"{a.key} has {len(a.values)} values: this command runs one point; "
                    f"pick one with --set {a.key}=VALUE")
        return self.point({a.name: a.values[0] for a in self.axes})


def _format_validation_error(err: ValidationError) -> str:
    e = err.errors()[0]
    loc = [str(p) for p in e["loc"] if not str(p).startswith(("FlexibleSpec", "BlockSpec"))]
    # pydantic reports union members; keep the path of keys the user wrote
    loc = [p for p in loc if p not in ("RangeSpec", "float", "int", "list[union[float,int]]",
                                       "constrained-str", "str", "bool", "literal['sine','cosine']",
                                       "list[literal['sine','cosine']]",
                                       "function-after[model_validator()]")
           and not p.startswith(("list[", "literal[", "union[", "function-"))]
    key = ".".join(loc) if loc else "(top level)"
    kind = e["type"]
    if kind == "extra_forbidden":
        return f"{key}: unknown key"
    if kind == "missing":
        return f"{key}: missing required key"
    value = e.get("input")
    return f"{key} = {_fmt(value)}: {e['msg']}"


def _allowed_keys(model: type[BaseModel]) -> str:
    return ", ".join(model.model_fields)


def _check_unknown(raw: dict) -> None:
    """Unknown keys with the list of allowed ones (clearer than pydantic's union report)."""
    sections = {"body": None, "impact": ImpactSpec, "pulse": PulseSpec,
                "numerics": NumericsSpec, "outputs": OutputsSpec}
    for k in raw:
        if k not in (*sections, "name"):
            raise SceneError(f"{k}: unknown key (allowed: name, {', '.join(sections)})")
    body = raw.get("body")
    if isinstance(body, dict):
        kind = body.get("kind", "flexible")
        if kind not in BODY_KEYS:
            raise SceneError(f"body.kind = {kind!r}: must be one of flexible, block")
        allowed = ("kind", *BODY_KEYS[kind])
        for k in body:
            if k not in allowed:
                raise SceneError(f"body.{k}: unknown key for a {kind} body "
                                 f"(allowed: {', '.join(allowed)})")
    for name, model in sections.items():
        sec = raw.get(name)
        if model is not None and isinstance(sec, dict):
            for k in sec:
                if k not in model.model_fields:
                    raise SceneError(f"{name}.{k}: unknown key (allowed: {_allowed_keys(model)})")


def apply_overrides(raw: dict, overrides: list[str]) -> dict:
    """Apply ``--set section.key=VALUE`` overrides (VALUE parsed as YAML) to a raw scene."""
    for item in overrides:
        if "=" not in item:
            raise SceneError(f"--set {item!r}: expected KEY=VALUE, e.g. pulse.A_ratio=4.5")
        key, text = item.split("=", 1)
        parts = key.strip().split(".")
        try:
            value = yaml.safe_load(text)
        except yaml.YAMLError:
            raise SceneError(f"--set {key}: value {text!r} is not valid YAML") from None
        node = raw
        for p in parts[:-1]:
            node = node.setdefault(p, {})
            if not isinstance(node, dict):
                raise SceneError(f"--set {key}: {p} is not a section")
        node[parts[-1]] = value
    return raw


def parse_scene(text: str, source: str = "scene", overrides: list[str] | None = None) -> Scene:
    """Validate scene YAML text. Raises SceneError (one line, prefixed by ``source``)."""
    try:
        return _parse(text, overrides or [])
    except SceneError as err:
        raise SceneError(f"{source}: {err}") from None


def load_scene(path: str | Path, overrides: list[str] | None = None) -> Scene:
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as err:
        raise SceneError(f"{path}: cannot read the scene ({err.strerror})") from None
    except UnicodeDecodeError:
        raise SceneError(f"{path}: not a text (YAML) file") from None
    return parse_scene(text, str(path), overrides)


def _parse(text: str, overrides: list[str]) -> Scene:
    try:
        raw = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(err, "problem", None) or "invalid YAML"
        raise SceneError(f"YAML syntax error{where}: {problem}") from None
    if raw is None:
        raw = {}
    if not isinstance(raw, dict):
        raise SceneError("a scene is a YAML mapping with sections body, impact, pulse")
    raw = apply_overrides(raw, overrides)
    _check_unknown(raw)
    if isinstance(raw.get("body"), dict):
        raw["body"].setdefault("kind", "flexible")
    try:
        spec = SceneSpec.model_validate(raw)
    except ValidationError as err:
        raise SceneError(_format_validation_error(err)) from None

    kind = spec.body.kind
    axes: list[Axis] = []
    shapes = spec.pulse.shape if isinstance(spec.pulse.shape, list) else [spec.pulse.shape]
    if not shapes:
        raise SceneError("pulse.shape = []: an empty list; use sine, cosine or both")
    axes.append(Axis("shape", "pulse.shape", tuple(shapes), isinstance(spec.pulse.shape, list)))
    for k in BODY_KEYS[kind]:
        values, swept = _axis_values(f"body.{k}", getattr(spec.body, k))
        axes.append(Axis(k, f"body.{k}", values, swept))
    if spec.impact is None:
        if kind == "flexible":
            raise SceneError("impact: missing required section (impact: {lam: ...})")
        lam_axis = Axis("lam", "impact.lam", (0.0,), False)  # Housner's impulse at the corner
    else:
        values, swept = _axis_values("impact.lam", spec.impact.lam)
        lam_axis = Axis("lam", "impact.lam", values, swept)
    axes.append(lam_axis)
    for k in PULSE_AXES:
        values, swept = _axis_values(f"pulse.{k}", getattr(spec.pulse, k))
        axes.append(Axis(k, f"pulse.{k}", values, swept))

    # every body of the grid must be physical (e.g. the top mass above the base)
    body_axes = [a for a in axes if a.key.startswith("body.")]
    for combo in product(*(a.values for a in body_axes)):
        try:
            (BlockBody if kind == "block" else FlexibleBody)(
                **{a.name: v for a, v in zip(body_axes, combo, strict=True)})
        except BodyError as err:
            raise SceneError(str(err)) from None

    n = spec.numerics
    overrides_n = {k: v for k, v in n.model_dump().items()
                   if k != "accuracy" and v is not None}
    checks = {"steps_per_period": (lambda v: v >= 4, "must be an integer >= 4"),
              "event_tol": (lambda v: 0 < v < 1, "must be in (0, 1) (p*t)"),
              "horizon": (lambda v: 0 < v < math.inf, "must be > 0 and finite (p*t)"),
              "rest_rate": (lambda v: 0 < v < 1, "must be in (0, 1) (x p alpha_cg)"),
              "max_events": (lambda v: v >= 1, "must be an integer >= 1")}
    for k, v in overrides_n.items():
        if k in checks and not (isinstance(v, int | float) and v == v and checks[k][0](v)):
            raise SceneError(f"numerics.{k} = {_fmt(v)}: {checks[k][1]}")
    if "horizon" in overrides_n:
        overrides_n["horizon"] = float(overrides_n["horizon"])
    assert n.accuracy is None or n.accuracy in PRESETS
    numerics = Numerics.preset(n.accuracy or "default", **overrides_n)
    # A single run exists for its time history and energy balance, which the outcome-tuned
    # `default` (5 steps per period) resolves only roughly; it costs milliseconds at `fine`.
    single_numerics = Numerics.preset(n.accuracy or "fine", **overrides_n)

    name = spec.name or "rocksweep scene"
    return Scene(name=name, kind=kind, axes=tuple(axes), numerics=numerics,
                 single_numerics=single_numerics, energy=spec.outputs.energy, text=text)
