"""The scene's keys: one table of types, admissible values and messages.

``KEYS`` maps every dotted scene key to a ``Key``: the kind of value it holds, the range
of admissible numbers (ends, inclusive or not, +inf allowed or not) and the text a user
reads when a value is refused. The scene validator (``rocksweep.scene.parse``) and the body
classes (``rocksweep.physics.bodies``) both check values here, so a body built from Python and a
scene file get the same one-line message ``KEY = VALUE: what is allowed``.

Bounds of the body's Pi groups. Beside the physical ranges (angles in (0, pi/2), lam in
[0, 2], I_O >= M R^2) the body's ratios are kept within a factor 1e6 of 1: a spring a
million times faster or slower than rocking, one mass a million times the other, a body a
million times taller than wide are no rocking problem, and the bounds stay ~1e140 away
from where the body's float64 arithmetic breaks (wn_over_p = 1e-300 divides by zero in
u_cr, mA_over_m = 1e200 overflows h^2, alpha_cg = 1e-300 divides by zero in b).
What a whole point costs (the step, the run's length) is checked by the scene, which
knows the pulse and the numerics.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np

from rocksweep.numerics import MIN_EVENT_TOL
from rocksweep.vocab.ground import (
    COMPONENTS,
    H1,
    MISSING,
    MISSING_ERROR,
    MISSING_SKIP,
    ROTD50,
    SCALE_IMS,
    SHAPES,
)
from rocksweep.vocab.laws import DEFAULT_LAW, LAWS
from rocksweep.vocab.settings import PRESET_NAMES, ROOTS

RATIO_MAX = 1e6  # bound of the body's ratios (see the module docstring)
ANGLE_MIN = 1e-6  # [rad] smallest slenderness: h/b = 1e6
CYCLES_MAX = 1000  # pulse.cycles: more cycles than this are no pulse
GAMMA_MAX = 100.0  # pulse.gamma: MP's gamma is 1-3 for near-fault records; 100 is plenty
E_FACTOR_MAX = 10.0  # impact.e_factor: experiments scale e by a few tens of per cent
# initial rate and top-mass state: 1e3 x the scales (theta' = 1e3 p alpha overturns at once)
INITIAL_MAX = 1e3


@dataclass(frozen=True)
class Key:
    """One scene key.

    kind: "axis" (a number, a list of numbers or a range {start, stop, num}: a swept
    parameter), "number", "integer", "choice" (one of ``choices``), "choices" (one of
    ``choices`` or a list of them: a swept axis of words), "bool" or "string".
    Numbers must lie between lo and hi (ends included when lo_in / hi_in), NaN never;
    inf_ok admits +inf beyond hi (wn_over_p = .inf: a rigid body).
    allowed: the message's right-hand side, what the user may write.
    required: a key the scene must give; default: its value otherwise.
    """

    kind: str
    allowed: str
    lo: float = -math.inf
    hi: float = math.inf
    lo_in: bool = True
    hi_in: bool = True
    inf_ok: bool = False
    choices: tuple[str, ...] = ()
    required: bool = True
    default: Any = None


_RATIO = f"[1e-06, {RATIO_MAX:g}]"
_ANGLE = f"must be in [{ANGLE_MIN:g}, pi/2) rad"


def _one_of(words: tuple[str, ...]) -> str:
    """"a, b, c" of a word list (the choices of a key)."""
    return ", ".join(words)


KEYS: dict[str, Key] = {
    "name": Key("string", "must be a string (the scene's title)", required=False),
    "body.kind": Key("choice", "must be one of flexible, block, physical",
                     choices=("flexible", "block", "physical"),
                     required=False, default="flexible"),
    # flexible body: Table 1's Pi groups
    "body.wn_over_p": Key("axis", f"must be in {_RATIO} (omega_n/p), or .inf for a rigid body",
                          1e-6, RATIO_MAX, inf_ok=True),
    "body.zeta": Key("axis", f"must be in [0, {RATIO_MAX:g}]", 0.0, RATIO_MAX),
    "body.alpha_cg": Key("axis", _ANGLE, ANGLE_MIN, math.pi / 2, hi_in=False),
    "body.alpha_A": Key("axis", _ANGLE, ANGLE_MIN, math.pi / 2, hi_in=False),
    "body.mA_over_m": Key("axis", f"must be in {_RATIO}", 1e-6, RATIO_MAX),
    "body.IA_ratio": Key("axis", f"must be in [0, {RATIO_MAX:g}] (I_A / (m_A R_A^2))",
                         0.0, RATIO_MAX),
    # block body
    "body.alpha": Key("axis", _ANGLE, ANGLE_MIN, math.pi / 2, hi_in=False),
    # A body's inertia about a corner is at least M R^2 (all its mass at distance R from O
    # would give exactly that only if concentrated at the centre of gravity).
    "body.inertia": Key("axis", f"must be in [1, {RATIO_MAX:g}] (I_O / (M R^2) >= 1)",
                        1.0, RATIO_MAX, required=False, default=4.0 / 3.0),
    # a body from the laboratory's numbers (body.kind physical): converted to the Pi groups
    # above and p (rocksweep.physics.bodies.body_from_geometry)
    "body.b": Key("number", "must be > 0 and finite (half-width of the base [m])", 0.0,
                  math.inf, lo_in=False, hi_in=False),
    "body.h": Key("number", "must be > 0 and finite (height of the top mass [m])", 0.0,
                  math.inf, lo_in=False, hi_in=False),
    "body.h_A": Key("number", "must be > 0 and finite (height of the base's centroid A [m])",
                    0.0, math.inf, lo_in=False, hi_in=False),
    "body.m": Key("number", "must be > 0 and finite (top mass [kg])", 0.0, math.inf,
                  lo_in=False, hi_in=False),
    "body.m_A": Key("number", "must be > 0 and finite (base mass [kg])", 0.0, math.inf,
                    lo_in=False, hi_in=False),
    "body.I_A": Key("number", "must be >= 0 and finite (base inertia about A [kg m^2])",
                    0.0, math.inf, hi_in=False),
    "body.k": Key("number", "must be > 0 (spring stiffness [N/m]; .inf: welded, a rigid "
                  "body)", 0.0, math.inf, lo_in=False, hi_in=False, inf_ok=True),
    "body.c": Key("number", "must be >= 0 and finite (damper [N s/m])", 0.0, math.inf,
                  hi_in=False, required=False, default=0.0),
    "impact.lam": Key("axis", "must be in [0, 2]", 0.0, 2.0),
    # impact laws (rocksweep.physics.impact): the law is a swept word axis like pulse.shape
    "impact.law": Key("choices", f"must be {_one_of(LAWS)} or a list of them",
                      choices=LAWS, required=False, default=DEFAULT_LAW),
    "impact.e": Key("axis", "must be in (0, 1] (the coefficient of restitution of law "
                    "constant)", 0.0, 1.0, lo_in=False, required=False),
    "impact.e_factor": Key("axis", f"must be in (0, {E_FACTOR_MAX:g}] (multiplies the law's "
                           "e)", 0.0, E_FACTOR_MAX, lo_in=False, required=False, default=1.0),
    "pulse.shape": Key("choices", f"must be {_one_of(SHAPES)} or a list of them",
                       choices=SHAPES),
    "pulse.w_over_p": Key("axis", "must be > 0 and finite (the pulse lasts 2 pi/omega)",
                          0.0, math.inf, lo_in=False, hi_in=False),
    "pulse.A_ratio": Key("axis",
                         "must be a finite number (negative: a pulse in the other direction)",
                         -math.inf, math.inf, lo_in=False, hi_in=False),
    "numerics.accuracy": Key("choice", f"must be one of {', '.join(PRESET_NAMES)}",
                             choices=PRESET_NAMES, required=False),
    "numerics.steps_per_period": Key("integer", "must be an integer in [4, 1e9]", 4, 1e9,
                                     required=False),
    "numerics.pulse_steps": Key("integer", "must be an integer in [4, 1e9] (RK4 steps per "
                                "pulse period while the pulse acts)", 4, 1e9, required=False),
    "numerics.refine": Key("integer", "must be an integer in [0, 6] (refinements of a close "
                           "call, each doubling the steps; 0: none)", 0, 6, required=False),
    "numerics.event_tol": Key(
        "number", f"must be in [{MIN_EVENT_TOL:g}, 1) (p*t; below {MIN_EVENT_TOL:g} an event "
        "time t ~ 1e2 is at float64's resolution)", MIN_EVENT_TOL, 1.0, hi_in=False,
        required=False),
    "numerics.horizon": Key("number", "must be > 0 and finite (p*t)", 0.0, math.inf,
                            lo_in=False, hi_in=False, required=False),
    "numerics.rest_rate": Key("number", "must be in (0, 1) (x p alpha_cg)", 0.0, 1.0,
                              lo_in=False, hi_in=False, required=False),
    "numerics.max_events": Key("integer", "must be an integer in [1, 1e9]", 1, 1e9,
                               required=False),
    "numerics.root": Key("choice", f"must be one of {', '.join(ROOTS)}", choices=ROOTS,
                         required=False),
    "numerics.rotation_step": Key("number", "must be in [0, 10] (x alpha_cg per rocking step; "
                                  "0: no limit)", 0.0, 10.0, required=False),
    "outputs.energy": Key("bool", "must be true or false (store energy metrics)",
                          required=False, default=False),
    # the sliding base (docs/sliding.md): given, the base slides (kernel.slide_loop)
    "body.mu": Key("axis", "must be in (0, 10] (kinetic friction coefficient of the base "
                   "on the ground)", 0.0, 10.0, lo_in=False, required=False),
    # the sliding base (docs/sliding.md): static friction, at least mu (default mu)
    "body.mu_static": Key("axis", "must be in (0, 10] and at least body.mu (static friction "
                          "coefficient of the base on the ground; default body.mu)", 0.0,
                          10.0, lo_in=False, required=False),
    # where the no-slip model holds (rocksweep.kernel.contact); not with body.mu
    "outputs.contact": Key("bool", "must be true or false (store the friction demand, the "
                           "smallest normal force and the impulse ratio)", required=False,
                           default=False),
    "outputs.check": Key("bool", "must be true or false (rerun every point at half the step "
                         "and store the differences: an error estimate per point)",
                         required=False, default=False),
    # adaptive sweeps (rocksweep.compute.adaptive): the section's presence turns them on; the
    # API's keywords and the command line's options override its values (one range each)
    "refine.axes": Key("string", "must be a list of the two diagram axes, swept ranges of "
                       "the scene, e.g. [w_over_p, A_ratio]", required=False),
    "refine.coarse": Key("integer", "must be an integer in [0, 20] (the coarse pass takes "
                         "every 2^coarse-th point of both axes)", 0, 20, required=False),
    "refine.audit": Key("number", "must be in [0, 1] (share of the filled points computed "
                        "as a check)", 0.0, 1.0, required=False),
    "refine.margin": Key("integer", "must be an integer in [0, 8] (cells refined around a "
                         "mixed cell)", 0, 8, required=False),
    "refine.final_margin": Key("integer", "must be an integer in [0, 8] (the same at the "
                               "last level; 0: the light last levels)", 0, 8, required=False),
    "refine.seed": Key("integer", "must be an integer in [0, 2^31) (seed of the audit "
                       "sample)", 0, 2**31 - 1, required=False),
    "refine.threshold": Key("number", "must be in [0, 1] (share of disagreeing audits "
                            "above which a run warns)", 0.0, 1.0, required=False),
    # pulse families (rocksweep.physics.excitation): full cycles of a sine or cosine, the
    # Mavroeidis-Papageorgiou pulse's oscillation parameter and phase
    "pulse.cycles": Key("integer", f"must be an integer in [1, {CYCLES_MAX}] (full cycles "
                        "of the sine or cosine)", 1, CYCLES_MAX, required=False, default=1),
    "pulse.gamma": Key("number", f"must be in [1, {GAMMA_MAX:g}] (the MP pulse's oscillation "
                       "parameter)", 1.0, GAMMA_MAX, required=False, default=2.0),
    "pulse.nu": Key("number", "must be a finite angle in degrees (the MP pulse's phase)",
                    -math.inf, math.inf, lo_in=False, hi_in=False, required=False,
                    default=90.0),
    # a recorded ground motion instead of a pulse (rocksweep.physics.records)
    # one record (ground.record, scaled by ground.A_ratio) or a suite (ground.records,
    # scaled by ground.scale): the scene requires one of the two pairs
    "ground.record": Key("string", "must be the path of a PEER .AT2 file or a two-column "
                         "file (t [s], xg'' [g]), relative to the scene file",
                         required=False),
    "ground.A_ratio": Key("axis", "must be a finite number (the record scaled to a peak of "
                          "A_ratio g tan(alpha_cg); negative: reversed)",
                          -math.inf, math.inf, lo_in=False, hi_in=False, required=False),
    "ground.records": Key("string", "must be a list of record files, a glob such as "
                          "suite/*.AT2, or a text file listing one path a line (relative to "
                          "the scene file)", required=False),
    "ground.scale": Key("string", "must be none, {factor: F} (the records as recorded, times "
                        "F) or {im: " + "|".join(SCALE_IMS) + ", values: a number, a list "
                        "or a range {start, stop, num}, period: T [s] for Sa}",
                        required=False, default="none"),
    "ground.scale.im": Key("choice", f"must be one of {', '.join(SCALE_IMS)}",
                           choices=tuple(SCALE_IMS)),
    "ground.scale.values": Key("axis", "must be finite numbers > 0 (the stripes' IM values: "
                               + ", ".join(f"{im} [{u if u != '1' else '-'}]"
                                           for im, u in SCALE_IMS.items()) + ")",
                               0.0, math.inf, lo_in=False, hi_in=False),
    "ground.scale.period": Key("number", "must be in (0, 100] s (the period of Sa)", 0.0,
                               100.0, lo_in=False),
    "ground.scale.component": Key("choice", f"must be {H1} (the first horizontal's IM) or "
                                  f"{ROTD50} (the median over orientations of both "
                                  "horizontals', NGA-West2's convention; a suite of PEER "
                                  "folders)", choices=COMPONENTS, required=False,
                                  default=H1),
    "ground.missing": Key("choice", f"must be {MISSING_ERROR} (a record of a PEER folder "
                          f"without one of its components is refused) or {MISSING_SKIP} "
                          "(left out, with a warning)", choices=MISSING, required=False,
                          default=MISSING_ERROR),
    "ground.scale.factor": Key("number", "must be a finite number > 0 (every record times "
                               "this factor)", 0.0, math.inf, lo_in=False, hi_in=False),
    "ground.periods": Key("string", "must be a list of periods in [0, 100] s (Sa stored per "
                          "record; 0 gives the PGA)", 0.0, 100.0, required=False,
                          default=(0.2, 1.0)),
    # the state at t = 0 (rocksweep.vocab.axes.INITIAL; the names simulate --csv writes)
    "initial.theta_over_alpha": Key(
        "axis", "must be a finite number (theta/alpha_cg at t = 0, |theta| < pi/2; > 0 "
        "rocking on one corner, < 0 on the other)", -math.inf, math.inf, lo_in=False,
        hi_in=False, required=False, default=0.0),
    "initial.thetadot_over_palpha": Key(
        "axis", f"must be in [-{INITIAL_MAX:g}, {INITIAL_MAX:g}] (theta'/(p alpha_cg) at "
        "t = 0)", -INITIAL_MAX, INITIAL_MAX, required=False, default=0.0),
    "initial.u_over_ucr": Key(
        "axis", f"must be in [-{INITIAL_MAX:g}, {INITIAL_MAX:g}] (u/u_cr of the top mass "
        "at t = 0)", -INITIAL_MAX, INITIAL_MAX, required=False, default=0.0),
    "initial.udot_over_pucr": Key(
        "axis", f"must be in [-{INITIAL_MAX:g}, {INITIAL_MAX:g}] (u'/(p u_cr) at t = 0)",
        -INITIAL_MAX, INITIAL_MAX, required=False, default=0.0),
    "ground.avgsa": Key("string", "must be [T_lo, T_hi], periods in (0, 100] s with T_lo <= "
                        "T_hi (AvgSa's range; default 0.2-3 x scale.period for Sa stripes, "
                        "else 0.2-3 x 2 pi/p)", 0.0, 100.0, required=False),
    # the excitation path (rocksweep.physics.path): a second horizontal component and the
    # body's orientation; a building's floor between the ground and the body
    "ground.h2": Key("string", "must be the path of the second horizontal component (PEER "
                     ".AT2 or two-column, the first component's DT), relative to the scene "
                     "file", required=False),
    "ground.angle": Key("axis", "must be in [0, 360) deg (the angle between the body's "
                        "rocking plane and the first horizontal component)", 0.0, 360.0,
                        hi_in=False, required=False, default=0.0),
    "floor.period": Key("axis", "must be a finite number > 0 [s] (the building mode's "
                        "period)", 0.0, math.inf, lo_in=False, hi_in=False, required=False),
    "floor.damping": Key("axis", "must be in (0, 1) (the building mode's damping ratio; an "
                         "undamped building would ring for ever)", 0.0, 1.0, lo_in=False,
                         hi_in=False, required=False),
    "floor.participation": Key("axis", "must be a finite number other than 0 (Gamma phi: "
                               "the mode's participation factor times its shape at the "
                               "floor)", -math.inf, math.inf, lo_in=False, hi_in=False,
                               required=False),
    "floor.modes": Key("string", "must be a list of modes {period: T [s], damping: zeta, "
                       "participation: Gamma phi} (numbers; sweep the one-mode form "
                       "floor: {period, damping, participation})", required=False),
    "ground.p": Key("axis", f"must be in [1e-3, {1e3:g}] rad/s (the body's frequency "
                    "parameter p)", 1e-3, 1e3),
    # the vertical ground acceleration a_v, positive up (docs/vertical.md): a record's
    # vertical component, scaled with ground.record, or a harmonic while the pulse acts
    "ground.vertical": Key("string", "must be the path of the record's vertical component, "
                           "a PEER .AT2 (UP) file or a two-column file (t [s], a_v [g], "
                           "positive up), relative to the scene file, with ground.record; "
                           "with a folder of PEER downloads in ground.records: true or "
                           "false (whether each record's UP file acts on the body)",
                           required=False),
    "pulse.vertical": Key("string", "must be {amplitude: a [g], w_over_p: w_v/p, phase: "
                          "deg} (a_v = a g sin(w_v t + phase) while the pulse acts)",
                          required=False),
    "pulse.vertical.amplitude": Key("axis", "must be a finite number [g] (the vertical "
                                    "harmonic's amplitude; negative: the opposite sign)",
                                    -math.inf, math.inf, lo_in=False, hi_in=False),
    "pulse.vertical.w_over_p": Key("axis", "must be >= 0 and finite (the vertical harmonic's "
                                   "frequency w_v/p; 0: a constant a_v = a g sin(phase))",
                                   0.0, math.inf, hi_in=False),
    "pulse.vertical.phase": Key("axis", "must be a finite angle in degrees (the vertical "
                                "harmonic's phase at t = 0)", -math.inf, math.inf,
                                lo_in=False, hi_in=False, required=False, default=0.0),
}
# the vertical harmonic's keys (pulse.vertical.*), in the grid's dimension order; their
# dimensions are named vertical.<key>
VERTICAL_KEYS: tuple[str, ...] = ("amplitude", "w_over_p", "phase")

# Keys of each body kind, in the grid's dimension order.
BODY_KEYS: dict[str, tuple[str, ...]] = {
    "flexible": ("wn_over_p", "zeta", "alpha_cg", "alpha_A", "mA_over_m", "IA_ratio"),
    "block": ("alpha", "inertia"),
    "physical": ("b", "h", "h_A", "m", "m_A", "I_A", "k", "c"),
}
#: the ground's keys in the body section (friction of the base on the ground; not the
#: body's own: a body is made of the other keys)
FRICTION_KEYS: tuple[str, ...] = ("mu", "mu_static")
SECTIONS = ("body", "impact", "pulse", "numerics", "outputs", "ground", "refine", "initial",
            "floor")


def section_keys(section: str, kind: str = "flexible") -> tuple[str, ...]:
    """The keys (without the section) a section may hold; body keys depend on its kind."""
    if section == "body":
        return ("kind", *BODY_KEYS[kind], *FRICTION_KEYS)
    pre = section + "."
    return tuple(k[len(pre):] for k in KEYS if k.startswith(pre) and "." not in k[len(pre):])


def fmt(v: Any) -> str:
    """A value as the user wrote it, in one line (floats in full, inf/nan as words)."""
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else str(v)
    if isinstance(v, np.floating):
        return fmt(float(v))
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def _ok(spec: Key, v: np.ndarray) -> np.ndarray:
    above = (v > spec.lo) | (spec.lo_in & (v == spec.lo))
    below = (v < spec.hi) | (spec.hi_in & (v == spec.hi))
    ok = above & below
    if spec.inf_ok:
        ok |= v == math.inf
    return ok & ~np.isnan(v)


def check_value(key: str, value: float) -> str | None:
    """None if the number is admissible for ``key``, else ``KEY = VALUE: allowed``."""
    spec = KEYS[key]
    v = float(value)
    ok = ((v > spec.lo or (spec.lo_in and v == spec.lo))
          and (v < spec.hi or (spec.hi_in and v == spec.hi)))
    if ok or (spec.inf_ok and v == math.inf):
        return None
    return f"{key} = {fmt(v)}: {spec.allowed}"


def check_values(key: str, values: np.ndarray) -> str | None:
    """As ``check_value``, vectorised over ``values`` (float64[n]): the message names the
    first value that is not admissible."""
    spec = KEYS[key]
    v = np.atleast_1d(np.asarray(values, dtype=float))
    bad = np.flatnonzero(~_ok(spec, v))
    if bad.size == 0:
        return None
    return f"{key} = {fmt(float(v[bad[0]]))}: {spec.allowed}"


def as_float(v: Any) -> float:
    """A number as a float; an integer beyond float64's range becomes +-inf (float()
    would raise OverflowError), so that the range check names it."""
    try:
        return float(v)
    except OverflowError:
        return math.inf if v > 0 else -math.inf


def is_number(v: Any) -> bool:
    """A real number (bool is not one, although Python counts it as an int)."""
    return isinstance(v, numbers.Real) and not isinstance(v, bool | np.bool_)


def check_option(key: str, value: Any) -> str | None:
    """None if ``value`` is admissible for ``key`` (None: not given), else what is allowed
    (``KEYS[key].allowed``). The settings the Python API's keywords and the command line's
    options give for a scene key (``margin=9``) are checked here, against the same table
    as the scene's own section."""
    if value is None:
        return None
    spec = KEYS[key]
    if spec.kind == "integer":
        ok = isinstance(value, numbers.Integral) and not isinstance(value, bool | np.bool_)
    else:
        ok = is_number(value)
    if ok:
        ok = check_value(key, as_float(value)) is None and not math.isnan(as_float(value))
    return None if ok else spec.allowed
