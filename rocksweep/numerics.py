"""Accuracy knobs of the kernel, the presets, and the step size rule.

Every knob has a measured price: ``rocksweep accuracy SCENE.yaml`` measures time per point
and error against the reference path for each setting; docs/accuracy.md gives the
presets' figures on the shipped paper scenes.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

# Event root finders (``rocksweep.kernel.events._locate``); each keeps the bracket and
# stops at event_tol. Hermite (the default) takes 2-5 RK4 re-integrations per event (3.8
# on Figure 3(a)) where bisection takes log2(step/event_tol) ~ 20, with bisection steps as
# its safeguard; on the four figures' accuracy samples all three give the same outcomes at
# every preset (`rocksweep accuracy configs/fig3a.yaml --points 1000 --ladder roots`).
ROOTS = ("bisection", "illinois", "hermite")

# name -> (steps_per_period, event_tol). A preset is these with rotation_step
# (PRESET_ROTATION), pulse_steps (PRESET_PULSE) and refine (PRESET_REFINE).
#
# Issue 28 (the step follows what acts, close calls certified): `default` classifies the
# four figures like `fine` on all but 0/0/0/1 of their 19 200 cells each (the rule before
# it: 72/32/1/2), at 0.4-4.6% more RK4 evaluations (1-11% more time) than that
# rule (`python scripts/bench_step_rule.py`), and the held-out-style spectra (blocks alpha
# 0.1/0.25/0.4, three flexible bodies, sine and cosine, omega/p 1-12, A/(g tan alpha) to
# 30 on a 1000-value grid) like `fine` on every curve's first overturning value and mode.
# `draft` is the smallest step allowed (4) with the pulse at 10 steps and no
# certification; `fine` 20 steps per period, the pulse at 40, event_tol 1e-8; the agreement
# of each with the reference and its price: docs/accuracy.md
# (`rocksweep accuracy FIG.yaml --points 1000 --ladder roots`, `scripts/accuracy_tables.py`).
# event_tol 1e-5 and above keep chattering above the rest rate (runs hit the event cap).
#
# `accurate` (issue 15) is fit for every stored quantity far outside the paper's region:
# the 95th percentile of the overturning-time error is below 0.05 p*t and of the safe runs'
# max|theta| relative error below 1% on the held-out wide-space samples (scripts/
# wide_space.py --seed 2 and 3) and on the stratified sample of configs/wide-space.yaml
# (`rocksweep accuracy configs/wide-space.yaml --points 300 --ladder presets`), where 8
# steps per period left the overturning time at 0.086 p*t (lam = 1.5: energy-gaining
# impacts). `default` keeps 5 steps per period and meets neither there; `sweep --check`
# stores a per-point estimate of what it misses.
PRESETS: dict[str, tuple[int, float]] = {
    "draft": (4, 1e-6),
    "default": (5, 1e-6),
    "fine": (20, 1e-8),
    "accurate": (10, 1e-8),
}

# name -> rotation_step: the largest rotation one rocking step may make, as a fraction of
# alpha_cg (the kernel's PAR_ROT_STEP = rotation_step * alpha_ref; 0: no such limit). The
# spring, pulse and rocking time scales above set the step in the paper's region; far
# outside it (a pulse 20x the uplift threshold, a fall to overturning, a rigid body) the body
# turns through alpha_cg or more in one step, and the overturning time and max|theta| lose
# their digits (issue 15; measured with scripts/wide_space.py, see docs/accuracy.md).
# A quarter of alpha_cg costs the four figures 3.5% more RK4 evaluations at `default` (0.1:
# 15%) and halves the overturning-time tail of the wide-space sample; `accurate` and `fine`
# take 0.1 (0.05 buys little more).
PRESET_ROTATION: dict[str, float] = {
    "draft": 0.25,
    "default": 0.25,
    "fine": 0.1,
    "accurate": 0.1,
}

# name -> pulse_steps: RK4 steps per pulse period while the pulse acts (at least
# steps_per_period; ``step_sizes``). At 5 (the rule before issue 28) the pulse's work on a
# uniform block (alpha 0.25, sine, omega/p = 8) was ~2% off and its mode-1 band A/(g tan
# alpha) in [10.86, 11.41] (the reference's) vanished; 10 finds [10.87, 11.40], 12 and
# more [10.86, 11.41] (scanned at steps of 0.01). On blocks at omega/p 3-12 (A to 30),
# 12 differs from `fine` on 3 of 18 000 cells (5: 17), for 11% more RK4 evaluations than
# 5; on the four figures it costs 1-3%.
PRESET_PULSE: dict[str, int] = {
    "draft": 10,
    "default": 12,
    "fine": 40,
    "accurate": 20,
}

# name -> refine: most refinements (2x, 4x, ... the steps) of a close call before its
# outcome is called uncertified (``rocksweep.compute.certify``; 0: no certification).
PRESET_REFINE: dict[str, int] = {
    "draft": 0,
    "default": 3,
    "fine": 3,
    "accurate": 3,
}

# Smallest event_tol [p*t] a scene may ask for. An event's time is t0 + tau in float64; at
# t ~ 1e2 (a run lasts the pulse plus the 200-long horizon) its spacing is 1.4e-14, and
# 2.8e-14 to 5.7e-14 up to t = 512: below ~1e-12 the tolerance asks for digits t does not
# have. (The root finders bracket tau inside one step, <= pi/2 long, spacing 2.2e-16, so
# they end for any tolerance above ~1e-15; 1e-12 leaves a margin of ~4000 spacings.)
MIN_EVENT_TOL = 1e-12

# RK4 evaluations the kernel may spend locating one event before a run is capped
# (``step_budget``): bisection takes log2(step/event_tol) ~ 20-40, Hermite 2-5.
EVENT_STEP_ALLOWANCE = 200.0

# Kernel time per RK4 evaluation [s] on the paper's figures at the default preset
# (scripts/bench_compile.py: core-us per point over RK4 evaluations per point, 75-83 ns on
# the four figures on the 2-core reference machine; docs/performance.md): the one price of
# a step, from which a sweep's estimate (``compute.sweep.estimate``, before a sample can
# be run) and the cost of a point at the cap below (``point_seconds``) are derived.
SECONDS_PER_EVALUATION = 85e-9

# Cap on one point's step budget (``step_budget``, PAR_MAXSTEPS) that a scene may imply.
# A point that runs to it takes ``point_seconds(MAX_POINT_STEPS)`` (~8.5 s) of one core:
# the longest a single point may take before the
# values are taken for a mistake (w_over_p = 1e-9, a pulse of 6e9 p*t; wn_over_p = 1e5 at
# steps of 1e-5). The shipped scenes need at most 1.5e6 (fig4b at `fine`), of which the
# default allowance for 5000 events is 1e6.
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
    root: event root finder, one of ROOTS (see ``rocksweep.kernel.events._locate``).
    rotation_step: largest rotation of one rocking step, a fraction of alpha_cg (0: none);
        the step is shortened to it from theta' and the last step's theta'' and a step that
        turned more than twice as far is taken again (``rocksweep.kernel.loop``).
    """

    accuracy: str = "default"
    steps_per_period: int = PRESETS["default"][0]
    event_tol: float = PRESETS["default"][1]
    horizon: float = 200.0
    rest_rate: float = 1e-4
    max_events: int = 5000
    max_steps_factor: float = 20.0
    root: str = "hermite"
    rotation_step: float = PRESET_ROTATION["default"]
    pulse_steps: int = PRESET_PULSE["default"]
    refine: int = PRESET_REFINE["default"]

    @classmethod
    def preset(cls, accuracy: str = "default", **overrides) -> Numerics:
        spp, tol = PRESETS[accuracy]
        return replace(cls(accuracy=accuracy, steps_per_period=spp, event_tol=tol,
                           rotation_step=PRESET_ROTATION[accuracy],
                           pulse_steps=PRESET_PULSE[accuracy],
                           refine=PRESET_REFINE[accuracy]), **overrides)

    def describe(self) -> str:
        label = self.accuracy
        base = PRESETS.get(self.accuracy)
        if base is None or base != (self.steps_per_period, self.event_tol) or (
                PRESET_ROTATION[self.accuracy] != self.rotation_step) or (
                PRESET_PULSE[self.accuracy] != self.pulse_steps) or (
                PRESET_REFINE[self.accuracy] != self.refine):
            label = "custom"
        return (f"{label} (steps_per_period={self.steps_per_period}, "
                f"pulse_steps={self.pulse_steps}, "
                f"event_tol={self.event_tol:g}, rotation_step={self.rotation_step:g}, "
                f"refine={self.refine}, horizon={self.horizon:g}, root={self.root})")

    def refined(self, level: int) -> Numerics:
        """These numerics at 2**level times the steps: a close call's rerun at that
        refinement (``compute.certify.refine_rows`` scales the rows the same way)."""
        f = 2 ** level
        return replace(self, steps_per_period=self.steps_per_period * f,
                       pulse_steps=self.pulse_steps * f,
                       rotation_step=self.rotation_step / f, refine=0)

    def as_dict(self) -> dict:
        return asdict(self)


