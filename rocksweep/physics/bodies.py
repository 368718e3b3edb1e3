"""The flexible rocking oscillator of Zhu, Chatzis & Acikgoz: Pi groups -> dimensional body.

Sketch (body frame, upright; the body is symmetric about its vertical axis)::

              P (m, at x = u, y = h)        top mass on a lateral spring k, damper c
          ----o----
          |       |
          |   A   |    U-shaped base: mass m_A at (0, h_A), inertia I_A about A
          |       |
     o'---+-------+---o     base corners at x = -b (o') and x = +b (o)

Glossary and sign conventions (used everywhere in rocksweep):

- ``theta`` [rad]: rotation of the body, positive clockwise. ``theta > 0`` is rocking on
  the corner at x = +b ("the +b corner"), ``theta < 0`` on the corner at x = -b.
- ``u`` [m]: lateral displacement of the top mass along the body's x axis (it rotates
  with the body), positive toward +b.
- ``s`` = +1 / -1: the corner the body rocks on (sign of theta); 0 is full contact.
- Eq. (1) of the paper: its *upper* sign is, in rocksweep, the impact that ends rocking
  on the +b corner (theta > 0 -> theta < 0, future corner at x = -b), with u positive
  toward +b. Eq. (6) uses the same correspondence.

Non-dimensionalisation (stated once, here). The response depends only on the Pi groups of
Table 1. rocksweep picks the three repeating quantities as

    m = 1 kg,   g = 9.81 m/s^2,   p = 1 rad/s,

so that kernel time t [s] *is* the paper's p*t. All lengths follow from the base half
width b, which is fixed by p = 1:

    h_cg = b / tan(alpha_cg),  h_A = b / tan(alpha_A),  h = ((m + m_A) h_cg - m_A h_A) / m,
    R_x  = sqrt(b^2 + h_x^2)   (x = cg, A, top),
    I_A  = IA_ratio * m_A * R_A^2,
    I_O  = I_A + m_A R_A^2 + m R^2           (inertia about a corner, u = 0),
    p^2  = (m + m_A) g R_cg / I_O   =>   b = (m + m_A) g (R_cg/b) / (I_O/b^2).

Then omega_n = wn_over_p * p, k = m omega_n^2, c = 2 zeta m omega_n,
A = A_ratio * g tan(alpha_cg), omega = w_over_p * p,
u_cr = (m_A/m + 1) g b / (omega_n^2 h)   (as printed; omits the top mass's own P-delta),
E_ref = (m + m_A) g R_cg (1 - cos alpha_cg).

``wn_over_p = inf`` is a rigid body: the top mass is welded to the frame (k = inf, u = 0).
The uniform rectangular block (``BlockBody``) is a rigid body too, with M = 1 kg and
p^2 = M g R / I_O.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rocksweep.errors import BodyError
from rocksweep.kernel import eq1 as _eq1
from rocksweep.schema import BODY_KEYS, check_value, fmt, is_number

G = 9.81  # m/s^2
M_TOP = 1.0  # kg, the top mass m (a repeating quantity)
P = 1.0  # rad/s, the rocking frequency p (a repeating quantity)



def _check_keys(body: object, keys: tuple[str, ...]) -> None:
    """Each Pi group against the scene's table (``rocksweep.schema.KEYS``): the same
    message as in a scene file, ``body.KEY = VALUE: allowed``."""
    for key in keys:
        value = getattr(body, key)
        if not is_number(value):
            raise BodyError(f"body.{key} = {fmt(value)}: must be a number")
        msg = check_value(f"body.{key}", value)
        if msg is not None:
            raise BodyError(msg)


@dataclass(frozen=True)
class FlexibleBody:
    """The paper's body from its Pi groups (Table 1).

    Attributes are the Pi groups; derived dimensional quantities are properties (SI).
    """

    wn_over_p: float  # Pi1; inf = rigid (top mass welded)
    zeta: float  # Pi2
    alpha_cg: float  # Pi3 [rad]
    alpha_A: float  # Pi4 [rad]
    mA_over_m: float  # Pi8
    IA_ratio: float  # Pi9 = I_A / (m_A R_A^2)

    kind = "flexible"

    def __post_init__(self) -> None:
        _check_keys(self, BODY_KEYS["flexible"])
        if self.h_over_b <= 0:
            raise BodyError(
                f"body: alpha_cg = {self.alpha_cg!r}, alpha_A = {self.alpha_A!r}, "
                f"mA_over_m = {self.mA_over_m!r} put the top mass at h/b = {self.h_over_b:.4g} "
                "(must be > 0: the top mass cannot sit below the base); lower alpha_cg, "
                "raise alpha_A or lower mA_over_m"
            )

    # -- geometry in units of b --------------------------------------------------------
    @property
    def h_over_b(self) -> float:
        mu = self.mA_over_m
        return (1 + mu) / math.tan(self.alpha_cg) - mu / math.tan(self.alpha_A)

    @property
    def rigid(self) -> bool:
        return math.isinf(self.wn_over_p)

    # -- dimensional quantities (SI) ---------------------------------------------------
    @property
    def m(self) -> float:
        return M_TOP

    @property
    def m_A(self) -> float:
        return self.mA_over_m * M_TOP

    @property
    def M(self) -> float:
        return self.m + self.m_A

    @cached_property  # every length derives from b; computed once per body
    def b(self) -> float:
        tan_cg, tan_A, hb = math.tan(self.alpha_cg), math.tan(self.alpha_A), self.h_over_b
        rA2 = 1 + 1 / tan_A**2
        j = (self.IA_ratio + 1) * self.mA_over_m * rA2 + (1 + hb**2)  # I_O / (m b^2)
        r_cg = math.hypot(1.0, 1 / tan_cg)
        return (1 + self.mA_over_m) * G * r_cg / (j * P**2)

    @property
    def h(self) -> float:
        return self.h_over_b * self.b

    @property
    def h_A(self) -> float:
        return self.b / math.tan(self.alpha_A)

    @property
    def h_cg(self) -> float:
        return self.b / math.tan(self.alpha_cg)

    @property
    def R(self) -> float:
        return math.hypot(self.b, self.h)

    @property
    def R_A(self) -> float:
        return math.hypot(self.b, self.h_A)

    @property
    def R_cg(self) -> float:
        return math.hypot(self.b, self.h_cg)

    @property
    def I_A(self) -> float:
        return self.IA_ratio * self.m_A * self.R_A**2

    @property
    def I_O(self) -> float:
        """Inertia of the whole body about a base corner with u = 0 [kg m^2]."""
        return self.I_A + self.m_A * self.R_A**2 + self.m * self.R**2

    @property
    def p(self) -> float:
        return math.sqrt(self.M * G * self.R_cg / self.I_O)

    @property
    def omega_n(self) -> float:
        return self.wn_over_p * self.p

    @property
    def k(self) -> float:
        return self.m * self.omega_n**2

    @property
    def c(self) -> float:
        return 0.0 if self.rigid else 2 * self.zeta * self.m * self.omega_n

    @property
    def u_cr(self) -> float:
        """Eq. (4)'s normaliser (m_A/m + 1) g b / (omega_n^2 h) [m]; 0 for a rigid body."""
        return self.M / self.m * G * self.b / (self.omega_n**2 * self.h)

    @property
    def E_ref(self) -> float:
        """(m + m_A) g R_cg (1 - cos alpha_cg) [J]: the energy that tips the rigid body."""
        return self.M * G * self.R_cg * (1 - math.cos(self.alpha_cg))

    @property
    def alpha_ref(self) -> float:
        """The slenderness theta is normalised by (alpha_cg)."""
        return self.alpha_cg

    @property
    def omega_rock(self) -> float:
        """Frequency of the top mass on its spring while the base rocks (u = 0) [rad/s].

        The rocking base is a light, rotating support: the spring sees a smaller mass and
        oscillates faster than omega_n, by sqrt(I_O / (I_A + m_A R_A^2 + m b^2)) (about 2.7
        for the paper's bodies). The step size must resolve this, not omega_n.
        """
        from rocksweep.kernel.spring import rocking_spring_omega  # one definition, no numba

        i_a0 = self.I_A + self.m_A * self.R_A**2
        # undamped, lever arm a = u - s b = -s b at u = 0
        return rocking_spring_omega(self.omega_n, 0.0, self.m, self.h, i_a0, self.b)


