"""A scene: YAML -> validated study (body, impact, pulse, numerics, outputs).

Any Pi-group value may be a scalar, a list, or a range ``{start, stop, num}`` (inclusive,
like ``numpy.linspace``); ``pulse.shape`` may be a list. Lists and ranges are swept axes.
Every problem is a ``SceneError`` with one line naming the key, the value and what is
allowed; the keys, their types, ranges and messages are one table, ``rocksweep.schema``.

Every valid scene runs in bounded time and space:

- YAML: numbers follow YAML 1.2 (``1e-6`` is a number), a key given twice in a mapping is
  refused, nesting is limited to MAX_DEPTH levels (``rocksweep.scene.loader``);
- at most MAX_AXIS_VALUES values per axis and MAX_POINTS points per grid;
- every point's cap on RK4 evaluations (the kernel's PAR_MAXSTEPS, ``points.run_cost``)
  is at most ``numerics.MAX_POINT_STEPS``, at the sweep's and at the single runs' accuracy
  (``rocksweep.scene.admission``).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np

from rocksweep.errors import BodyError, SceneError, set_key
from rocksweep.numerics import Numerics
from rocksweep.outputs import input_problem, shown
from rocksweep.physics.bodies import body_from_geometry
from rocksweep.physics.records import GroundRecord
from rocksweep.physics.suite import (
    Suite,
)
from rocksweep.scene.admission import candidate_bodies, check_cost
from rocksweep.scene.floors import excitation_path
from rocksweep.scene.friction import check_friction, friction_specs
from rocksweep.scene.ground import ground_record, ground_suite
from rocksweep.scene.loader import CONTROL_CHARS, YamlError, load_yaml
from rocksweep.scene.model import Axis, Scene
from rocksweep.scene.sections import axis_spec, axis_values, section, shape_words, words
from rocksweep.scene.vertical import check_vertical_start, pulse_vertical
from rocksweep.schema import (
    BODY_KEYS,
    FRICTION_KEYS,
    KEYS,
    SECTIONS,
    VERTICAL_KEYS,
    as_float,
    check_values,
    fmt,
    is_number,
)
from rocksweep.vocab.axes import DIAGRAM_AXES, INITIAL, alpha_symbol, axis_name
from rocksweep.vocab.ground import FREE, MP, RECORD
from rocksweep.vocab.ground import PULSE_KEY_SHAPES as _PULSE_KEY_SHAPES
from rocksweep.vocab.laws import CONSTANT, DEFAULT_LAW
from rocksweep.vocab.settings import DEFAULT_PRESET, FINE

# Largest grid a scene may describe [points]. A sweep file stores 45 bytes a point (69
# with energy metrics, ``rocksweep.fields.variables``): 2e8 points are a 9-14 GB file, one
# float64 variable read back for a figure or xarray is 1.6 GB of memory, and at tens of
# microseconds a point (docs/performance.md) the sweep takes hours of one core.
MAX_POINTS = 200_000_000
PULSE_AXES = tuple(reversed(DIAGRAM_AXES))  # (A_ratio, w_over_p)
# The pulse shapes each optional pulse key means something for (rocksweep.physics.excitation);
# given for none of the scene's shapes, the key is refused (it would be silently ignored).
PULSE_KEY_SHAPES = _PULSE_KEY_SHAPES


def apply_overrides(raw: dict, overrides: list[str]) -> dict:
    """Apply ``section.key=VALUE`` overrides (VALUE parsed as YAML) to a raw scene.

    ``section.key=null`` leaves the key out (its default, or none), the one way an override
    can take a key away (switching ``impact.law`` away from ``constant`` drops ``impact.e``);
    a null written in a scene file is refused instead, where it would read as a value."""
    for item in overrides:
        if "=" not in item:
            raise SceneError("{entry}: expected KEY=VALUE, e.g. pulse.A_ratio=4.5",
                             entry=set_key(item, "set_entry"))
        key, text = item.split("=", 1)
        key = key.strip()
        parts = key.split(".")
        if not all(parts):
            raise SceneError("{entry}: expected KEY=VALUE, e.g. pulse.A_ratio=4.5",
                             entry=set_key(item, "set_entry"))
        try:
            value = load_yaml(text)
        except YamlError as err:
            raise SceneError("{key}: value {text} is not valid YAML ({why})",
                             key=set_key(key), text=fmt(text), why=err) from None
        node: Any = raw
        for p in parts[:-1]:
            if node.get(p) is None:
                if value is None:  # the section is not there: nothing to leave out
                    node = None
                    break
                node[p] = {}
            node = node[p]
            if not isinstance(node, dict):
                raise SceneError("{key}: {p} is not a section", key=set_key(key), p=p)
        if value is None:
            if node is not None:
                node.pop(parts[-1], None)
        else:
            node[parts[-1]] = value
    return raw


def parse_scene(text: str, source: str = "scene", overrides: list[str] | None = None,
                base: str | Path | None = None, record: GroundRecord | None = None,
                records: tuple[GroundRecord, ...] | None = None,
                h2: GroundRecord | None = None,
                vertical: GroundRecord | None = None) -> Scene:
    """Validate scene YAML text. Raises SceneError (one line, prefixed by ``source``).

    base: the directory a ``ground.record`` path is relative to (the scene file's; None:
    the working directory); record: the record of a ``ground`` section, already read (a
    result file's stored copy): the ``ground.record`` path is then not read; records: the
    same for a suite's ``ground.records`` (in the suite's order; their file names label
    the record dimension); h2, vertical: the same for ``ground.h2`` and
    ``ground.vertical``."""
    try:
        return _parse(text, overrides or [], Path(base) if base is not None else None,
                      record, records, h2, vertical)
    except SceneError as err:
        raise SceneError("{source}: {err}", source=source, err=err) from None


def load_scene(path: str | Path, overrides: list[str] | None = None) -> Scene:
    """The validated scene of a YAML file (a regular file: a FIFO, device or directory is
    refused before it is opened, never waited on; a missing file is "no such scene file":
    the one place that says it)."""
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
    scene = parse_scene(text, str(path), overrides, base=path.parent)
    return dataclasses.replace(scene, inputs=(str(path), *scene.inputs))


def _impact_law(impact: dict) -> tuple[Axis | None, list[tuple[str, str, Any]]]:
    """The impact law's axes: the law (a word axis; None when the scene does not name
    one: eq. 1, ``vertical``) and the specs of ``impact.e`` and ``impact.e_factor`` given.
    ``e`` is required by law ``constant`` and refused without it."""
    law_axis = None
    laws: tuple[str, ...] = (DEFAULT_LAW,)
    if impact.get("law") is not None:
        laws, swept = words("impact.law", impact["law"])
        law_axis = Axis("law", "impact.law", laws, swept)
    specs = []
    e_spec = impact.get("e")
    if e_spec is None and CONSTANT in laws:
        raise SceneError("impact.e: missing; law constant needs its coefficient of "
                         "restitution e: a number in (0, 1], a list or a range")
    if e_spec is not None:
        if CONSTANT not in laws:
            raise SceneError(f"impact.e = {fmt(e_spec)}: only law constant uses e (the law "
                             f"here is {', '.join(laws)}); remove impact.e or add law: "
                             "constant")
        specs.append(("e", "impact.e", *axis_spec("impact.e", e_spec)[:2]))
    if impact.get("e_factor") is not None:
        specs.append(("e_factor", "impact.e_factor",
                      *axis_spec("impact.e_factor", impact["e_factor"])[:2]))
    return law_axis, specs


def _refine(raw: dict, kind: str) -> dict | None:
    """The checked ``refine`` section as ``rocksweep.compute.adaptive.Options`` keywords,
    or None."""
    if raw.get("refine") is None:
        return None
    sec = section(raw, "refine", kind, required=False)
    out: dict[str, Any] = {}
    for k, v in sec.items():
        key = f"refine.{k}"
        spec = KEYS[key]
        if k == "axes":
            if not (isinstance(v, list) and len(v) == 2
                    and all(isinstance(a, str) for a in v) and v[0] != v[1]):
                raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
            out[k] = tuple(axis_name(a) if "." in a else a for a in v)
            continue
        if spec.kind == "integer" and not (isinstance(v, int) and not isinstance(v, bool)):
            raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
        if not is_number(v) or check_values(key, np.array([as_float(v)])) is not None:
            raise SceneError(f"{key} = {fmt(v)}: {spec.allowed}")
        out[k] = int(v) if spec.kind == "integer" else float(v)
    return out


def _numerics(sec: dict, contact: bool = False) -> tuple[Numerics, Numerics]:
    """The sweeps' and the single runs' numerics of a checked ``numerics`` section: the
    same (one point, one answer).

    Without a preset named, sweeps and single runs run `default`, but a scene that stores
    the contact demands runs `fine`: at `default` the demands of long-rocking points differ from the
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
    numerics = Numerics.preset(accuracy or (FINE if contact else DEFAULT_PRESET), **given)
    # One default: a single run (simulate) runs what a sweep of the same point
    # runs, so one point has one answer; the certification of close calls
    # (``compute.certify``) makes the default trustworthy for both.
    single = numerics
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
            if not (k != "cycles" and MP in shapes):
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