# The spring's steps (``step_sizes``): steps_per_period x the larger of two factors, each
# bounding one error of RK4 on the top mass's spring while the base rocks (a mode
# u ~ exp(i omega_rock t); at n steps per spring period, y = omega_rock dt = 2 pi/n, RK4
# multiplies it by R(iy) per step, |R(iy)| = sqrt(1 - y^6/72 + y^8/576)).
#
# A softer spring holds more of the energy, ~(p/omega_rock)^2, and RK4 takes ~n^-5 of it
# per unit time (its numerical damping), so a spring below OMEGA_SPRING x p gets
# (OMEGA_SPRING/omega_rock)^(2/5) times the steps: the energy error of Figure 4's spring
# (omega_rock/p = 27.5) at 5 steps. Figure 3(a)'s spring (6.8) gets 1.75x: 73 cells that
# went safe where `fine` overturns (mode 1) became 2, for 0% more RK4 evaluations (the
# rotation limit sets most of its rocking steps).
OMEGA_SPRING = 27.5

# A stiffer spring holds less energy but is damped faster: -ln|R(iy)| per step is
# y^6/144 to leading order, a decay rate of the spring's amplitude of
# omega_rock (2 pi/n)^5/144 per unit p*t, growing with omega_rock at fixed n. At 5 steps
# per period Figure 4's spring (27.5) lost 0.49 p to the integrator (exactly; 0.60 to
# leading order), on top of its physical zeta' omega' = zeta omega_n Gamma = 3.8 p while the
# top mass is over the corner (``rocking_spring_omega``) and 0.49 p in full contact: near
# the uplift threshold under long pulses (A_ratio 0.9-1.4, w_over_p 0.15-1.2, hundreds of
# small uplifts) `default` then classed 10 and 16 of 6579 cells of Figures 4(a)/(b) unlike
# `fine` and the scipy reference, none flagged. So an oscillating spring (zeta' < 1) also
# gets the steps that hold that numerical decay rate to ``spring_decay`` at 5 steps per
# period, (5/steps_per_period)^5 of it at others (the presets keep their order; a
# refinement's doubling halves every step):
#
#     SPRING_DECAY_FREE + SPRING_DECAY_REL x zeta' omega_rock, at most SPRING_DECAY [p].
#
# What the error does to the spring's amplitude depends on what else damps it: driven and
# damped at zeta' omega', the amplitude is off by ~sigma/(zeta' omega'), 1/38 = 2.6% at
# SPRING_DECAY_REL; an undamped spring (zeta = 0) keeps the whole error for as long as the
# run lasts (~50 p*t under a long pulse near the threshold) and gets SPRING_DECAY_FREE,
# 10% of its amplitude over 50 p*t. Measured (scripts/bench_threshold.py; cells of the
# band unlike `fine`, the reference siding with `fine`): at 0.1 p Figure 4's body (3.8 p:
# 0.1) 10/16 -> 2/3, stiffer damped bodies (wn/p = 20, 50) 6 -> 0 and 9 -> 3, and 0.05 or
# 0.02 fix ~nothing more there; three undamped bodies kept 36-127 wrong cells before,
# 19-95 at a flat 0.1 p, 4-26 at a floor of 0.01 p, 5-9 at 0.002 (docs/accuracy.md).
# Price: +15% RK4 evaluations on the four figures at `default`
# (Figures 4(a)/(b) +23%/+22%, their spring's steps 1.43x; `fine` there +38%/+37%), 1.4-1.6x
# on the stiffer damped bodies' band, 3.0-4.6x on the undamped ones' (docs/accuracy.md,
# "Stiff springs near the uplift threshold"); Figure 3's body (6.8 p, zeta' omega' = 0.95
# p), the block and the rigid bodies keep their steps, bit for bit.
SPRING_DECAY = 0.1
SPRING_DECAY_FREE = 0.002
SPRING_DECAY_REL = 1.0 / 38.0


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
    (5/steps_per_period)^5. At zeta_rock >= 1 omega_rock is the overdamped mode's fast
    decay rate, which RK4 follows without such a bound. omega_rock [rad/s], p = 1."""
    w = np.asarray(omega_rock, float)
    zr = np.asarray(zeta_rock, float)
    omega_d = 144.0 * spring_decay(zr, w) * (5.0 / (2 * math.pi)) ** 5
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.maximum(1.0, (OMEGA_SPRING / w) ** 0.4)
        damp = np.where(zr < 1.0, (w / omega_d) ** 0.2, 0.0)
    return steps_per_period * np.maximum(f, damp)


# A rigid body under a pulse just above its uplift threshold (A_ratio = 1: A = g tan
# alpha_ref) rocks in tiny chattering arcs driven by the small difference between the
# ground's push and gravity, (A - 1)/A of the push: the step that integrates the push to the
# pulse's accuracy leaves an error that is large beside that difference. Measured on the
# classic block (configs/block.yaml, sine and cosine, A_ratio 0.9-1.4 x w_over_p 0.15-1.2,
# 4386 cells; `default` against `fine`, the scipy reference siding with `fine`): 31 cells
# differed at pulse_steps alone; (A/(A - 1))^(1/4) more steps left 7, (A/(A - 1))^(1/2)
# left 1, for 69 -> 82 RK4 evaluations a point on that band. So a rigid body's pulse gets
# min(THRESHOLD_CAP, sqrt(A/(A - 1))) times the pulse steps above the threshold: 1.41x at
# A_ratio 2, 1.05x at 10, THRESHOLD_CAP within 7% of 1 (below it a rigid body does not
# lift off). Flexible bodies are left alone: Figure 3's body showed no such cell on the
# same band, and Figure 4's were the spring's (SPRING_DECAY).
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
    outcomes: issue 28), and the free rocking after it is not stepped at the pulse's rate.
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


# The margin (OUT_MARGIN, alpha_ref) below which a run is a close call, re-run finer
# (``close_margin``), at 5 steps per period. Measured on the four figures at `default`
# against `fine` (scripts/bench_certify.py): the outcomes that differ before the
# certification came within 0.005 of the saddle (Figure 3(a), with the spring's steps of
# ``spring_steps``; 0.044 at 5 steps per spring period), 0.003 on Figures 4(a)/(b).
CLOSE_MARGIN = 0.0125


def close_margin(steps_per_period: int) -> float:
    """How close [alpha_ref] the free rocking may come to the overturning saddle before a
    run counts as a close call (the kernel's PAR_CLOSE): CLOSE_MARGIN at 5 steps per
    period, (5/steps_per_period)^(5/2) of it at more (the energy's error falls as the
    step^5 per unit time, the margin it can flip, ~ sqrt(|E - E_barrier|/E_ref), as its
    square root)."""
    return CLOSE_MARGIN * (5.0 / steps_per_period) ** 2.5


def amplitude_frequency(A_ratio: np.ndarray | float, alpha_ref: np.ndarray | float
                        ) -> np.ndarray:
    """p sqrt(A/g) [rad/s] (p = 1): the rate at which the pulse alone turns the body.

    A = A_ratio g tan(alpha_ref). The pulse's moment about a corner gives the body an
    angular acceleration of about M h_cg A / I_O <= p^2 A/g (p^2 = M g R_cg / I_O), so it
    turns the body through a radian in about 1/(p sqrt(A/g)). Below A = g (the paper's
    ranges) this is slower than the rocking scale p and changes nothing; far above it
    (A_ratio = 1e3 overturns the body in a few hundredths of 2 pi/p) a step following only
    2 pi/p would jump over the whole motion (issue 5, "A_ratio huge").
    """
    return np.sqrt(np.abs(np.asarray(A_ratio, float)) * np.tan(np.asarray(alpha_ref, float)))
