"""Closed forms of the sliding base (docs/sliding.md): the phase a body at rest enters
under a ground acceleration, and the rigid-plastic sliding block under a pulse.

Written from the equations by hand, apart from the kernel (``rocksweep.kernel.sliding``
finds the same phases by testing each one's consistency with the reactions; the tests
compare the two). Conventions as in ``rocksweep.physics.bodies``: SI, m = 1 kg, g = 9.81,
p = 1; A [m/s^2] the ground's acceleration, positive toward +b; a body at rest under A > 0
tips onto the -b corner (s = -1) and its base slips toward -b relative to the ground
(sigma = -1).

Onset from rest (Shenton 1996 for the rigid block, here with mu_s >= mu and exactly for
any rigid body and for the paper's flexible body). Priority: a stuck contact stays stuck
while it can (rest, then rock), then slide, then slide-rock.

Rigid body (mass M, centre of gravity at h_cg, inertia I_G about it, t = b/h_cg =
tan alpha_cg, a = |A|):

    rest         a <= mu_s g  and  a < g t
    rock         a >= g t  and
                 a (I_G + M b^2 - mu_s M b h_cg) <= g (mu_s (I_G + M h_cg^2) - M b h_cg)
    slide        mu <= t                      (a > mu g holds once rest fails; at
                                              mu = t it slides with theta'' = 0)
    slide-rock   mu > t, den = I_G + M b^2 - mu M b h_cg > 0 and a > A_r(mu),
                 A_r(mu) = g (mu (I_G + M h_cg^2) - M b h_cg) / den

(A_r(mu) is also the base's absolute acceleration while it slide-rocks from rest; rock
needs mu_s > t: A_r(mu_s) > g t iff mu_s > t.)

Flexible body at rest in full contact with the top mass at (u, u') (f_s = k u + c u', the
spring's force on the base): under the base's absolute acceleration a (a = A while stuck)

    flat:           H(a) = m_A a - f_s,   N = M g,   Q(a) = h f_s + m g u - m_A h_A a
    rocking on s:   theta''(a) = (Q(a) - s M g b) / (I_A + m_A R_A^2 + m (u - s b)^2),
                    H(a) = m_A a - f_s + m_A h_A theta''(a),
                    N(a) = M g + (M s b - m u) theta''(a)

and the phases' conditions are those of ``kernel.sliding.choose_phase`` with these: rest
|H(A)| <= mu_s M g and |Q(A)| < M g b; rock s = sign Q(A) if |Q(A)| >= M g b,
|H_s(A)| <= mu_s N_s(A); slide sigma = -sign H(A), a = (f_s - mu sigma M g)/m_A, if
|Q(a)| < M g b; slide-rock (s, sigma): a from H_s(a) = -mu sigma N_s(a),
sigma (a - A) > 0, s Q(a) >= M g b, N_s(a) > 0.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from rocksweep.physics.bodies import Body, FlexibleBody, G
from rocksweep.vocab.ground import COSINE, SINE
from rocksweep.vocab.phases import REST, ROCK, SLIDE, SLIDE_ROCK

JAM = "jam"  # no phase is consistent (Painleve): the contact sticks by an impulse


def _rigid_inertia(body: Body) -> tuple[float, float, float, float]:
    """(M, b, h_cg, I_G) of a rigid body (a block, or the welded flexible body)."""
    return body.M, body.b, body.h_cg, body.I_O - body.M * (body.b**2 + body.h_cg**2)


def rock_threshold(body: Body, mu: float) -> tuple[float, float]:
    """(A_r [m/s^2], den [kg m^2]) of a rigid body: a body tipping onto a corner from rest
    under |A| <= A_r(mu_s) keeps the corner stuck (den > 0); A_r(mu) is the base's
    absolute acceleration while it slide-rocks from rest."""
    M, b, h, i_g = _rigid_inertia(body)
    den = i_g + M * b * b - mu * M * b * h
    return G * (mu * (i_g + M * h * h) - M * b * h) / den, den


def _onset_rigid(body: Body, A: float, mu: float, mu_s: float) -> tuple[str, int, int]:
    M, b, h, i_g = _rigid_inertia(body)
    a, t = abs(A), b / h
    d = -1 if A > 0 else 1  # the corner it tips onto, the way its base slips
    if a <= mu_s * G and a < G * t:
        return REST, 0, 0
    if a >= G * t and a * (i_g + M * b * b - mu_s * M * b * h) <= G * (
            mu_s * (i_g + M * h * h) - M * b * h):
        return ROCK, d, 0
    if mu <= t:  # (at mu = t it slides, the normal force at its leading corner)
        return SLIDE, 0, d
    a_r, den = rock_threshold(body, mu)
    if mu > t and den > 0 and a > a_r:
        return SLIDE_ROCK, d, d
    return JAM, 0, 0


def _flexible_terms(body: FlexibleBody, u: float, f_s: float, s: int, a: float):
    """(H, N, Q, theta'') of the flexible body at theta = theta' = 0 under the base's
    absolute acceleration a, flat (s = 0) or on corner s (module docstring)."""
    m, m_A, M, h, h_A, b = body.m, body.m_A, body.M, body.h, body.h_A, body.b
    q = h * f_s + m * G * u - m_A * h_A * a
    if s == 0:
        return m_A * a - f_s, M * G, q, 0.0
    i_a0 = body.I_A + m_A * body.R_A**2
    th_dd = (q - s * M * G * b) / (i_a0 + m * (u - s * b) ** 2)
    return m_A * a - f_s + m_A * h_A * th_dd, M * G + (M * s * b - m * u) * th_dd, q, th_dd


def _onset_flexible(body: FlexibleBody, A: float, mu: float, mu_s: float, u: float,
                    u_dot: float) -> tuple[str, int, int]:
    f_s = body.k * u + body.c * u_dot
    mgb = body.M * G * body.b
    h_r, n_r, q, _ = _flexible_terms(body, u, f_s, 0, A)
    if abs(h_r) <= mu_s * n_r and abs(q) < mgb:
        return REST, 0, 0
    tip = 0 if abs(q) < mgb else (1 if q > 0 else -1)
    if tip:
        h_s, n_s, _, _ = _flexible_terms(body, u, f_s, tip, A)
        if n_s > 0 and abs(h_s) <= mu_s * n_s:
            return ROCK, tip, 0
    for sg in (1, -1):
        a = (f_s - mu * sg * body.M * G) / body.m_A  # m_A a - f_s = -mu sg M g
        if sg * (a - A) > 0 and abs(_flexible_terms(body, u, f_s, 0, a)[2]) < mgb:
            return SLIDE, 0, sg
    for s in (1, -1):
        for sg in (1, -1):
            h0, n0, _, _ = _flexible_terms(body, u, f_s, s, 0.0)
            h1, n1, _, _ = _flexible_terms(body, u, f_s, s, 1.0)
            den = (h1 - h0) + mu * sg * (n1 - n0)
            a = -(h0 + mu * sg * n0) / den
            _, n_a, q_a, _ = _flexible_terms(body, u, f_s, s, a)
            if den > 0 and sg * (a - A) > 0 and s * q_a >= mgb and n_a > 0:
                return SLIDE_ROCK, s, sg
    return JAM, tip, 0


def onset(body: Body, A: float, mu: float, mu_s: float | None = None, u: float = 0.0,
          u_dot: float = 0.0) -> tuple[str, int, int]:
    """The phase a body at rest in full contact enters under the ground acceleration A
    [m/s^2] (a step, or the value at that instant): (word, s, sigma), the word one of
    ``vocab.phases.PHASES`` (or ``JAM``), s the corner it rocks on, sigma the slip
    direction. mu, mu_s: kinetic and static friction (mu_s default mu). u [m], u_dot
    [m/s]: the top mass's state (flexible bodies; the spring pushes the base with k u +
    c u'). The module docstring has the formulas."""
    mu_s = mu if mu_s is None else mu_s
    if body.rigid:
        return _onset_rigid(body, A, mu, mu_s)
    return _onset_flexible(body, A, mu, mu_s, u, u_dot)