@dataclasses.dataclass
class _Motion:
    """The ground motion of a scene, as its sections give it (before the axes are built).

    free: no ground motion (free vibration from the initial state); pulse: the raw keys of
    the pulse axes (``pulse`` section, or the ``ground`` keys a record is scaled by);
    record: one ground record; suite, stripe: a suite of records and its stripe axis
    (im, form, spec) or None; inputs: the files read."""

    free: bool
    pulse: dict
    record: GroundRecord | None = None
    suite: Suite | None = None
    stripe: tuple | None = None
    inputs: tuple[str, ...] = ()
    # the vertical ground acceleration: a record's vertical component (ground.vertical)
    # or the raw keys of a pulse's vertical harmonic (pulse.vertical)
    vertical: GroundRecord | None = None
    pulse_vertical: dict | None = None
    ground: dict = dataclasses.field(default_factory=dict)  # the ground section's keys


@dataclasses.dataclass
class _Forms:
    """The motion's axes before their values: the shapes, the section and names of the
    pulse axes, and the unswept pulse options."""

    shapes: tuple[str, ...]
    shape_swept: bool
    section: str
    pulse_axes: tuple[str, ...]
    options: list[Axis]


def _parse(text: str, overrides: list[str], base: Path | None = None,
           given_record: GroundRecord | None = None,
           given_records: tuple[GroundRecord, ...] | None = None,
           given_h2: GroundRecord | None = None,
           given_vertical: GroundRecord | None = None) -> Scene:
    """The scene of YAML text: each section parsed in turn, then the grid's size checked
    before any axis value is built, then the scene's admission (initial state, cost)."""
    raw = _document(text, overrides)
    name = _name(raw)
    body, kind, physical = _body(raw)
    impact = section(raw, "impact", kind, required=kind == "flexible")
    if raw.get("ground") is not None and raw.get("pulse") is not None:
        raise SceneError("pulse, ground: give one of them (a pulse, or a recorded ground "
                         "motion)")
    initial = section(raw, "initial", kind, required=False)
    motion = _motion(raw, kind, base, given_record, given_records, given_vertical)
    numerics_sec = section(raw, "numerics", kind, required=False)
    energy, contact, check = _outputs(raw, kind, body.get("mu"))

    # forms and lengths first: the grid's size is known before any value is built
    forms = _forms(motion)
    law_axis, law_specs = _impact_law(impact)
    if motion.pulse_vertical is not None and raw.get("floor") is not None:
        raise SceneError("floor: not with pulse.vertical (a pulse's vertical harmonic acts "
                         "while the pulse acts; on a floor give the ground motion as a "
                         "record with ground.vertical, which reaches the floor unfiltered)")
    # the orientation and the floor: after the records, before the ground's own axes

    path, path_specs, path_inputs = excitation_path(
        raw, motion.ground, kind, motion.free, motion.record, motion.suite, base, physical,
        given_h2)
    specs = _axis_specs(kind, body, impact, initial, motion, forms, law_specs, path_specs)
    _check_size(motion, forms, specs, 1 if law_axis is None else len(law_axis.values))
    axes = _axes(motion, forms, specs, law_axis)
    check_friction(axes)

    numerics, single = _numerics(numerics_sec, contact)
    scene = Scene(name=name or "rocksweep scene", kind=kind, axes=tuple(axes),
                  numerics=numerics, single_numerics=single, energy=energy, text=text,
                  contact=contact, check=check, record=motion.record,
                  refine=_refine(raw, kind), suite=motion.suite,
                  inputs=(*motion.inputs, *path_inputs), physical=physical,
                  vertical=motion.vertical, path=path)
    _admit(scene)
    return scene


