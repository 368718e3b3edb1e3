"""The cost admission of scenes: every valid scene finishes in bounded time.

Every point's cap on RK4 evaluations (the kernel's PAR_MAXSTEPS, ``points.run_cost``,
``points.record_cost``) must be at most ``numerics.MAX_POINT_STEPS``, at the sweep's and
at the single runs' accuracy; the bodies checked stand for the grid's
(``candidate_bodies``), and a refused scene's message names the value that makes a point
costly and the bound it must keep (``_cost_message``).
"""

from __future__ import annotations

import math
from dataclasses import replace
from itertools import product

import numpy as np

from rocksweep.errors import BodyError, SceneError
from rocksweep.numerics import (
    EVENT_STEP_ALLOWANCE,
    MAX_POINT_STEPS,
    Numerics,
    point_seconds,
)
from rocksweep.physics.points import (
    body_omega_rock,
    body_zeta_rock,
    record_cost,
    run_cost,
)
from rocksweep.scene.model import FLOOR_AXES, Scene
from rocksweep.schema import KEYS, fmt

# Body grids up to this many distinct bodies are checked body by body; larger ones at the
# combinations of each key's extreme values (``candidate_bodies``).
MAX_BODIES_CHECKED = 1024
# Typical values (Table 3; the `default` numerics) that the cost check puts in place of a
# value, one at a time, to find which value makes a point too costly.
_TAME = {"body.wn_over_p": 2.43, "body.zeta": 0.05, "body.alpha_cg": 0.15,
         "body.alpha_A": 0.28, "body.mA_over_m": 0.47, "body.IA_ratio": 0.56,
         "body.alpha": 0.2618, "body.inertia": 4.0 / 3.0,
         "pulse.w_over_p": 1.0, "pulse.A_ratio": 1.0,
         **{f"numerics.{k}": getattr(Numerics(), k)
            for k in ("steps_per_period", "horizon", "max_events")}}


def candidate_bodies(scene: Scene) -> list[dict[str, float]]:
    """Body values (by key name) that stand for the grid's bodies; each is built, so a body
    that is not physical raises its ``BodyError`` (as a SceneError).

    Up to MAX_BODIES_CHECKED distinct bodies: all of them. Beyond: the combinations of
    each key's extreme values (its least and largest, and wn_over_p's largest finite
    one), at most 3 x 2^5 = 96 bodies. The body's conditions and costs reach their worst
    there: with each key's range checked value by value, what is left is h/b > 0, and h/b
    is monotonic in alpha_cg and alpha_A and linear in mA_over_m; the step's rate
    ``body_omega_rock`` grows with wn_over_p and zeta, falls with IA_ratio and alpha_cg,
    rises with alpha_A and is convex in mA_over_m (m h^2 / (I_A + m_A R_A^2) ~ (c + d
    mu)^2 / mu); the pulse's rate grows with tan(alpha_cg). A function that is monotonic
    or convex in each key alone takes its largest value over a grid at such a corner.
    """
    axes = scene.body_axes()
    n_bodies = math.prod(len(a.values) for a in axes)
    if n_bodies <= MAX_BODIES_CHECKED:
        choices = [a.values for a in axes]
    else:
        choices = []
        for a in axes:
            v = np.asarray(a.values)
            pick = {float(v.min()), float(v.max())}
            finite = v[np.isfinite(v)]
            if finite.size:
                pick.add(float(finite.max()))
            choices.append(sorted(pick))
    out = []
    for combo in product(*choices):
        values = {a.name: float(v) for a, v in zip(axes, combo, strict=True)}
        try:
            scene.make_body(**values)
        except BodyError as err:
            raise SceneError(str(err)) from None
        out.append(values)
    return out


