"""The scene model: ``Scene`` (a validated study: its axes in the grid's order, numerics,
outputs, record or suite) and ``Axis``, and ``SceneError``, the one error of scenes."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rocksweep import fields
from rocksweep.errors import SceneError, set_key
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, Body, FlexibleBody, G
from rocksweep.physics.path import GroundPath
from rocksweep.physics.points import Point
from rocksweep.physics.records import GroundRecord, vertical_samples
from rocksweep.physics.suite import Suite
from rocksweep.physics.vertical import VerticalHarmonic
from rocksweep.schema import FRICTION_KEYS, KEYS
from rocksweep.vocab.axes import INITIAL
from rocksweep.vocab.ground import FREE, PAPER_SHAPES, RECORD, pulse_duration
from rocksweep.vocab.laws import CONSTANT, DEFAULT_LAW

#: the one-mode floor's keys, the names of their axes (``floor.period`` is a dimension of
#: its own: a suite's ``period`` is the Sa periods')
FLOOR_AXES = ("floor.period", "floor.damping", "floor.participation")


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
    single_numerics: Numerics  # single runs (simulate): the sweeps' numerics (one default)
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
    # every file the scene was read from: the scene file, its record, a suite's records and
    # listings (paths as read); an output is never one of them (``outputs.check_output``)
    inputs: tuple[str, ...] = field(default=(), repr=False)
    # a body given by the laboratory's numbers (body.kind physical): its Pi groups, p
    # [rad/s], omega_n [rad/s] and h_cg [m] (``physics.bodies.body_from_geometry``), else None
    physical: dict | None = field(default=None, repr=False)
    # the record's vertical component (``ground.vertical``, read at load), else None; a
    # pulse's vertical harmonic is three axes, vertical.amplitude, .w_over_p and .phase
    vertical: GroundRecord | None = field(default=None, repr=False)
    # the excitation path (``ground.h2``/``ground.angle``, ``floor:``): what the body
    # feels is computed from the ground motion (``physics.path``); None without those keys
    path: GroundPath | None = field(default=None, repr=False)

    @property
    def floor(self) -> bool:
        """Whether the body stands on a building's floor (a ``floor:`` section)."""
        return self.path is not None and self.path.floor

    def floor_words(self) -> str:
        """One line stating the building ('' without a floor)."""
        if not self.floor:
            return ""
        if self.path.modes is not None:
            modes = self.path.modes
            return ("floor of a linear building, modes (period [s], damping, "
                    "participation): " + "; ".join(
                        f"({m.period:g}, {m.damping:g}, {m.participation:g})" for m in modes))
        vals = ", ".join(f"{k.split('.')[1]} = " + (
            f"{self.axis(k).values[0]:g}" if len(self.axis(k).values) == 1 else
            f"{len(self.axis(k).values)} values {min(self.axis(k).values):g}.."
            f"{max(self.axis(k).values):g}") for k in FLOOR_AXES)
        return f"floor of a linear building, one mode: {vals}"

    def physical_words(self) -> str:
        """One line stating what a physical body became ('' for a body of Pi groups)."""
        if self.physical is None:
            return ""
        d = self.physical
        return ("body (kind physical): " + ", ".join(
            f"{k} = {d[k]:.5g}" for k in ("wn_over_p", "zeta", "alpha_cg", "alpha_A",
                                          "mA_over_m", "IA_ratio"))
                + f", p = {d['p']:.5g} rad/s, h_cg = {d['h_cg']:.4g} m")

    def physical_summary(self) -> dict[str, float]:
        """A physical body's frequency parameter {"p": p [rad/s]} (the key of
        ``rocksweep.simulate``'s summary, ``simulate --json`` and a result file's attrs);
        {} for a body of Pi groups."""
        return {} if self.physical is None else {"p": float(self.physical["p"])}

    def floor_summary(self, point: Point) -> dict[str, float]:
        """A run's peak floor acceleration {"floor_pfa": [g]} (a scene with a floor: the
        peak of the motion that drove it, as a sweep stores it); {} without a floor."""
        return {fields.FLOOR_PFA: point.A / G} if self.floor else {}

    def variables(self) -> dict[str, tuple[str, float, str]]:
        """The per-point variables a sweep of this scene stores, name -> (dtype, fill value
        of a point not computed, meaning): ``fields.variables`` of its outputs."""
        return fields.variables(self.energy, self.contact, self.check, self.floor)

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
    def ground(self) -> int:
        """The kernel variants' ground code the scene needs (``layout.GROUND_*``, false
        for the pulse variants): GROUND_VERTICAL with a vertical ground acceleration,
        GROUND_ANY for a Ricker or MP pulse or a record; the paper's sine and cosine (n
        cycles too) run the pulse variants."""
        if self.has_vertical:
            return L.GROUND_VERTICAL
        if self.recorded or self.floor or any(
                sh not in (*PAPER_SHAPES, FREE) for sh in self.axis("shape").values):
            return L.GROUND_ANY
        return L.GROUND_PULSE

    @property
    def has_vertical(self) -> bool:
        """Whether the ground has a vertical acceleration (``ground.vertical`` or
        ``pulse.vertical``)."""
        return (self.vertical is not None or (self.suite is not None
                                              and self.suite.vertical_acts)
                or any(a.name == "vertical.amplitude" for a in self.axes))

    def vertical_samples(self):
        """The vertical record [g] on the horizontal record's samples
        (``records.vertical_samples``; float64[npts]), None without one."""
        if self.vertical is None:
            return None
        return vertical_samples(self.vertical, self.record)

    def record_vertical(self, r: int = 0) -> GroundRecord | None:
        """The vertical component acting with record r: ``ground.vertical``, or a folder
        suite's record r's UP file (``Suite.acting_vertical``); None without one."""
        if self.suite is not None:
            return self.suite.acting_vertical(r)
        return self.vertical

    def path_vertical(self, motion: GroundRecord, r: int = 0):
        """Record r's vertical [g] on the samples of a motion of the excitation path
        (``physics.path``: it reaches the floor unfiltered), None without one."""
        vertical = self.record_vertical(r)
        return None if vertical is None else vertical_samples(vertical, motion)

    def option(self, name: str) -> Any:
        """A pulse option's value (cycles, gamma, nu [deg]): the scene's or the default."""
        for a in self.axes:
            if a.name == name:
                return a.values[0]
        return KEYS[f"pulse.{name}"].default

    def phase_max(self) -> float:
        """The longest pulse of the scene's shapes in w t (2 pi n, 6 pi, 2 pi gamma)."""
        return max(pulse_duration(sh, self.option("cycles"), self.option("gamma"))
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
        """The axes that make the body (body.mu, body.mu_static are the ground's, not the
        body's: ``schema.FRICTION_KEYS``)."""
        return tuple(a for a in self.axes if a.key.startswith("body.")
                     and a.key[5:] not in FRICTION_KEYS)

    def make_body(self, **values: float) -> Body:
        """A body from values of the body keys (as in ``body_axes``; friction keys among
        them are the ground's and left out)."""
        values = {k: v for k, v in values.items() if k not in FRICTION_KEYS}
        if self.kind == "block":
            return BlockBody(**values)
        return FlexibleBody(**values)

    def point(self, values: dict[str, Any]) -> Point:
        """The point with the given value of every axis (by name)."""
        body = self.make_body(**{a.name: values[a.name] for a in self.body_axes()})
        if self.path is not None:
            return self._path_point(body, values)
        if self.suite is not None:
            su = self.suite
            r = su.names.index(str(values["record"]))
            s = (np.array([self.axis(su.im).values.index(float(values[su.im]))])
                 if su.im else None)
            p = float(values["p"])
            a_ratio = float(su.peak_ratio(np.array([r]), s, np.array([body.alpha_ref]),
                                          np.array([p]))[0])
            return Point(body, float(values["lam"]), RECORD, math.nan, a_ratio,
                         record=su.records[r], p=p, **self._law(values),
                         initial=self.initial_state(values), vertical=su.acting_vertical(r))
        if self.record is not None:
            return Point(body, float(values["lam"]), RECORD, math.nan,
                         float(values["A_ratio"]), record=self.record, p=float(values["p"]),
                         **self._law(values), initial=self.initial_state(values),
                         vertical=self.vertical)
        return Point(body, float(values["lam"]), str(values["shape"]),
                     float(values["w_over_p"]), float(values["A_ratio"]),
                     int(values.get("cycles", self.option("cycles"))),
                     float(values.get("gamma", self.option("gamma"))),
                     float(values.get("nu", self.option("nu"))),
                     mu=float(values.get("mu", math.nan)), **self._law(values),
                     initial=self.initial_state(values),
                     pulse_vertical=self._pulse_vertical(values))

    def _pulse_vertical(self, values: dict[str, Any]) -> VerticalHarmonic | None:
        """A point's vertical harmonic (``pulse.vertical``) from axis values, or None."""
        if "vertical.amplitude" not in values:
            return None
        return VerticalHarmonic(float(values["vertical.amplitude"]),
                                float(values["vertical.w_over_p"]),
                                float(values["vertical.phase"]))

    def path_motion(self, values: dict[str, Any]):
        """(the motion the body feels per unit of ground motion, the ground's peak that
        A_ratio scales, record index) at one point (``physics.path``)."""
        pa = self.path
        angle = float(values.get("angle", 0.0))
        floor = (tuple(float(values[k]) for k in FLOOR_AXES)
                 if pa.floor and pa.modes is None else None)
        if self.suite is not None:
            r = self.suite.names.index(str(values["record"]))
            ground = self.suite.records[r]
            return pa.motion(ground, r, angle, floor), ground.pga, r
        if self.record is not None:
            return pa.motion(self.record, 0, angle, floor), self.record.pga, 0
        from rocksweep.physics.excitation import PulseShape

        shape = PulseShape(str(values["shape"]), int(self.option("cycles")),
                           float(self.option("gamma")), float(self.option("nu")))
        return pa.motion(None, 0, 0.0, floor, (shape, float(values["w_over_p"]))), 1.0, 0

    def _path_point(self, body: Body, values: dict[str, Any]) -> Point:
        """A point of a scene with an excitation path: driven by its computed motion, the
        kernel's A_ratio the ground's scaled by the motion's gain."""
        motion, ground_peak, r = self.path_motion(values)
        if self.suite is not None:
            su = self.suite
            s = (np.array([self.axis(su.im).values.index(float(values[su.im]))])
                 if su.im else None)
            p = float(values["p"])
            fac = float(su.factors(np.array([r]), s, np.array([body.alpha_ref]),
                                   np.array([p]))[0])
            a_ratio = fac * motion.pga / math.tan(body.alpha_ref)
        else:
            a_ratio = float(values["A_ratio"]) * motion.pga / ground_peak
            p = float(values["p"]) if self.recorded else self.path.p
        return Point(body, float(values["lam"]), RECORD, math.nan, a_ratio, record=motion,
                     p=p, **self._law(values), initial=self.initial_state(values),
                     vertical=self.record_vertical(r))

    @property
    def free(self) -> bool:
        """No ground motion (neither ``pulse`` nor ``ground``): free vibration from the
        initial state."""
        return self.axis("shape").values == (FREE,)

    def initial_state(self, values: dict[str, Any]) -> tuple[float, float, float, float]:
        """A point's initial state (``vocab.axes.INITIAL``, normalised) from axis values; the
        keys the scene does not give are 0."""
        return tuple(float(values.get(k, 0.0)) for k in INITIAL)  # type: ignore[return-value]

    def _law(self, values: dict[str, Any]) -> dict[str, Any]:
        """A point's impact law (Point keywords law, e, e_factor) from axis values."""
        law = str(values.get("law", DEFAULT_LAW))
        return {"law": law, "e": float(values["e"]) if law == CONSTANT else math.nan,
                "e_factor": float(values.get("e_factor", 1.0))}

    def single_point(self) -> Point:
        """The scene's only point; a SceneError names the first swept key otherwise."""
        for a in self.axes:
            if len(a.values) != 1:
                raise SceneError(
                    f"{a.key} has {len(a.values)} values: this runs one point; pick one "
                    "with {fix}", fix=set_key(a.key, "set_fix"))
        return self.point({a.name: a.values[0] for a in self.axes})