def _document(text: str, overrides: list[str]) -> dict:
    """The scene's YAML mapping, overrides applied, its top-level keys checked."""
    try:
        raw = load_yaml(text)
    except YamlError as err:
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
    return raw


def _name(raw: dict) -> str | None:
    """The scene's ``name`` (None: not given)."""
    name = raw.get("name")
    if name is not None and not isinstance(name, str):
        raise SceneError(f"name = {fmt(name)}: {KEYS['name'].allowed}")
    if name is not None and CONTROL_CHARS.search(name):
        raise SceneError(f"name = {fmt(name)}: must not hold control characters (NUL, BEL, "
                         "ESC...): it is stored in the result file and printed")
    return name


def _body(raw: dict) -> tuple[dict, str, dict | None]:
    """The ``body`` section: (keys, kind, physical). A ``physical`` body (the laboratory's
    numbers) becomes a flexible one (its Pi groups and p); physical keeps its numbers."""
    body = section(raw, "body", "flexible", required=True)
    kind = body.get("kind", "flexible")
    if kind != "physical":
        return body, kind, None
    try:
        physical = body_from_geometry(**{k: body.get(k, KEYS[f"body.{k}"].default)
                                         for k in BODY_KEYS["physical"]})
    except BodyError as err:
        raise SceneError(str(err)) from None
    body = {**{k: physical[k] for k in BODY_KEYS["flexible"]},
            **{k: body[k] for k in FRICTION_KEYS if body.get(k) is not None}}
    return body, "flexible", physical


