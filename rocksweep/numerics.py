"""Accuracy knobs of the kernel, the presets, and the step size rule.

Every knob has a measured price: ``rocksweep accuracy SCENE.yaml`` measures time per point
and error against the reference path for each setting; the README's table gives the
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

# name -> (steps_per_period, event_tol). Measured with `rocksweep accuracy FIG.yaml
# --points 1000 --ladder candidates` on configs/fig3a, fig3b, fig4a, fig4b and
# `python scripts/accuracy_tables.py` (README, "Accuracy and its price"). `default` is the
# cheapest setting whose outcomes agree with the reference on >= 99.5% of each scene's
# points, also with two standard errors of the sample off (99.69% or more on all four);
# `draft` is the smallest step allowed (4), ~6% cheaper, >= 99.59% on the four; `fine`
# agrees on every sampled point, with errors ~1e-5 (p*t, theta/alpha_cg). event_tol 1e-5
# and above keep chattering above the rest rate (runs hit the event cap). The presets were
# chosen with bisection; the Hermite finder gives the same outcomes at half the time.
#
# `accurate` (issue 15) is fit for every stored quantity far outside the paper's region:
# the 95th percentile of the overturning-time error is below 0.05 p*t and of the safe runs'
# max|theta| relative error below 1% on the held-out wide-space samples (scripts/
# wide_space.py --seed 2 and 3) and on the stratified sample of configs/wide-space.yaml
# (`rocksweep accuracy configs/wide-space.yaml --points 300 --ladder presets`), where 8
# steps per period left the overturning time at 0.086 p*t (lam = 1.5: energy-gaining
# impacts). `default` keeps 5 steps per period (the paper's figures may not get more than
# ~10% slower) and meets neither there; `sweep --check` stores a per-point estimate of
# what it misses.
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
# their digits (issue 15; measured with scripts/wide_space.py, see the README).
# A quarter of alpha_cg costs the four figures 3.5% more RK4 evaluations at `default` (0.1:
# 15%) and halves the overturning-time tail of the wide-space sample; `accurate` and `fine`
# take 0.1 (0.05 buys little more).
PRESET_ROTATION: dict[str, float] = {
    "draft": 0.25,
    "default": 0.25,
    "fine": 0.1,
    "accurate": 0.1,
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

# Cap on one point's step budget (``step_budget``, PAR_MAXSTEPS) that a scene may imply.
# At the kernel's ~75-120 ns per RK4 evaluation (docs/performance.md, measured by
# scripts/bench_kernel.py) a point that runs to 1e8 takes 8-12 s of one core: the
# longest a single point may take before the
# values are taken for a mistake (w_over_p = 1e-9, a pulse of 6e9 p*t; wn_over_p = 1e5 at
# steps of 1e-5). The shipped scenes need at most 1.5e6 (fig4b at `fine`), of which the
# default allowance for 5000 events is 1e6.
MAX_POINT_STEPS = 1e8


@dataclass(frozen=True)
class Numerics:
    """Resolved numerical settings of a run (all times in p*t).

    steps_per_period: RK4 steps per shortest time scale of the point, see ``step_size``.
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

    @classmethod
    def preset(cls, accuracy: str = "default", **overrides) -> Numerics:
        spp, tol = PRESETS[accuracy]
        return replace(cls(accuracy=accuracy, steps_per_period=spp, event_tol=tol,
                           rotation_step=PRESET_ROTATION[accuracy]), **overrides)

    def describe(self) -> str:
        label = self.accuracy
        base = PRESETS.get(self.accuracy)
        if base is None or base != (self.steps_per_period, self.event_tol) or (
                PRESET_ROTATION[self.accuracy] != self.rotation_step):
            label = "custom"
        return (f"{label} (steps_per_period={self.steps_per_period}, "
                f"event_tol={self.event_tol:g}, rotation_step={self.rotation_step:g}, "
                f"horizon={self.horizon:g}, root={self.root})")

    def as_dict(self) -> dict:
        return asdict(self)


def step_size(omega_rock: np.ndarray | float, omega: np.ndarray | float,
              steps_per_period: int, omega_amp: np.ndarray | float = 0.0) -> np.ndarray:
    """RK4 step [p*t]: the shortest period of the point over ``steps_per_period``.

    The periods are the top mass's spring period while the base rocks (2 pi/omega_rock,
    the stiffest the kernel meets; inf for a rigid body), the pulse period 2 pi/omega,
    the rocking period scale 2 pi/p (= 2 pi) and the pulse's own rocking time scale
    2 pi/omega_amp (``amplitude_frequency``; 0 leaves it out). A stiff spring or a pulse
    far above the uplift threshold thus gets a smaller step. While the body rocks, the
    kernel shortens it further so that one step turns the body by at most
    ``Numerics.rotation_step`` x alpha_cg (PAR_ROT_STEP, ``rocksweep.kernel.loop``).
    """
    two_pi = 2 * math.pi
    with np.errstate(divide="ignore"):
        periods = np.minimum(np.minimum(two_pi / np.asarray(omega_rock, float),
                                        two_pi / np.asarray(omega, float)), two_pi)
        periods = np.minimum(periods, two_pi / np.asarray(omega_amp, float))
    return periods / steps_per_period


def step_budget(t_end: np.ndarray | float, dt: np.ndarray | float,
                numerics: Numerics) -> np.ndarray:
    """Cap on the RK4 evaluations of one run (the kernel's PAR_MAXSTEPS).

    max_steps_factor x the regular steps of a run to t_end [p*t] at step dt [p*t], plus
    EVENT_STEP_ALLOWANCE re-integrations for each of max_events events.
    """
    return numerics.max_steps_factor * np.ceil(np.asarray(t_end) / dt) + EVENT_STEP_ALLOWANCE * (
        numerics.max_events)


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
