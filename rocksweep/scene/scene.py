"""A scene: YAML -> validated study (body, impact, pulse, numerics, outputs).

Any Pi-group value may be a scalar, a list, or a range ``{start, stop, num}`` (inclusive,
like ``numpy.linspace``); ``pulse.shape`` may be a list. Lists and ranges are swept axes.
Every problem is a ``SceneError`` with one line naming the key, the value and what is
allowed; the keys, their types, ranges and messages are one table, ``rocksweep.schema``.

Every valid scene runs in bounded time and space:

- YAML: numbers follow YAML 1.2 (``1e-6`` is a number), a key given twice in a mapping is
  refused, nesting is limited to MAX_DEPTH levels;
- at most MAX_AXIS_VALUES values per axis and MAX_POINTS points per grid;
- every point's cap on RK4 evaluations (the kernel's PAR_MAXSTEPS, ``points.run_cost``)
  is at most ``numerics.MAX_POINT_STEPS``, at the sweep's and at the single runs' accuracy.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from glob import glob, has_magic
from itertools import product
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from rocksweep.errors import RocksweepError
from rocksweep.numerics import (
    EVENT_STEP_ALLOWANCE,
    MAX_POINT_STEPS,
    PRESETS,
    Numerics,
)
from rocksweep.outputs import input_problem, shown
from rocksweep.physics.model import BlockBody, Body, BodyError, FlexibleBody
from rocksweep.physics.points import RECORD, Point, body_omega_rock, record_cost, run_cost
from rocksweep.physics.records import GroundRecord, RecordError, read_record
from rocksweep.physics.suite import DEFAULT_PERIODS, SCALE_IMS, Suite, SuiteError, make_suite
from rocksweep.schema import (
    BODY_KEYS,
    KEYS,
    SECTIONS,
    as_float,
    check_values,
    fmt,
    is_number,
    section_keys,
)


class SceneError(RocksweepError, ValueError):
    """A scene that cannot be run; ``str()`` is one line for the user."""


# Largest grid a scene may describe [points]. A sweep file stores 45 bytes a point (69
# with energy metrics, ``rocksweep.fields.variables``): 2e8 points are a 9-14 GB file, one
# float64 variable read back for a figure or xarray is 1.6 GB of memory, and at tens of
# microseconds a point (docs/performance.md) the sweep takes hours of one core.
MAX_POINTS = 200_000_000
# Values per axis: an axis is kept as a tuple of Python floats (~32 bytes a value; 1e6
# values are 32 MB and 0.1 s to build); a figure's axis needs a few thousand at most.
MAX_AXIS_VALUES = 1_000_000
# Nesting of the scene's YAML (a scene needs 3 levels: section, key, range or list).
# PyYAML composes nodes recursively; 3000 levels would end in a RecursionError.
MAX_DEPTH = 20
# Expanded size of a scene's YAML [characters of scalars + nodes], aliases counted at each
# use, beyond the text's own length: an alias bomb (9 levels of 9 aliases in 640 bytes)
# expands to ~4e8 nodes and took 4 GB and 35 s to build; it is refused before it is built.
MAX_EXPANDED = 4_000_000
# Body grids up to this many distinct bodies are checked body by body; larger ones at the
# combinations of each key's extreme values (``_candidate_bodies``).
MAX_BODIES_CHECKED = 1024
PULSE_AXES = ("A_ratio", "w_over_p")
# The pulse shapes each optional pulse key means something for (rocksweep.physics.excitation);
# given for none of the scene's shapes, the key is refused (it would be silently ignored).
PULSE_KEY_SHAPES = {"cycles": ("sine", "cosine"), "gamma": ("mp",), "nu": ("mp",)}
# Typical values (Table 3; the `default` numerics) that the cost check puts in place of a
# value, one at a time, to find which value makes a point too costly.
_TAME = {"body.wn_over_p": 2.43, "body.zeta": 0.05, "body.alpha_cg": 0.15,
         "body.alpha_A": 0.28, "body.mA_over_m": 0.47, "body.IA_ratio": 0.56,
         "body.alpha": 0.2618, "body.inertia": 4.0 / 3.0,
         "pulse.w_over_p": 1.0, "pulse.A_ratio": 1.0,
         "numerics.steps_per_period": PRESETS["default"][0], "numerics.horizon": 200.0,
         "numerics.max_events": Numerics().max_events}


# ---------------------------------------------------------------------------------------
# YAML
# ---------------------------------------------------------------------------------------

class _YamlError(Exception):
    """A YAML text the scene refuses; ``str()`` says where (1-based line) and why."""


class SceneLoader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 numbers, no duplicate keys and a depth limit.

    PyYAML follows YAML 1.1, where a float needs a dot and a signed exponent: ``1e-6`` and
    ``1E+3`` would be strings. The resolver added below reads them as numbers (YAML 1.2's
    core schema).
    """

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0
        self._limit = max(MAX_EXPANDED, 2 * len(stream))

    def get_single_data(self) -> Any:
        node = self.get_single_node()
        if node is None:
            return None
        self._check_expanded(node)
        return self.construct_document(node)

    def _check_expanded(self, root: yaml.Node) -> None:
        """Refuse a document whose expansion (aliases repeated at every use) exceeds the
        limit, counting on the composed graph (each node once, memoised): nothing of the
        expansion is built."""
        sizes: dict[int, int] = {}
        active: set[int] = set()

        def size(node: yaml.Node) -> int:
            key = id(node)
            if key in sizes:
                return sizes[key]
            if key in active:
                raise _YamlError(f"error at line {node.start_mark.line + 1}: an alias "
                                 "refers to a node that contains it (a recursive structure)")
            active.add(key)
            if isinstance(node, yaml.ScalarNode):
                n = 1 + len(node.value)
            elif isinstance(node, yaml.SequenceNode):
                n = 1 + sum(size(x) for x in node.value)
            else:
                n = 1 + sum(size(k) + size(v) for k, v in node.value)
            active.discard(key)
            if n > self._limit:
                raise _YamlError(f"expands to more than {self._limit:,} characters (aliases "
                                 "repeated at every use, e.g. an alias bomb); write the "
                                 "values out or use fewer aliases")
            sizes[key] = n
            return n

        size(root)

    def compose_node(self, parent: Any, index: Any) -> Any:
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise _YamlError(f"error at line {mark.line + 1}: nested more than "
                                 f"{MAX_DEPTH} levels deep")
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict:
        seen: set = set()
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue
            key = self.construct_object(key_node, deep=True)
            try:
                dup = key in seen
                seen.add(key)
            except TypeError:  # an unhashable key: PyYAML reports it below
                continue
            if dup:
                raise _YamlError(f"error at line {key_node.start_mark.line + 1}: key "
                                 f"{fmt(key)} given twice in one mapping")
        return super().construct_mapping(node, deep=deep)


SceneLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
    list("-+0123456789."))


_NOT_YAML = re.compile(  # PyYAML's reader refuses these (yaml.reader.Reader.NON_PRINTABLE)
    r"[^\x09\x0a\x0d\x20-\x7e\x85\xa0-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")  # C0 controls but tab and newline


def _control_character(text: str) -> str | None:
    """Where ``text`` holds a character YAML refuses to read (NUL, BEL, ESC, other C0/C1
    controls but tab and newlines): 'character 0x07 at line 2, column 7', or None."""
    m = _NOT_YAML.search(text)
    if m is None:
        return None
    line = text.count("\n", 0, m.start()) + 1
    column = m.start() - (text.rfind("\n", 0, m.start()) + 1) + 1
    return f"character {ord(m.group()):#04x} at line {line}, column {column}"


def _load_yaml(text: str) -> Any:
    """Parse YAML text with ``SceneLoader``; problems raise ``_YamlError``."""
    bad = _control_character(text)
    if bad is not None:
        raise _YamlError(f"error: {bad} is a control character (NUL, BEL, ESC...); a "
                         "scene is plain text")
    loader = SceneLoader(text)
    try:
        return loader.get_single_data()
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        problem = getattr(err, "problem", None) or "invalid YAML"
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise _YamlError(f"syntax error{where}: {problem}") from None
    except RecursionError:
        raise _YamlError("error: nested too deeply") from None
    finally:
        loader.dispose()


# ---------------------------------------------------------------------------------------
# Scene
# ---------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Axis:
    """One parameter of a scene: its name (the dimension name), values and whether swept."""

    name: str
    key: str  # dotted scene key, e.g. "pulse.A_ratio"
    values: tuple
    swept: bool


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
    contact: bool = False  # outputs.contact (on when body.mu is given)
    check: bool = False  # outputs.check: per-point error estimates (a half-step rerun)
    # the `refine` section (adaptive sweep settings, rocksweep.compute.adaptive.Options keywords),
    # None without one
    refine: dict | None = None
    # a record scene (``ground`` section): the record read at load (else None); the grid's
    # frequency axis is then p [rad/s], not w_over_p
    record: GroundRecord | None = field(default=None, repr=False)
    # a suite scene (``ground.records``): the records, their IMs and the scaling (the
    # grid's axes then hold ``record`` (file names), the stripe IM if scaled, and p)
    suite: Suite | None = field(default=None, repr=False)

    @property
    def freq_axis(self) -> str:
        """The name of the axis that sets the ground motion's time scale: ``w_over_p``
        (a pulse) or ``p`` (a record or a suite, [rad/s])."""
        return "p" if self.recorded else "w_over_p"

    @property
    def recorded(self) -> bool:
        """Whether the ground motion is recorded (``ground.record`` or ``ground.records``)."""
        return self.record is not None or self.suite is not None

    @property
    def ground(self) -> bool:
        """Whether the scene needs the kernel's GROUND variants (a Ricker or MP pulse, or a
        record); the paper's sine and cosine (n cycles too) run the pulse variants."""
        return self.recorded or any(
            sh in ("ricker", "mp") for sh in self.axis("shape").values)

    def option(self, name: str) -> Any:
        """A pulse option's value (cycles, gamma, nu [deg]): the scene's or the default."""
        for a in self.axes:
            if a.name == name:
                return a.values[0]
        return KEYS[f"pulse.{name}"].default

    def phase_max(self) -> float:
        """The longest pulse of the scene's shapes in w t (2 pi n, 6 pi, 2 pi gamma)."""
        from rocksweep.physics.points import RECORD, phase_duration

        return max(phase_duration(sh, self.option("cycles"), self.option("gamma"))
                   for sh in self.axis("shape").values if sh != RECORD)

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
        """Number of points of the grid (<= MAX_POINTS)."""
        return math.prod(self.shape)

    def body_axes(self) -> tuple[Axis, ...]:
        """The axes that make the body (body.mu is the ground's, not the body's)."""
        return tuple(a for a in self.axes if a.key.startswith("body.") and a.key != "body.mu")

    def make_body(self, **values: float) -> Body:
        """A body from values of the body keys (as in ``body_axes``)."""
        if self.kind == "block":
            return BlockBody(**values)
        return FlexibleBody(**values)

    def point(self, values: dict[str, Any]) -> Point:
        """The point with the given value of every axis (by name)."""
        body = self.make_body(**{a.name: values[a.name] for a in self.body_axes()})
        if self.suite is not None:
            su = self.suite
            r = su.names.index(str(values["record"]))
            s = (np.array([self.axis(su.im).values.index(float(values[su.im]))])
                 if su.im else None)
            p = float(values["p"])
            a_ratio = float(su.peak_ratio(np.array([r]), s, np.array([body.alpha_ref]),
                                          np.array([p]))[0])
            return Point(body, float(values["lam"]), RECORD, math.nan, a_ratio,
                         record=su.records[r], p=p, **self._law(values))
        if self.record is not None:
            return Point(body, float(values["lam"]), RECORD, math.nan,
                         float(values["A_ratio"]), record=self.record, p=float(values["p"]),
                         **self._law(values))
        return Point(body, float(values["lam"]), str(values["shape"]),
                     float(values["w_over_p"]), float(values["A_ratio"]),
                     int(values.get("cycles", self.option("cycles"))),
                     float(values.get("gamma", self.option("gamma"))),
                     float(values.get("nu", self.option("nu"))),
                     mu=float(values.get("mu", math.nan)), **self._law(values))

    def _law(self, values: dict[str, Any]) -> dict[str, Any]:
        """A point's impact law (Point keywords law, e, e_factor) from axis values."""
        law = str(values.get("law", "vertical"))
        return {"law": law, "e": float(values["e"]) if law == "constant" else math.nan,
                "e_factor": float(values.get("e_factor", 1.0))}

    def single_point(self) -> Point:
        """The scene's only point; a SceneError names the first swept key otherwise."""
        for a in self.axes:
            if len(a.values) != 1:
                raise SceneError(
                    f"{a.key} has {len(a.values)} values: this command runs one point; "
                    f"pick one with --set {a.key}=VALUE")
        return self.point({a.name: a.values[0] for a in self.axes})