def _motion(raw: dict, kind: str, base: Path | None, given_record: GroundRecord | None,
            given_records: tuple[GroundRecord, ...] | None,
            given_vertical: GroundRecord | None = None) -> _Motion:
    """The ground motion: none (free vibration), a ``pulse`` (with its vertical harmonic,
    if given), or a ``ground`` section (one record scaled by A_ratio, with its vertical
    component if given, or a suite of records)."""
    for name in ("pulse", "ground"):
        if name in raw and raw[name] is None:  # refused as every null section
            section(raw, name, kind, required=False)
    if raw.get("ground") is None and raw.get("pulse") is None:
        return _Motion(free=True, pulse={"shape": FREE, "w_over_p": 0.0, "A_ratio": 0.0})
    if raw.get("ground") is None:
        pulse = section(raw, "pulse", kind, required=True)
        return _Motion(free=False, pulse=pulse, pulse_vertical=pulse_vertical(pulse))
    ground = section(raw, "ground", kind, required=True)
    if (ground.get("vertical") is not None and ground.get("record") is None
            and ground.get("records") is None):
        raise SceneError(f"ground.vertical = {fmt(ground['vertical'])}: works with one "
                         "ground.record (its horizontal component), or as true/false with "
                         "a folder of PEER downloads in ground.records")
    if ground.get("records") is not None:
        suite, stripe, inputs = ground_suite(ground, base, given_records)
        return _Motion(free=False, pulse={"shape": RECORD, "p": ground["p"]}, suite=suite,
                       stripe=stripe, inputs=inputs, ground=ground)
    for k in ("scale", "periods", "avgsa"):
        if ground.get(k) is not None:
            raise SceneError(f"ground.{k}: works with ground.records (a suite); one "
                             "ground.record is scaled by ground.A_ratio")
    if ground.get("record") is None:
        raise SceneError("ground.record: missing required key (a record file; or "
                         "ground.records and ground.scale for a suite)")
    if ground.get("A_ratio") is None:
        raise SceneError("ground.A_ratio: missing required key (a number, a list of "
                         "numbers or a range {start, stop, num})")
    record = ground_record(ground, base) if given_record is None else given_record
    inputs = (str(record.source),) if given_record is None else ()
    vertical = given_vertical
    if ground.get("vertical") is not None and vertical is None:
        vertical = ground_record(ground, base, "vertical")
        inputs = (*inputs, str(vertical.source))
    return _Motion(free=False,
                   pulse={"shape": RECORD, "A_ratio": ground["A_ratio"], "p": ground["p"]},
                   record=record, inputs=inputs,
                   vertical=vertical if ground.get("vertical") is not None else None,
                   ground=ground)


