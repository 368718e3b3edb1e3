"""The scene model: ``Scene`` (a validated study: its axes in the grid's order, numerics,
outputs, its ground motion and the excitations it makes of it) and ``Axis``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rocksweep import fields
from rocksweep.errors import SceneError, set_key
from rocksweep.kernel.layout import CONTACT_NOSLIP, CONTACT_SLIDE
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, Body, FlexibleBody, G
from rocksweep.physics.excitation import PulseShape
from rocksweep.physics.ground_motion import (
    Excitation,
    Excitations,
    Harmonic,
    ground_code,
    pulse,
    recorded,
    shared_ground,
)
from rocksweep.physics.path import GroundPath
from rocksweep.physics.points import Point
from rocksweep.physics.records import GroundRecord
from rocksweep.physics.suite import Suite
from rocksweep.schema import FRICTION_KEYS, KEYS, VERTICAL_KEYS
from rocksweep.vocab.axes import INITIAL
from rocksweep.vocab.ground import FREE, RECORD, pulse_duration
from rocksweep.vocab.laws import CONSTANT, DEFAULT_LAW

#: the one-mode floor's keys, the names of their axes (``floor.period`` is a dimension of
#: its own: a suite's ``period`` is the Sa periods')
FLOOR_AXES = ("floor.period", "floor.damping", "floor.participation")
# a pulse's vertical harmonic's axes (``pulse.vertical``: amplitude, w_over_p, phase)
_HARMONIC = tuple(f"vertical.{k}" for k in VERTICAL_KEYS)


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
    contact: bool = False  # outputs.contact (the no-slip model's; not with body.mu)
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
    # the excitations made of the ground motion (``excitation``), each once; shared by a
    # ``dataclasses.replace`` copy, which keeps the ground motion (never replaced)
    motions: Excitations = field(default_factory=Excitations, repr=False, compare=False)

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

    def slide_metres(self, summary: dict) -> dict[str, float]:
        """A physical body's sliding displacements in metres, ``slide_max_m`` and
        ``slide_final_m`` (the summary's slide_max, slide_final times its half-width
        b = h_cg tan(alpha_cg)); {} for a body of Pi groups or a run without mu."""
        if self.physical is None or summary.get("slide_max") is None:
            return {}
        b = float(self.physical["h_cg"]) * math.tan(float(self.physical["alpha_cg"]))
        return {f"{k}_m": summary[k] * b for k in ("slide_max", "slide_final")}

    def floor_summary(self, point: Point) -> dict[str, float]:
        """A run's peak floor acceleration {"floor_pfa": [g]} (a scene with a floor:
        ``floor_pfa`` of the motion that drove it, as a sweep stores it); {} without a
        floor."""
        return {fields.FLOOR_PFA: self.floor_pfa(point.A)} if self.floor else {}

    @staticmethod
    def floor_pfa(A: np.ndarray | float) -> np.ndarray | float:
        """The peak floor acceleration a run stores [g]: the peak A [m/s^2] of the motion
        that drove it (``points.peak_acc``, the rows' PAR_AMP) over g."""
        return A / G

    def variables(self) -> dict[str, tuple[str, float, str]]:
        """The per-point variables a sweep of this scene stores, name -> (dtype, fill value
        of a point not computed, meaning): ``fields.variables`` of its outputs."""
        return fields.variables(self.energy, self.contact, self.check, self.floor,
                                self.slides)

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
        """The kernel variants' ground code a sweep of the scene runs (``layout.GROUND_*``):
        the most general of its excitations' (``ground_motion.shared_ground``; a path's
        motions are samples)."""
        shapes = ((RECORD,) if self.recorded or self.path is not None
                  else self.axis("shape").values)
        return shared_ground(ground_code(sh, self.has_vertical) for sh in shapes)

    @property
    def slides(self) -> bool:
        """Whether the scene gives body.mu: its base may slide (docs/sliding.md), and its
        results carry slide_max, slide_final and regime."""
        return any(a.key == "body.mu" for a in self.axes)

    @property
    def contact_model(self) -> int:
        """The kernel's contact model a sweep of the scene runs (``layout.CONTACT_*``): the
        sliding base where the scene gives body.mu (docs/sliding.md), else the paper's."""
        return CONTACT_SLIDE if self.slides else CONTACT_NOSLIP

    @property
    def has_vertical(self) -> bool:
        """Whether the ground has a vertical acceleration (``ground.vertical`` or
        ``pulse.vertical``)."""
        return (self.vertical is not None or (self.suite is not None
                                              and self.suite.vertical_acts)
                or any(a.name == _HARMONIC[0] for a in self.axes))

    def ground_files(self) -> dict[str, GroundRecord]:
        """The files of the scene's one ground record by role: ``record`` and, when
        given, its vertical component (``vertical``, ``ground.vertical``); what a result
        file keeps and states under those names (``store.format``, ``store.identity``);
        {} without one record (a suite keeps its own)."""
        if self.record is None:
            return {}
        return {"record": self.record,
                **({"vertical": self.vertical} if self.vertical is not None else {})}

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

    @property
    def excitation_axes(self) -> tuple[str, ...]:
        """The axes a point's excitation depends on (``excitation``): a suite's record,
        the angle and the one-mode floor's keys of an excitation path, a pulse's shape
        (and its w_over_p when a building samples it) and vertical harmonic; none for one
        record. The other axes scale it (A_ratio, p, a pulse's w_over_p) or are the
        body's."""
        names = [a.name for a in self.axes]
        if self.path is not None:
            return tuple(k for k in ("record", "angle", *FLOOR_AXES) if k in names) + (
                () if self.recorded else ("shape", "w_over_p"))
        if self.recorded:
            return ("record",) if self.suite is not None else ()
        return ("shape", *(k for k in _HARMONIC if k in names))

    def excitation(self, values: dict[str, Any]) -> Excitation:
        """The excitation of the points with these axis values (``excitation_axes`` read;
        ``physics.ground_motion``): made once, when first asked for, and kept
        (``motions``)."""
        key = tuple(str(values[k]) if k in ("shape", "record") else float(values[k])
                    for k in self.excitation_axes)
        return self.motions.get(key, lambda: self._make_excitation(values))

    def _make_excitation(self, values: dict[str, Any]) -> Excitation:
        if self.path is not None:
            motion, ground_pga, r = self._path_motion(values)
            return recorded(motion, self.suite.acting_vertical(r) if self.suite is not None
                            else self.vertical, ground_pga)
        if self.suite is not None:
            r = self.suite.names.index(str(values["record"]))
            return recorded(self.suite.records[r], self.suite.acting_vertical(r))
        if self.record is not None:
            return recorded(self.record, self.vertical)
        harmonic = (Harmonic(*(float(values[k]) for k in _HARMONIC))
                    if _HARMONIC[0] in values else None)
        return pulse(str(values["shape"]), int(self.option("cycles")),
                     float(self.option("gamma")), float(self.option("nu")), harmonic)

    def drive_ratio(self, a_ratio: np.ndarray | None, rec: np.ndarray | None,
                    stripe: np.ndarray | None, alpha_ref: np.ndarray, p: np.ndarray,
                    excitations: tuple[Excitation, ...], which: np.ndarray) -> np.ndarray:
        """The kernel's A_ratio of n points (``Point.A_ratio``: the peak of what the body
        feels over g tan alpha_ref), float64[n]: the A_ratio axis's values (a_ratio), or a
        suite's record rec (int64[n]) at stripe (int64[n], None for a cloud) scaled for
        alpha_ref [rad] and p [rad/s] (``Suite.peak_ratio``); through an excitation path,
        the ground's amplitude times the gain of point i's motion ``excitations[which[i]]``
        (its peak over the ground's, ``Excitation.ground_pga``)."""
        su = self.suite
        if self.path is None:
            return a_ratio if su is None else su.peak_ratio(rec, stripe, alpha_ref, p)
        motion_pga = np.array([ex.record.pga for ex in excitations])[which]
        if su is not None:
            return su.factors(rec, stripe, alpha_ref, p) * motion_pga / np.tan(alpha_ref)
        return a_ratio * motion_pga / np.array([ex.ground_pga for ex in excitations])[which]

    def point(self, values: dict[str, Any]) -> Point:
        """The point with the given value of every axis (by name)."""
        body = self.make_body(**{a.name: values[a.name] for a in self.body_axes()})
        ex = self.excitation(values)
        if not self.recorded and self.path is None:
            rate, a_ratio = float(values["w_over_p"]), float(values["A_ratio"])
        else:
            su = self.suite
            rate = float(values["p"]) if self.recorded else self.path.p
            rec = None if su is None else np.array([su.names.index(str(values["record"]))])
            stripe = (np.array([self.axis(su.im).values.index(float(values[su.im]))])
                      if su is not None and su.im else None)
            a_ratio = float(self.drive_ratio(
                None if su is not None else np.array([float(values["A_ratio"])]), rec,
                stripe, np.array([body.alpha_ref]), np.array([rate]), (ex,),
                np.zeros(1, np.int64))[0])
        kw = {"mu": float(values.get("mu", math.nan)),
              "mu_static": float(values.get("mu_static", math.nan)), **self._law(values),
              "initial": self.initial_state(values)}
        if ex.record is None:
            return Point(body, float(values["lam"]), ex, rate, a_ratio, **kw)
        return Point(body, float(values["lam"]), ex, math.nan, a_ratio, p=rate, **kw)

    def path_motion(self, values: dict[str, Any]) -> tuple[GroundRecord, float, int]:
        """(the motion the body feels per unit of ground motion, the ground's peak that
        A_ratio scales, record index) at one point (``physics.path``; the excitation's,
        made once)."""
        ex = self.excitation(values)
        r = 0 if self.suite is None else self.suite.names.index(str(values["record"]))
        return ex.record, ex.ground_pga, r

    def _path_motion(self, values: dict[str, Any]) -> tuple[GroundRecord, float, int]:
        """``path_motion`` computed (``GroundPath.motion``)."""
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
        shape = PulseShape(str(values["shape"]), int(self.option("cycles")),
                           float(self.option("gamma")), float(self.option("nu")))
        return pa.motion(None, 0, 0.0, floor, (shape, float(values["w_over_p"]))), 1.0, 0

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
