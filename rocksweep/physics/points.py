"""One point of a study (body, impact, pulse) -> the kernel's parameter row.

This is the only place where the model's dimensional quantities are packed for the kernel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from rocksweep.kernel import layout as L
from rocksweep.kernel.spring import rocking_spring_omega
from rocksweep.numerics import (
    EVENT_STEP_ALLOWANCE,
    Numerics,
    amplitude_frequency,
    close_band,
    step_budget,
    step_sizes,
    vertical_step,
)
from rocksweep.physics.bodies import Body, FlexibleBody, G, u_cr
from rocksweep.physics.records import GroundRecord, vertical_samples
from rocksweep.physics.vertical import VerticalHarmonic, air_time_harmonic, air_time_record
from rocksweep.vocab.ground import (
    CYCLES,
    FREE,
    GAMMA,
    MP,
    NU_DEG,
    PAPER_SHAPES,
    RECORD,
    RICKER,
    SHAPE_CODE,
    SINE,
    pulse_duration,
)
from rocksweep.vocab.laws import DEFAULT_LAW, LAW_CODE
from rocksweep.vocab.settings import ROOT_CODE

if TYPE_CHECKING:
    from rocksweep.physics.excitation import PulseShape

# shapes, laws and their kernel codes: rocksweep.vocab (the names re-exported here)
# FREE runs as a sine of amplitude 0 that ends at t = 0 (its own code would be a new
# branch of the kernel for nothing)
_SHAPE_CODE = {**SHAPE_CODE, FREE: SHAPE_CODE[SINE]}
_LAW_CODE = LAW_CODE


@dataclass(frozen=True)
class Point:
    """One simulation: a body, the impulse position lam, and a ground motion.

    A pulse (shape one of SHAPES, ``rocksweep.physics.excitation``): w_over_p = omega/p, cycles
    (sine, cosine), gamma and nu [deg] (MP). A record (shape RECORD): ``record`` and the
    body's frequency parameter p [rad/s], which fixes the body's size against the
    record's seconds (kernel time p t); w_over_p is NaN. A is the peak |xg''| either way.
    mu: the friction coefficient of the base on the ground (NaN: none given; only the
    contact status bits read it). law, e, e_factor: the impact law (one of LAWS), the
    coefficient of restitution of law ``constant`` (NaN for the others) and the factor on
    the law's e (``rocksweep.physics.impact``).
    """

    body: Body
    lam: float
    shape: str
    w_over_p: float
    A_ratio: float
    cycles: int = CYCLES
    gamma: float = GAMMA
    nu: float = NU_DEG
    record: GroundRecord | None = None
    p: float = math.nan
    mu: float = math.nan
    law: str = DEFAULT_LAW
    e: float = math.nan
    e_factor: float = 1.0
    # the state at t = 0 (``INITIAL``, normalised; all 0: at rest in full contact)
    initial: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    # a vertical ground acceleration (docs/vertical.md): the record's vertical component
    # (with ``record``, ``ground.vertical``), or a harmonic while the pulse acts
    # (``pulse.vertical``)
    vertical: GroundRecord | None = None
    pulse_vertical: VerticalHarmonic | None = None

    @property
    def omega(self) -> float:
        return self.w_over_p * self.body.p

    @property
    def A(self) -> float:
        """Pulse amplitude [m/s^2]: A_ratio * g tan(alpha_cg) (alpha for a block)."""
        return self.A_ratio * G * math.tan(self.body.alpha_ref)

    @property
    def ground(self) -> int:
        """The kernel variants' ground code the point needs (``layout.GROUND_*``):
        GROUND_VERTICAL with a vertical, GROUND_ANY for the shapes beyond the paper's."""
        if self.vertical is not None or self.pulse_vertical is not None:
            return L.GROUND_VERTICAL
        return L.GROUND_ANY if self.shape not in (*PAPER_SHAPES, FREE) else L.GROUND_PULSE

    def vertical_on_samples(self) -> np.ndarray | None:
        """The vertical record [g] on the horizontal record's samples (None without)."""
        if self.vertical is None or self.record is None:
            return None
        return vertical_samples(self.vertical, self.record)

    @property
    def pulse(self) -> PulseShape | None:
        """The pulse's reference definition (None for a record)."""
        from rocksweep.physics.excitation import PulseShape  # scipy: loaded when needed

        if self.shape in (RECORD, FREE):
            return None
        return PulseShape(self.shape, int(self.cycles), float(self.gamma), float(self.nu))

    @property
    def t_pulse(self) -> float:
        """How long the ground moves [p*t]: the pulse's phase duration / omega, or the
        record's last sample time p (npts - 1) DT."""
        if self.shape == RECORD:
            return self.p * self.record.duration
        if self.shape == FREE:
            return 0.0
        return self.pulse.duration / self.omega