# ----------------------------------------------------------------------------------------
# The rigid-plastic sliding block under a pulse
# ----------------------------------------------------------------------------------------


def _pulse(shape: str, A: float, w: float, n: int):
    """(acc(t), its integral V(t) = int_0^t acc, and its double integral X(t)) of n cycles
    of A sin(w t) or A cos(w t), 0 after them."""
    t_end = 2 * math.pi * n / w
    if shape == SINE:
        def acc(t):
            return A * math.sin(w * t) if t <= t_end else 0.0

        def vel(t):
            t = min(t, t_end)
            return A / w * (1 - math.cos(w * t))

        def pos(t):
            tc = min(t, t_end)
            return A / w * tc - A / w**2 * math.sin(w * tc) + vel(t_end) * max(t - t_end, 0)
    elif shape == COSINE:
        def acc(t):
            return A * math.cos(w * t) if t <= t_end else 0.0

        def vel(t):
            return A / w * math.sin(w * min(t, t_end))

        def pos(t):
            tc = min(t, t_end)
            return A / w**2 * (1 - math.cos(w * tc)) + vel(t_end) * max(t - t_end, 0)
    else:
        raise ValueError(f"shape {shape!r}: the closed form is for {SINE} and {COSINE}")
    return acc, vel, pos, t_end