def _budgets(scene: Scene, bodies: list[dict[str, float]], w: np.ndarray, A: np.ndarray,
             numerics: Numerics) -> np.ndarray:
    """Step cap (PAR_MAXSTEPS) of every combination of the bodies, w and A: float64[b, w, A]
    (NaN, from an overflow, counts as inf)."""
    built = [scene.make_body(**b) for b in bodies]
    omega_rock = np.array([body_omega_rock(b) for b in built])[:, None, None]
    zeta_rock = np.array([body_zeta_rock(b) for b in built])[:, None, None]
    alpha_ref = np.array([b.alpha_ref for b in built])[:, None, None]
    shape = (len(built), w.size, A.size)
    _, _, _, _, cap = run_cost(np.broadcast_to(omega_rock, shape),
                               np.broadcast_to(alpha_ref, shape),
                               np.broadcast_to(w[None, :, None], shape),
                               np.broadcast_to(A[None, None, :], shape), numerics,
                               scene.phase_max(), np.broadcast_to(zeta_rock, shape))
    return np.where(np.isnan(cap), math.inf, cap)


def _check_record_cost(scene: Scene, bodies: list[dict[str, float]]) -> None:
    """A record scene's cost check: the step cap at the ends of the p and A_ratio axes
    (the record's length grows with p, the step shrinks with the body's rates and |A|)."""
    p = np.asarray(scene.axis("p").values)
    A = np.asarray(scene.axis("A_ratio").values)
    rec = scene.record
    for b in bodies:
        body = scene.make_body(**b)
        for n, label in _runs(scene):
            for pv in (p.min(), p.max()):
                for av in (A.min(), A.max()):
                    dt, h_rec, _, t_end, cap = record_cost(
                        np.array([body_omega_rock(body)]), np.array([body.alpha_ref]),
                        np.array([pv]), np.array([av]), rec, n, body_zeta_rock(body))
                    c = float(cap[0])
                    if not (c <= MAX_POINT_STEPS):
                        raise SceneError(
                            f"ground.record {rec.name}: {rec.npts} samples at DT = "
                            f"{rec.dt:g} s ({rec.duration:g} s) with ground.p = "
                            f"{fmt(float(pv))}: one point could need {c:.2g} RK4 steps{label}"
                            f" (the record at steps of {float(h_rec[0]):.3g} p*t, then "
                            f"{n.horizon:g} p*t of free vibration), more than the cap of "
                            f"{MAX_POINT_STEPS:.0e} a point; use a smaller p, fewer "
                            "steps_per_period or a shorter horizon")


def _check_suite_cost(scene: Scene, bodies: list[dict[str, float]]) -> None:
    """A suite scene's cost check: for every record, the step cap at the ends of the p
    axis and at the record's largest scaled peak (the step shrinks with it)."""
    su = scene.suite
    p = np.asarray(scene.axis("p").values)
    p_ends = np.array([p.min(), p.max()])
    stripes = (np.arange(len(su.levels)) if su.im else None)
    for b in bodies:
        body = scene.make_body(**b)
        alpha = np.array([body.alpha_ref])
        for r, rec in enumerate(su.records):
            if stripes is None:
                peak = su.peak_ratio(np.array([r]), None, alpha, p_ends[:1])
            else:
                rr = np.full((stripes.size, 2), r)
                peak = su.peak_ratio(rr, np.repeat(stripes[:, None], 2, 1), alpha,
                                     p_ends[None, :])
            A = np.array([float(np.max(np.abs(peak)))] * 2)
            for n, label in _runs(scene):
                _, h_rec, _, _, cap = record_cost(np.array([body_omega_rock(body)] * 2),
                                                  np.array([body.alpha_ref] * 2), p_ends, A,
                                                  rec, n, body_zeta_rock(body))
                worst = int(np.argmax(np.where(np.isnan(cap), math.inf, cap)))
                c = float(cap[worst])
                if not (c <= MAX_POINT_STEPS):
                    raise SceneError(
                        f"ground.records: {su.names[r]} at p = {fmt(float(p_ends[worst]))}: "
                        f"one point could need {c:.2g} RK4 steps{label} (the record's "
                        f"{rec.npts} samples at steps of {float(h_rec[worst]):.3g} p*t, "
                        f"scaled to a peak of {A[0]:.3g} g tan(alpha), then {n.horizon:g} "
                        f"p*t of free vibration), more than the cap of {MAX_POINT_STEPS:.0e} "
                        "a point; use a smaller p or scale, fewer steps_per_period or a "
                        "shorter horizon")


