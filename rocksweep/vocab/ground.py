"""Ground motions: pulse shapes, records and the intensity measures of a record suite.

Shapes (``pulse.shape``; ``rocksweep.physics.excitation`` defines each as a function of
the phase phi = w t, the kernel evaluates the same formulas, ``pulse_acc``): ``sine``,
``cosine`` (eq. 2; n cycles), ``ricker``, ``mp`` (Mavroeidis-Papageorgiou, OpenSees'
``MPAcc``). A record (``ground.record``/``ground.records``) runs as the shape ``record``.

Intensity measures of a suite (``ground.scale.im``): PGA [g], PGV [m/s], Sa(T) [g] at
``SA_DAMPING`` (5%), the slenderness-normalised PGA_ratio = PGA/(g tan alpha_ref),
PGV_ratio = PGV p/(g tan alpha_ref) [-], AvgSa [g], CAV [m/s] and Arias [m/s]; the
component it is taken of (H1, RotD50); a PEER folder's missing components (error, skip);
the two answers of a sweep over the motion's angle (each, worst).
"""

from __future__ import annotations

import math

SINE, COSINE, RICKER, MP = "sine", "cosine", "ricker", "mp"
SHAPES: tuple[str, ...] = (SINE, COSINE, RICKER, MP)
RECORD = "record"  # the shape of a point driven by a ground-motion record
#: the shape of a scene without ground motion (neither pulse: nor ground:): free vibration
#: from the initial state; it runs the pulse variants with A = 0 and a pulse that ends at
#: t = 0 (w_over_p = 0, ``physics.points.run_cost``)
FREE = "free"
#: shapes the kernel's pulse variants run (the paper's; every other shape and a record run
#: the GROUND variants, ``rocksweep.kernel.variants``)
PAPER_SHAPES: tuple[str, ...] = (SINE, COSINE)
#: the kernel's PAR_SHAPE code of each shape (float64 parameter row entry)
SHAPE_CODE: dict[str, float] = {SINE: 0.0, COSINE: 1.0, RICKER: 2.0, MP: 3.0, RECORD: 4.0}
SHAPE_TITLE: dict[str, str] = {SINE: "sine", COSINE: "cosine", RICKER: "Ricker",
                               MP: "Mavroeidis-Papageorgiou", FREE: "free rocking"}
#: the shapes each optional pulse key (pulse.cycles, pulse.gamma, pulse.nu) means something for
PULSE_KEY_SHAPES: dict[str, tuple[str, ...]] = {"cycles": PAPER_SHAPES, "gamma": (MP,),
                                                "nu": (MP,)}
# Defaults of the pulse's optional keys (scene keys pulse.cycles, pulse.gamma, pulse.nu [deg])
CYCLES, GAMMA, NU_DEG = 1, 2.0, 90.0

# Ricker: tau = phi/2 - RICKER_TAU0 (t0 = 1.5/f, f = w/(2 pi)), on for 0 <= phi <= 6 pi
RICKER_TAU0 = 1.5 * math.pi
RICKER_DURATION = 6.0 * math.pi


def pulse_duration(shape: str, cycles: int = CYCLES, gamma: float = GAMMA) -> float:
    """The pulse's duration D in phase (w t): 2 pi n (sine, cosine), 6 pi (Ricker),
    2 pi gamma (MP), 0 (FREE: no ground motion)."""
    if shape == FREE:
        return 0.0
    if shape == RICKER:
        return RICKER_DURATION
    if shape == MP:
        return 2.0 * math.pi * gamma
    return 2.0 * math.pi * cycles


# ---------------------------------------------------------------------------------------
# The Ricker and MP formulas, written once: plain ``math`` on floats, called per sample by
# ``rocksweep.physics.excitation`` and compiled into the kernel (``kernel.equations``,
# which passes its amplitude as ``scale``: the same operations in the same order).
# ---------------------------------------------------------------------------------------

def ricker_tau(phi: float) -> float:
    """tau = pi f (t - t0) = phi/2 - 3 pi/2 of the Ricker wavelet at phase phi."""
    return 0.5 * phi - RICKER_TAU0


def ricker(tau: float, scale: float = 1.0) -> float:
    """scale (1 - 2 tau^2) exp(-tau^2): the Ricker wavelet, peak ``scale`` at tau = 0."""
    return scale * (1.0 - 2.0 * tau * tau) * math.exp(-tau * tau)


def ricker_rate(tau: float, scale: float = 1.0) -> float:
    """d/dphi of ``ricker`` (d tau/d phi = 1/2): scale tau (2 tau^2 - 3) exp(-tau^2)."""
    return scale * tau * (2.0 * tau * tau - 3.0) * math.exp(-tau * tau)