def apply_overrides(raw: dict, overrides: list[str]) -> dict:
    """Apply ``--set section.key=VALUE`` overrides (VALUE parsed as YAML) to a raw scene."""
    for item in overrides:
        if "=" not in item:
            raise SceneError(f"--set {item!r}: expected KEY=VALUE, e.g. pulse.A_ratio=4.5")
        key, text = item.split("=", 1)
        key = key.strip()
        parts = key.split(".")
        if not all(parts):
            raise SceneError(f"--set {item!r}: expected KEY=VALUE, e.g. pulse.A_ratio=4.5")
        try:
            value = _load_yaml(text)
        except _YamlError as err:
            raise SceneError(f"--set {key}: value {fmt(text)} is not valid YAML "
                             f"({err})") from None
        node = raw
        for p in parts[:-1]:
            if node.get(p) is None:
                node[p] = {}
            node = node[p]
            if not isinstance(node, dict):
                raise SceneError(f"--set {key}: {p} is not a section")
        node[parts[-1]] = value
    return raw


def parse_scene(text: str, source: str = "scene", overrides: list[str] | None = None,
                base: str | Path | None = None, record: GroundRecord | None = None) -> Scene:
    """Validate scene YAML text. Raises SceneError (one line, prefixed by ``source``).

    base: the directory a ``ground.record`` path is relative to (the scene file's; None:
    the working directory); record: the record of a ``ground`` section, already read (a
    result file's stored copy): the ``ground.record`` path is then not read."""
    try:
        return _parse(text, overrides or [], Path(base) if base is not None else None,
                      record)
    except SceneError as err:
        raise SceneError(f"{source}: {err}") from None


def load_scene(path: str | Path, overrides: list[str] | None = None) -> Scene:
    """The validated scene of a YAML file (a regular file: a FIFO, device or directory is
    refused before it is opened, never waited on)."""
    path = Path(path)
    problem = input_problem(path)
    if problem is not None:
        raise SceneError(f"{shown(path)}: {problem}" if problem != "no such file"
                         else f"{shown(path)}: no such scene file")
    try:
        text = path.read_text()
    except OSError as err:
        raise SceneError(f"{path}: cannot read the scene ({err.strerror})") from None
    except UnicodeDecodeError:
        raise SceneError(f"{path}: not a text (YAML) file") from None
    return parse_scene(text, str(path), overrides, base=path.parent)


# -- structure ---------------------------------------------------------------------------

def _section(raw: dict, name: str, kind: str, required: bool) -> dict:
    """The mapping of a section, with its keys checked against the table."""
    sec = raw.get(name)
    if name == "body" and isinstance(sec, dict):
        kind = sec.get("kind", "flexible")
        if not (isinstance(kind, str) and kind in BODY_KEYS):
            raise SceneError(f"body.kind = {fmt(kind)}: {KEYS['body.kind'].allowed}")
    allowed = section_keys(name, kind)
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
    for k in allowed:
        spec = KEYS[f"{name}.{k}"]
        if spec.required and sec.get(k) is None:
            hint = {"axis": "a number, a list of numbers or a range {start, stop, num}",
                    "choices": spec.allowed.removeprefix("must be ")}.get(spec.kind, "")
            raise SceneError(f"{name}.{k}: missing required key ({hint})")
    return sec


def _axis_spec(key: str, spec: Any) -> tuple[str, Any, int]:
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


def _axis_values(key: str, form: str, spec: Any) -> np.ndarray:
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


def _words(key: str, spec: Any) -> tuple[tuple[str, ...], bool]:
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


def _shapes(spec: Any) -> tuple[tuple[str, ...], bool]:
    return _words("pulse.shape", spec)


def _impact_law(impact: dict) -> tuple[Axis | None, list[tuple[str, str, Any]]]:
    """The impact law's axes: the law (a word axis; None when the scene does not name
    one: eq. 1, ``vertical``) and the specs of ``impact.e`` and ``impact.e_factor`` given.
    ``e`` is required by law ``constant`` and refused without it."""
    law_axis = None
    laws: tuple[str, ...] = ("vertical",)
    if impact.get("law") is not None:
        laws, swept = _words("impact.law", impact["law"])
        law_axis = Axis("law", "impact.law", laws, swept)
    specs = []
    e_spec = impact.get("e")
    if e_spec is None and "constant" in laws:
        raise SceneError("impact.e: missing; law constant needs its coefficient of "
                         "restitution e: a number in (0, 1], a list or a range")
    if e_spec is not None:
        if "constant" not in laws:
            raise SceneError(f"impact.e = {fmt(e_spec)}: only law constant uses e (the law "
                             f"here is {', '.join(laws)}); remove impact.e or add law: "
                             "constant")
        specs.append(("e", "impact.e", *_axis_spec("impact.e", e_spec)[:2]))
    if impact.get("e_factor") is not None:
        specs.append(("e_factor", "impact.e_factor",
                      *_axis_spec("impact.e_factor", impact["e_factor"])[:2]))
    return law_axis, specs