@dataclass(frozen=True)
class BlockBody:
    """The uniform rectangular block of the classic rocking literature (rigid).

    ``alpha`` is its slenderness [rad]; ``inertia`` = I_O / (M R^2) (4/3 for a uniform block).
    M = 1 kg, g = 9.81, p^2 = M g R / I_O = 1 rad^2/s^2 fixes R = g / (inertia p^2).
    """

    alpha: float
    inertia: float = 4.0 / 3.0

    # One mass M at its centre, no base/top split, no spring: none of FlexibleBody's m,
    # m_A, h, h_A, I_A, k, c, zeta, u_cr (``u_cr(body)`` for any body; the kernel row of a
    # block carries M, b, h_cg and I_O, ``rocksweep.physics.points.body_row``)
    kind = "block"
    rigid = True
    M = 1.0

    def __post_init__(self) -> None:
        _check_keys(self, BODY_KEYS["block"])

    @property
    def R(self) -> float:
        return G / (self.inertia * P**2)

    R_cg = R

    @property
    def b(self) -> float:
        return self.R * math.sin(self.alpha)

    @property
    def h_cg(self) -> float:
        return self.R * math.cos(self.alpha)

    @property
    def I_O(self) -> float:
        return self.inertia * self.M * self.R**2

    @property
    def p(self) -> float:
        return math.sqrt(self.M * G * self.R / self.I_O)

    @property
    def E_ref(self) -> float:
        return self.M * G * self.R * (1 - math.cos(self.alpha))

    @property
    def alpha_ref(self) -> float:
        return self.alpha

    alpha_cg = alpha_ref