def mp_raw(phi: float, gamma: float, nu: float) -> float:
    """r(phi) = sin(phi/gamma) cos(psi) - gamma (1 - cos(phi/gamma)) sin(psi), psi =
    phi - pi gamma + nu [rad]: the unnormalised MP acceleration (OpenSees' MPAcc)."""
    psi = phi - math.pi * gamma + nu
    x = phi / gamma
    return math.sin(x) * math.cos(psi) - gamma * (1.0 - math.cos(x)) * math.sin(psi)


def mp_raw_rate(phi: float, gamma: float, nu: float) -> float:
    """dr/dphi of ``mp_raw``."""
    psi = phi - math.pi * gamma + nu
    x = phi / gamma
    return (math.cos(psi) * (math.cos(x) / gamma - gamma * (1.0 - math.cos(x)))
            - 2.0 * math.sin(x) * math.sin(psi))


# ---------------------------------------------------------------------------------------
# Intensity measures of a record suite
# ---------------------------------------------------------------------------------------

PGA, PGV, SA, PGA_RATIO, PGV_RATIO = "PGA", "PGV", "Sa", "PGA_ratio", "PGV_ratio"
ARIAS, CAV, D5_95, PGV_OVER_PGA, AVGSA = "Arias", "CAV", "D5_95", "PGV_over_PGA", "AvgSa"
#: the IMs a suite can be scaled to (its stripe dimension's name) and their CF units: every
#: IM that a scale factor F changes (Arias as F^2, the others as F); D5-95 and PGV/PGA do
#: not change with F and cannot be stripes
SCALE_IMS: dict[str, str] = {PGA: "g", PGV: "m/s", SA: "g", PGA_RATIO: "1", PGV_RATIO: "1",
                             AVGSA: "g", CAV: "m/s", ARIAS: "m/s"}
#: the IMs of the records as recorded (a cloud) and the per-record variables holding them
CLOUD_IMS: dict[str, str] = {PGA: "record_pga", PGV: "record_pgv", SA: "record_sa"}
#: what each ratio IM divides (its physical IM)
RATIO_OF: dict[str, str] = {PGA_RATIO: PGA, PGV_RATIO: PGV}
SA_DAMPING = 0.05  # damping ratio of the spectral acceleration (5%)
AVGSA_POINTS = 10  # periods of AvgSa, evenly spaced in ln T
DEFAULT_PERIODS = (0.2, 1.0)  # [s] Sa stored per record
#: the horizontal component a suite's stripe IM is taken of (``ground.scale.component``):
#: the first horizontal's, or RotD50, the median over orientations of both horizontals'
#: (Boore 2010; NGA-West2's convention)
H1, ROTD50 = "H1", "RotD50"
COMPONENTS: tuple[str, ...] = (H1, ROTD50)
#: the stripe IMs RotD50 is taken of (Boore 2010: the median over orientations of a
#: peak: the acceleration's, the velocity's, the 5% oscillator's); AvgSa, CAV and Arias
#: have no RotD50 convention (refused in one line, ``ground.scale.component``)
ROTD50_IMS: tuple[str, ...] = (PGA, PGA_RATIO, PGV, PGV_RATIO, SA)
#: a record of a folder of PEER downloads without one of its components
#: (``ground.missing``): refused, or left out with a warning
MISSING_ERROR, MISSING_SKIP = "error", "skip"
MISSING: tuple[str, ...] = (MISSING_ERROR, MISSING_SKIP)
#: the two answers of a sweep over the ground motion's ``angle`` (an analysis's
#: ``orientation`` dimension): every (record, angle) a sample, or each record at its worst
#: angle (it overturns at any angle)
EACH, WORST = "each", "worst"
ORIENTATIONS: tuple[str, ...] = (EACH, WORST)
#: The record IMs stored per record (the one list): name -> (variable, units, exponent n:
#: the IM of the record times F is F^n times its IM; 0: scale-invariant). Sa(T) is
#: ``record_sa`` along ``period`` (n = 1).
RECORD_IMS: dict[str, tuple[str, str, int]] = {
    PGA: ("record_pga", "g", 1),
    PGV: ("record_pgv", "m/s", 1),
    ARIAS: ("record_arias", "m/s", 2),
    CAV: ("record_cav", "m/s", 1),
    D5_95: ("record_d5_95", "s", 0),
    PGV_OVER_PGA: ("record_pgv_over_pga", "s", 0),
    AVGSA: ("record_avgsa", "g", 1),
}