def _refine(raw: dict, kind: str) -> dict | None:
    """The checked ``refine`` section as ``rocksweep.compute.adaptive.Options`` keywords,
    or None."""
    if raw.get("refine") is None:
        return None
    sec = _section(raw, "refine", kind, required=False)
    out: dict[str, Any] = {}
    for k, v in sec.items():
        key = f"refine.{k}"
        spec = KEYS[key]
        if k == "axes":
            if not (isinstance(v, list) and len(v) == 2
                    and all(isinstance(a, str) for a in v) and v[0] != v[1]):
                raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
            out[k] = (v[0].split(".")[-1], v[1].split(".")[-1])
            continue
        if spec.kind == "integer" and not (isinstance(v, int) and not isinstance(v, bool)):
            raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
        if not is_number(v) or check_values(key, np.array([as_float(v)])) is not None:
            raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
        out[k] = int(v) if spec.kind == "integer" else float(v)
    return out


def _numerics(sec: dict, contact: bool = False) -> tuple[Numerics, Numerics]:
    """The sweeps' and the single runs' numerics of a checked ``numerics`` section.

    Without a preset named, sweeps run `default`, but a sweep that stores the contact
    demands runs `fine`: at `default` the demands of long-rocking points differ from the
    reference by up to ~20% (the trajectory after many impacts), at 20 steps per period by
    5e-4 (scripts/contact_check.py)."""
    given: dict[str, Any] = {}
    for k, v in sec.items():
        if v is None:
            continue
        key = f"numerics.{k}"
        spec = KEYS[key]
        if spec.kind == "choice":
            if not (isinstance(v, str) and v in spec.choices):
                raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
        elif spec.kind == "integer":
            if not (isinstance(v, int) and not isinstance(v, bool)):
                raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
        elif not is_number(v):
            raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
        if spec.kind in ("integer", "number"):
            msg = check_values(key, np.array([as_float(v)]))
            if msg is not None:
                raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
            v = float(v) if spec.kind == "number" else v
        given[k] = v
    accuracy = given.pop("accuracy", None)
    numerics = Numerics.preset(accuracy or ("fine" if contact else "default"), **given)
    # A single run exists for its time history and energy balance, which the outcome-tuned
    # `default` (5 steps per period) resolves only roughly; it costs milliseconds at `fine`.
    single = Numerics.preset(accuracy or "fine", **given)
    return numerics, single


def _pulse_options(pulse: dict, shapes: tuple[str, ...]) -> list[Axis]:
    """The pulse's optional keys as unswept axes: those the scene gives, and gamma and nu
    when a shape is mp (so the file records the values used). Each a single value."""
    out = []
    for k in ("cycles", "gamma", "nu"):
        key = f"pulse.{k}"
        spec = KEYS[key]
        v = pulse.get(k)
        given = v is not None
        if v is None:
            if not (k != "cycles" and "mp" in shapes):
                continue
            v = spec.default
        ok = (isinstance(v, int) and not isinstance(v, bool)) if spec.kind == "integer" \
            else is_number(v)
        if not ok or check_values(key, np.array([as_float(v)])) is not None:
            raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
        if given:
            applies = PULSE_KEY_SHAPES[k]
            if not set(applies) & set(shapes):
                which = (f"the scene's shapes are {', '.join(shapes)}" if len(shapes) > 1
                         else f"the scene's shape is {shapes[0]}")
                raise SceneError(f"{key} = {fmt(v)}: applies to {' and '.join(applies)} pulses "
                                 f"only ({which}); remove it or sweep one of those shapes")
        out.append(Axis(k, key, (int(v) if spec.kind == "integer" else float(v),), False))
    return out


def _record(ground: dict, base: Path | None) -> GroundRecord:
    """The record of a ``ground`` section, read (and hashed) now."""
    spec = KEYS["ground.record"]
    v = ground["record"]
    if not (isinstance(v, str) and v.strip()):
        raise SceneError(f"ground.record = {fmt(v)}: {spec.allowed}")
    path = _where(v, base)
    try:
        return read_record(path)
    except RecordError as err:
        raise SceneError(f"ground.record: {err}") from None


def _where(v: str, base: Path | None) -> Path:
    """A path of the scene, relative to ``base`` (the scene file's directory), absolute:
    the file records where it read a record (spectra re-read it)."""
    path = Path(v).expanduser()
    if not path.is_absolute() and base is not None:
        path = base / path
    return path.absolute()


# Most records a suite may hold (a scene's axis holds at most MAX_AXIS_VALUES values;
# FEMA P695's sets are 44 and 28 records).
MAX_RECORDS = 10_000
_LIST_SUFFIXES = (".txt", ".list", ".lst")