def _path_ends(scene: Scene) -> list[dict]:
    """Values of the axes a path's motion depends on that stand for its longest and
    finest motions: every record (or pulse shape), the ends of w_over_p and of the
    angle, the floor's longest ring-down (largest period, least damping, largest
    |participation|) and its finest sampling (least period)."""
    names = {a.name for a in scene.axes}
    choices: dict[str, list] = {}
    for a in scene.axes:
        if a.name in ("record", "shape"):
            choices[a.name] = list(a.values)
        elif a.name in ("angle", "w_over_p") and (a.name != "w_over_p" or not scene.recorded):
            choices[a.name] = sorted({min(a.values), max(a.values)})
    floors = [{}]
    if scene.floor and scene.path.modes is None:
        per, damp, part = (scene.axis(k).values for k in FLOOR_AXES)
        big = max(part, key=abs)
        floors = [{"floor.period": max(per), "floor.damping": min(damp),
                   "floor.participation": big},
                  {"floor.period": min(per), "floor.damping": min(damp),
                   "floor.participation": big}]
    out = []
    for combo in product(*choices.values()):
        for fl in floors:
            out.append({**dict(zip(choices, combo, strict=True)), **fl})
    return [v for v in out if all(k in names for k in v)]


def _check_path_cost(scene: Scene, bodies: list[dict[str, float]]) -> None:
    """A scene with an excitation path: the step cap of its longest and finest motions
    (``_path_ends``) at the ends of p (a record's) and of the ground's amplitude."""
    if scene.recorded:
        p = np.asarray(scene.axis("p").values)
        p_ends = np.array([p.min(), p.max()])
    else:
        p_ends = np.array([scene.path.p] * 2)
    su = scene.suite
    for values in _path_ends(scene):
        motion, peak, r = scene.path_motion(values)
        for b in bodies:
            body = scene.make_body(**b)
            alpha = body.alpha_ref
            if su is not None:
                s = np.arange(len(su.levels)) if su.im else None
                fac = su.factors(np.full(1 if s is None else s.size, r), s,
                                 np.array([alpha]), p_ends[:1])
                amp = float(np.max(np.abs(fac))) * su.pga[r] / math.tan(alpha)
            else:
                amp = float(np.max(np.abs(scene.axis("A_ratio").values)))
            A = np.array([amp * motion.pga / peak] * 2)
            for n, label in _runs(scene):
                _, h_rec, _, _, cap = record_cost(np.array([body_omega_rock(body)] * 2),
                                                  np.array([alpha] * 2), p_ends, A,
                                                  motion, n, body_zeta_rock(body))
                worst = int(np.argmax(np.where(np.isnan(cap), math.inf, cap)))
                c = float(cap[worst])
                if not (c <= MAX_POINT_STEPS):
                    at = ", ".join(f"{k} = {fmt(v)}" for k, v in values.items())
                    raise SceneError(
                        f"the motion the body feels at {at or 'the scene'}: "
                        f"{motion.npts} samples at DT = {motion.dt:.3g} s "
                        f"({motion.duration:.4g} s with the floor's ring-down): one point "
                        f"could need {c:.2g} RK4 steps{label} (steps of "
                        f"{float(h_rec[worst]):.3g} p*t, then {n.horizon:g} p*t of free "
                        f"vibration), more than the cap of {MAX_POINT_STEPS:.0e} a point; "
                        "use a smaller p, a more damped or stiffer building, fewer "
                        "steps_per_period or a shorter horizon")


def _runs(scene: Scene) -> tuple[tuple[Numerics, str], ...]:
    """The numerics a scene's points run at, with the words that name them: the sweeps'
    (the single runs' are the same) and, with the certification of close calls
    (``numerics.refine``), its finest rerun (``Numerics.refined``), which must fit the
    same cap: the refinement stays bounded."""
    n = scene.numerics
    runs: list[tuple[Numerics, str]] = [(n, "")]
    if scene.single_numerics != n:
        single = scene.single_numerics
        runs.append((single, f" at the single runs' accuracy ({single.accuracy})"))
    if n.refine > 0:
        runs.append((n.refined(n.refine), f" when a close call is refined {n.refine} times "
                                          f"(numerics.refine = {n.refine})"))
    return tuple(runs)