def kernel_kind(body: Body) -> int:
    """The specialised kernel a body needs (only the effects it calls for)."""
    if body.rigid:
        return L.KIND_RIGID
    return L.KIND_FLEXIBLE if body.zeta > 0 else L.KIND_FLEXIBLE_UNDAMPED


def body_row(body: Body) -> np.ndarray:
    """The body's part of a parameter row (float64[N_PAR], other entries zero)."""
    row = np.zeros(L.N_PAR)
    row[L.PAR_MTOT] = body.M
    row[L.PAR_B] = body.b
    row[L.PAR_G] = G
    row[L.PAR_HCG] = body.h_cg
    row[L.PAR_IO] = body.I_O
    row[L.PAR_THETA_OVER] = math.pi / 2
    row[L.PAR_LAW] = L.LAW_EQ1  # eq. (1), unless fill_rows is told otherwise
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
    return row


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


def fill_rows(rows: np.ndarray, body_rows: np.ndarray, omega_rock: np.ndarray,
              alpha_ref: np.ndarray, lam: np.ndarray, shape_code: np.ndarray,
              w_over_p: np.ndarray, A_ratio: np.ndarray, numerics: Numerics,
              cycles: int = CYCLES, gamma: float = GAMMA, nu_deg: float = NU_DEG,
              record: GroundRecord | None = None,
              mu: np.ndarray | float = math.nan, law: np.ndarray | float = L.LAW_EQ1,
              e: np.ndarray | float = math.nan, e_factor: np.ndarray | float = 1.0,
              initial: tuple | None = None, u_cr: np.ndarray | float = 0.0,
              vertical: np.ndarray | None = None,
              pulse_vertical: tuple | None = None) -> None:
    """Fill parameter rows in place, vectorised over points.

    rows: float64[n, N_PAR] (out); body_rows: float64[n, N_PAR] from ``body_row``;
    omega_rock, alpha_ref, lam, shape_code, w_over_p, A_ratio: float64[n] (p = 1).
    cycles (sine, cosine), gamma and nu_deg [deg] (MP): the pulse's optional keys, one
    value for all points. With ``record``, every point is driven by it and w_over_p holds
    the body's p [rad/s]; the rows then still lack the samples (``with_record``).
    mu: friction coefficient, float64[n] or a scalar (NaN: none). law (a LAW_* code), e
    (law constant's, else NaN) and e_factor: the impact law, float64[n] or scalars.
    initial: the state at t = 0 as four float64[n] or scalars in ``INITIAL``'s order
    (theta/alpha_ref, theta'/(p alpha_ref), u/u_cr, u'/(p u_cr)), None: at rest; u_cr [m]
    float64[n] or a scalar (0 for a rigid body). PAR_THETA0.. PAR_U_DOT0 in SI (p = 1).
    vertical: with ``record``, its vertical component [g] on its samples
    (``records.vertical_samples``; the rows then lack its samples too: ``with_record``);
    pulse_vertical: (amplitude [g], w_over_p, phase [deg]), float64[n] or scalars, a
    harmonic while the pulse acts. Either fills PAR_V_* and PAR_T_AIR (``physics.vertical``)
    and runs on the GROUND_VERTICAL variants; without, PAR_T_AIR is inf.
    """
    rows[:] = body_rows
    omega = np.asarray(w_over_p, float)  # p = 1 rad/s
    code = np.asarray(shape_code, float)
    zeta_rock = rocking_spring_zeta(omega_rock, body_rows[:, L.PAR_K], body_rows[:, L.PAR_C])
    if record is not None:
        dt, h_rec, t_pulse, t_end, max_steps = record_cost(omega_rock, alpha_ref, omega,
                                                           A_ratio, record, numerics,
                                                           zeta_rock)
        rows[:, L.PAR_REC_DT] = omega * record.dt
        rows[:, L.PAR_REC_H] = h_rec
        dt_on = h_rec
        omega = 0.0
    else:
        # each point's duration in w t by its shape (``vocab.ground.pulse_duration``)
        phase = np.select([code == L.SHAPE_RICKER, code == L.SHAPE_MP],
                          [pulse_duration(RICKER), pulse_duration(MP, gamma=gamma)],
                          pulse_duration(SINE, cycles=cycles))
        dt, dt_on, t_pulse, t_end, max_steps = run_cost(omega_rock, alpha_ref, omega,
                                                        A_ratio, numerics, phase, zeta_rock)
        if np.any(code == L.SHAPE_MP):
            from rocksweep.physics.excitation import mp_peak

            rows[:, L.PAR_GAMMA] = gamma
            rows[:, L.PAR_NU] = math.radians(nu_deg)
            rows[:, L.PAR_AMP_NORM] = 1.0 / mp_peak(float(gamma), float(nu_deg))
    rows[:, L.PAR_T_AIR] = np.inf
    if pulse_vertical is not None:
        amp_v, w_v, phase_v = (np.asarray(v, float) for v in pulse_vertical)
        rows[:, L.PAR_V_AMP] = amp_v * G
        rows[:, L.PAR_V_OMEGA] = w_v
        rows[:, L.PAR_V_PHASE] = np.radians(phase_v)
        rows[:, L.PAR_T_AIR] = air_time_harmonic(amp_v, w_v, phase_v, t_pulse)
        # the step resolves the vertical as it does the pulse; the cap follows
        dt_on = vertical_step(dt_on, w_v, numerics.steps_per_period, numerics.pulse_steps)
        max_steps = step_budget(t_pulse, t_end, dt, dt_on, numerics)
    elif vertical is not None:
        # one factor for both components: a_v = |A| acc_v / PGA_h (A's sign turns the
        # horizontal round only)
        scale = np.abs(A_ratio * G * np.tan(alpha_ref))
        rows[:, L.PAR_V_AMP] = scale
        rows[:, L.PAR_V_REC] = L.PAR_REC + record.npts + 1
        rows[:, L.PAR_T_AIR] = air_time_record(np.asarray(vertical) / record.pga,
                                               rows[:, L.PAR_REC_DT], scale / G)
    rows[:, L.PAR_AMP] = A_ratio * G * np.tan(alpha_ref)
    rows[:, L.PAR_OMEGA] = omega
    rows[:, L.PAR_SHAPE] = code
    rows[:, L.PAR_TPULSE] = t_pulse
    rows[:, L.PAR_LAM] = lam
    rows[:, L.PAR_DT] = dt
    rows[:, L.PAR_DT_ON] = dt_on
    rows[:, L.PAR_TOL] = numerics.event_tol
    rows[:, L.PAR_TEND] = t_end
    rows[:, L.PAR_MAXSTEPS] = max_steps
    rows[:, L.PAR_MAXEVENTS] = numerics.max_events
    rows[:, L.PAR_RESTRATE] = numerics.rest_rate * alpha_ref  # p = 1
    rows[:, L.PAR_ROOT] = ROOT_CODE[numerics.root]
    rows[:, L.PAR_MU] = mu
    rows[:, L.PAR_ROT_STEP] = numerics.rotation_step * alpha_ref
    rows[:, L.PAR_ALPHA_REF] = alpha_ref
    rows[:, L.PAR_CLOSE] = close_band(numerics.steps_per_period)
    rows[:, L.PAR_LAW] = law
    rows[:, L.PAR_E] = e
    rows[:, L.PAR_E_FACTOR] = e_factor
    if initial is not None:
        th, thd, u, ud = initial
        rows[:, L.PAR_THETA0] = np.asarray(th, float) * alpha_ref
        rows[:, L.PAR_THETA_DOT0] = np.asarray(thd, float) * alpha_ref
        rows[:, L.PAR_U0] = np.asarray(u, float) * u_cr
        rows[:, L.PAR_U_DOT0] = np.asarray(ud, float) * u_cr