def _outputs(raw: dict, kind: str, mu_spec: Any) -> tuple[bool, bool, bool]:
    """The ``outputs`` section: (energy, contact, check). The contact outputs are the
    no-slip model's friction demand: a scene that gives ``body.mu`` (mu_spec, None: not
    given) slides instead (docs/sliding.md) and has none."""
    outputs = section(raw, "outputs", kind, required=False)
    energy = outputs.get("energy", KEYS["outputs.energy"].default)
    if not isinstance(energy, bool):
        raise SceneError(f"outputs.energy = {fmt(energy)}: {KEYS['outputs.energy'].allowed}")
    contact = outputs.get("contact")
    if contact is not None and not isinstance(contact, bool):
        raise SceneError(f"outputs.contact = {fmt(contact)}: {KEYS['outputs.contact'].allowed}")
    if mu_spec is not None and contact:
        raise SceneError(f"outputs.contact = true: the friction demand is the no-slip "
                         f"model's, and body.mu = {fmt(mu_spec)} makes the base slide "
                         "(slide_max, slide_final, regime); remove body.mu for the demand "
                         "of a base that cannot slide")
    contact = bool(contact)
    check = outputs.get("check", KEYS["outputs.check"].default)
    if not isinstance(check, bool):
        raise SceneError(f"outputs.check = {fmt(check)}: {KEYS['outputs.check'].allowed}")
    return energy, contact, check


def _forms(motion: _Motion) -> _Forms:
    """The motion's shapes, the section and names of its pulse axes, its pulse options."""
    if motion.free:
        return _Forms((FREE,), False, "pulse", PULSE_AXES, [])
    if motion.record is None and motion.suite is None:
        shapes, shape_swept = shape_words(motion.pulse["shape"])
        return _Forms(shapes, shape_swept, "pulse", PULSE_AXES,
                      _pulse_options(motion.pulse, shapes))
    return _Forms((RECORD,), False, "ground",
                  ("A_ratio", "p") if motion.suite is None else ("p",), [])


def _axis_specs(kind: str, body: dict, impact: dict, initial: dict, motion: _Motion,
                forms: _Forms, law_specs: list[tuple[str, str, Any]],
                path_specs: list[tuple[str, str, str, Any]] = ()
                ) -> list[tuple[str, str, str, Any]]:
    """(name, key, form, spec) of every axis after the shape, in the grid's order, their
    forms checked but no value built: the body, lam (then the impact law's keys), the
    initial state, a suite's records and stripes, the excitation path's (angle, floor),
    the pulse axes, body.mu and body.mu_static last."""
    specs: list[tuple[str, str, str, Any]] = []
    for k in BODY_KEYS[kind]:
        spec = body.get(k, KEYS[f"body.{k}"].default)
        specs.append((k, f"body.{k}", *axis_spec(f"body.{k}", spec)[:2]))
    lam = impact.get("lam", 0.0)  # a block without an impact section: Housner's corner
    specs.append(("lam", "impact.lam", *axis_spec("impact.lam", lam)[:2]))
    specs.extend(law_specs)  # after lam (and the law's axis, added by _axes)
    for k in INITIAL:  # the initial state's keys given (none: at rest, no axis)
        if initial.get(k) is not None:
            specs.append((k, f"initial.{k}", *axis_spec(f"initial.{k}", initial[k])[:2]))
    for k in VERTICAL_KEYS if motion.pulse_vertical is not None else ():
        spec = motion.pulse_vertical.get(k, KEYS[f"pulse.vertical.{k}"].default)
        key = f"pulse.vertical.{k}"
        specs.append((f"vertical.{k}", key, *axis_spec(key, spec)[:2]))
    if motion.suite is not None:  # the records (words), then the stripes, before p
        specs.append(("record", "ground.record", "words", motion.suite.names))
        if motion.stripe is not None:
            im = motion.stripe[0]
            specs.append((im, f"ground.{im}", "stripes", motion.stripe[1:]))
    specs.extend(path_specs)
    for k in forms.pulse_axes:
        key = f"{forms.section}.{k}"
        if motion.free:  # not the user's: no check (w_over_p = 0 is no ground motion)
            specs.append((k, key, "given", motion.pulse[k]))
            continue
        specs.append((k, key, *axis_spec(key, motion.pulse[k])[:2]))
    specs.extend(friction_specs(body))  # the last axes: mu, mu_static
    return specs


def _check_size(motion: _Motion, forms: _Forms, specs: list[tuple[str, str, str, Any]],
                n_laws: int) -> None:
    """Refuse a grid of more than MAX_POINTS points, from the axes' lengths alone."""
    lengths = [len(forms.shapes)] + [
        1 if form in ("scalar", "given") else
        (spec["num"] if form == "range" else
         len(motion.suite.levels) if form == "stripes" else len(spec))
        for _, _, form, spec in specs]
    size = math.prod(lengths) * n_laws
    if size > MAX_POINTS:
        dims = " x ".join(f"{n:,} {key}" for n, (_, key, form, _) in
                          zip(lengths[1:], specs, strict=True) if form != "scalar")
        raise SceneError(f"the grid has {size:,} points ({dims}): at most {MAX_POINTS:,} "
                         "points per scene (a sweep file stores 45 bytes a point); split it "
                         "into several scenes or use fewer values")