def check_cost(scene: Scene, bodies: list[dict[str, float]]) -> None:
    """Refuse a scene with a point whose step cap exceeds MAX_POINT_STEPS.

    The cap grows with the run's length t_pulse + horizon and with 1/step; over the pulse
    axes it is largest at an end of each (the step follows max(omega, rates of the body and
    of |A|), the length 2 pi/omega: (2 pi/w + H) max(X, w) falls then rises in w); along
    A_ratio also at the smallest |A| above 1, where a rigid body's pulse steps are most
    (``numerics.threshold_factor``).
    """
    if scene.path is not None:
        _check_path_cost(scene, bodies)
        return
    if scene.record is not None:
        _check_record_cost(scene, bodies)
        return
    if scene.suite is not None:
        _check_suite_cost(scene, bodies)
        return
    w = np.asarray(scene.axis("w_over_p").values)
    A = np.asarray(scene.axis("A_ratio").values)
    above = np.abs(A)[np.abs(A) > 1.0]
    w = np.array([w.min(), w.max()])
    A = np.array([A.min(), A.max(), *([above.min()] if above.size else [])])
    caps = np.max([_budgets(scene, bodies, w, A, n) for n, _ in _runs(scene)], axis=0)
    worst = int(np.argmax(caps))
    if caps.flat[worst] <= MAX_POINT_STEPS:
        return
    i, j, k = np.unravel_index(worst, caps.shape)
    point = {**{f"body.{n}": v for n, v in bodies[i].items()},
             "pulse.w_over_p": float(w[j]), "pulse.A_ratio": float(A[k])}
    raise SceneError(_cost_message(scene, point))


def _point_cost(scene: Scene, point: dict[str, float], numerics: Numerics | None = None
                ) -> tuple[float, float, float, str] | None:
    """(step cap, t_end, dt, words naming the numerics) of one point given by key, at the
    scene's costlier numerics (or at ``numerics``); None for a body that is not physical."""
    try:
        body = scene.make_body(**{k[5:]: v for k, v in point.items() if k.startswith("body.")})
    except BodyError:
        return None
    worst = None
    for n, label in _runs(scene) if numerics is None else ((numerics, ""),):
        _, dt, _, t_end, cap = run_cost(np.array([body_omega_rock(body)]),
                                        np.array([body.alpha_ref]),
                                        np.array([point["pulse.w_over_p"]]),
                                        np.array([point["pulse.A_ratio"]]), n,
                                        scene.phase_max(), body_zeta_rock(body))
        c = float(cap[0])
        c = math.inf if math.isnan(c) else c
        if worst is None or c > worst[0]:
            worst = (c, float(t_end[0]), float(dt[0]), label)
    return worst


def _with(scene: Scene, point: dict, key: str, value: float) -> float | None:
    """The step cap of ``point`` (at the costlier numerics) with one key of the point or
    of the numerics changed."""
    if key.startswith("numerics."):
        name = key.split(".", 1)[1]
        value = int(value) if name != "horizon" else float(value)
        caps = [_point_cost(scene, point, replace(n, **{name: value})) for n, _ in _runs(scene)]
        return max(c[0] for c in caps)  # type: ignore[index]
    got = _point_cost(scene, {**point, key: value})
    return None if got is None else got[0]


