"""One point of a study (body, impact, ground motion) -> the kernel's parameter row.

This is the only place where the model's dimensional quantities are packed for the kernel:
``build_rows`` makes the rows of any points (a sweep's chunk, ``scene.grid``; a list of
``Point``s, ``points_rows``), one ``fill_rows`` per excitation they share
(``physics.ground_motion``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rocksweep.kernel import layout as L
from rocksweep.kernel.eq1 import restitution
from rocksweep.kernel.ridge import ridge_energy, ridge_theta
from rocksweep.kernel.spring import rocking_spring_omega
from rocksweep.numerics import (
    EVENT_STEP_ALLOWANCE,
    Numerics,
    amplitude_frequency,
    close_band,
    spring_memory,
    step_budget,
    step_sizes,
)
from rocksweep.physics.bodies import Body, FlexibleBody, G, u_cr
from rocksweep.physics.ground_motion import Excitation, pulse
from rocksweep.physics.records import GroundRecord
from rocksweep.vocab.ground import FREE, RECORD, pulse_duration
from rocksweep.vocab.laws import DEFAULT_LAW, LAW_CODE
from rocksweep.vocab.settings import ROOT_CODE

# the impact laws' kernel codes: rocksweep.vocab.laws
_LAW_CODE = LAW_CODE


@dataclass(frozen=True)
class Point:
    """One simulation: a body, the impulse position lam, and a ground motion.

    excitation: the ground motion (``physics.ground_motion.Excitation``: a pulse, or
    samples the body feels); a pulse shape's name (sine, cosine, ricker, mp, free) stands
    for that pulse with its default options. A pulse is timed by w_over_p = omega/p
    (p: NaN); samples by the body's frequency parameter p [rad/s], which fixes the body's
    size against the record's seconds (kernel time p t; w_over_p: NaN). A_ratio: the
    peak |xg''| of what the body feels over g tan(alpha_ref) (``A``). mu: the kinetic
    friction coefficient of the base on the ground (NaN: none given, the base cannot
    slide; given, it may: the sliding base, ``kernel_contact``); mu_static: the static one
    (NaN: mu's). law, e, e_factor: the impact law (one of LAWS), the coefficient of
    restitution of law ``constant`` (NaN for the others) and the factor on the law's e
    (``rocksweep.physics.impact``).
    """

    body: Body
    lam: float
    excitation: Excitation
    w_over_p: float
    A_ratio: float
    p: float = math.nan
    mu: float = math.nan
    law: str = DEFAULT_LAW
    e: float = math.nan
    e_factor: float = 1.0
    # the state at t = 0 (``INITIAL``, normalised; all 0: at rest in full contact)
    initial: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    mu_static: float = math.nan

    def __post_init__(self) -> None:
        if isinstance(self.excitation, str):
            object.__setattr__(self, "excitation", pulse(self.excitation))

    @property
    def shape(self) -> str:
        """The pulse's shape, or RECORD for samples."""
        return self.excitation.shape

    @property
    def record(self) -> GroundRecord | None:
        """The samples the body feels (None for a pulse)."""
        return self.excitation.record

    @property
    def omega(self) -> float:
        return self.w_over_p * self.body.p

    @property
    def A(self) -> float:
        """Peak |xg''| of what the body feels [m/s^2] (``peak_acc``)."""
        return float(peak_acc(self.A_ratio, self.body.alpha_ref))

    @property
    def ground(self) -> int:
        """The kernel variants' ground code the point needs (its excitation's)."""
        return self.excitation.ground

    @property
    def t_pulse(self) -> float:
        """How long the ground moves [p*t]: the pulse's phase duration / omega, or the
        record's last sample time p (npts - 1) DT."""
        if self.shape == RECORD:
            return self.p * self.record.duration
        if self.shape == FREE:
            return 0.0
        return self.excitation.pulse.duration / self.omega


def peak_acc(A_ratio: np.ndarray | float, alpha_ref: np.ndarray | float) -> np.ndarray:
    """The peak |xg''| of what the body feels [m/s^2], A = A_ratio g tan(alpha_ref) (signed
    like A_ratio; the kernel's PAR_AMP): the one definition, float64 like the input."""
    return A_ratio * G * np.tan(alpha_ref)


def kernel_kind(body: Body) -> int:
    """The specialised kernel a body needs (only the effects it calls for)."""
    if body.rigid:
        return L.KIND_RIGID
    return L.KIND_FLEXIBLE if body.zeta > 0 else L.KIND_FLEXIBLE_UNDAMPED


def kernel_contact(mu: np.ndarray | float) -> int:
    """The contact model (``layout.CONTACT_*``) of points with friction coefficients mu
    (NaN: none given): the sliding base where every point gives mu, the paper's no-slip
    model where none does (ValueError for a mix: the dispatch splits them)."""
    given = np.isfinite(np.asarray(mu, float))
    if given.all():
        return L.CONTACT_SLIDE
    if not given.any():
        return L.CONTACT_NOSLIP
    raise ValueError("points with and without body.mu in one kernel call")


def body_row(body: Body) -> np.ndarray:
    """The body's part of a parameter row (float64[N_PAR], other entries zero)."""
    row = np.zeros(L.N_PAR)
    row[L.PAR_MTOT] = body.M
    row[L.PAR_B] = body.b
    row[L.PAR_G] = G
    row[L.PAR_HCG] = body.h_cg
    row[L.PAR_IO] = body.I_O
    row[L.PAR_THETA_OVER] = math.pi / 2
    row[L.PAR_LAW] = _LAW_CODE[DEFAULT_LAW]  # eq. (1), unless fill_rows is told otherwise
    row[L.PAR_E] = math.nan
    row[L.PAR_E_FACTOR] = 1.0
    if isinstance(body, FlexibleBody):
        row[L.PAR_M] = body.m
        row[L.PAR_MA] = body.m_A
        row[L.PAR_IA0] = body.I_A + body.m_A * body.R_A**2
        row[L.PAR_IAH] = body.I_A + body.m_A * body.h_A**2
        row[L.PAR_H] = body.h
        row[L.PAR_HA] = body.h_A
        row[L.PAR_K] = body.k if not body.rigid else 0.0
        row[L.PAR_C] = body.c
        row[L.PAR_MEMORY] = spring_memory(body_omega_rock(body), body_zeta_rock(body))
    return row


# Results by distinct row (``per_distinct``): a sweep's chunks share their bodies and lam
_RIDGE: dict[bytes, float] = {}
_LOSE: dict[bytes, bool] = {}
_CACHE_MAX = 100_000


def per_distinct(part: np.ndarray, compute: Callable[[np.ndarray], np.ndarray],
                 cache: dict[bytes, Any]) -> np.ndarray:
    """compute(rows float64[k, c]) -> values[k] on the distinct rows of ``part`` (float64[n,
    c], compared bit for bit), each computed once per process and kept in ``cache``
    (cleared past _CACHE_MAX entries). Returns values[n]."""
    c = np.ascontiguousarray(part, float)
    keys, first, back = np.unique(c.view(np.dtype((np.void, c.itemsize * c.shape[1]))).ravel(),
                                  return_index=True, return_inverse=True)
    keys = [k.tobytes() for k in keys]
    new = [j for j, k in enumerate(keys) if k not in cache]
    if new:
        if len(cache) > _CACHE_MAX:
            cache.clear()
        cache.update(zip([keys[j] for j in new], compute(c[first[new]]), strict=True))
    return np.array([cache[k] for k in keys])[back.ravel()]


def ridge_column(rows: np.ndarray) -> np.ndarray:
    """PAR_RIDGE of body rows float64[n, N_PAR] (``body_row``): theta_r [rad], where a
    flexible body's ridge of potential energy peaks (``kernel.ridge.ridge_theta``), NaN for
    a rigid body (k = 0), float64[n]."""
    cols = [L.PAR_M, L.PAR_MA, L.PAR_H, L.PAR_HA, L.PAR_B, L.PAR_K, L.PAR_G]

    def theta_r(r: np.ndarray) -> np.ndarray:
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(r[:, cols.index(L.PAR_K)] > 0.0, ridge_theta(*r.T), math.nan)

    return per_distinct(rows[:, cols], theta_r, _RIDGE).astype(float)


# The top mass's positions, as fractions of the largest |u| an impact can have below the
# ridge, on which ``impacts_lose`` checks eq. (1)'s energy balance (a smooth rational
# function of u; the slack below covers it between the grid's points)
_IMPACT_U = np.linspace(-1.0, 1.0, 201)
_IMPACT_SLACK = 1e-6


def impacts_lose(rows: np.ndarray) -> np.ndarray:
    """bool[n]: rows (float64[n, N_PAR], filled) of flexible bodies whose every impact loses
    energy once the run's energy is below the ridge W(theta_r) (``ridge_column``): what
    ``kernel.transitions.flexible_bounded`` needs to end a run.

    An impact is at theta = 0, where V - V_rest = 1/2 k u^2, so |u| <= sqrt(2 W(theta_r) /
    k). Under eq. (1) and a constant e the top mass keeps its velocity, and the impact loses
    1/2 (I_0 + m (u - s b)^2) w^2 - 1/2 (I_0 + m (u + s b)^2) (e w)^2 (``equations.
    impact_loss``, I_0 = PAR_IA0): >= 0 where e <= 0 (full contact) or e^2 (I_0 + m (u +
    s b)^2) <= I_0 + m (u - s b)^2, checked on ``_IMPACT_U``'s grid of |u| for both corners
    with e of the row's law and factor (less ``_IMPACT_SLACK``). A locked top mass's impact
    moves it (its loss depends on u'): never. Computed once per distinct (body, lam, law,
    e, e_factor)."""
    cols = [L.PAR_M, L.PAR_MA, L.PAR_IA0, L.PAR_IAH, L.PAR_B, L.PAR_K, L.PAR_RIDGE,
            L.PAR_LAM, L.PAR_LAW, L.PAR_E, L.PAR_E_FACTOR, L.PAR_G, L.PAR_H, L.PAR_HA]

    def lose(part: np.ndarray) -> np.ndarray:
        m, m_a, i_a0, i_ah, b, k, theta_r, lam, law, e_c, factor, g, h, h_a = (
            part[:, j:j + 1] for j in range(len(cols)))
        with np.errstate(invalid="ignore", divide="ignore"):
            w_r = ridge_energy(theta_r, m, m_a, h, h_a, b, k, g)
            u = np.sqrt(2.0 * w_r / k) * _IMPACT_U
            ok = (k[:, 0] > 0.0) & (w_r[:, 0] > 0.0) & (law[:, 0] != L.LAW_LOCKED)
            for s in (1.0, -1.0):
                e = np.where(law == L.LAW_CONSTANT, e_c,
                             restitution(s, u, lam, m, m_a, b, i_ah, 0.0)) * factor
                after = e * e * (i_a0 + m * (u + s * b) ** 2)
                ok &= ((e <= 0.0)
                       | (after <= (1.0 - _IMPACT_SLACK) * (i_a0 + m * (u - s * b) ** 2))
                       ).all(axis=1)
        return ok

    return per_distinct(rows[:, cols], lose, _LOSE).astype(bool)


def body_omega_rock(body: Body) -> float:
    """Fastest rate of the top mass's motion [rad/s], which the step must follow (0 for a
    rigid body: no spring).

    While the base rocks, the spring and the damper reach the top mass also through the
    base's rotation: a spring of frequency omega_n sqrt(Gamma) and damping ratio
    zeta sqrt(Gamma), Gamma = 1 + m h^2 / (I_A + m_A R_A^2 + m a^2) with a = u - s b the
    top mass's lever arm (``rocksweep.kernel.spring.rocking_spring_omega``, the one
    definition). ``body.omega_rock`` takes a = b (u = 0); Gamma is largest at a = 0 (the
    top mass above the corner), which rocking reaches whenever |u| ~ b, so that is the rate
    used. Above a damping ratio of 1 the mode is overdamped and its fast root,
    omega (zeta' + sqrt(zeta'^2 - 1)), is what an explicit RK4 step must resolve (it is
    unstable beyond |lambda dt| ~ 2.8): a slender, tall body with a light base (m h^2 >>
    I_A + m_A R_A^2) and zeta ~ 0.2 has zeta' ~ 5 (found by the hard cases' property test).
    """
    if body.rigid:
        return 0.0
    i_a0 = body.I_A + body.m_A * body.R_A**2
    return float(rocking_spring_omega(body.omega_n, body.zeta, body.m, body.h, i_a0, 0.0))


def rocking_spring_zeta(omega_rock: np.ndarray | float, k: np.ndarray | float,
                        c: np.ndarray | float) -> np.ndarray:
    """The spring's damping ratio while the base rocks, zeta' = zeta sqrt(Gamma) =
    c omega_rock / (2 k) (``rocking_spring_omega``: omega_rock = omega_n sqrt(Gamma),
    omega_n = sqrt(k/m), zeta = c / (2 sqrt(k m))), where it is below 1; where the mode is
    overdamped, omega_rock is its fast root and this is zeta' (zeta' + sqrt(zeta'^2 - 1)),
    above 1 too: < 1 says the mode oscillates (``numerics.spring_steps``). k [N/m], c
    [N s/m], omega_rock [rad/s], p = 1; 0 for a rigid body (k = 0). float64 like the input."""
    k = np.asarray(k, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(k > 0.0, np.asarray(c, float) * np.asarray(omega_rock, float)
                        / (2.0 * k), 0.0)


def body_zeta_rock(body: Body) -> float:
    """``rocking_spring_zeta`` of a body (0 for a rigid one)."""
    if body.rigid:
        return 0.0
    return float(rocking_spring_zeta(body_omega_rock(body), body.k, body.c))


def run_cost(omega_rock: np.ndarray, alpha_ref: np.ndarray, w_over_p: np.ndarray,
             A_ratio: np.ndarray, numerics: Numerics,
             phase: np.ndarray | float = 2 * math.pi,
             zeta_rock: np.ndarray | float = 0.0) -> tuple[np.ndarray, ...]:
    """A run's steps, length and step cap, vectorised over points (all float64[n], p = 1).

    phase: the pulse's duration in w t (2 pi n, 6 pi for the Ricker, 2 pi gamma for MP).
    zeta_rock: the spring's damping ratio while rocking (``rocking_spring_zeta``; 0, the
    default, takes the spring to oscillate: the most steps). Returns dt [p*t] after the
    pulse and dt_on while it acts (``step_sizes``), t_pulse =
    phase/omega, t_end = t_pulse + horizon [p*t] and the cap on RK4 evaluations
    (``step_budget``): the kernel's PAR_DT, PAR_DT_ON, PAR_TPULSE, PAR_TEND and
    PAR_MAXSTEPS. The scene bounds the last (MAX_POINT_STEPS). w_over_p = 0 is no ground
    motion (shape FREE): t_pulse = 0.
    """
    omega = np.asarray(w_over_p, float)  # p = 1 rad/s
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        dt, dt_on = step_sizes(omega_rock, omega, numerics.steps_per_period,
                               numerics.pulse_steps, amplitude_frequency(A_ratio, alpha_ref),
                               zeta_rock, A_ratio)
        t_pulse = np.where(omega == 0.0, 0.0, phase / omega)
        t_end = t_pulse + numerics.horizon
        max_steps = step_budget(t_pulse, t_end, dt, dt_on, numerics)
    return dt, dt_on, t_pulse, t_end, max_steps


def record_cost(omega_rock: np.ndarray, alpha_ref: np.ndarray, p: np.ndarray,
                A_ratio: np.ndarray, record: GroundRecord, numerics: Numerics,
                zeta_rock: np.ndarray | float = 0.0) -> tuple[np.ndarray, ...]:
    """``run_cost`` for a record, vectorised over points (float64[n]; p [rad/s]).

    The step after the record is ``step_sizes``' dt (no pulse period). While the record
    acts the step is h_rec = p DT / m, m = ceil(p DT / dt_on): the largest step of at most
    dt_on that lands on every sample time (the kernel's PAR_REC_H); after the last sample
    the kernel steps at dt again, so the cap counts the record's time at h_rec and the
    free vibration after it at dt (a short record sampled at 100 kHz costs what its
    duration asks, not its horizon at the sample spacing). Returns (dt, h_rec, t_pulse =
    p (npts - 1) DT, t_end = t_pulse + horizon, step cap), p*t.
    """
    p = np.asarray(p, float)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        dt, dt_on = step_sizes(omega_rock, 0.0, numerics.steps_per_period,
                               numerics.pulse_steps, amplitude_frequency(A_ratio, alpha_ref),
                               zeta_rock)
        dt_k = p * record.dt
        h_rec = dt_k / np.ceil(dt_k / dt_on)
        t_pulse = p * record.duration
        t_end = t_pulse + numerics.horizon
        steps = np.ceil(t_pulse / h_rec) + np.ceil(numerics.horizon / dt) + 1.0
        max_steps = numerics.max_steps_factor * steps + EVENT_STEP_ALLOWANCE * (
            numerics.max_events)
    return dt, h_rec, t_pulse, t_end, max_steps


@dataclass(frozen=True)
class Bodies:
    """The bodies of n points, as the rows and the results take them (one entry a point):
    rows float64[n, N_PAR] (``body_row``), omega_rock [rad/s] (``body_omega_rock``),
    alpha_ref [rad], E_ref [J], u_cr [m] (0 for a rigid body): float64[n]; kinds: int64[n]
    (``kernel_kind``)."""

    rows: np.ndarray
    omega_rock: np.ndarray
    alpha_ref: np.ndarray
    E_ref: np.ndarray
    u_cr: np.ndarray
    kinds: np.ndarray

    @classmethod
    def of(cls, bodies: Sequence[Body]) -> Bodies:
        """The entries of these bodies (each computed once per distinct body object)."""
        first: dict[int, int] = {}
        index = np.array([first.setdefault(id(b), len(first)) for b in bodies], np.int64)
        distinct = list({id(b): b for b in bodies}.values())
        rows = np.empty((len(distinct), L.N_PAR))
        for j, b in enumerate(distinct):
            rows[j] = body_row(b)
        rows[:, L.PAR_RIDGE] = ridge_column(rows)
        return cls(rows, np.array([body_omega_rock(b) for b in distinct], float),
                   np.array([b.alpha_ref for b in distinct], float),
                   np.array([b.E_ref for b in distinct], float),
                   np.array([u_cr(b) for b in distinct], float),
                   np.array([kernel_kind(b) for b in distinct], np.int64)).take(index)

    def take(self, index: np.ndarray) -> Bodies:
        """The entries at ``index`` (int64[m] or bool[n])."""
        return Bodies(*(np.asarray(v)[index] for v in (self.rows, self.omega_rock,
                                                       self.alpha_ref, self.E_ref,
                                                       self.u_cr, self.kinds)))


@dataclass(frozen=True)
class Columns:
    """A point's own numbers, for n points: float64[n] arrays or scalars (one value for
    all). lam; rate: a pulse's w_over_p, or the body's p [rad/s] against samples; A_ratio:
    the kernel's (``Point.A_ratio``); mu, mu_static (NaN: none; mu_static NaN: mu's); law
    (a LAW_* code), e (law constant's, else NaN) and e_factor: the impact law; initial:
    the state at t = 0 as four arrays or scalars in ``INITIAL``'s order (theta/alpha_ref, theta'/(p
    alpha_ref), u/u_cr, u'/(p u_cr)), None: at rest."""

    lam: np.ndarray | float
    rate: np.ndarray | float
    A_ratio: np.ndarray | float
    mu: np.ndarray | float = math.nan
    law: np.ndarray | float = _LAW_CODE[DEFAULT_LAW]
    e: np.ndarray | float = math.nan
    e_factor: np.ndarray | float = 1.0
    initial: tuple | None = None
    mu_static: np.ndarray | float = math.nan

    def take(self, sel: np.ndarray) -> Columns:
        """The columns at ``sel`` (bool[n] or int64[m]); scalars stay."""
        def part(v):
            return v[sel] if np.ndim(v) else v

        return replace(self, **{k: part(getattr(self, k)) for k in (
            "lam", "rate", "A_ratio", "mu", "law", "e", "e_factor", "mu_static")},
            initial=None if self.initial is None else tuple(part(v) for v in self.initial))


def fill_rows(rows: np.ndarray, bodies: Bodies, excitation: Excitation, columns: Columns,
              numerics: Numerics) -> None:
    """Fill the parameter rows float64[n, N_PAR] (out) of n points that share one
    excitation, vectorised over them: the bodies' part (``Bodies``), the ground motion's
    (its time scale, length and steps: ``run_cost``, or ``record_cost`` for samples, which
    the rows then still lack: ``Excitation.with_samples``; gravity g + a_v:
    ``Excitation.fill_gravity``), the points' own numbers (``Columns``; PAR_THETA0..
    PAR_U_DOT0 in SI, p = 1) and the numerics' settings."""
    ex = excitation
    rows[:] = bodies.rows
    omega_rock, alpha_ref = bodies.omega_rock, bodies.alpha_ref
    rate = np.asarray(columns.rate, float)  # p = 1 rad/s
    zeta_rock = rocking_spring_zeta(omega_rock, bodies.rows[:, L.PAR_K], bodies.rows[:, L.PAR_C])
    A_ratio = columns.A_ratio
    if ex.record is not None:
        dt, h_rec, t_pulse, t_end, max_steps = record_cost(omega_rock, alpha_ref, rate,
                                                           A_ratio, ex.record, numerics,
                                                           zeta_rock)
        rows[:, L.PAR_REC_DT] = rate * ex.record.dt
        rows[:, L.PAR_REC_H] = h_rec
        dt_on = h_rec
        omega = 0.0
    else:
        # the duration in w t of the shape (``vocab.ground.pulse_duration``)
        phase = pulse_duration(ex.shape, cycles=ex.cycles, gamma=ex.gamma)
        dt, dt_on, t_pulse, t_end, max_steps = run_cost(omega_rock, alpha_ref, rate,
                                                        A_ratio, numerics, phase, zeta_rock)
        omega = rate
        if not math.isnan(ex.mp_norm):
            rows[:, L.PAR_GAMMA] = ex.gamma
            rows[:, L.PAR_NU] = math.radians(ex.nu)
            rows[:, L.PAR_AMP_NORM] = ex.mp_norm
    A = peak_acc(A_ratio, alpha_ref)
    ex.fill_gravity(rows, A, t_pulse)
    if ex.harmonic is not None:  # the step resolves the harmonic as it does the pulse
        dt_on = ex.step_on(dt_on, numerics)
        max_steps = step_budget(t_pulse, t_end, dt, dt_on, numerics)
    rows[:, L.PAR_AMP] = A
    rows[:, L.PAR_OMEGA] = omega
    rows[:, L.PAR_SHAPE] = ex.code
    rows[:, L.PAR_TPULSE] = t_pulse
    rows[:, L.PAR_LAM] = columns.lam
    rows[:, L.PAR_DT] = dt
    rows[:, L.PAR_DT_ON] = dt_on
    rows[:, L.PAR_TOL] = numerics.event_tol
    rows[:, L.PAR_TEND] = t_end
    rows[:, L.PAR_MAXSTEPS] = max_steps
    rows[:, L.PAR_MAXEVENTS] = numerics.max_events
    rows[:, L.PAR_RESTRATE] = numerics.rest_rate * alpha_ref  # p = 1
    rows[:, L.PAR_ROOT] = ROOT_CODE[numerics.root]
    rows[:, L.PAR_MU] = columns.mu
    mu_s = np.asarray(columns.mu_static, float)
    rows[:, L.PAR_MU_STATIC] = np.where(np.isnan(mu_s), columns.mu, mu_s)
    rows[:, L.PAR_ROT_STEP] = numerics.rotation_step * alpha_ref
    rows[:, L.PAR_ALPHA_REF] = alpha_ref
    rows[:, L.PAR_CLOSE] = close_band(numerics.steps_per_period)
    rows[:, L.PAR_LAW] = columns.law
    rows[:, L.PAR_E] = columns.e
    rows[:, L.PAR_E_FACTOR] = columns.e_factor
    # the energy bound only where impacts lose energy (``impacts_lose``)
    rows[:, L.PAR_RIDGE] = np.where(impacts_lose(rows), rows[:, L.PAR_RIDGE], math.nan)
    if columns.initial is not None:
        th, thd, u, ud = columns.initial
        rows[:, L.PAR_THETA0] = np.asarray(th, float) * alpha_ref
        rows[:, L.PAR_THETA_DOT0] = np.asarray(thd, float) * alpha_ref
        rows[:, L.PAR_U0] = np.asarray(u, float) * bodies.u_cr
        rows[:, L.PAR_U_DOT0] = np.asarray(ud, float) * bodies.u_cr


def build_rows(bodies: Bodies, excitations: Sequence[Excitation], which: np.ndarray,
               columns: Columns, numerics: Numerics) -> np.ndarray:
    """The parameter rows float64[n, N_PAR] of n points: point i driven by
    ``excitations[which[i]]`` (which: int64[n]), filled excitation by excitation
    (``fill_rows``; each excitation's samples are added by ``Excitation.with_samples``
    just before the kernel runs)."""
    n = which.size
    rows = np.empty((n, L.N_PAR))
    if len(excitations) == 1:
        fill_rows(rows, bodies, excitations[0], columns, numerics)
        return rows
    for j, ex in enumerate(excitations):
        sel = which == j
        if not sel.any():
            continue
        part = np.empty((int(sel.sum()), L.N_PAR))
        fill_rows(part, bodies.take(sel), ex, columns.take(sel), numerics)
        rows[sel] = part
    return rows


def points_rows(points: Sequence[Point], numerics: Numerics
                ) -> tuple[np.ndarray, tuple[Excitation, ...], np.ndarray]:
    """The rows of arbitrary points (``build_rows``): (rows float64[n, N_PAR], the
    distinct excitations, which: int64[n], each point's index into them)."""
    first: dict[int, int] = {}
    which = np.array([first.setdefault(id(p.excitation), len(first)) for p in points],
                     np.int64)
    excitations = tuple({id(p.excitation): p.excitation for p in points}.values())

    def column(name: str) -> np.ndarray:
        return np.array([getattr(p, name) for p in points], float)

    rate = np.array([p.w_over_p if p.record is None else p.p for p in points], float)
    initial = (None if not any(any(p.initial) for p in points) else
               tuple(np.array(v, float) for v in zip(*(p.initial for p in points),
                                                      strict=True)))
    columns = Columns(column("lam"), rate, column("A_ratio"), column("mu"),
                      np.array([law_code(p.law) for p in points]), column("e"),
                      column("e_factor"), initial, column("mu_static"))
    rows = build_rows(Bodies.of([p.body for p in points]), excitations, which, columns,
                      numerics)
    return rows, excitations, which


def point_row(point: Point, numerics: Numerics) -> np.ndarray:
    """The kernel's parameter row for one point: float64[N_PAR], or float64[N_PAR + npts]
    with its samples (``Excitation.with_samples``)."""
    rows, _, _ = points_rows([point], numerics)
    return point.excitation.with_samples(rows)[0]


def law_code(law: str) -> float:
    """The kernel's code (PAR_LAW) of an impact law."""
    return _LAW_CODE[law]