def _axes(motion: _Motion, forms: _Forms, specs: list[tuple[str, str, str, Any]],
          law_axis: Axis | None) -> list[Axis]:
    """The scene's axes, values built: the shape, the specs' (the impact law's after
    lam), then the unswept pulse options."""
    shape_key = ("ground.record" if motion.record else
                 "ground.shape" if motion.suite else "pulse.shape")
    axes = [Axis("shape", shape_key, forms.shapes, forms.shape_swept)]
    for name_, key, form, spec in specs:
        if form == "words":  # a suite's records: always a dimension
            axes.append(Axis(name_, key, tuple(spec), True))
            continue
        if form == "stripes":  # checked by ground_suite; always a dimension
            axes.append(Axis(name_, key, motion.suite.levels, True))
            continue
        if form == "given":  # a free scene's pulse axes (no ground motion)
            axes.append(Axis(name_, key, (float(spec),), False))
            continue
        values = axis_values(key, form, spec)
        axes.append(Axis(name_, key, tuple(values.tolist()), form != "scalar"))
        if name_ == "lam" and law_axis is not None:
            axes.append(law_axis)
    axes.extend(forms.options)  # unswept: the flat index and the result's shape stay as they are
    return axes


def _admit(scene: Scene) -> None:
    """Checks of the whole scene: outputs available with its motion, the initial state,
    the cost of a point; a suite's drift and large factors as RecordWarnings."""
    if scene.contact and scene.ground:
        # the contact outputs are compiled into the sine/cosine variants only (a kernel
        # variant per combination costs compile time no scene has asked for yet)
        what = ("a vertical ground acceleration" if scene.has_vertical else
                "a recorded ground motion" if scene.recorded else "a floor" if scene.floor
                else "ricker and mp pulses")
        raise SceneError(f"outputs.contact = true: not available with {what} yet; contact "
                         "outputs work with sine and cosine pulses")
    bodies = candidate_bodies(scene)
    check_vertical_start(scene)
    _check_initial(scene, bodies)
    check_cost(scene, bodies)
    if scene.suite is not None:
        scene.suite.warn(scene.axis(alpha_symbol(scene.kind)).values,
                         scene.axis("p").values)


def _check_initial(scene: Scene, bodies: list[dict[str, float]]) -> None:
    """Refuse an initial state that is not admissible (one line): |theta| >= pi/2 (the
    body lies on its side) for a body of the scene, and a displacement or rate of the top
    mass given to a rigid body (it has none). The contact phase follows from the state:
    theta > 0 rocks on corner +1, theta < 0 on -1, theta = 0 with theta' != 0 on the corner
    theta' points to, theta = theta' = 0 full contact (uplift checked at t = 0)."""
    names = {a.name for a in scene.axes}
    if "theta_over_alpha" in names:
        th = np.asarray(scene.axis("theta_over_alpha").values)
        worst = float(th[np.argmax(np.abs(th))])
        alpha = max(scene.make_body(**b).alpha_ref for b in bodies)
        if abs(worst) * alpha >= math.pi / 2:
            ref = alpha_symbol(scene.kind)
            raise SceneError(f"initial.theta_over_alpha = {fmt(worst)}: |theta| = "
                             f"{abs(worst):g} x {ref} ({alpha:.4g} rad) = "
                             f"{abs(worst) * alpha:.4g} rad; must be < pi/2 (|theta_over_alpha|"
                             f" < {math.pi / 2 / alpha:.4g}: beyond, the body lies on its side)")
    for k in ("u_over_ucr", "udot_over_pucr"):
        if k not in names:
            continue
        v = np.asarray(scene.axis(k).values)
        if np.any(v != 0.0) and any(scene.make_body(**b).rigid for b in bodies):
            bad = float(v[np.flatnonzero(v != 0.0)[0]])
            why = ("a block" if scene.kind == "block" else "body.wn_over_p = .inf")
            raise SceneError(f"initial.{k} = {fmt(bad)}: a rigid body ({why}) has no top-mass "
                             "motion; must be 0 (or give a finite body.wn_over_p)")
