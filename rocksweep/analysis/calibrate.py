"""Calibration: the scene numbers (lam, e, e_factor, zeta...) that reproduce a measured
rocking history, with a confidence interval.

The method, in three rooms: the misfit of candidate values (``analysis.misfit``: the
excursions of both histories, aligned; ``analysis.peaks`` their primitives), what may be
fitted and within which bounds (``analysis.fit_keys``), and the least misfit with its
profile-likelihood interval (``analysis.fit_search``). This module is the front:
``calibrate_scene`` (``rocksweep.calibrate``) checks the arguments, reads the measurement,
fits, says the verdicts and returns the Dataset.

Verdicts
--------
``reason``: "ok", or the words below joined by "," (with a ``CalibrationWarning`` giving
the numbers): "misfit" when the peaks' RMS error over the degrees of freedom, sqrt(S_min /
(N - k)), exceeds MISFIT_RATIO times the noise (``noise``: the measurement's, estimated
from the history or given, and at least NOISE_FLOOR of the largest |theta/alpha|, the
agreement a right model reaches on a noise-free measurement): the model cannot reproduce
the measurement at any value inside the bounds, and the interval is not an uncertainty of
a right model; "unidentifiable" when a key's interval spans its bounds (the profile is
flat: the history does not say the key, or the key does not change it); "at_bound" when
an estimate sits on a search bound (within AT_BOUND of the span: the minimum may lie
beyond; not at the key's own limit, as lam = 0, where nothing lies beyond).
"not_converged" when a minimisation stopped without meeting its test (Nelder-Mead at its
evaluation cap on the full history; a profile's inner minimisation at its cap, or with its
minimum still at the edge of its widened bracket: the profile misfit is then too high and
the interval may be too narrow), or when any run of the fit or the profiles found a
misfit below the estimate's by more than LOWER_SHARE of the interval's rise (the estimate
is not the least misfit). Golden-section searches stop only at their tolerance.
A fitted key that cannot change the scene's runs (lam under law constant) is refused
before any run.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from statistics import NormalDist
from typing import Any

import numpy as np

from rocksweep.analysis.fit_search import fit, profile_end, smooth_profile
from rocksweep.analysis.misfit import Problem
from rocksweep.compute.compile_cost import prepare_point
from rocksweep.errors import CalibrationError, check_type, is_real
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.bodies import u_cr
from rocksweep.physics.measured import Measured, read_measured
from rocksweep.physics.points import kernel_kind
from rocksweep.schema import KEYS
from rocksweep.vocab.kinds import CALIBRATION, KIND_ATTR

# Longest measured history fitted [p t]: a free-rocking block comes to rest within ~100.
MAX_SPAN = 1e4
# Largest |theta| [rad] of a measurement: pi/2 (the body on its side) and 5% for noise.
THETA_LIMIT = 1.05 * math.pi / 2
#: "misfit": the peaks' RMS error over the degrees of freedom above this many noises. Good
#: fits of independent histories (scipy's block at 0-1% noise, a flexible body at 0.2-1%)
#: give 0.14-1.04; a block under the vertical law fitted to e = 0.6 (no lam gives it) 210
MISFIT_RATIO = 3.0
#: the least noise a misfit is compared with, as a share of the largest |theta/alpha|
NOISE_FLOOR = 0.002
#: "at_bound": an estimate within this share of its bounds' span from one of them
AT_BOUND = 1e-3
#: "not_converged": a run whose misfit is below the estimate's by more than this share of
#: the interval's rise chi2_1(ci) s^2 (less is the misfit's roughness at the scale of the
#: search's tolerance, and moves no interval end)
LOWER_SHARE = 0.01
VERDICTS = ("ok", "misfit", "unidentifiable", "at_bound", "not_converged")


class CalibrationWarning(UserWarning):
    """A fit that should not be trusted as it is (its ``reason`` is not "ok"); ``str()``
    is one line with the numbers."""


def calibrate_problem(problem: Problem, ci: float = 0.95,
                      say: Callable[[str], None] | None = None) -> Any:
    """Fit a ``Problem``: the Dataset of ``rocksweep.calibrate`` (see ``calibrate``).
    say: told when the runs' kernel variant compiles first, and what it costs
    (``compile_cost.prepare_point``)."""
    import xarray as xr  # lazy: xarray (+90 ms)

    t0 = time.perf_counter()
    k = len(problem.keys)
    kind = kernel_kind(problem.point(problem.bounds.mean(axis=1)).body)
    prepare_point(kind, problem.scene.ground, say or (lambda _m: None))
    x_hat, s_min = fit(problem)
    if not math.isfinite(s_min):
        raise CalibrationError("no candidate inside the bounds gives a physical body; "
                               "check the bounds")
    best = problem.evaluate(x_hat)
    n = problem.peaks.value.size
    s2 = max(s_min / max(n - k, 1), problem.sigma**2)
    # chi2 quantile of 1 degree of freedom: the square of the normal's two-sided quantile
    # (statistics, not scipy.stats: its import costs ~0.5 s of every command)
    limit = NormalDist().inv_cdf(0.5 + 0.5 * ci) ** 2 * s2
    lo, hi, lo_b, hi_b = (np.empty(k), np.empty(k), np.zeros(k, bool), np.zeros(k, bool))
    for i in range(k):
        lo[i], lo_b[i] = profile_end(problem, i, x_hat, s_min, limit, -1)
        hi[i], hi_b[i] = profile_end(problem, i, x_hat, s_min, limit, +1)
        lo[i], hi[i], lo_b[i], hi_b[i] = smooth_profile(problem, i, x_hat, lo[i], hi[i],
                                                         limit, lo_b[i], hi_b[i])
    reason, why, noise, dof = _verdict(problem, x_hat, s_min, lo, hi, lo_b, hi_b, limit)
    wall = time.perf_counter() - t0
    m = problem.m
    pairs = best["pairs"]
    fitted_peak = np.full(n, np.nan)
    for i, j in pairs:
        fitted_peak[i] = best["peaks"].value[j]
    notes = list(m.notes)
    if best["shift"] > 2 * float(np.median(np.diff(m.t))):
        notes.append(f"a leading quiet part: the motion starts {best['shift']:.4g} p*t later "
                     "than in the simulation (aligned by shifting the simulation)")
    ds = xr.Dataset(
        {"estimate": ("parameter", x_hat), "lo": ("parameter", lo), "hi": ("parameter", hi),
         "lo_at_bound": ("parameter", lo_b), "hi_at_bound": ("parameter", hi_b),
         "bound_lo": ("parameter", problem.bounds[:, 0]),
         "bound_hi": ("parameter", problem.bounds[:, 1]),
         "misfit": ((), math.sqrt(s_min / n)),
         "noise": ((), noise, {"long_name": "the measurement's noise the misfit is compared "
                                            "with (estimated from the history, or given; at "
                                            "least NOISE_FLOOR x max |theta/alpha|)",
                               "units": "theta/alpha_ref"}),
         "dof": ((), np.int64(dof), {"long_name": "degrees of freedom: measured half "
                                                  "cycles less fitted keys"}),
         "reason": ((), reason, {"long_name": "verdict: ok, or the reasons joined by ',' ("
                                              + ", ".join(VERDICTS[1:]) + ")"}),
         "measured_theta": ("p_t", m.theta,
                            {"long_name": "measured theta / alpha_ref"}),
         "fitted_theta": ("p_t", best["theta"],
                          {"long_name": "simulated theta / alpha_ref at the estimate"}),
         "impact_time": ("impact", best["impacts"],
                         {"long_name": "impacts of the fitted simulation [p*t, measured "
                                       "time]"}),
         "peak_time": ("peak", problem.peaks.time),
         "measured_peak": ("peak", problem.peaks.value),
         "fitted_peak": ("peak", fitted_peak)},
        coords={"parameter": ("parameter", list(problem.keys)), "p_t": ("p_t", m.t)})
    ds["misfit"].attrs = {"long_name": "RMS error of the half-cycle peaks at the estimate",
                          "units": "theta/alpha_ref"}
    ds.attrs = {
        KIND_ATTR: CALIBRATION,
        "title": f"calibration of {', '.join(problem.keys)}",
        "ci": ci,
        "interval": "profile likelihood: misfit <= min + chi2_1(ci) s^2, s^2 = max(S_min/"
                    "(N - k), sigma^2)",
        "misfit_definition": "sqrt(S/N): S the least cost of aligning the measured and "
                             "simulated half-cycle peaks (rocksweep.analysis.calibrate)",
        "noise_sigma": problem.sigma, "threshold": problem.h, "n_peaks": n,
        "time_shift": best["shift"], "runs": problem.runs, "wall_time_s": wall,
        "measured": m.source, "notes": "; ".join(notes) if notes else "",
        "scene": problem.scene.text, "accuracy": problem.numerics.describe(),
        "outcome": int(best["out"][L.OUT_OUTCOME]),
        "noise_given": int(problem.noise_given),
    }
    if reason != "ok":
        warnings.warn(CalibrationWarning(
            f"calibration of {', '.join(problem.keys)}: " + "; ".join(
                f"{w} ({why[w]})" for w in reason.split(","))), stacklevel=2)
    return ds


def _verdict(problem: Problem, x_hat: np.ndarray, s_min: float, lo: np.ndarray,
             hi: np.ndarray, lo_b: np.ndarray, hi_b: np.ndarray, limit: float
             ) -> tuple[str, dict[str, str], float, int]:
    """(reason, {word: the numbers}, noise, dof) of a fit (module docstring, Verdicts);
    limit: the interval's rise of the misfit."""
    n, k = problem.peaks.value.size, len(problem.keys)
    dof = n - k
    amp = float(np.max(np.abs(problem.m.theta)))
    noise = max(problem.sigma, NOISE_FLOOR * amp)
    why: dict[str, str] = {}
    rms = math.sqrt(s_min / max(dof, 1))
    if rms > MISFIT_RATIO * noise:
        whose = "given" if problem.noise_given else "estimated"
        why["misfit"] = (f"the peaks' RMS error {rms:.3g} on {dof} dof is {rms / noise:.3g} "
                         f"times the {whose} noise {noise:.3g}: the model does not reproduce "
                         "the measurement inside the bounds")
    span = problem.bounds[:, 1] - problem.bounds[:, 0]
    flat, edge = [], []
    for i, key in enumerate(problem.keys):
        if lo_b[i] and hi_b[i]:
            ends = [problem.misfit(np.where(np.arange(k) == i, b, x_hat))
                    for b in problem.bounds[i]]
            same = all(math.isclose(e, s_min, rel_tol=1e-9, abs_tol=1e-300) for e in ends)
            flat.append(f"{key} in [{lo[i]:.4g}, {hi[i]:.4g}] spans its bounds" +
                        (": it does not change the simulated history" if same else ""))
        x = float(x_hat[i])
        b_lo, b_hi = problem.bounds[i]
        near = b_lo if x - b_lo < b_hi - x else b_hi
        # a bound that is the key's own limit (lam = 0, e = 1) has nothing beyond it
        limit = near in (KEYS[key].lo, KEYS[key].hi)
        if min(x - b_lo, b_hi - x) <= AT_BOUND * span[i] and not limit:
            edge.append(f"{key} = {x:.4g} on the bound {near:g}; the least misfit may lie "
                        "beyond")
    if flat:
        why["unidentifiable"] = "; ".join(flat)
    if edge:
        why["at_bound"] = "; ".join(edge)
    stops = []
    least, where = problem.least
    if where is not None and least < s_min - LOWER_SHARE * limit:
        at = ", ".join(f"{k} = {v:.4g}" for k, v in zip(problem.keys, where, strict=True))
        stops.append(f"a run at {at} has misfit S {least:.4g} below the estimate's "
                     f"{s_min:.4g}: the fit missed the least misfit")
    for place, count in problem.unconverged.items():
        cap = "its evaluation cap" if place == "fit" else "a cap or its bracket's edge"
        stops.append(f"{count} {place} minimisation{'s' * (count > 1)} stopped at {cap}")
    if stops:
        why["not_converged"] = "; ".join(stops)
    return (",".join(why) or "ok"), why, noise, dof