Body = FlexibleBody | BlockBody


def u_cr(body: Body) -> float:
    """Eq. (4)'s normaliser of the top mass's u [m] (``FlexibleBody.u_cr``); 0 for a body
    whose u stays 0: a welded top mass (wn_over_p = inf) or a block (no top mass)."""
    return body.u_cr if isinstance(body, FlexibleBody) else 0.0


def restitution(
    body: FlexibleBody, lam: float | np.ndarray, u: float | np.ndarray, upper: bool
) -> np.ndarray:
    """Eq. (1): e = theta'^+ / theta'^- for a rocking-to-rocking impact (the formula:
    ``rocksweep.kernel.eq1.restitution``, the kernel's own).

    Parameters: lam (Pi10, impulse at lam*b from the future corner), u [m] at impact,
    ``upper`` selects the paper's upper sign (in rocksweep: rocking on the +b corner ends,
    future corner -b; see the module docstring). Arrays broadcast. Returns e (may be <= 0,
    meaning full contact follows, or > 1).
    """
    return _eq1.restitution(1.0 if upper else -1.0, np.asarray(u, dtype=float),
                            np.asarray(lam, dtype=float), body.m, body.m_A, body.b,
                            body.I_A + body.m_A * body.h_A**2, 0.0)


def restitution_rigid(body: Body, lam: float | np.ndarray) -> np.ndarray:
    """Restitution of a rigid body for an impulse at lam*b from the future corner
    (``rocksweep.kernel.eq1.restitution_rigid``): the angular momentum about the impulse
    point is conserved, e = (I_O - M b^2 (2 - lam)) / (I_O - lam M b^2); lam = 0 is
    Housner's 1 - 2 M b^2/I_O."""
    return _eq1.restitution_rigid(body.I_O, body.M * body.b**2, np.asarray(lam, dtype=float))