def with_record(rows: np.ndarray, record: GroundRecord | None,
                vertical: np.ndarray | None = None) -> np.ndarray:
    """Rows float64[n, N_PAR] -> float64[n, N_PAR + npts] with the record's samples
    xg''/PGA after the parameters (``layout.PAR_REC``); ``rows`` itself without one.
    vertical: its vertical component [g] on its samples: the rows are then float64[n,
    N_PAR + 2 npts + 1], the last horizontal sample once more, then a_v/(g PGA)
    (``layout.PAR_V_REC``)."""
    if record is None:
        return rows
    shape = record.acc / record.pga
    if vertical is not None:
        shape = np.concatenate((shape, shape[-1:], np.asarray(vertical, float) / record.pga))
    out = np.empty((rows.shape[0], L.N_PAR + shape.size))
    out[:, :L.N_PAR] = rows
    out[:, L.N_PAR:] = shape
    return out


def point_row(point: Point, numerics: Numerics) -> np.ndarray:
    """The kernel's parameter row for one point: float64[N_PAR], or float64[N_PAR + npts]
    with a record's samples."""
    body = point.body
    rows = np.empty((1, L.N_PAR))
    rec = point.record if point.shape == RECORD else None
    vertical = point.vertical_on_samples() if rec is not None else None
    pv = point.pulse_vertical
    fill_rows(rows, body_row(body)[None, :], np.array([body_omega_rock(body)]),
              np.array([body.alpha_ref]), np.array([point.lam]),
              np.array([_SHAPE_CODE[point.shape]]),
              np.array([point.p if rec is not None else point.w_over_p]),
              np.array([point.A_ratio]), numerics, point.cycles, point.gamma, point.nu, rec,
              point.mu, law_code(point.law), point.e, point.e_factor,
              point.initial if any(point.initial) else None, u_cr(body), vertical,
              None if pv is None else (pv.amplitude, pv.w_over_p, pv.phase))
    return with_record(rows, rec, vertical)[0]


def shape_code(shape: str) -> float:
    return _SHAPE_CODE[shape]


def law_code(law: str) -> float:
    """The kernel's code (PAR_LAW) of an impact law."""
    return _LAW_CODE[law]