def _bound(scene: Scene, point: dict, key: str, bad: float, good: float) -> float:
    """The value between ``good`` (within the cap) and ``bad`` (beyond) where the cap is
    reached, rounded to 3 digits on the good side (60 bisections; log scale when both
    have one sign)."""
    logs = good * bad > 0
    lo, hi = (math.log(abs(good)), math.log(abs(bad))) if logs else (good, bad)
    sign = math.copysign(1.0, bad)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        v = sign * math.exp(mid) if logs else mid
        cost = _with(scene, point, key, v)
        if cost is not None and cost <= MAX_POINT_STEPS:
            lo = mid
        else:
            hi = mid
    v = sign * math.exp(lo) if logs else lo
    if KEYS[key].kind == "integer":
        return float(math.floor(v) if bad > good else math.ceil(v))
    e = 10.0 ** (math.floor(math.log10(abs(v))) - 2) if v else 1.0
    return (math.floor(v / e) if bad > good else math.ceil(v / e)) * e


def _cost_message(scene: Scene, point: dict) -> str:
    cap, t_end, dt, label = _point_cost(scene, point)  # type: ignore[misc]
    n = scene.numerics
    why = (f"{n.max_steps_factor:g} x a run of {t_end:.3g} p*t in steps of {dt:.3g} p*t, "
           f"plus {EVENT_STEP_ALLOWANCE:g} per event x max_events {n.max_events}")
    head = (f"one point could need {cap:.2g} RK4 steps{label} ({why}), more than the cap of "
            f"{MAX_POINT_STEPS:.0e} a point (~{point_seconds(MAX_POINT_STEPS):.2g} s of one "
            "core)")
    # which value of the point makes it costly: the one whose typical value cuts the most
    current = {**point, **{f"numerics.{k}": getattr(n, k)
                           for k in ("steps_per_period", "horizon", "max_events")}}

    def tame(key: str) -> float:
        t = _TAME[key]
        return math.copysign(t, current[key]) if key == "pulse.A_ratio" else t

    best, best_key = 1.0, None
    for key, value in current.items():
        if value == tame(key):
            continue
        cost = _with(scene, point, key, tame(key))
        if cost is not None and cap / max(cost, 1.0) > best:
            best, best_key = cap / max(cost, 1.0), key
    if best_key is None:
        return (f"{head}; use fewer steps_per_period, a shorter horizon, fewer max_events "
                "or a smaller numerics.refine")
    value = current[best_key]
    if _with(scene, point, best_key, tame(best_key)) > MAX_POINT_STEPS:  # type: ignore[operator]
        return f"{best_key} = {fmt(value)}: {head}; other values of this point are costly too"
    bound = _bound(scene, point, best_key, value, tame(best_key))
    shown = f"{abs(bound):.3g}" if KEYS[best_key].kind != "integer" else str(int(bound))
    if best_key == "pulse.A_ratio":
        rule = f"|{best_key}| must be <= {shown}"
    else:
        rule = f"{best_key} must be {'<=' if value > tame(best_key) else '>='} {shown}"
    return f"{best_key} = {fmt(value)}: {head}; with the scene's other values {rule}"


def check_vertical_cost(scene: Scene) -> None:
    """Refuse a vertical harmonic whose steps (``numerics.vertical_step``: its period over
    max(pulse_steps, steps_per_period) while the pulse acts) alone would put a point's
    step cap above MAX_POINT_STEPS, at the scene's costliest numerics: the largest
    w_v/p over the longest pulse (the smallest pulse.w_over_p)."""
    w_v = float(np.max(scene.axis("vertical.w_over_p").values))
    w = float(np.min(scene.axis("w_over_p").values))
    t_pulse = scene.phase_max() / w
    for n, words in _runs(scene):
        per_rad = max(n.pulse_steps, n.steps_per_period) / (2 * math.pi)
        cap = n.max_steps_factor * t_pulse * w_v * per_rad
        if cap > MAX_POINT_STEPS:
            bound = MAX_POINT_STEPS / (n.max_steps_factor * t_pulse * per_rad)
            raise SceneError(f"pulse.vertical.w_over_p = {fmt(w_v)}: with pulse.w_over_p = "
                             f"{fmt(w)} its steps while the pulse acts cap a point at "
                             f"{cap:.3g} RK4 steps{words}, above {MAX_POINT_STEPS:.0e}; "
                             f"pulse.vertical.w_over_p must be <= {bound:.3g}")
