"""Accuracy knobs of the kernel, the presets, and the step size rule.

Every knob has a measured price: ``rocksweep accuracy SCENE.yaml`` measures time per point
and error against the reference path for each setting; docs/accuracy.md gives the
presets' figures on the shipped paper scenes.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from rocksweep.vocab.settings import ACCURATE, DEFAULT_PRESET, DEFAULT_ROOT, DRAFT, FINE


@dataclass(frozen=True)
class Preset:
    """The values an accuracy preset (``numerics.accuracy``) sets; each field is the
    ``Numerics`` field of the same name."""

    steps_per_period: int
    event_tol: float
    rotation_step: float
    pulse_steps: int
    refine: int


# How each value was chosen, with its measured price and agreement with the reference:
# docs/accuracy.md ("Where the presets' values come from" and the tables above it).
# - steps_per_period 5 and pulse_steps 12 (`default`): the fewest steps that classify the
#   four figures like `fine` (0/0/0/1 of 19 200 cells) and the held-out spectra's first
#   overturning values; fewer pulse steps lose a uniform block's narrow mode-1 band.
# - event_tol: 1e-5 and above keep chattering above the rest rate (runs hit the event cap).
# - rotation_step (a fraction of alpha_cg; 0: no limit): far outside the paper's region a
#   body would turn through alpha_cg or more in one step; a quarter halves the
#   overturning-time tail of the wide-space sample for a few percent more steps.
# - refine: most refinements of a close call (``rocksweep.compute.certify``); `draft`
#   certifies nothing.
# - `accurate`: every stored quantity to 0.05 p*t and 1% (95th percentile) far outside the
#   paper's region, where `default` meets neither; `fine` for histories and energies.
PRESETS: dict[str, Preset] = {
    DRAFT: Preset(steps_per_period=4, event_tol=1e-6, rotation_step=0.25, pulse_steps=10,
                  refine=0),
    DEFAULT_PRESET: Preset(steps_per_period=5, event_tol=1e-6, rotation_step=0.25,
                           pulse_steps=12, refine=3),
    FINE: Preset(steps_per_period=20, event_tol=1e-8, rotation_step=0.1, pulse_steps=40,
                 refine=3),
    ACCURATE: Preset(steps_per_period=10, event_tol=1e-8, rotation_step=0.1, pulse_steps=20,
                     refine=3),
}
_DEFAULT = PRESETS[DEFAULT_PRESET]

# Smallest event_tol [p*t] a scene may ask for. An event's time is t0 + tau in float64; at
# t ~ 1e2 (a run lasts the pulse plus the 200-long horizon) its spacing is 1.4e-14, and
# 2.8e-14 to 5.7e-14 up to t = 512: below ~1e-12 the tolerance asks for digits t does not
# have. (The root finders bracket tau inside one step, <= pi/2 long, spacing 2.2e-16, so
# they end for any tolerance above ~1e-15; 1e-12 leaves a margin of ~4000 spacings.)
MIN_EVENT_TOL = 1e-12
# A refinement's event tolerance: event_tol x EVENT_TOL_REFINE per halving of the step,
# down to MIN_EVENT_TOL (``Numerics.refined``, ``fields.refined_rows``). An event's time
# error carries into the state as a step's error does, and RK4's global error falls as
# the step^4: a refinement that halved the steps alone left each event's error where it
# was. On a threshold sample (seed 36) a lightly damped spring's runs at 20-80 steps a
# period agreed on an overturn after 5 impacts at event_tol 1e-6; at 1e-7 and below every
# one of them rocks to rest, as `fine` (1e-8) and the reference do (docs/accuracy.md,
# "Clear by twice the margin, events located finer").
EVENT_TOL_REFINE = 0.5 ** 4

# RK4 evaluations the kernel may spend locating one event before a run is capped
# (``step_budget``): bisection takes log2(step/event_tol) ~ 20-40, Hermite 2-5.
EVENT_STEP_ALLOWANCE = 200.0

# Kernel time per RK4 evaluation [s] on the paper's figures at the default preset
# (scripts/bench_compile.py: core-us per point over RK4 evaluations per point, 75-83 ns on
# the four figures on the 2-core reference machine; docs/performance.md): the one price of
# a step, from which a sweep's estimate (``compute.sweep.estimate``, before a sample can
# be run) and the cost of a point at the cap below (``point_seconds``) are derived.
SECONDS_PER_EVALUATION = 85e-9

# Cap on one point's step budget (``step_budget``, PAR_MAXSTEPS) that a scene may imply:
# a point that long takes ``point_seconds(MAX_POINT_STEPS)`` (~8.5 s) of one core, the
# longest a single point may take before its values are taken for a mistake (w_over_p =
# 1e-9, a pulse of 6e9 p*t; wn_over_p = 1e5 at steps of 1e-5). The shipped scenes' largest
# caps and what their points spend: docs/accuracy.md (scripts/make_docs_numbers.py).
MAX_POINT_STEPS = 1e8


def point_seconds(steps: float) -> float:
    """Seconds of one core a point of ``steps`` RK4 evaluations takes (at
    ``SECONDS_PER_EVALUATION``)."""
    return steps * SECONDS_PER_EVALUATION


@dataclass(frozen=True)
class Numerics:
    """Resolved numerical settings of a run (all times in p*t).

    steps_per_period: RK4 steps per shortest time scale of the body (its spring while it
        rocks, its rocking), and of the pulse's amplitude while it acts: ``step_sizes``.
    pulse_steps: RK4 steps per pulse period while the pulse acts (the larger of this and
        steps_per_period counts; after the pulse its period sets no step): ``step_sizes``.
    refine: most refinements of a close call (each doubling every step), until its outcome
        is stable (``rocksweep.compute.certify``); 0: no certification.
    event_tol: width [p*t] to which an event's time is bracketed.
    horizon: how long after the pulse's end a run may go on [p*t] before it is flagged.
    rest_rate: post-impact |theta'| / (p * alpha_cg) below which the body settles into full
        contact (ends a chattering sequence after finitely many impacts).
    max_events: cap on impacts + uplifts per run (reported as a status flag).
    max_steps_factor: cap on RK4 evaluations per run, as a multiple of horizon/step.
    root: event root finder, one of ``vocab.settings.ROOTS`` (``kernel.events._locate``):
        each keeps the bracket and stops at event_tol; Hermite takes 2-5 re-integrations
        per event where bisection takes ~20, with the same outcomes (docs/accuracy.md).
    rotation_step: largest rotation of one rocking step, a fraction of alpha_cg (0: none);
        the step is shortened to it from theta' and the last step's theta'' and a step that
        turned more than twice as far is taken again (``rocksweep.kernel.loop``).
    """

    accuracy: str = DEFAULT_PRESET
    steps_per_period: int = _DEFAULT.steps_per_period
    event_tol: float = _DEFAULT.event_tol
    horizon: float = 200.0
    rest_rate: float = 1e-4
    max_events: int = 5000
    max_steps_factor: float = 20.0
    root: str = DEFAULT_ROOT
    rotation_step: float = _DEFAULT.rotation_step
    pulse_steps: int = _DEFAULT.pulse_steps
    refine: int = _DEFAULT.refine

    @classmethod
    def preset(cls, accuracy: str = DEFAULT_PRESET, **overrides) -> Numerics:
        return replace(cls(accuracy=accuracy, **asdict(PRESETS[accuracy])), **overrides)

    def preset_values(self) -> Preset:
        """The values of these numerics that a preset sets."""
        return Preset(**{f.name: getattr(self, f.name) for f in fields(Preset)})

    def describe(self) -> str:
        label = self.accuracy
        if PRESETS.get(self.accuracy) != self.preset_values():
            label = "custom"
        return (f"{label} (steps_per_period={self.steps_per_period}, "
                f"pulse_steps={self.pulse_steps}, "
                f"event_tol={self.event_tol:g}, rotation_step={self.rotation_step:g}, "
                f"refine={self.refine}, horizon={self.horizon:g}, root={self.root})")

    def refined(self, level: int) -> Numerics:
        """These numerics at 2**level times the steps (and EVENT_TOL_REFINE**level times
        the event tolerance): a close call's rerun at that refinement
        (``fields.refined_rows`` scales the rows the same way)."""
        f = 2 ** level
        return replace(self, steps_per_period=self.steps_per_period * f,
                       pulse_steps=self.pulse_steps * f,
                       rotation_step=self.rotation_step / f,
                       event_tol=max(self.event_tol * EVENT_TOL_REFINE ** level,
                                     MIN_EVENT_TOL), refine=0)

    def as_dict(self) -> dict:
        return asdict(self)


# The spring's steps (``step_sizes``): steps_per_period x the largest of three factors, each
# bounding one error of RK4 on the top mass's spring while the base rocks (a mode
# u ~ exp(i omega_rock t); at n steps per spring period, y = omega_rock dt = 2 pi/n, RK4
# multiplies it by R(iy) per step, |R(iy)| = sqrt(1 - y^6/72 + y^8/576)).
#
# A softer spring holds more of the energy, ~(p/omega_rock)^2, and RK4 takes ~n^-5 of it
# per unit time (its numerical damping), so a spring below OMEGA_SPRING x p gets
# (OMEGA_SPRING/omega_rock)^(2/5) times the steps: the energy error of Figure 4's spring
# (omega_rock/p = 27.5) at 5 steps, which classifies like `fine` (docs/accuracy.md).
OMEGA_SPRING = 27.5

# A stiffer spring holds less energy but is damped faster: -ln|R(iy)| per step is
# y^6/144 to leading order, a decay rate of the spring's amplitude of
# omega_rock (2 pi/n)^5/144 per unit p*t, growing with omega_rock at fixed n. Near the
# uplift threshold under long pulses (hundreds of small uplifts) that numerical damping,
# beside the physical zeta' omega', decided outcomes. So an oscillating spring (zeta' < 1)
# also gets the steps that hold that numerical decay rate to ``spring_decay`` at 5 steps
# per period, (5/steps_per_period)^5 of it at others (the presets keep their order; a
# refinement's doubling halves every step):
#
#     SPRING_DECAY_FREE + SPRING_DECAY_REL x zeta' omega_rock, at most SPRING_DECAY [p].
#
# Driven and damped at zeta' omega', the amplitude is off by ~sigma/(zeta' omega'), 1/38 =
# 2.6% at SPRING_DECAY_REL; an undamped spring (zeta = 0) keeps the whole error for as long
# as the run lasts (~50 p*t under a long pulse near the threshold) and gets
# SPRING_DECAY_FREE, 10% of its amplitude over 50 p*t. Smaller bounds fixed nothing more;
# the cells each bound fixes and its price: docs/accuracy.md, "Stiff springs near the
# uplift threshold".
SPRING_DECAY = 0.1
SPRING_DECAY_FREE = 0.002
SPRING_DECAY_REL = 1.0 / 38.0

# RK4 also turns the spring too slowly: arg R(iy) = y - y^5/120 + ..., a relative frequency
# error y^4/120, so its oscillation falls behind by (2 pi/n)^4/120 of the time it runs.
# That is of lower order than the damping above, and a lightly damped spring keeps it for
# as long as it remembers its past, ~1/(zeta' omega_rock), at most the run (SPRING_MEMORY
# p*t, as SPRING_DECAY_FREE takes it). The spring then pushes the base at the wrong moments
# of each rocking cycle, and over ~100 impacts the coarse run parts from the reference's:
# 16 of the 17 wrong, unflagged classes left on nine threshold samples were bodies with
# zeta <= 0.036 (docs/accuracy.md, "Lightly damped springs"). So an oscillating spring
# (zeta' < 1) also gets the steps that hold that lag over its memory to SPRING_SHIFT [p*t]
# at 5 steps per period ((5/steps_per_period)^4 of it at others):
#
#     n >= 2 pi (min(SPRING_MEMORY, 1/(zeta' omega_rock)) / (120 SPRING_SHIFT))^(1/4).
#
# It binds on springs that ring long (21.6 steps a period for an undamped spring, 14.4 where
# 1/(zeta' omega_rock) = 10 p*t); of the shipped scenes, only on wide-space.yaml's undamped
# bodies.
SPRING_SHIFT = 0.003
SPRING_MEMORY = 50.0


def spring_memory(omega_rock: np.ndarray | float, zeta_rock: np.ndarray | float
                  ) -> np.ndarray:
    """How long [p t] the top mass's spring remembers its past while the base rocks:
    1/(zeta' omega_rock) for an oscillating spring (zeta_rock = zeta' < 1; inf undamped),
    0 for an overdamped one or none (omega_rock = 0: a rigid body). omega_rock [rad/s],
    p = 1 (``points.body_omega_rock``, ``points.rocking_spring_zeta``). float64 like the
    input."""
    w = np.asarray(omega_rock, float)
    zr = np.asarray(zeta_rock, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where((w > 0.0) & (zr < 1.0), 1.0 / (zr * w), 0.0)


def spring_decay(zeta_rock: np.ndarray | float, omega_rock: np.ndarray | float
                 ) -> np.ndarray:
    """The largest numerical decay rate [p] RK4 may add to an oscillating spring at 5 steps
    per period: min(SPRING_DECAY, SPRING_DECAY_FREE + SPRING_DECAY_REL zeta' omega_rock)
    (zeta_rock = zeta', the spring's damping ratio while rocking; omega_rock [rad/s], p =
    1)."""
    rate = np.asarray(zeta_rock, float) * np.asarray(omega_rock, float)
    return np.minimum(SPRING_DECAY, SPRING_DECAY_FREE + SPRING_DECAY_REL * rate)


def spring_steps(omega_rock: np.ndarray | float, steps_per_period: int,
                 zeta_rock: np.ndarray | float = 0.0) -> np.ndarray:
    """RK4 steps per spring period 2 pi/omega_rock: steps_per_period x the largest of 1,
    (OMEGA_SPRING/omega_rock)^(2/5) and, for a spring that oscillates while the base rocks
    (zeta_rock < 1: ``points.rocking_spring_zeta``; 0, the default, an undamped one),
    (omega_rock/omega_d)^(1/5), omega_d = 144 ``spring_decay`` (5/2 pi)^5: RK4's
    leading-order damping of it, omega_rock (2 pi/n)^5/144, is then spring_decay
    (5/steps_per_period)^5; and (2 pi/5) (T/(120 SPRING_SHIFT))^(1/4), T =
    min(SPRING_MEMORY, 1/(zeta_rock omega_rock)): RK4's lag of its phase over T,
    T (2 pi/n)^4/120, is then SPRING_SHIFT (5/steps_per_period)^4. At zeta_rock >= 1
    omega_rock is the overdamped mode's fast decay rate, which RK4 follows without such
    bounds. omega_rock [rad/s], p = 1."""
    w = np.asarray(omega_rock, float)
    zr = np.asarray(zeta_rock, float)
    omega_d = 144.0 * spring_decay(zr, w) * (5.0 / (2 * math.pi)) ** 5
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.maximum(1.0, (OMEGA_SPRING / w) ** 0.4)
        damp = np.where(zr < 1.0, (w / omega_d) ** 0.2, 0.0)
        memory = np.minimum(SPRING_MEMORY, spring_memory(w, zr))
        lag = np.where(zr < 1.0, (2 * math.pi / 5.0)
                       * (memory / (120.0 * SPRING_SHIFT)) ** 0.25, 0.0)
    return steps_per_period * np.maximum(np.maximum(f, damp), lag)


# A rigid body under a pulse just above its uplift threshold (A_ratio = 1: A = g tan
# alpha_ref) rocks in tiny chattering arcs driven by the small difference between the
# ground's push and gravity, (A - 1)/A of the push: the step that integrates the push to the
# pulse's accuracy leaves an error that is large beside that difference. So a rigid body's
# pulse gets min(THRESHOLD_CAP, sqrt(A/(A - 1))) times the pulse steps above the threshold
# (the square root, not the fourth root, matched the reference; docs/accuracy.md, "Rigid
# bodies just above the uplift threshold"): 1.41x at A_ratio 2, 1.05x at 10, THRESHOLD_CAP
# within 7% of 1 (below it a rigid body does not lift off). Flexible bodies are left
# alone: their spring sets their steps there (SPRING_DECAY).
THRESHOLD_CAP = 4.0


def threshold_factor(A_ratio: np.ndarray | float, rigid: np.ndarray | bool) -> np.ndarray:
    """The factor on a pulse's steps of a rigid body near its uplift threshold:
    min(THRESHOLD_CAP, sqrt(|A|/(|A| - 1))) for |A_ratio| > 1, else 1; 1 for a flexible
    body (``rigid`` False). Float64 like A_ratio."""
    a = np.abs(np.asarray(A_ratio, float))
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(a > 1.0, np.minimum(THRESHOLD_CAP, np.sqrt(a / (a - 1.0))), 1.0)
    return np.where(np.asarray(rigid, bool), f, 1.0)


def step_sizes(omega_rock: np.ndarray | float, omega: np.ndarray | float,
               steps_per_period: int, pulse_steps: int = 0,
               omega_amp: np.ndarray | float = 0.0,
               zeta_rock: np.ndarray | float = 0.0,
               A_ratio: np.ndarray | float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The RK4 steps [p*t] of a run: (dt, dt_on), after and while the ground moves.

    The step follows the time scales that act at each moment. Always: the top mass's
    spring period while the base rocks (2 pi/omega_rock, the stiffest the kernel meets;
    inf for a rigid body) over ``spring_steps`` and the rocking period scale 2 pi/p
    (= 2 pi) over ``steps_per_period``: that is dt (zeta_rock: the spring's damping ratio
    while rocking, ``spring_steps``). While the pulse (or record) acts, also
    its period 2 pi/omega over max(pulse_steps, steps_per_period) and the pulse's own
    rocking time scale 2 pi/omega_amp (``amplitude_frequency``; 0 leaves it out) over
    steps_per_period: dt_on <= dt. A short, strong pulse thus gets the steps its work on
    the body needs (at 5 steps per pulse period that work is ~2% off, enough to flip
    outcomes), and the free rocking after it is not stepped at the pulse's rate.
    While the body rocks, the kernel shortens either further so that one step turns the
    body by at most ``Numerics.rotation_step`` x alpha_cg (PAR_ROT_STEP,
    ``rocksweep.kernel.loop``). omega = 0 (a record: no period) leaves the pulse out. A
    rigid body (omega_rock = 0) just above its uplift threshold gets ``threshold_factor``
    (A_ratio) times the pulse's steps (0, the default, leaves them alone).
    """
    two_pi = 2 * math.pi
    n_on = max(int(pulse_steps), int(steps_per_period))
    w = np.asarray(omega_rock, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        spring = np.where(w > 0.0, two_pi / (w * spring_steps(w, steps_per_period,
                                                                zeta_rock)), np.inf)
        free = np.minimum(spring, two_pi / steps_per_period)
        n_pulse = n_on * threshold_factor(A_ratio, w == 0.0)
        on = np.minimum(free, two_pi / np.asarray(omega, float) / n_pulse)
        on = np.minimum(on, two_pi / np.asarray(omega_amp, float) / steps_per_period)
    return free, on


def vertical_step(dt_on: np.ndarray | float, omega_v: np.ndarray | float,
                  steps_per_period: int, pulse_steps: int = 0) -> np.ndarray:
    """dt_on [p*t] shortened to resolve a vertical harmonic of frequency omega_v [rad/s]
    (p = 1) as ``step_sizes`` resolves the pulse: its period over max(pulse_steps,
    steps_per_period). (A vertical record needs nothing more: it is on the horizontal's
    samples, which the steps land on.)"""
    n_on = max(int(pulse_steps), int(steps_per_period))
    with np.errstate(divide="ignore"):
        return np.minimum(dt_on, 2 * math.pi / np.asarray(omega_v, float) / n_on)


def step_budget(t_pulse: np.ndarray | float, t_end: np.ndarray | float,
                dt: np.ndarray | float, dt_on: np.ndarray | float,
                numerics: Numerics) -> np.ndarray:
    """Cap on the RK4 evaluations of one run (the kernel's PAR_MAXSTEPS).

    max_steps_factor x the regular steps of a run to t_end [p*t] (the pulse's t_pulse at
    step dt_on, the rest at dt, all [p*t]), plus EVENT_STEP_ALLOWANCE re-integrations for
    each of max_events events.
    """
    t_pulse = np.minimum(np.asarray(t_pulse, float), np.asarray(t_end, float))
    steps = np.ceil(t_pulse / dt_on) + np.ceil((np.asarray(t_end) - t_pulse) / dt)
    return numerics.max_steps_factor * steps + EVENT_STEP_ALLOWANCE * numerics.max_events


# The margin (OUT_MARGIN, alpha_ref) below which a safe run is a close call, re-run finer
# (``close_margin``), at 5 steps per period: a few times the closest approach of any run
# of the four figures whose `default` outcome differed from `fine`'s before certification
# (docs/accuracy.md, "Where the presets' values come from").
CLOSE_MARGIN = 0.0125
# A safe run is near its threshold up to this many times CLOSE_MARGIN (``close_band``, the
# kernel's PAR_CLOSE): a near-miss turns back on one approach with the error of every step
# before it (a finer run overturned one that `default` turned back with a margin of
# 3.3 x CLOSE_MARGIN; docs/accuracy.md, "Close calls on both sides"). 8, not 4: lightly
# damped bodies whose coarse runs part from the finer ones over many impacts turned back
# with margins of 5-7 x CLOSE_MARGIN where 10 steps and the reference overturn; probing up
# to 8 x halved the unflagged wrong classes of six threshold samples, and with the spring's
# lag bounded (``spring_steps``) 4 still left 15 on twelve samples against 9 at 8
# (docs/accuracy.md, "Round 4", "Lightly damped springs"). 10, not 8: fresh threshold
# samples found safe runs just past 8 x (seed 208 at 8.26 x, a base that may slide, seed
# 20, at 8.5 x) where 20 steps a period and the reference overturn; probing to 10 x
# cost the four adaptive figures 1.4% more RK4 evaluations, the record scenes nothing
# (docs/accuracy.md, "Just outside the band"). The bands of grazes below (GRAZE_BAND,
# MODE_BAND, LIFT_BAND x PAR_CLOSE) kept their size in alpha_ref.
CLOSE_BAND = 10.0
# An overturn is a close call up to this many times CLOSE_MARGIN: it commits to falling on
# one approach with the error of every step before it (finer runs survived overturns that
# `default` committed to with margins to 6.5 x CLOSE_MARGIN). 16 caught 3 more of six
# threshold samples' ~12 000 points and cost rigid blocks' full grids 14% more RK4
# evaluations (docs/accuracy.md, "Round 4").
OVERTURN_BAND = 8.0
# A safe run between the margin and the band is checked by a finer run that stops this long
# [p t] after the run was last within the band (OUT_T_CLOSE): long enough for a body that
# passes the saddle there to reach theta = pi/2 (~ln(pi/alpha_ref)/p from alpha_ref/2
# past the saddle: < 6 for alpha_ref > 0.01), short of the rocking to rest that holds most
# of such a run's steps.
CLOSE_AFTER = 4.0 * math.pi
# A spring that remembers its past longer than RINGING_MEMORY [p t] (``spring_memory``,
# the kernel's PAR_MEMORY) carries the step's error across many impacts: such a body's
# coarse run parts from the finer ones far from the saddle, and the finer run falls on an
# approach the coarse one passed wide, after a probe's stop. Its safe runs are close calls
# (full runs) up to RINGING_BAND x the band, its overturns up to RINGING_BAND x
# OVERTURN_BAND x the close-call margin, its class is trusted only from two refined runs,
# and a repeated safe outcome below the last level only where both runs made the same
# number of impacts, within IMPACT_AGREE of the larger (``compute.certify.same_path``).
# The four figures' springs remember 0.26-1.05 p t; the threshold samples' wrong,
# unflagged classes were bodies of 12-90 p t (docs/accuracy.md, "Springs that ring long",
# "Two paths, one class"), then of 4.1 and 4.16 p t (seeds 91 and 143: a coarse run whose
# path parted from the finer ones' over its impacts, 7 against 6), so 3, not 5: +3.6% of
# the certified evaluations on fresh threshold samples, nothing measurable on the shipped
# scenes ("A graze far from the saddle").
RINGING_MEMORY = 3.0
RINGING_BAND = 2.0
# Seeds 54 and 64's default runs at 5 and 10 steps a period rocked to rest after 24 and
# 29, 82 and 36 impacts where finer runs fall in mode 1 (after 22 and 12); of the ~1800
# safe runs of ringing bodies on seeds 51-70, 1 in 9 differed by more than this between
# the two levels and all but 7 of those agreed at the next.
IMPACT_AGREE = 0.1
# A rocking arc that turns back just short of an impact (a graze: OUT_GRAZE, the least
# minimum of s theta in a step while the ground moves, in alpha_ref) decides whether that
# impact happens, and a coarse run can miss one a finer run makes: flexible bodies just
# above the pulse's uplift threshold rocked to rest at 5 and 10 steps a period where 20
# steps and the reference overturn, after an arc that grazed theta = 0 at 7-8e-4
# alpha_ref, then 1.3-2.6e-4, and finer runs impacted (docs/accuracy.md, "Grazes while
# the ground moves"). Below the last level, a repeated outcome whose finer run grazed
# below GRAZE_MARGIN with a graze that moved by more than itself between the two runs is
# not trusted (``compute.certify.grazed``).
GRAZE_MARGIN = 1e-3
# ... and a run that grazed below GRAZE_BAND x PAR_CLOSE (GRAZE_MARGIN at 5 steps a period,
# scaled with the step as the band) is re-run finer whatever its margin, safe or overturned
# (``compute.certify.graze_close``): threshold seed 123's safe run at 5 steps a period, 0.2
# alpha_ref from the saddle, turned back 2e-4 alpha_ref short of an impact during the
# pulse, which 10 steps a period and finer make, and fall in mode 1 as the reference. On
# Figure 4(b)'s adaptive points (1000 x 1000 x 3 lam) the graze of such a run moved by 17%
# of itself (median; 80% at the 90th percentile) between 5 and 40 steps a period;
# MODE_BAND's band, 20 times as wide, cost that figure 18% more RK4 evaluations, this one
# 2.7% (docs/accuracy.md, "A graze far from the saddle").
GRAZE_BAND = 0.008
# ... and an impact made that shallow while the ground moved (OUT_SHALLOW, the mirror: an
# impact a finer run may miss) sends a run finer where it came within PATH_REACH
# [alpha_ref] of the saddle, safe or overturned (``compute.certify.shallow_close``), as
# does a base that rocked on a slipping corner (``compute.certify.slide_rock_close``):
# where a path may part from the finer runs' there, it can end with its energy a
# barrier's worth away. Threshold seed 36's body, safe at 5 steps a period with margin
# 0.21 after an impact pair 3.6e-4 deep during the pulse, and two Figure 4(b) points,
# safe with margins 0.37 and 0.56 after impacts 2e-4 and 6e-9 deep, where finer runs,
# `fine` and the reference fall in mode 1; on a base that slides, threshold points under
# cosines of A 5-16 whose slide-rock at 5 steps a period took another path than at 10
# (docs/sliding.md, "Near thresholds"). Without the reach, every run with a shallow impact
# (most under a record, whose margins are far or never taken) was re-run: +88% RK4
# evaluations on the record scenes (docs/accuracy.md, "An impact too shallow to trust").
PATH_REACH = 1.0

# A base that may slide whose rocking corner's normal force fell to zero (lifts_off) after
# the ground stopped, with |theta| beyond LIFT_PAST alpha_ref (OUT_LIFT_ANGLE): far past
# the saddle, the body is falling, and where its corner is held changes no class. Such
# lift-offs are not re-run (``compute.certify.lifted_off``). On Figure 3(a)'s sliding
# grid at mu 0.3, 28% of the runs lift off, all at 6.96-10.5 alpha_ref, 0-0.44 p t
# before they lie on their side (re-running them cost +29% RK4 evaluations and changed
# no class); the misses the rule is for lift off during the pulse, near theta = 0.
LIFT_PAST = 2.0

# A repeated overturn still inside the overturn band at its own step, below the last
# level, is certified if its margins have converged (``compute.certify.converged``): both
# runs fell within SAME_FALL [p t] of each other (on the same approach), and the finer
# run's squared margin (~ the energy past the barrier, m^2 ~ |E - E_barrier|/E_ref) is at
# least RICHARDSON_SAFETY times Richardson's estimate of its error, |m_f^2 - m_c^2| /
# (2^ENERGY_ORDER - 1), the energy's error taken to fall as the step^4, one order below
# the step^5 of ``close_margin``, so the estimate errs large. Without the same fall, order
# 5 and safety 1 certified a held-out overturn that finer runs rock to rest (docs/
# accuracy.md, "What the certification costs").
ENERGY_ORDER = 4
RICHARDSON_SAFETY = 2.0
# Any repeated overturn, converged or not, is trusted only where both runs fell within
# SAME_FALL of each other (``compute.certify.certify``). Half a p t: a fall that moved by
# more crept toward the saddle, where the class hangs on the speed it came with (seeds 10
# and 37 of the threshold samples fell 0.67 and 0.86 p t apart at 5 and 10 steps a period
# and rock to rest at 20 and in the reference); on the four adaptive figures (400 x 400 x
# 3 lam) 99% of the repeated falls at refined points are within 0.63 p t, the median 0.003.
SAME_FALL = 0.5
# Below the last level, a repeated outcome is trusted only where the finer run cleared
# CLEARANCE times its own step's close-call margin (``compute.certify.clear``): the
# coarse step's margin scaled as the step^(3/2), not the step^(5/2) of ``close_margin``
# (2^(5/2 - 3/2) = 2). Where impacts lead the motion to its approach, the error can fall
# as the step^3 between the first two levels: at a threshold sample's point (seed 10) the
# speed after a pair of impacts erred by 4.9e-3, 6e-4, 1e-4 alpha_ref p at 5, 10, 20
# steps a period, and the overturn its 5 and 10 steps agreed on (margins 0.0036 and 0.0042
# alpha_ref: 1.9 x the finer step's close-call margin) rocks to rest at 20 and in the
# reference; another's (seed 18) safe runs, 1.9 x too, overturn there (docs/accuracy.md,
# "Clear by twice the margin, events located finer").
CLEARANCE = 2.0
# An overturn's mode (1: after impacts, 2: without) hangs on whether the rocking touched
# theta = 0 before the fall. Where it came near (OUT_MODE_GRAZE: a mode 2's least dip
# toward theta = 0, a mode 1's deepest impact, in alpha_ref) below MODE_BAND x PAR_CLOSE
# (0.02 alpha_ref at 5 steps a period, scaled with the step as the band), the overturn is
# a close call (``compute.certify.mode_close``): on threshold samples, default runs that
# turned back 1e-3 and 8e-3 alpha_ref short of theta = 0 after the pulse fell in mode 2
# where finer runs and the reference impact and fall in mode 1, and one whose only
# impacts (a pair) were as shallow fell in mode 1 where they fall in mode 2 (none was a
# close call by its saddle margin, 0.15-0.2 or inf).
MODE_BAND = 0.16
# A mode 2 also hangs on an uplift it nearly made before the one it fell from: where the
# uplift function M g b - s Q turned back in full contact within LIFT_BAND x PAR_CLOSE of
# M g b of zero (OUT_LIFT_GRAZE: the cubic Hermite minimum of a dip inside a step, as a
# fraction of M g b; 2e-3 at 5 steps a period, scaled with the step as the band), the
# overturn is a close call (``compute.certify.mode_close``). On a threshold sample (seed
# 63) a default run's uplift function turned back 3.5e-5 M g b short of zero and the run
# fell in mode 2, where finer runs and the reference uplift there by ~1e-10 rad, impact
# and fall in mode 1; the dips of the mode 2 runs around it moved by 1.2-1.5e-4 M g b
# between 5 and 10 steps a period (docs/accuracy.md, "Nearly uplifted").
LIFT_BAND = 0.016
# A phase (event to event) that ended inside the first step after its start is one RK4
# step of its own length at every step longer than it: two runs at such steps integrate
# it alike, and their agreement says nothing of its error. Where the finer of two runs had
# one longer than this share of its step before its last approach to the saddle (or its
# fall; OUT_UNSPLIT: a phase shorter than half the finer step errs by at most 1/32 of a
# full step's local error) and came within its band of the saddle (PAR_CLOSE), their
# agreement does not certify the class (``compute.certify.unsplit``).
# Threshold seed 116: a body chattering through the pulse, impacts 0.007-0.044 p t apart;
# the phase of 0.0363 p t after the one at 0.929 p t is a single step at 5 and at 10 steps
# a period (0.073, 0.0366 p t), and theta' after its impact errs by 1.6e-4 and 2.3e-4 rad/s
# there (1.3e-5 at 20 steps, two steps): both runs fall after 7 impacts with margins
# 0.0150 and 0.0152 alpha_ref that converged by every test, where 20 steps a period and
# finer, and the reference, rock to rest. Seeds 37 and 168 (fresh): a chatter after the
# pulse, then both coarse runs creep toward the saddle and turn back where finer runs fall
# (docs/accuracy.md, "A phase no step split").
UNSPLIT_SHARE = 0.5


def close_margin(steps_per_period: int) -> float:
    """How close [alpha_ref] the free rocking may come to the overturning saddle before a
    safe run counts as a close call: CLOSE_MARGIN at 5 steps per period,
    (5/steps_per_period)^(5/2) of it at more (the energy's error falls as the step^5 per
    unit time, the margin it can flip, ~ sqrt(|E - E_barrier|/E_ref), as its square
    root). ``compute.certify`` takes it from the row as PAR_CLOSE / CLOSE_BAND, the one
    definition its bounds are multiples of."""
    return CLOSE_MARGIN * (5.0 / steps_per_period) ** 2.5


def close_band(steps_per_period: int) -> float:
    """CLOSE_BAND x ``close_margin``: the margin [alpha_ref] below which a run is near its
    threshold on either side (the kernel's PAR_CLOSE; ``compute.certify``)."""
    return CLOSE_BAND * close_margin(steps_per_period)


def amplitude_frequency(A_ratio: np.ndarray | float, alpha_ref: np.ndarray | float
                        ) -> np.ndarray:
    """p sqrt(A/g) [rad/s] (p = 1): the rate at which the pulse alone turns the body.

    A = A_ratio g tan(alpha_ref). The pulse's moment about a corner gives the body an
    angular acceleration of about M h_cg A / I_O <= p^2 A/g (p^2 = M g R_cg / I_O), so it
    turns the body through a radian in about 1/(p sqrt(A/g)). Below A = g (the paper's
    ranges) this is slower than the rocking scale p and changes nothing; far above it
    (A_ratio = 1e3 overturns the body in a few hundredths of 2 pi/p) a step following only
    2 pi/p would jump over the whole motion.
    """
    return np.sqrt(np.abs(np.asarray(A_ratio, float)) * np.tan(np.asarray(alpha_ref, float)))