def impact_energy_loss(
    body: FlexibleBody, e: float | np.ndarray, u: float | np.ndarray,
    theta_dot_minus: float | np.ndarray, upper: bool,
) -> np.ndarray:
    """Eq. (6): energy E_d [J] dissipated by an impact with restitution e at lateral u [m]."""
    sg = 1.0 if upper else -1.0
    e = np.asarray(e, dtype=float)
    i = body.I_A + body.m_A * body.R_A**2 + body.m * body.b**2 + body.m * np.asarray(u) ** 2
    w2 = np.asarray(theta_dot_minus, dtype=float) ** 2
    return -0.5 * i * (e**2 - 1) * w2 - sg * body.m * body.b * u * (e**2 + 1) * w2


def body_from_geometry(b: float, h: float, h_A: float, m: float, m_A: float, I_A: float,
                       k: float, c: float = 0.0) -> dict[str, float]:
    """The Pi groups (Table 1) and p of a body given by the laboratory's numbers.

    b: half-width of the base [m]; h, h_A: heights of the top mass and of the base's
    centroid A [m]; m, m_A [kg]; I_A: the base's inertia about A [kg m^2]; k [N/m]
    (inf: welded, rigid); c [N s/m]. Returns {wn_over_p, zeta, alpha_cg, alpha_A,
    mA_over_m, IA_ratio, p [rad/s], omega_n [rad/s], h_cg [m]} with h_cg = (m h +
    m_A h_A)/M, alpha_cg = atan(b/h_cg), alpha_A = atan(b/h_A), p = sqrt(M g R_cg /
    (I_A + m_A R_A^2 + m R^2)) (section 3.1), omega_n = sqrt(k/m), zeta = c/(2 sqrt(k m)).
    A BodyError (one line) for a value out of range or geometry no scene could hold.
    """
    vals = {"b": b, "h": h, "h_A": h_A, "m": m, "m_A": m_A, "I_A": I_A, "k": k, "c": c}
    for key, v in vals.items():
        if not is_number(v):
            raise BodyError(f"body.{key} = {fmt(v)}: must be a number")
        msg = check_value(f"body.{key}", v)
        if msg is not None:
            raise BodyError(msg)
    M = m + m_A
    h_cg = (m * h + m_A * h_A) / M
    R_A, R, R_cg = math.hypot(b, h_A), math.hypot(b, h), math.hypot(b, h_cg)
    p = math.sqrt(M * G * R_cg / (I_A + m_A * R_A**2 + m * R**2))
    rigid = math.isinf(k)
    omega_n = math.inf if rigid else math.sqrt(k / m)
    if rigid and c > 0:
        raise BodyError(f"body.c = {fmt(c)}: a welded top mass (body.k = .inf) has no "
                        "damper; give c: 0 or a finite k")
    out = {"wn_over_p": omega_n / p, "zeta": 0.0 if rigid else c / (2 * math.sqrt(k * m)),
           "alpha_cg": math.atan2(b, h_cg), "alpha_A": math.atan2(b, h_A),
           "mA_over_m": m_A / m, "IA_ratio": I_A / (m_A * R_A**2)}
    for key, v in out.items():
        msg = check_value(f"body.{key}", v)
        if msg is not None:
            raise BodyError(f"body (kind physical): b = {fmt(b)}, h = {fmt(h)}, h_A = "
                            f"{fmt(h_A)}, m = {fmt(m)}, m_A = {fmt(m_A)}, I_A = {fmt(I_A)}, "
                            f"k = {fmt(k)}, c = {fmt(c)} give {msg.removeprefix('body.')}")
    return {**out, "p": p, "omega_n": omega_n, "h_cg": h_cg}