def _is_listing(path: Path) -> bool:
    """A text file listing record paths (suffix .txt, .list or .lst, and its first line
    that is not blank or a # comment is not made of numbers: a two-column record's is)."""
    if path.suffix.lower() not in _LIST_SUFFIXES or not path.is_file():
        return False
    try:
        with path.open("r", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                text = line.strip()
                if not text or text.startswith("#"):
                    continue
                try:
                    [float(t) for t in text.replace(",", " ").split()]
                except ValueError:
                    return True
                return False
    except OSError:
        return False
    return True


def _record_paths(spec: Any, base: Path | None) -> list[Path]:
    """The files of ``ground.records`` in order: each entry a path, a glob (sorted) or a
    listing (one path a line, relative to the listing's directory; # comments)."""
    key = "ground.records"
    entries = spec if isinstance(spec, list) else [spec]
    if isinstance(spec, list) and not spec:
        raise SceneError(f"{key} = []: an empty list; {KEYS[key].allowed}")
    out: list[Path] = []
    for e in entries:
        if not (isinstance(e, str) and e.strip()):
            raise SceneError(f"{key} = {fmt(e)}: {KEYS[key].allowed}")
        if has_magic(e):
            pattern = str(_where(e, base))
            found = sorted(Path(p) for p in glob(pattern) if Path(p).is_file())
            if not found:
                raise SceneError(f"{key}: {e!r} matches no file (looked for {pattern})")
            out.extend(found)
            continue
        path = _where(e, base)
        if _is_listing(path):
            lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
            listed = [ln.strip() for ln in lines if ln.strip() and not
                      ln.strip().startswith("#")]
            if not listed:
                raise SceneError(f"{key}: {e} lists no record file")
            out.extend(_where(ln, path.parent) for ln in listed)
        else:
            out.append(path)
        if len(out) > MAX_RECORDS:
            break
    if len(out) > MAX_RECORDS:
        raise SceneError(f"{key}: more than {MAX_RECORDS:,} records; split the suite")
    seen: dict[str, Path] = {}
    for path in out:
        real = str(path.resolve())
        if real in seen:
            raise SceneError(f"{key}: {path} is listed twice (each record once: the file "
                             "names label the record dimension)")
        seen[real] = path
    names: dict[str, Path] = {}
    for path in out:
        if path.name in names:
            raise SceneError(f"{key}: two records named {path.name} ({names[path.name]} and "
                             f"{path}): the file names label the record dimension, rename "
                             "one")
        names[path.name] = path
    return out


def _periods(ground: dict) -> list[float]:
    key = "ground.periods"
    spec = ground.get("periods", list(DEFAULT_PERIODS))
    values = spec if isinstance(spec, list) else [spec]
    if not values or not all(is_number(v) for v in values):
        raise SceneError(f"{key} = {fmt(spec)}: {KEYS[key].allowed}")
    out = [as_float(v) for v in values]
    for v in out:
        if not (0.0 <= v <= 100.0):
            raise SceneError(f"{key} = {fmt(v)}: {KEYS[key].allowed}")
    if len(set(out)) != len(out):
        raise SceneError(f"{key} = {fmt(spec)}: a period is given twice")
    return out


def _scale(ground: dict) -> tuple[str | None, str, Any, float, float]:
    """(im or None, form, values spec, period [s] or NaN, cloud factor or NaN) of
    ``ground.scale``."""
    key = "ground.scale"
    v = ground.get("scale", "none")
    if v is None or v == "none":
        return None, "", None, math.nan, 1.0
    if not isinstance(v, dict):
        raise SceneError(f"{key} = {fmt(v)}: {KEYS[key].allowed}")
    if "factor" in v:
        extra = sorted(set(v) - {"factor"})
        if extra:
            raise SceneError(f"{key}.{extra[0]}: not with factor ({KEYS[key].allowed})")
        f = v["factor"]
        if not is_number(f) or check_values(f"{key}.factor", np.array([as_float(f)])):
            raise SceneError(f"{key}.factor = {fmt(f)}: {KEYS[key + '.factor'].allowed}")
        return None, "", None, math.nan, as_float(f)
    for k in v:
        if k not in ("im", "values", "period"):
            raise SceneError(f"{key}.{k}: unknown key (allowed: im, values, period; or "
                             "factor alone)")
    im = v.get("im")
    if im not in SCALE_IMS:
        raise SceneError(f"{key}.im = {fmt(im)}: {KEYS[key + '.im'].allowed}")
    if v.get("values") is None:
        raise SceneError(f"{key}.values: missing required key (the stripes' {im} values: "
                         "a number, a list of numbers or a range {start, stop, num})")
    form, spec, _ = _axis_spec(f"{key}.values", v["values"])
    period = math.nan
    if im == "Sa":
        T = v.get("period")
        if T is None:
            raise SceneError(f"{key}.period: missing required key (Sa's period [s])")
        if not is_number(T) or check_values(f"{key}.period", np.array([as_float(T)])):
            raise SceneError(f"{key}.period = {fmt(T)}: {KEYS[key + '.period'].allowed}")
        period = as_float(T)
    elif v.get("period") is not None:
        raise SceneError(f"{key}.period = {fmt(v['period'])}: only with im: Sa")
    return im, form, spec, period, math.nan


def _suite(ground: dict, base: Path | None) -> tuple[Suite, tuple[str, str, Any] | None]:
    """The suite of a ``ground.records`` section (records read and hashed, IMs computed
    now) and the stripe axis's (name, form, spec), None for a cloud."""
    for k in ("record", "A_ratio"):
        if ground.get(k) is not None:
            other = ("ground.scale: {im: PGA_ratio, values: ...}" if k == "A_ratio"
                     else "a list in ground.records")
            raise SceneError(f"ground.{k}: not with ground.records (use {other})")
    paths = _record_paths(ground["records"], base)
    im, form, spec, period, factor = _scale(ground)
    records = []
    for path in paths:
        try:
            records.append(read_record(path))
        except RecordError as err:
            raise SceneError(f"ground.records: {err}") from None
    values = _axis_values("ground.scale.values", form, spec).tolist() if im else []
    try:
        suite = make_suite(records, [p.name for p in paths], im, values, period, factor,
                           _periods(ground))
    except SuiteError as err:
        raise SceneError(f"ground.records: {err}") from None
    return suite, ((im, form, spec) if im else None)


def _parse(text: str, overrides: list[str], base: Path | None = None,
           given_record: GroundRecord | None = None) -> Scene:
    try:
        raw = _load_yaml(text)
    except _YamlError as err:
        raise SceneError(f"YAML {err}") from None
    if raw is None:
        raw = {}
    if not isinstance(raw, dict):
        raise SceneError(f"a scene is a YAML mapping with sections {', '.join(SECTIONS)} "
                         f"(got {fmt(raw)})")
    raw = apply_overrides(raw, overrides)
    for k in raw:
        if k not in ("name", *SECTIONS):
            raise SceneError(f"{k}: unknown key (allowed: name, {', '.join(SECTIONS)})")
    name = raw.get("name")
    if name is not None and not isinstance(name, str):
        raise SceneError(f"name = {fmt(name)}: {KEYS['name'].allowed}")
    if name is not None and _CONTROL.search(name):
        raise SceneError(f"name = {fmt(name)}: must not hold control characters (NUL, BEL, "
                         "ESC...): it is stored in the result file and printed")

    body = _section(raw, "body", "flexible", required=True)
    kind = body.get("kind", "flexible")
    impact = _section(raw, "impact", kind, required=kind == "flexible")
    if raw.get("ground") is not None and raw.get("pulse") is not None:
        raise SceneError("pulse, ground: give one of them (a pulse, or a recorded ground "
                         "motion)")
    if raw.get("ground") is None and raw.get("pulse") is None:
        raise SceneError("pulse: missing required section (pulse: {shape, w_over_p, "
                         "A_ratio}, or ground: {record, A_ratio, p} for a record)")
    record = suite = stripe = None
    if raw.get("ground") is not None:
        ground = _section(raw, "ground", kind, required=True)
        if ground.get("records") is not None:
            suite, stripe = _suite(ground, base)
            pulse = {"shape": RECORD, "p": ground["p"]}
        else:
            for k in ("scale", "periods"):
                if ground.get(k) is not None:
                    raise SceneError(f"ground.{k}: works with ground.records (a suite); one "
                                     "ground.record is scaled by ground.A_ratio")
            if ground.get("record") is None:
                raise SceneError("ground.record: missing required key (a record file; or "
                                 "ground.records and ground.scale for a suite)")
            if ground.get("A_ratio") is None:
                raise SceneError("ground.A_ratio: missing required key (a number, a list of "
                                 "numbers or a range {start, stop, num})")
            record = _record(ground, base) if given_record is None else given_record
            pulse = {"shape": RECORD, "A_ratio": ground["A_ratio"], "p": ground["p"]}
    else:
        pulse = _section(raw, "pulse", kind, required=True)
    numerics_sec = _section(raw, "numerics", kind, required=False)
    outputs = _section(raw, "outputs", kind, required=False)
    energy = outputs.get("energy", KEYS["outputs.energy"].default)
    if not isinstance(energy, bool):
        raise SceneError(f"outputs.energy = {fmt(energy)}: {KEYS['outputs.energy'].allowed}")
    contact = outputs.get("contact")
    if contact is not None and not isinstance(contact, bool):
        raise SceneError(f"outputs.contact = {fmt(contact)}: {KEYS['outputs.contact'].allowed}")
    mu_spec = body.get("mu")
    if mu_spec is not None and contact is False:
        raise SceneError(f"body.mu = {fmt(mu_spec)}: the slides/lifts_off flags need the "
                         "contact outputs; remove outputs.contact: false (body.mu turns "
                         "them on)")
    contact = bool(contact) or mu_spec is not None
    check = outputs.get("check", KEYS["outputs.check"].default)
    if not isinstance(check, bool):
        raise SceneError(f"outputs.check = {fmt(check)}: {KEYS['outputs.check'].allowed}")

    # forms and lengths first: the grid's size is known before any value is built
    if record is None and suite is None:
        shapes, shape_swept = _shapes(pulse["shape"])
        section, pulse_axes = "pulse", PULSE_AXES
        options = _pulse_options(pulse, shapes)
    else:
        shapes, shape_swept = (RECORD,), False
        section, pulse_axes = "ground", ("A_ratio", "p") if suite is None else ("p",)
        options = []
    specs: list[tuple[str, str, str, Any]] = []  # (name, key, form, spec)
    for k in BODY_KEYS[kind]:
        spec = body.get(k, KEYS[f"body.{k}"].default)
        specs.append((k, f"body.{k}", *_axis_spec(f"body.{k}", spec)[:2]))
    lam = impact.get("lam", 0.0)  # a block without an impact section: Housner's corner
    specs.append(("lam", "impact.lam", *_axis_spec("impact.lam", lam)[:2]))
    law_axis, law_specs = _impact_law(impact)
    n_laws = 1 if law_axis is None else len(law_axis.values)
    specs.extend(law_specs)  # after lam (and the law's axis, added below)
    if suite is not None:  # the records (words), then the stripes, before p
        specs.append(("record", "ground.record", "words", suite.names))
        if stripe is not None:
            specs.append((stripe[0], f"ground.{stripe[0]}", "stripes", stripe[1:]))
    for k in pulse_axes:
        specs.append((k, f"{section}.{k}", *_axis_spec(f"{section}.{k}", pulse[k])[:2]))
    if mu_spec is not None:  # the last axis: the same grid of runs, flagged per mu
        specs.append(("mu", "body.mu", *_axis_spec("body.mu", mu_spec)[:2]))
    lengths = [len(shapes)] + [1 if form == "scalar" else
                               (spec["num"] if form == "range" else
                                len(suite.levels) if form == "stripes" else len(spec))
                               for _, _, form, spec in specs]
    size = math.prod(lengths) * n_laws
    if size > MAX_POINTS:
        dims = " x ".join(f"{n:,} {key}" for n, (_, key, form, _) in
                          zip(lengths[1:], specs, strict=True) if form != "scalar")
        raise SceneError(f"the grid has {size:,} points ({dims}): at most {MAX_POINTS:,} "
                         "points per scene (a sweep file stores 45 bytes a point); split it "
                         "into several scenes or use fewer values")

    shape_key = ("ground.record" if record else "ground.shape" if suite else "pulse.shape")
    axes = [Axis("shape", shape_key, shapes, shape_swept)]
    for name_, key, form, spec in specs:
        if form == "words":  # a suite's records: always a dimension
            axes.append(Axis(name_, key, tuple(spec), True))
            continue
        if form == "stripes":  # checked by _suite; always a dimension
            axes.append(Axis(name_, key, suite.levels, True))
            continue
        values = _axis_values(key, form, spec)
        axes.append(Axis(name_, key, tuple(values.tolist()), form != "scalar"))
        if name_ == "lam" and law_axis is not None:
            axes.append(law_axis)
    axes.extend(options)  # unswept: the flat index and the result's shape stay as they are

    numerics, single = _numerics(numerics_sec, contact)
    scene = Scene(name=name or "rocksweep scene", kind=kind, axes=tuple(axes),
                  numerics=numerics, single_numerics=single, energy=energy, text=text,
                  contact=contact, check=check, record=record, refine=_refine(raw, kind),
                  suite=suite)
    if scene.contact and scene.ground:
        # the contact outputs are compiled into the sine/cosine variants only (a kernel
        # variant per combination costs compile time no scene has asked for yet)
        what = "a recorded ground motion" if scene.recorded else "ricker and mp pulses"
        raise SceneError(f"outputs.contact = true: not available with {what} yet; contact "
                         "outputs work with sine and cosine pulses")
    bodies = _candidate_bodies(scene)
    _check_cost(scene, bodies)
    return scene


# -- bodies and cost ---------------------------------------------------------------------

def _candidate_bodies(scene: Scene) -> list[dict[str, float]]:
    """Body values (by key name) that stand for the grid's bodies; each is built, so a body
    that is not physical raises its ``BodyError`` (as a SceneError).

    Up to MAX_BODIES_CHECKED distinct bodies: all of them. Beyond: the combinations of
    each key's extreme values (its least and largest, and wn_over_p's largest finite
    one), at most 3 x 2^5 = 96 bodies. The body's conditions and costs reach their worst
    there: with each key's range checked value by value, what is left is h/b > 0, and h/b
    is monotonic in alpha_cg and alpha_A and linear in mA_over_m; the step's rate
    ``body_omega_rock`` grows with wn_over_p and zeta, falls with IA_ratio and alpha_cg,
    rises with alpha_A and is convex in mA_over_m (m h^2 / (I_A + m_A R_A^2) ~ (c + d
    mu)^2 / mu); the pulse's rate grows with tan(alpha_cg). A function that is monotonic
    or convex in each key alone takes its largest value over a grid at such a corner.
    """
    axes = scene.body_axes()
    n_bodies = math.prod(len(a.values) for a in axes)
    if n_bodies <= MAX_BODIES_CHECKED:
        choices = [a.values for a in axes]
    else:
        choices = []
        for a in axes:
            v = np.asarray(a.values)
            pick = {float(v.min()), float(v.max())}
            finite = v[np.isfinite(v)]
            if finite.size:
                pick.add(float(finite.max()))
            choices.append(sorted(pick))
    out = []
    for combo in product(*choices):
        values = {a.name: float(v) for a, v in zip(axes, combo, strict=True)}
        try:
            scene.make_body(**values)
        except BodyError as err:
            raise SceneError(str(err)) from None
        out.append(values)
    return out


def _budgets(scene: Scene, bodies: list[dict[str, float]], w: np.ndarray, A: np.ndarray,
             numerics: Numerics) -> np.ndarray:
    """Step cap (PAR_MAXSTEPS) of every combination of the bodies, w and A: float64[b, w, A]
    (NaN, from an overflow, counts as inf)."""
    built = [scene.make_body(**b) for b in bodies]
    omega_rock = np.array([body_omega_rock(b) for b in built])[:, None, None]
    alpha_ref = np.array([b.alpha_ref for b in built])[:, None, None]
    shape = (len(built), w.size, A.size)
    _, _, _, cap = run_cost(np.broadcast_to(omega_rock, shape),
                            np.broadcast_to(alpha_ref, shape),
                            np.broadcast_to(w[None, :, None], shape),
                            np.broadcast_to(A[None, None, :], shape), numerics,
                            scene.phase_max())
    return np.where(np.isnan(cap), math.inf, cap)


def _check_record_cost(scene: Scene, bodies: list[dict[str, float]]) -> None:
    """A record scene's cost check: the step cap at the ends of the p and A_ratio axes
    (the record's length grows with p, the step shrinks with the body's rates and |A|)."""
    p = np.asarray(scene.axis("p").values)
    A = np.asarray(scene.axis("A_ratio").values)
    rec = scene.record
    for b in bodies:
        body = scene.make_body(**b)
        for n, label in _runs(scene):
            for pv in (p.min(), p.max()):
                for av in (A.min(), A.max()):
                    dt, h_rec, _, t_end, cap = record_cost(
                        np.array([body_omega_rock(body)]), np.array([body.alpha_ref]),
                        np.array([pv]), np.array([av]), rec, n)
                    c = float(cap[0])
                    if not (c <= MAX_POINT_STEPS):
                        raise SceneError(
                            f"ground.record {rec.name}: {rec.npts} samples at DT = "
                            f"{rec.dt:g} s ({rec.duration:g} s) with ground.p = "
                            f"{fmt(float(pv))}: one point could need {c:.2g} RK4 steps{label}"
                            f" (the record at steps of {float(h_rec[0]):.3g} p*t, then "
                            f"{n.horizon:g} p*t of free vibration), more than the cap of "
                            f"{MAX_POINT_STEPS:.0e} a point; use a smaller p, fewer "
                            "steps_per_period or a shorter horizon")


def _check_suite_cost(scene: Scene, bodies: list[dict[str, float]]) -> None:
    """A suite scene's cost check: for every record, the step cap at the ends of the p
    axis and at the record's largest scaled peak (the step shrinks with it)."""
    su = scene.suite
    p = np.asarray(scene.axis("p").values)
    p_ends = np.array([p.min(), p.max()])
    stripes = (np.arange(len(su.levels)) if su.im else None)
    for b in bodies:
        body = scene.make_body(**b)
        alpha = np.array([body.alpha_ref])
        for r, rec in enumerate(su.records):
            if stripes is None:
                peak = su.peak_ratio(np.array([r]), None, alpha, p_ends[:1])
            else:
                rr = np.full((stripes.size, 2), r)
                peak = su.peak_ratio(rr, np.repeat(stripes[:, None], 2, 1), alpha,
                                     p_ends[None, :])
            A = np.array([float(np.max(np.abs(peak)))] * 2)
            for n, label in _runs(scene):
                _, h_rec, _, _, cap = record_cost(np.array([body_omega_rock(body)] * 2),
                                                  np.array([body.alpha_ref] * 2), p_ends, A,
                                                  rec, n)
                worst = int(np.argmax(np.where(np.isnan(cap), math.inf, cap)))
                c = float(cap[worst])
                if not (c <= MAX_POINT_STEPS):
                    raise SceneError(
                        f"ground.records: {su.names[r]} at p = {fmt(float(p_ends[worst]))}: "
                        f"one point could need {c:.2g} RK4 steps{label} (the record's "
                        f"{rec.npts} samples at steps of {float(h_rec[worst]):.3g} p*t, "
                        f"scaled to a peak of {A[0]:.3g} g tan(alpha), then {n.horizon:g} "
                        f"p*t of free vibration), more than the cap of {MAX_POINT_STEPS:.0e} "
                        "a point; use a smaller p or scale, fewer steps_per_period or a "
                        "shorter horizon")


def _runs(scene: Scene) -> tuple[tuple[Numerics, str], ...]:
    """The numerics a scene's points run at, with the words that name them: the sweeps'
    and the single runs' (``simulate``; `fine`, 4x the steps of `default`, unless the scene
    names an accuracy)."""
    single = scene.single_numerics
    return ((scene.numerics, ""),
            (single, f" at the single runs' accuracy ({single.accuracy})"))


def _check_cost(scene: Scene, bodies: list[dict[str, float]]) -> None:
    """Refuse a scene with a point whose step cap exceeds MAX_POINT_STEPS.

    The cap grows with the run's length t_pulse + horizon and with 1/step; over the pulse
    axes it is largest at an end of each (the step follows max(omega, rates of the body and
    of |A|), the length 2 pi/omega: (2 pi/w + H) max(X, w) falls then rises in w).
    """
    if scene.record is not None:
        _check_record_cost(scene, bodies)
        return
    if scene.suite is not None:
        _check_suite_cost(scene, bodies)
        return
    w = np.asarray(scene.axis("w_over_p").values)
    A = np.asarray(scene.axis("A_ratio").values)
    w, A = np.array([w.min(), w.max()]), np.array([A.min(), A.max()])
    caps = np.max([_budgets(scene, bodies, w, A, n) for n, _ in _runs(scene)], axis=0)
    worst = int(np.argmax(caps))
    if caps.flat[worst] <= MAX_POINT_STEPS:
        return
    i, j, k = np.unravel_index(worst, caps.shape)
    point = {**{f"body.{n}": v for n, v in bodies[i].items()},
             "pulse.w_over_p": float(w[j]), "pulse.A_ratio": float(A[k])}
    raise SceneError(_cost_message(scene, point))


def _point_cost(scene: Scene, point: dict[str, float], numerics: Numerics | None = None
                ) -> tuple[float, float, float, str] | None:
    """(step cap, t_end, dt, words naming the numerics) of one point given by key, at the
    scene's costlier numerics (or at ``numerics``); None for a body that is not physical."""
    try:
        body = scene.make_body(**{k[5:]: v for k, v in point.items() if k.startswith("body.")})
    except BodyError:
        return None
    worst = None
    for n, label in _runs(scene) if numerics is None else ((numerics, ""),):
        dt, _, t_end, cap = run_cost(np.array([body_omega_rock(body)]),
                                     np.array([body.alpha_ref]),
                                     np.array([point["pulse.w_over_p"]]),
                                     np.array([point["pulse.A_ratio"]]), n, scene.phase_max())
        c = float(cap[0])
        c = math.inf if math.isnan(c) else c
        if worst is None or c > worst[0]:
            worst = (c, float(t_end[0]), float(dt[0]), label)
    return worst


def _with(scene: Scene, point: dict, key: str, value: float) -> float | None:
    """The step cap of ``point`` (at the costlier numerics) with one key of the point or
    of the numerics changed."""
    if key.startswith("numerics."):
        name = key.split(".", 1)[1]
        value = int(value) if name != "horizon" else float(value)
        caps = [_point_cost(scene, point, replace(n, **{name: value})) for n, _ in _runs(scene)]
        return max(c[0] for c in caps)  # type: ignore[index]
    got = _point_cost(scene, {**point, key: value})
    return None if got is None else got[0]


def _bound(scene: Scene, point: dict, key: str, bad: float, good: float) -> float:
    """The value between ``good`` (within the cap) and ``bad`` (beyond) where the cap is
    reached, rounded to 3 digits on the good side (60 bisections; log scale when both
    have one sign)."""
    logs = good * bad > 0
    lo, hi = (math.log(abs(good)), math.log(abs(bad))) if logs else (good, bad)
    sign = math.copysign(1.0, bad)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        v = sign * math.exp(mid) if logs else mid
        cost = _with(scene, point, key, v)
        if cost is not None and cost <= MAX_POINT_STEPS:
            lo = mid
        else:
            hi = mid
    v = sign * math.exp(lo) if logs else lo
    if KEYS[key].kind == "integer":
        return float(math.floor(v) if bad > good else math.ceil(v))
    e = 10.0 ** (math.floor(math.log10(abs(v))) - 2) if v else 1.0
    return (math.floor(v / e) if bad > good else math.ceil(v / e)) * e


def _cost_message(scene: Scene, point: dict) -> str:
    cap, t_end, dt, label = _point_cost(scene, point)  # type: ignore[misc]
    n = scene.numerics
    why = (f"{n.max_steps_factor:g} x a run of {t_end:.3g} p*t in steps of {dt:.3g} p*t, "
           f"plus {EVENT_STEP_ALLOWANCE:g} per event x max_events {n.max_events}")
    head = (f"one point could need {cap:.2g} RK4 steps{label} ({why}), more than the cap of "
            f"{MAX_POINT_STEPS:.0e} a point (~17 s of one core)")
    # which value of the point makes it costly: the one whose typical value cuts the most
    current = {**point, **{f"numerics.{k}": getattr(n, k)
                           for k in ("steps_per_period", "horizon", "max_events")}}

    def tame(key: str) -> float:
        t = _TAME[key]
        return math.copysign(t, current[key]) if key == "pulse.A_ratio" else t

    best, best_key = 1.0, None
    for key, value in current.items():
        if value == tame(key):
            continue
        cost = _with(scene, point, key, tame(key))
        if cost is not None and cap / max(cost, 1.0) > best:
            best, best_key = cap / max(cost, 1.0), key
    if best_key is None:
        return f"{head}; use fewer steps_per_period, a shorter horizon or fewer max_events"
    value = current[best_key]
    if _with(scene, point, best_key, tame(best_key)) > MAX_POINT_STEPS:  # type: ignore[operator]
        return f"{best_key} = {fmt(value)}: {head}; other values of this point are costly too"
    bound = _bound(scene, point, best_key, value, tame(best_key))
    shown = f"{abs(bound):.3g}" if KEYS[best_key].kind != "integer" else str(int(bound))
    if best_key == "pulse.A_ratio":
        rule = f"|{best_key}| must be <= {shown}"
    else:
        rule = f"{best_key} must be {'<=' if value > tame(best_key) else '>='} {shown}"
    return f"{best_key} = {fmt(value)}: {head}; with the scene's other values {rule}"