def sliding_block(A: float, w: float, mu: float, mu_s: float | None = None,
                  shape: str = SINE, cycles: int = 1) -> dict:
    """The rigid-plastic block on a ground accelerating by ``cycles`` cycles of A sin(w t)
    (or cos) [m/s^2, rad/s], friction mu (kinetic) and mu_s (static, default mu), a block
    that never rocks (mu < tan alpha). Relative to the ground, while it slips in direction
    sigma: x'' = -xg'' - mu g sigma, so on a slip from (t0, x0, v0):

        x'(t) = v0 - [V(t) - V(t0)] - mu g sigma (t - t0)
        x(t)  = x0 + v0 (t - t0) - [X(t) - X(t0) - V(t0) (t - t0)] - mu g sigma (t - t0)^2 / 2

    with V, X the ground's velocity and displacement (closed forms of the pulse). It
    sticks where x' = 0 if |xg''| <= mu_s g, else slips on the other way; it starts to
    slip where |xg''| first exceeds mu_s g. Slip stops are the roots of x'(t), bracketed on
    a grid of w t / 64 (x' has at most a few turns per cycle) and found by Brent's method.

    Returns {slide_max, slide_final [m], segments: [(t0, t1, sigma)], t_stop [s]}.
    """
    mu_s = mu if mu_s is None else mu_s
    acc, vel, pos, t_end = _pulse(shape, A, w, cycles)
    t, x = 0.0, 0.0
    slide_max, segments = 0.0, []
    dt_grid = 2 * math.pi / w / 64
    while True:
        # stuck from t: the first time |xg''| > mu_s g (sampled, refined)
        if abs(acc(t)) <= mu_s * G:
            if t >= t_end:
                break
            grid = np.arange(t, t_end + dt_grid, dt_grid)
            grid[-1] = min(grid[-1], t_end)
            over = [abs(acc(tt)) - mu_s * G for tt in grid]
            hit = next((i for i, f in enumerate(over) if f > 0), None)
            if hit is None:
                break
            t = brentq(lambda tt: abs(acc(tt)) - mu_s * G, grid[hit - 1], grid[hit],
                       xtol=1e-15, rtol=1e-15)
            t = math.nextafter(t, math.inf) if abs(acc(t)) <= mu_s * G else t
        sigma = -1 if acc(t) > 0 else 1
        t0, x0, v0 = t, x, 0.0

        def rate(tt, t0=t0, v0=v0, sigma=sigma):
            return v0 - (vel(tt) - vel(t0)) - mu * G * sigma * (tt - t0)

        def disp(tt, t0=t0, x0=x0, v0=v0, sigma=sigma):
            d = tt - t0
            return (x0 + v0 * d - (pos(tt) - pos(t0) - vel(t0) * d)
                    - 0.5 * mu * G * sigma * d * d)

        # the slip stops at the first root of sigma x'(t) after t0
        tt, t1 = t0, None
        while t1 is None:
            nxt = tt + dt_grid
            if tt >= t_end:  # after the pulse x' falls linearly: its root exactly
                t1 = tt + sigma * rate(tt) / (mu * G)
                break
            nxt = min(nxt, t_end)
            if sigma * rate(nxt) <= 0:
                t1 = brentq(lambda z, sg=sigma: sg * rate(z), tt, nxt, xtol=1e-15,
                            rtol=1e-15)
            tt = nxt
        x = disp(t1)
        segments.append((t0, t1, sigma))
        slide_max = max(slide_max, abs(x))
        t = t1
        if t >= t_end and abs(acc(t)) <= mu_s * G:
            break
    return {"slide_max": slide_max, "slide_final": abs(x), "segments": segments,
            "t_stop": t}