def calibrate_scene(scene: Any, measured: Any, fit: str | Sequence[str],
                    bounds: Mapping[str, Sequence[float]] | None = None, ci: float = 0.95,
                    p: float | None = None, overrides: Any = (),
                    noise: float | None = None,
                    say: Callable[[str], None] | None = None) -> Any:
    """``rocksweep.calibrate`` (its arguments documented there): ``fit`` (a key or a
    non-empty list of distinct keys) and ``ci`` (in [0.5, 1)) checked first, then the scene
    loaded (``scene.inputs.load``: a Scene, a path, YAML text or a dict, with
    ``overrides``), the measured history read (``physics.measured.read_measured``, in the
    scene's body's alpha_ref and u_cr; p [rad/s] given, else the scene's ``_body_p``) and
    the keys fitted (``calibrate_problem``)."""
    from rocksweep.scene.inputs import load  # lazy: yaml (+25 ms)

    check_type("fit", fit, isinstance(fit, str) or (
        isinstance(fit, Sequence) and all(isinstance(k, str) for k in fit)),
        "a dotted scene key (e.g. 'impact.lam') or a list of them")
    check_type("bounds", bounds, bounds is None or isinstance(bounds, Mapping),
               "a mapping {key: (lo, hi)}, e.g. {'impact.lam': (0, 1)}, or None")
    check_type("p", p, p is None or is_real(p), "a number (the body's p [rad/s]) or None")
    check_type("noise", noise, noise is None or is_real(noise),
               "a number (the measurement noise, theta/alpha_ref) or None")
    keys = [fit] if isinstance(fit, str) else list(fit)
    if not keys:
        raise CalibrationError("fit = []: give at least one key, e.g. impact.lam")
    if len(set(keys)) < len(keys):
        raise CalibrationError(f"fit = {keys}: a key is given twice")
    if isinstance(ci, bool) or not (isinstance(ci, float | int) and 0.5 <= ci < 1):
        raise CalibrationError(f"ci = {ci!r}: must be in [0.5, 1)")
    ci = float(ci)
    if bounds is not None:
        for k in bounds:
            if k not in keys:
                raise CalibrationError(f"bounds {k!r}: not a fitted key (fitted: "
                                       f"{', '.join(map(str, keys))}); give bounds of the "
                                       "fitted keys only")
    if p is not None:
        if isinstance(p, bool) or not isinstance(p, int | float | np.integer | np.floating):
            raise TypeError(f"p = {p!r}: must be a number (the body's p [rad/s]) or None")
        if not (math.isfinite(p) and p > 0):
            raise CalibrationError(f"p = {p!r}: must be a finite number > 0 [rad/s]")
    if noise is not None:
        if isinstance(noise, bool) or not isinstance(noise, int | float | np.integer
                                                     | np.floating):
            raise TypeError(f"noise = {noise!r}: must be a number (theta/alpha_ref) or None")
        if not (math.isfinite(noise) and noise >= 0):
            raise CalibrationError(f"noise = {noise!r}: must be a finite number >= 0 (the "
                                   "measurement noise's standard deviation, theta/alpha_ref)")
    scene, _ = load(scene, overrides)
    p_body = _body_p(scene) if p is None else float(p)
    values = {a.name: a.values[0] for a in scene.axes}
    body = scene.point(values).body
    m = read_measured(measured, p=p_body, alpha_ref=body.alpha_ref, u_cr=u_cr(body) or None)
    if p is not None and not m.physical:
        raise CalibrationError(f"p = {p!r}: {m.source} has the dimensionless columns p_t, "
                               "theta_over_alpha; p reads physical columns t [s], theta "
                               "[rad] only (leave it out)")
    _check_measured_span(m, body.alpha_ref)
    return calibrate_problem(Problem(scene, m, keys, bounds, noise), ci, say)


