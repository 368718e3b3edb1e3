"""What accuracy costs in time: the kernel's settings against the reference path.

``accuracy_study(scene, n_points, ladder)``:

1. Classify every point of the scene with the kernel at the scene's own numerics (the
   sweep machinery, ``rocksweep.compute.driver.sweep_arrays``) and mark the points on an outcome
   boundary of the stability diagram (a neighbour along A_ratio or w_over_p has another
   outcome).
2. Draw a stratified sample of ``n_points``: strata are (outcome, boundary or interior);
   half the sample goes to boundary strata, half to interior strata, equally over the
   outcomes present (capped by each stratum's size). Every sampled point carries the
   weight N_h / n_h of its stratum, so weighted means estimate the whole scene (outcome
   flips gather at boundaries; sampling them more sharpens the estimate, the weights undo
   the bias).
3. Run the sample with the reference (``rocksweep.physics.reference``, DOP853 at rtol 1e-10;
   a scene that gives body.mu: the sliding base's, ``rocksweep.physics.sliding_reference``,
   DOP853 phase by phase at the same tolerances) and with the kernel at each setting of the
   ladder (a scene with body.mu: the sliding variants). Kernel times exclude compilation
   (``kernel.warm_up``). Per-point times come from timing each point as its own 1-row
   chunk (one call into the jitted chunk kernel per point; the call overhead is ~1 us);
   the total is one call on the whole sample (best of ``repeat``).
4. For each setting: time per point (median of the 1-row timings, and the weighted mean:
   the scene's estimate), RK4 evaluations per point, and errors against the reference:
   |d theta_max|/alpha_cg (points both call safe), |d t_first_impact| (both impact),
   |d t_overturn| (both overturn), |d impacts| (same outcome), and the outcome flips
   (weighted share, and a matrix of counts: reference outcome -> kernel outcome); a scene
   with body.mu also |d slide_max| / slide_max (same outcome, the reference slid at least
   SLIDE_REL_FLOOR b).
5. The observed order of convergence of the step ladder (settings with a common event
   tolerance, steps_per_period doubling): log2 of the ratio of median errors per halving
   of the step, on the first impact time (the smooth stretch uplift -> first impact) and
   on theta_max of points that never impact (a smooth stretch from uplift to rest), and on
   slide_max where the scene slides.

Times are p*t (p = 1 rad/s); theta_max errors are in units of alpha_cg (alpha_ref).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from rocksweep import fields
from rocksweep.compute.dispatch import run_variant
from rocksweep.compute.driver import sweep_arrays
from rocksweep.compute.sweep import run_rows
from rocksweep.errors import SceneError
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel import warm_up
from rocksweep.numerics import PRESETS, Numerics
from rocksweep.physics import sliding_reference as slide_ref
from rocksweep.physics.points import Point
from rocksweep.physics.reference import ATOL, RTOL, reference_run, result_row
from rocksweep.scene.grid import Grid
from rocksweep.scene.model import Scene
from rocksweep.vocab.axes import DIAGRAM_AXES, RECORD_X
from rocksweep.vocab.outcomes import CLASSES, FLAGGED, OUTCOME_NOT_RUN, OUTCOME_SAFE
from rocksweep.vocab.settings import DEFAULT_PRESET, DEFAULT_SAMPLE_SEED, ROOTS

OUTCOMES = CLASSES  # codes 0, 1, 2
# Per-point fields of the report: all the outcome-level kernel fills (no energies).
REPORT_FIELDS = tuple(f for f in fields.RUN_FIELDS if not f.energy)
MEASURES = ("theta_max", "t_first_impact", "t_overturn", "impacts", "theta_rel", "energy",
            "slide_max")
# the measures of a scene that gives body.mu only (the sliding base's)
SLIDE_MEASURES = ("slide_max",)
MEASURE_LABELS = {
    "theta_max": "|d theta_max|/alpha_cg",
    "t_first_impact": "|d t_first_impact| (p*t)",
    "t_overturn": "|d t_overturn| (p*t)",
    "impacts": "mean |d impacts|",
    "slide_max": "|d slide_max|/slide_max",  # a scene with body.mu (``measures``)
}
# theta_rel is taken where the reference's theta_max is at least this x alpha_cg
THETA_REL_FLOOR = fields.THETA_REL_FLOOR
# slide_max's relative error is taken where the reference's slide_max is at least this x b
# (the base's half-width): below, the base barely slipped and a relative error says nothing
SLIDE_REL_FLOOR = 1e-3
# Error bounds against which ``--check`` scores the per-point error estimates (the
# `accurate` preset's targets for the 95th percentiles, docs/accuracy.md): overturning
# time [p*t] and relative max|theta|.
CHECK_TARGETS = {"t_overturn": 0.05, "theta_rel": 0.01}


@dataclass(frozen=True)
class Setting:
    """One rung of a ladder: kernel steps per period, event tolerance [p*t], root finder.

    group: the curve the rung belongs to. "steps ..." groups share one event tolerance
    with the steps per period doubling (observed order), "tol ..." groups share one step
    with the tolerance shrinking, "preset" holds the named presets, "root ..." the presets
    with one event root finder. root: None runs the scene's own (``numerics.root``).
    """

    name: str
    steps_per_period: int
    event_tol: float
    group: str
    root: str | None = None
    rotation_step: float = 0.0
    pulse_steps: int = 0  # 0: steps_per_period (the bare step ladders)
    refine: int = 0  # certification of close calls (0: none, the bare kernel)


def _steps(steps: tuple[int, ...], tol: float, tag: bool = False, rot: float = 0.0
           ) -> list[Setting]:
    """A step ladder; rot: rotation_step of every rung (0: none, the bare RK4 order)."""
    return [Setting(f"{s}/{tol:.0e}" if tag else f"spp={s}", s, tol, f"steps tol={tol:.0e}",
                    rotation_step=rot) for s in steps]


def _tols(spp: int, tols: tuple[float, ...]) -> list[Setting]:
    return [Setting(f"tol={t:.0e}", spp, t, f"tol spp={spp}") for t in tols]


def _presets() -> list[Setting]:
    return [Setting(name, group="preset", **asdict(p)) for name, p in PRESETS.items()]


def _roots() -> list[Setting]:
    return [Setting(f"{name}-{root}", group=f"root {root}", root=root, **asdict(p))
            for root in ROOTS for name, p in PRESETS.items()]


LADDERS: dict[str, Callable[[], list[Setting]]] = {
    # the step ladder at a tolerance far below the step's error (its order), the event
    # tolerance at a fine step, and the presets
    "full": lambda: (_steps((5, 10, 20, 40, 80, 160), 1e-12)
                     + _tols(80, (1e-4, 1e-5, 1e-6, 1e-8)) + _presets()),
    "short": lambda: _steps((10, 20), 1e-12) + _presets(),
    # the cheap settings the default preset is chosen from (docs/accuracy.md)
    # (with the default preset's rotation limit)
    "candidates": lambda: (_steps((4, 5, 6, 8, 10, 12, 16, 20), 1e-6, True,
                                  PRESETS[DEFAULT_PRESET].rotation_step)
                           + _steps((4, 5, 6, 8, 10, 12, 16, 20), 1e-8, True,
                                    PRESETS[DEFAULT_PRESET].rotation_step)
                           + _presets()),
    # the presets alone: their tails on a scene far from the paper's (configs/wide-space.yaml)
    "presets": _presets,
    # every preset with every event root finder: what each costs, and whether the outcomes
    # stay the same
    "roots": _roots,
}


def ladder(name: str) -> list[Setting]:
    """The settings of a named ladder (a key of ``LADDERS``)."""
    return LADDERS[name]()


# ----------------------------------------------------------------------------------------
# Sampling
# ----------------------------------------------------------------------------------------


def boundary_mask(outcome: np.ndarray, dims: tuple[str, ...]) -> np.ndarray:
    """Points of a stability diagram next to another outcome (bool, outcome's shape).

    outcome: int[grid shape] over the swept dims ``dims``; neighbours are taken along the
    diagram's axes A_ratio and w_over_p, or a record's p (where swept).
    """
    mask = np.zeros(outcome.shape, bool)
    for ax, name in enumerate(dims):
        if name not in (*DIAGRAM_AXES, RECORD_X):
            continue
        diff = np.diff(outcome, axis=ax) != 0
        lo = [slice(None)] * outcome.ndim
        hi = [slice(None)] * outcome.ndim
        lo[ax] = slice(0, -1)
        hi[ax] = slice(1, None)
        mask[tuple(lo)] |= diff
        mask[tuple(hi)] |= diff
    return mask


def _allocate(sizes: list[int], n: int) -> list[int]:
    """Split n as equally as possible over strata of the given sizes (water filling)."""
    take = [0] * len(sizes)
    left = min(n, sum(sizes))
    open_ = [i for i, s in enumerate(sizes) if s > 0]
    while left > 0 and open_:
        share = max(1, left // len(open_))
        for i in list(open_):
            k = min(share, sizes[i] - take[i], left)
            take[i] += k
            left -= k
            if take[i] == sizes[i]:
                open_.remove(i)
            if left == 0:
                break
    return take


@dataclass
class Sample:
    """A stratified sample of a scene's points.

    flat: int64[n] flat point indices (``Grid``); stratum: int64[n] index into ``strata``;
    weight: float64[n] = N_h / n_h; strata: names "outcome/boundary|interior";
    stratum_size: int64[H] points of each stratum in the scene; classified: int8[size]
    outcome of every point at the scene's numerics; classify_seconds: time of that pass.
    """

    flat: np.ndarray
    stratum: np.ndarray
    weight: np.ndarray
    strata: list[str]
    stratum_size: np.ndarray
    size: int
    classified: np.ndarray
    classify_seconds: float


def stratified_sample(outcome: np.ndarray, boundary: np.ndarray, n: int | None,
                      seed: int = DEFAULT_SAMPLE_SEED
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str], np.ndarray]:
    """Draw the sample (see the module docstring). outcome, boundary: flat arrays [size].

    Returns (flat indices sorted, stratum per point, weight per point, strata names,
    stratum sizes). ``n`` None or >= size takes every point (weights 1).
    """
    size = outcome.size
    codes = np.asarray(outcome).ravel()
    bnd = np.asarray(boundary, bool).ravel()
    names, members = [], []
    for part, sel in (("boundary", bnd), ("interior", ~bnd)):
        for code in sorted(set(codes[sel].tolist())):
            word = OUTCOMES[code] if 0 <= code < len(OUTCOMES) else f"code{code}"
            names.append(f"{word}/{part}")
            members.append(np.flatnonzero(sel & (codes == code)))
    sizes = [len(m) for m in members]
    if n is None or n >= size:
        take = sizes
    else:
        is_b = [nm.endswith("/boundary") for nm in names]
        n_b = n // 2 if any(is_b) and not all(is_b) else (n if any(is_b) else 0)
        b_idx = [i for i in range(len(names)) if is_b[i]]
        i_idx = [i for i in range(len(names)) if not is_b[i]]
        take = [0] * len(names)
        tb = _allocate([sizes[i] for i in b_idx], n_b)
        for i, k in zip(b_idx, tb, strict=True):
            take[i] = k
        ti = _allocate([sizes[i] for i in i_idx], n - sum(tb))
        for i, k in zip(i_idx, ti, strict=True):
            take[i] = k
        short = n - sum(take)  # a half could not absorb its share: give it to the other
        if short > 0:
            extra = _allocate([s - t for s, t in zip(sizes, take, strict=True)], short)
            take = [t + e for t, e in zip(take, extra, strict=True)]
    rng = np.random.default_rng(seed)
    flat, stratum, weight = [], [], []
    for h, (m, k) in enumerate(zip(members, take, strict=True)):
        if k == 0:
            continue
        pick = m if k == len(m) else rng.choice(m, size=k, replace=False)
        flat.append(pick)
        stratum.append(np.full(k, h))
        weight.append(np.full(k, len(m) / k))
    flat_a = np.concatenate(flat).astype(np.int64)
    order = np.argsort(flat_a)
    return (flat_a[order], np.concatenate(stratum)[order].astype(np.int64),
            np.concatenate(weight)[order], names, np.asarray(sizes, np.int64))


def sample_scene(scene: Scene, n: int | None, seed: int = DEFAULT_SAMPLE_SEED) -> Sample:
    """Classify every point at the scene's numerics, then draw the stratified sample.

    ``n`` None or >= the scene's size takes every point (one stratum "all", weights 1,
    no classification pass).
    """
    grid = Grid(scene)
    if n is None or n >= grid.size:
        return Sample(np.arange(grid.size, dtype=np.int64), np.zeros(grid.size, np.int64),
                      np.ones(grid.size), ["all"], np.array([grid.size], np.int64),
                      grid.size, np.full(grid.size, OUTCOME_NOT_RUN, np.int8), 0.0)
    t0 = time.perf_counter()
    outcome = sweep_arrays(scene)[0]["outcome"]
    secs = time.perf_counter() - t0
    bnd = boundary_mask(outcome, grid.dims)
    flat, stratum, weight, names, sizes = stratified_sample(outcome.ravel(), bnd.ravel(), n,
                                                            seed)
    return Sample(flat, stratum, weight, names, sizes, grid.size, outcome.ravel(), secs)


# ----------------------------------------------------------------------------------------
# Running
# ----------------------------------------------------------------------------------------


def measures(scene: Scene) -> tuple[str, ...]:
    """The measures of a scene's study: ``MEASURES`` less the sliding base's where the
    scene gives no body.mu."""
    return tuple(m for m in MEASURES if scene.slides or m not in SLIDE_MEASURES)


def reference_words(scene: Scene) -> str:
    """What the scene's reference is, in a few words (the table, the report's attrs)."""
    if scene.slides:
        return (f"sliding reference (physics/sliding_reference.py: scipy DOP853 phase by "
                f"phase, rtol {slide_ref.RTOL:g}, atol {slide_ref.ATOL:g})")
    return f"reference (scipy DOP853, rtol {RTOL:g}, atol {ATOL:g})"


def _no_suite(scene: Scene) -> None:
    """The accuracy study runs one recorded motion a scene (its rows carry its samples),
    and a scene with body.mu no vertical (the sliding reference has none)."""
    if scene.slides and scene.has_vertical:
        key = "ground.vertical" if scene.recorded else "pulse.vertical"
        raise SceneError(f"{key}: the accuracy study of a scene with body.mu takes a "
                         "horizontal ground motion only (the sliding reference has no "
                         "vertical); remove it or body.mu")
    if scene.suite is not None:
        raise SceneError(f"ground.records: the accuracy study takes one record "
                         f"(ground.record: one of {scene.suite.names[0]}, ...), not a suite")
    if scene.path is not None:
        for k in scene.excitation_axes:
            if len(scene.axis(k).values) > 1:
                raise SceneError(f"{scene.axis(k).key}: the accuracy study takes one "
                                 "motion the body feels; give one value")


def _with_numerics(scene: Scene, numerics: Numerics) -> Scene:
    return dataclasses.replace(scene, numerics=numerics)


def run_kernel(scene: Scene, flat: np.ndarray, numerics: Numerics, repeat: int = 3
               ) -> tuple[np.ndarray, np.ndarray, float]:
    """The outcome-only kernel on the given points.

    Returns (outs float64[n, N_OUT], seconds per point float64[n], seconds for the whole
    sample). Each point is timed as its own 1-row chunk (one call of the jitted chunk
    kernel); the sample is also timed as one call per kernel kind. Both are the best of
    ``repeat`` rounds (the machine's noise only ever adds time). Compilation is excluded.
    """
    _no_suite(scene)
    cr = Grid(_with_numerics(scene, numerics)).rows_at(flat)
    # the excitation's samples ride on each row
    rows_all = cr.with_samples()
    ground = scene.ground  # the Ricker, MP and records run the GROUND variants
    n = len(flat)
    outs = np.empty((n, L.N_OUT))
    kinds = np.unique(cr.kinds)
    for kind in kinds:
        warm_up(int(kind), L.LEVEL_OUTCOME, ground, scene.contact_model)
    per_point = np.full(n, np.inf)
    batch = math.inf
    part = np.empty_like(outs)
    groups = [(int(k), np.ascontiguousarray(rows_all[cr.kinds == k])) for k in kinds]
    clock = time.perf_counter
    refine = numerics.refine

    def certified(kind: int, rows: np.ndarray, out: np.ndarray) -> None:
        # the one dispatch; the close calls re-run finer, as a sweep does
        run_variant(rows, kind, L.LEVEL_OUTCOME, ground, refine, out=out)

    for _ in range(max(1, repeat)):
        for i in range(n):
            row, out = rows_all[i:i + 1], outs[i:i + 1]
            t0 = clock()
            certified(int(cr.kinds[i]), row, out)
            dt = clock() - t0
            if dt < per_point[i]:
                per_point[i] = dt
        t0 = clock()
        for kind, rows in groups:
            certified(kind, rows, part[:len(rows)])
        batch = min(batch, clock() - t0)
    return outs, per_point, batch


def run_reference(scene: Scene, flat: np.ndarray,
                  progress: Callable[[int, int], None] | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The reference path on the given points: ``reference_run``, or where the scene gives
    body.mu the sliding base's ``sliding_reference`` (its anomalies 0: it has no such
    self-check).

    Returns (outs float64[n, N_OUT], seconds float64[n]: each point's wall time, anomalies
    int64[n]: the reference's self-check, see ``reference_run``). The first point is run
    once untimed before: the reference's first call in a process loads (or compiles) the
    jitted equations it shares with the kernel, ~0.25 s that is no point's cost."""
    grid = Grid(scene)
    values = grid.index_values(flat)
    n = len(flat)

    def run(point: Point) -> tuple[np.ndarray, dict]:
        if scene.slides:
            r = slide_ref.sliding_reference(point, numerics=scene.numerics)
            return slide_ref.result_row(r), r
        r = reference_run(point, scene.numerics)
        return result_row(r), r

    if n and not scene.slides:  # the sliding reference shares no jitted equations
        run(scene.point({k: v[0] for k, v in values.items()}))
    outs = np.empty((n, L.N_OUT))
    secs = np.empty(n)
    anomalies = np.zeros(n, np.int64)
    for i in range(n):
        outs[i], r = run(scene.point({k: v[i] for k, v in values.items()}))
        secs[i] = r["wall_time"]
        anomalies[i] = r.get("anomalies", 0)
        if progress is not None:
            progress(i + 1, n)
    return outs, secs, anomalies


# ----------------------------------------------------------------------------------------
# Comparing
# ----------------------------------------------------------------------------------------


def point_errors(k: np.ndarray, r: np.ndarray, alpha_ref: np.ndarray,
                 k_energy: np.ndarray | None = None, e_ref: np.ndarray | None = None,
                 b: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Per-point absolute errors of kernel rows k against reference rows r (NaN where a
    measure does not apply: theta_max where both are safe, t_first_impact where both
    impact, t_overturn where both overturn, impacts where the outcomes agree).

    theta_rel: |d theta_max| / theta_max of the reference, where both are safe and the
    reference's theta_max >= THETA_REL_FLOOR alpha_cg. energy: the kernel's own energy
    balance |W_in - D_damp - D_fric - E_impact - E_end| / E_ref from k_energy (rows of the
    energy-accounting kernel at the same setting; NaN without them; D_fric, friction's
    loss, where the base may slide), e_ref [J] per point. slide_max: |d slide_max| /
    slide_max of the reference, where the outcomes agree, both are finite and the
    reference slid at least SLIDE_REL_FLOOR b (b [m] per point: the base's half-width;
    NaN everywhere without b or where the rows carry no slide, the no-slip model's).
    """
    ko, ro = k[:, L.OUT_OUTCOME], r[:, L.OUT_OUTCOME]
    nan = np.full(len(k), np.nan)
    both_safe = (ko == OUTCOME_SAFE) & (ro == OUTCOME_SAFE)
    d_theta = np.where(both_safe, np.abs(k[:, L.OUT_THETA_MAX] - r[:, L.OUT_THETA_MAX])
                       / alpha_ref, nan)
    d_imp = np.abs(k[:, L.OUT_T_FIRST_IMPACT] - r[:, L.OUT_T_FIRST_IMPACT])
    d_over = np.abs(k[:, L.OUT_T_OVERTURN] - r[:, L.OUT_T_OVERTURN])
    d_n = np.where(ko == ro, np.abs(k[:, L.OUT_IMPACTS] - r[:, L.OUT_IMPACTS]), nan)
    up = both_safe & (r[:, L.OUT_THETA_MAX] >= THETA_REL_FLOOR * alpha_ref)
    d_rel = np.where(up, np.abs(k[:, L.OUT_THETA_MAX] - r[:, L.OUT_THETA_MAX])
                     / np.where(up, r[:, L.OUT_THETA_MAX], 1.0), nan)
    d_e = nan
    if k_energy is not None and e_ref is not None:
        d_fric = np.nan_to_num(k_energy[:, L.OUT_D_FRIC])  # NaN: the no-slip model's
        d_e = np.abs(k_energy[:, L.OUT_W_IN] - k_energy[:, L.OUT_D_DAMP] - d_fric
                     - k_energy[:, L.OUT_E_IMPACT] - k_energy[:, L.OUT_E_END]) / e_ref
    d_slide = nan
    if b is not None:
        ks, rs = k[:, L.OUT_SLIDE_MAX], r[:, L.OUT_SLIDE_MAX]
        with np.errstate(invalid="ignore"):  # NaN slides: the comparison is False
            slid = (ko == ro) & np.isfinite(ks) & (rs >= SLIDE_REL_FLOOR * b)
        d_slide = np.where(slid, np.abs(ks - rs) / np.where(slid, rs, 1.0), nan)
    return {"theta_max": d_theta, "t_first_impact": d_imp, "t_overturn": d_over,
            "impacts": d_n, "theta_rel": d_rel, "energy": d_e, "slide_max": d_slide}


def run_energy(scene: Scene, flat: np.ndarray, numerics: Numerics) -> np.ndarray:
    """The energy-accounting kernel on the given points (untimed): float64[n, N_OUT].
    Through the sweep's dispatch (``compute.sweep.run_rows``), so Ricker, MP and record
    scenes run their ground variants with the record's samples."""
    sc = _with_numerics(scene, numerics)
    cr = Grid(sc).rows_at(flat)
    return run_rows(cr, cr.rows, L.LEVEL_ENERGY, sc)


def run_half(scene: Scene, flat: np.ndarray, numerics: Numerics) -> np.ndarray:
    """The half-step reruns of ``outputs.check`` (``fields.check_rows``) on the given
    points, outcome-only kernel, untimed: float64[n, N_OUT] (the sweep's dispatch)."""
    _no_suite(scene)
    sc = _with_numerics(scene, numerics)
    cr = Grid(sc).rows_at(flat)
    return run_rows(cr, fields.check_rows(cr.rows), L.LEVEL_OUTCOME, sc)


def estimate_scores(k: np.ndarray, half: np.ndarray, r: np.ndarray,
                    errors: dict[str, np.ndarray], targets: dict[str, float] = CHECK_TARGETS
                    ) -> dict:
    """How well the per-point error estimates of ``outputs.check`` (|half-step rerun -
    run|) tell the points whose true error exceeds a target.

    k, half, r: the run's, the rerun's and the reference's rows float64[n, N_OUT];
    errors: ``point_errors(k, r, ...)``; targets: measure -> bound (t_overturn [p*t],
    theta_rel). Per measure: above (points whose true error exceeds the bound), caught
    (those whose estimate does too), flagged (points whose estimate exceeds it), real
    (flagged points truly above half the bound), ratio (median estimate / error over the
    points above). outcome: wrong (unflagged runs whose outcome differs from the
    reference), wrong_changes (those whose outcome changes at half the step), changes (all
    runs whose outcome changes at half the step).
    """
    d = fields.convert_check(k, half, 1.0)  # the estimates as a sweep stores them [rad]
    est = {"t_overturn": np.abs(d["check_t_overturn_diff"])}
    with np.errstate(invalid="ignore", divide="ignore"):
        est["theta_rel"] = np.abs(d["check_theta_max_diff"]) / k[:, L.OUT_THETA_MAX]
    out: dict = {}
    for m, bound in targets.items():
        e, x = errors[m], est[m]
        ok = np.isfinite(e) & np.isfinite(x)
        above, flagged = ok & (e > bound), ok & (x > bound)
        out[m] = {"bound": bound, "above": int(above.sum()),
                  "caught": int((above & flagged).sum()), "flagged": int(flagged.sum()),
                  "real": int((flagged & (e > bound / 2)).sum()),
                  "ratio": float(np.median(x[above] / e[above])) if above.any() else math.nan}
    st = k[:, L.OUT_STATUS].astype(np.int64) | r[:, L.OUT_STATUS].astype(np.int64)
    wrong = ((st & FLAGGED) == 0) & (k[:, L.OUT_OUTCOME] != r[:, L.OUT_OUTCOME])
    changes = half[:, L.OUT_OUTCOME] != k[:, L.OUT_OUTCOME]
    out["outcome"] = {"wrong": int(wrong.sum()), "wrong_changes": int((wrong & changes).sum()),
                      "changes": int(changes.sum())}
    return out


def format_scores(scores: dict) -> str:
    """``estimate_scores`` as one line."""
    parts = []
    for m, d in scores.items():
        if m == "outcome":
            parts.append(f"outcome: {d['wrong']} differ from the reference, "
                         f"{d['wrong_changes']} of them change at half the step; "
                         f"{d['changes']} change in all")
            continue
        ratio = "-" if not math.isfinite(d["ratio"]) else f"{d['ratio']:.2f}"
        parts.append(f"{m} > {d['bound']:g}: {d['above']} points, {d['caught']} caught, "
                     f"{d['flagged']} flagged ({d['real']} truly > {d['bound'] / 2:g}), "
                     f"median estimate/error {ratio}")
    return "; ".join(parts)


@dataclass
class SettingResult:
    """One setting's measurements on the sample (see ``accuracy_study``)."""

    setting: Setting
    outs: np.ndarray  # float64[n, N_OUT]
    seconds: np.ndarray  # float64[n], each point as a 1-row chunk
    batch_seconds: float  # the whole sample in one call per kind (best of repeat)
    errors: dict[str, np.ndarray]  # per point, see ``point_errors``
    agreement: float  # weighted share of points with the reference's outcome
    agreement_se: float  # its standard error (stratified, finite population)
    flips: np.ndarray  # int64[3, 3]: [reference outcome, kernel outcome] counts
    flagged: int  # sampled points with a flagged status (horizon, caps, nonfinite)
    # with ``check``: the half-step reruns' rows float64[n, N_OUT] and ``estimate_scores``
    half: np.ndarray | None = None
    check: dict | None = None

    @property
    def median_us(self) -> float:
        return float(np.median(self.seconds) * 1e6)

    def mean_us(self, weight: np.ndarray) -> float:
        return float(np.sum(self.seconds * weight) / np.sum(weight) * 1e6)

    @property
    def evals(self) -> np.ndarray:
        """RK4 step evaluations per point (regular + event re-integrations)."""
        return self.outs[:, L.OUT_STEPS] + self.outs[:, L.OUT_EVENT_STEPS]

    def median_error(self, measure: str) -> float:
        e = self.errors[measure]
        e = e[np.isfinite(e)]
        if measure == "impacts":
            return float(np.mean(e)) if e.size else math.nan
        return float(np.median(e)) if e.size else math.nan

    def max_error(self, measure: str) -> float:
        e = self.errors[measure]
        e = e[np.isfinite(e)]
        return float(np.max(e)) if e.size else math.nan

    def p95_error(self, measure: str) -> float:
        """95th percentile over the sampled points where the measure applies (unweighted:
        the tail of the sample, which over-samples the diagram's boundaries)."""
        e = self.errors[measure]
        e = e[np.isfinite(e)]
        return float(np.percentile(e, 95)) if e.size else math.nan


def _agreement(agree: np.ndarray, sample: Sample) -> tuple[float, float]:
    """Stratified estimate of the scene's share of agreeing points and its standard error."""
    total, var = 0.0, 0.0
    size = sample.size
    for h in range(len(sample.strata)):
        sel = sample.stratum == h
        n_h = int(sel.sum())
        if n_h == 0:
            continue
        big_n = int(sample.stratum_size[h])
        w = big_n / size
        p = float(np.mean(agree[sel]))
        total += w * p
        if n_h > 1:
            var += w * w * p * (1 - p) / (n_h - 1) * (1 - n_h / big_n)
    return total, math.sqrt(var)


def flip_matrix(k_outcome: np.ndarray, r_outcome: np.ndarray) -> np.ndarray:
    """Counts [reference outcome, kernel outcome] over codes 0..2."""
    m = np.zeros((3, 3), np.int64)
    for a, b in zip(r_outcome.astype(int), k_outcome.astype(int), strict=True):
        if 0 <= a < 3 and 0 <= b < 3:
            m[a, b] += 1
    return m


def observed_order(results: list[SettingResult], measure: str) -> list[tuple[int, int, float]]:
    """Observed order between consecutive rungs of the step ladder.

    Returns [(spp, 2 spp, log2(median error at spp / median error at 2 spp))] for every
    pair of rungs of a "steps" group; errors are taken on the points where both rungs'
    errors are finite and nonzero.
    """
    out = []
    groups = sorted({r.setting.group for r in results if r.setting.group.startswith("steps")})
    pairs = []
    for g in groups:
        steps = sorted((r for r in results if r.setting.group == g),
                       key=lambda r: r.setting.steps_per_period)
        pairs += [(a, b) for a in steps for b in steps
                  if b.setting.steps_per_period == 2 * a.setting.steps_per_period]
    for a, b in pairs:
        ea, eb = a.errors[measure], b.errors[measure]
        ok = np.isfinite(ea) & np.isfinite(eb) & (ea > 0) & (eb > 0)
        if not ok.any():
            continue
        out.append((a.setting.steps_per_period, b.setting.steps_per_period,
                    float(np.log2(np.median(ea[ok]) / np.median(eb[ok])))))
    return out


@dataclass
class Study:
    """Everything ``rocksweep accuracy`` measured (see the module docstring)."""

    scene: Scene
    sample: Sample
    alpha_ref: np.ndarray  # float64[n]
    values: dict[str, np.ndarray]  # axis name -> value per sampled point
    reference: np.ndarray  # float64[n, N_OUT]
    reference_seconds: np.ndarray  # float64[n]
    results: list[SettingResult]
    orders: dict[str, list[tuple[int, int, float]]] = field(default_factory=dict)
    wall_seconds: float = 0.0
    reference_anomalies: np.ndarray | None = None  # int64[n], see ``run_reference``
    b: np.ndarray | None = None  # float64[n]: each point's base half-width [m]

    def row(self, r: SettingResult) -> dict:
        """One line of the table (plain numbers)."""
        w = self.sample.weight
        d = {
            "setting": r.setting.name, "group": r.setting.group,
            "steps_per_period": r.setting.steps_per_period, "event_tol": r.setting.event_tol,
            "root": r.setting.root or self.scene.numerics.root,
            "rotation_step": r.setting.rotation_step,
            "median_us": r.median_us, "mean_us": r.mean_us(w),
            "total_s": r.batch_seconds,
            "evals_per_point": float(np.sum(r.evals * w) / np.sum(w)),
            "agreement": r.agreement, "agreement_se": r.agreement_se,
            "flips": int(r.flips.sum() - np.trace(r.flips)), "flagged": r.flagged,
        }
        for m in measures(self.scene):
            d[f"err_{m}"] = r.median_error(m)
            d[f"p95_err_{m}"] = r.p95_error(m)
            d[f"max_err_{m}"] = r.max_error(m)
        return d

    def table(self) -> list[dict]:
        return [self.row(r) for r in self.results]


def _e_ref(scene: Scene, values: dict[str, np.ndarray], n: int) -> np.ndarray:
    """E_ref [J] of each sampled point (its body)."""
    return np.array([scene.point({k: v[i] for k, v in values.items()}).body.E_ref
                     for i in range(n)])


def accuracy_study(scene: Scene, n_points: int | None = 200,
                   settings: list[Setting] | None = None, seed: int = DEFAULT_SAMPLE_SEED,
                   repeat: int = 5,
                   progress: Callable[[str, int, int], None] | None = None,
                   check: bool = False) -> Study:
    """Measure time and error of each kernel setting against the reference on a sample.

    n_points: sample size (None: every point); settings: the ladder (default "full");
    progress(stage, done, total) is called as the reference and the settings run;
    check: also rerun every setting at half the step and score the per-point error
    estimates of ``outputs.check`` against the true errors (``estimate_scores``).
    """
    _no_suite(scene)
    t_wall = time.perf_counter()
    settings = settings if settings is not None else ladder("full")
    if progress:
        progress("classify", 0, 1)
    sample = sample_scene(scene, n_points, seed)
    if progress:
        progress("classify", 1, 1)
    grid = Grid(scene)
    cr = grid.rows_at(sample.flat)
    values = grid.index_values(sample.flat)
    e_ref = _e_ref(scene, values, len(sample.flat))
    ref, ref_secs, anomalies = run_reference(
        scene, sample.flat, (lambda i, n: progress("reference", i, n)) if progress else None)
    results = []
    for j, s in enumerate(settings):
        numerics = dataclasses.replace(scene.numerics, accuracy=s.name,
                                       steps_per_period=s.steps_per_period,
                                       event_tol=s.event_tol,
                                       root=s.root or scene.numerics.root,
                                       rotation_step=s.rotation_step,
                                       pulse_steps=s.pulse_steps, refine=s.refine)
        outs, secs, batch = run_kernel(scene, sample.flat, numerics, repeat)
        outs_e = run_energy(scene, sample.flat, numerics)
        agree = outs[:, L.OUT_OUTCOME] == ref[:, L.OUT_OUTCOME]
        share, se = _agreement(agree, sample)
        flagged = int(np.sum((outs[:, L.OUT_STATUS].astype(np.int64) & FLAGGED) != 0))
        errors = point_errors(outs, ref, cr.alpha_ref, outs_e, e_ref, cr.rows[:, L.PAR_B])
        half = run_half(scene, sample.flat, numerics) if check else None
        results.append(SettingResult(
            s, outs, secs, batch, errors, share, se,
            flip_matrix(outs[:, L.OUT_OUTCOME], ref[:, L.OUT_OUTCOME]), flagged, half,
            estimate_scores(outs, half, ref, errors) if check else None))
        if progress:
            progress("kernel", j + 1, len(settings))
    study = Study(scene, sample, cr.alpha_ref, values, ref, ref_secs, results,
                  reference_anomalies=anomalies, b=cr.rows[:, L.PAR_B].copy())
    study.orders = {m: observed_order(results, m)
                    for m in ("t_first_impact", "theta_max", *SLIDE_MEASURES)
                    if m in measures(scene)}
    study.wall_seconds = time.perf_counter() - t_wall
    return study


# ----------------------------------------------------------------------------------------
# Output
# ----------------------------------------------------------------------------------------


def _e(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{x:.1e}"


def format_table(study: Study) -> str:
    """The table ``rocksweep accuracy`` prints."""
    s = study.sample
    n = len(s.flat)
    lines = []
    ref_ms = np.median(study.reference_seconds) * 1e3
    mean_w = float(np.sum(study.reference_seconds * s.weight) / np.sum(s.weight)) * 1e3
    how = ("every point" if n == s.size else
           f"stratified sample of {n} of {s.size} points (strata: outcome x boundary/interior "
           f"at the scene's numerics; weighted to estimate the whole scene)")
    lines.append(f"{study.scene.name}: {how}")
    counts = ", ".join(f"{nm} {int((s.stratum == h).sum())}/{int(s.stratum_size[h])}"
                       for h, nm in enumerate(s.strata))
    lines.append(f"  strata (sampled/in scene): {counts}")
    lines.append(f"  {reference_words(study.scene)}: {ref_ms:.1f} ms/point median, "
                 f"{mean_w:.1f} ms/point scene mean, {study.reference_seconds.sum():.1f} s total")
    lines.append("  kernel time per point: median of 1-row chunk calls; mean = weighted scene "
                 "estimate; total = one call on the sample")
    slides = study.scene.slides
    lines.append("  errors against the reference: median |d| (max in brackets); "
                 "d impacts: mean |d| where outcomes agree"
                 + (f"; slide_max: |d slide_max|/slide_max where outcomes agree and the "
                    f"reference slid >= {SLIDE_REL_FLOOR:g} b" if slides else ""))
    w = max(11, *(len(r.setting.name) for r in study.results))
    main_m = ("theta_max", "t_first_impact", "t_overturn") + (SLIDE_MEASURES if slides else ())
    heads = {"theta_max": "theta_max", "t_first_impact": "t_1st_impact",
             "t_overturn": "t_overturn", "slide_max": "slide_max (rel)"}
    head = (f"{'setting':>{w}} {'spp':>4} {'tol':>6} {'med us':>8} {'mean us':>8} "
            f"{'total s':>7} {'evals':>7} {'agree %':>13} {'flips':>5} "
            + " ".join(f"{heads[m]:>17}" for m in main_m) + f" {'d impacts':>9}")
    lines.append(head)
    lines.append("-" * len(head))
    for d in study.table():
        agree = f"{100 * d['agreement']:.2f}+-{100 * d['agreement_se']:.2f}"
        cells = [f"{_e(d['err_' + m])} ({_e(d['max_err_' + m])})" for m in main_m]
        imp = "-" if not math.isfinite(d["err_impacts"]) else f"{d['err_impacts']:.2f}"
        lines.append(
            f"{d['setting']:>{w}} {d['steps_per_period']:>4} {d['event_tol']:>6.0e} "
            f"{d['median_us']:>8.1f} {d['mean_us']:>8.1f} {d['total_s']:>7.3g} "
            f"{d['evals_per_point']:>7.0f} {agree:>13} {d['flips']:>5} "
            + " ".join(f"{c:>17}" for c in cells) + f" {imp:>9}")
    lines.append("  tails of the errors against the reference, median / 95th percentile / max "
                 "over the sampled points where each applies (impacts: mean / p95 / max; "
                 "theta_rel: |d theta_max| / theta_max, safe and uplifted; energy: the "
                 "kernel's own balance / E_ref"
                 + (", friction included; slide_max: relative" if slides else "") + ")")
    tail_m = ("t_overturn", "theta_max", "theta_rel", "t_first_impact", "impacts",
              "energy") + (SLIDE_MEASURES if slides else ())
    head = f"{'setting':>{w}} " + " ".join(f"{m:>26}" for m in tail_m)
    lines.append(head)
    lines.append("-" * len(head))
    for d in study.table():
        cells = [f"{_e(d['err_' + m])}/{_e(d['p95_err_' + m])}/{_e(d['max_err_' + m])}"
                 for m in tail_m]
        lines.append(f"{d['setting']:>{w}} " + " ".join(f"{c:>26}" for c in cells))
    checked = [r for r in study.results if r.check is not None]
    if checked:
        lines.append("  per-point error estimates (outputs.check: |half-step rerun - run|) "
                     "against the true errors: points above each bound, caught by an "
                     "estimate above it, flagged by the estimate")
        for r in checked:
            lines.append(f"{r.setting.name:>{w}} {format_scores(r.check)}")
    for m, orders in study.orders.items():
        if orders:
            txt = ", ".join(f"{a}->{b}: {p:.2f}" for a, b, p in orders)
            lines.append(f"  observed order on {m} (step ladder, per halving of the step; "
                         f"RK4: 4): {txt}")
    for r in study.results:
        flips = [(OUTCOMES[a], OUTCOMES[b], int(r.flips[a, b]))
                 for a in range(3) for b in range(3) if a != b and r.flips[a, b]]
        if flips:
            txt = ", ".join(f"{a} -> {b}: {c}" for a, b, c in flips)
            lines.append(f"  flips at {r.setting.name} (reference -> kernel): {txt}")
    flagged = [(r.setting.name, r.flagged) for r in study.results if r.flagged]
    if flagged:
        lines.append("  flagged runs (horizon, caps, nonfinite): "
                     + ", ".join(f"{nm} {c}" for nm, c in flagged))
    ref_flagged = int(np.sum((study.reference[:, L.OUT_STATUS].astype(np.int64)
                              & FLAGGED) != 0))
    if ref_flagged:
        lines.append(f"  reference flagged runs: {ref_flagged}")
    if study.reference_anomalies is not None and study.reference_anomalies.any():
        bad = int(np.count_nonzero(study.reference_anomalies))
        lines.append(f"  WARNING: the reference's self-check failed on {bad} points "
                     "(an impact with theta' pointing away from theta = 0)")
    return "\n".join(lines)