def _check_measured_span(m: Measured, alpha_ref: float) -> None:
    """Refuse a measured history no rocking body of this scene can have (one line): |theta|
    reaching pi/2 (the body would lie on its side: the wrong column, unit or body), or a
    span longer than MAX_SPAN (each candidate is simulated over all of it)."""
    amax = float(np.max(np.abs(m.theta)))
    if amax * alpha_ref > THETA_LIMIT:
        raise CalibrationError(f"{m.source}: |theta_over_alpha| reaches {amax:.4g}, |theta| "
                               f"= {amax * alpha_ref:.4g} rad for this body (alpha "
                               f"{alpha_ref:.4g} rad); a rocking body's |theta| stays below "
                               "pi/2, where it lies on its side (is it the wrong column, unit "
                               "or body?)")
    span = m.duration
    if span > MAX_SPAN:
        raise CalibrationError(f"{m.source}: the history spans {span:.4g} p*t; at most "
                               f"{MAX_SPAN:g} (each candidate is simulated over all of it: "
                               "cut the history to the rocking)")


def _body_p(scene: Any) -> float | None:
    """The body's p [rad/s] a scene knows (a physical body's, a record scene's ground.p),
    else None."""
    if scene.physical is not None:
        return scene.physical["p"]
    names = {a.name: a for a in scene.axes}
    if "p" in names and len(names["p"].values) == 1:
        return float(names["p"].values[0])
    return None

def calibrated_overrides(fit: Any, which: str = "all") -> dict[str, Any]:
    """Overrides that sweep a scene at a calibration's values: ``which`` "estimate", "lo"
    or "hi" gives one value per key; "all" the list [lo, estimate, hi] (distinct values,
    ascending), so that ``rocksweep.run(scene, overrides=calibrated_overrides(fit))`` draws
    the diagram at the estimate and at both ends of the interval (a swept dimension per
    key)."""
    if which not in ("all", "estimate", "lo", "hi"):
        raise CalibrationError(f"which = {which!r}: must be all, estimate, lo or hi")
    out: dict[str, Any] = {}
    for key in fit["parameter"].values.tolist():
        sel = fit.sel(parameter=key)
        if which != "all":
            out[key] = float(sel[which])
            continue
        vals = sorted({float(sel["lo"]), float(sel["estimate"]), float(sel["hi"])})
        out[key] = vals if len(vals) > 1 else vals[0]
    return out
