"""Rocking and overturning spectra of a sweep over the time scale and A_ratio.

A sweep over ``p`` (a record scene: the body's frequency parameter [rad/s]) or
``w_over_p`` (a pulse scene), ``A_ratio`` and, optionally, ``lam`` and other keys (an
orientation ``angle``, a building's ``floor.period``: one spectrum per value) gives:

- the rocking spectrum: max |theta| / alpha_cg against p, one curve per A_ratio and lam
  (overturned points marked; their max |theta| is the overturning angle's pi/2);
- the overturning spectrum: the smallest A_ratio that overturns against p, one curve per
  lam, with the mode it overturns in, to ``rtol`` (relative) whatever the grid's spacing:
  a search below the first overturning grid value of each p and a bisection, with single
  kernel runs at the sweep's numerics: ``rocksweep.analysis.boundaries.a_min`` (shared
  with the stability diagram's A_min curves), with an evaluator here that also runs
  records and the GROUND pulses (``boundaries.kernel_evaluator``, which runs every ground
  motion's kernel).

The scene is rebuilt from the file (its YAML); a record is re-read from the path the sweep
read it at and must have the same SHA-256 as then. The figure is
``rocksweep.figures.spectrum.spectra_figure``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from rocksweep import fields
from rocksweep.analysis.boundaries import (
    A_MIN_METHODS,
    RESPONSE,
    AMinCurve,
    a_min,
    check_search,
    grid_response,
    kernel_evaluator,
)
from rocksweep.analysis.tolerance import DEFAULT_RTOL
from rocksweep.errors import (
    SpectrumError,
    check_rtol,
)
from rocksweep.store.reader import as_result, result_scene
from rocksweep.vocab.kinds import KIND_ATTR, SPECTRA
from rocksweep.vocab.outcomes import MODE_WORDS, OUTCOME_WORDS, flag_attrs


@dataclass
class Spectra:
    """The spectra of one sweep.

    freq: "p" [rad/s] or "w_over_p"; x: float64[nx] its values; A: float64[nA] the
    A_ratio values; lam: float64[nl] (one NaN when lam is not swept); theta_max:
    float64[nl, nA, nx] max |theta|/alpha_ref; outcome: int8[nl, nA, nx]; a_min: one
    ``AMinCurve`` per lam (x = freq, a_min [A_ratio], mode 1 or 2 at a_min, NaN: no grid
    value overturns); rtol: the bisection's relative tolerance; runs: kernel runs spent;
    kind: the body kind ("flexible": alpha_ref is alpha_cg; "block": alpha); search:
    whether A_min was searched below the grid's first overturning value.
    """

    name: str
    freq: str
    x: np.ndarray
    A: np.ndarray
    lam: np.ndarray
    theta_max: np.ndarray
    outcome: np.ndarray
    a_min: list[AMinCurve]
    rtol: float
    runs: int
    record: str = ""
    kind: str = "flexible"
    search: bool = True
    # other swept keys (an orientation ``angle``, a building's ``floor.period``, body
    # keys...): their names and values; theta_max and outcome then lead with their
    # dimensions (float64[*extra, nl, nA, nx]) and ``a_min`` runs over them in C order
    extra: tuple[tuple[str, np.ndarray], ...] = ()

    def to_dataset(self):
        """The spectra as an ``xarray.Dataset``: ``theta_max_over_alpha`` and ``outcome``
        over (lam, A_ratio, freq) (the rocking spectrum), ``A_min``, ``mode`` and
        ``A_min_method`` (how A_min was found, ``boundaries.A_MIN_METHODS``) over (lam,
        freq) (the overturning spectrum, bisected to ``rtol``; NaN: no grid value
        overturns), freq being ``p`` [rad/s] or ``w_over_p``; attrs: rocksweep_kind
        "spectra" (``analysis.kinds``), title, rtol, runs, record."""
        lead = tuple(v.size for _, v in self.extra) + (len(self.lam),)
        a_min = np.array([c.a_min for c in self.a_min], float).reshape(*lead, -1)
        mode = np.array([c.mode for c in self.a_min], np.int8).reshape(a_min.shape)
        method = np.array([c.method_words for c in self.a_min], str).reshape(a_min.shape)
        f = self.freq
        ex = tuple(d for d, _ in self.extra)
        theta_attrs = fields.field_attrs(fields.BY_NAME["theta_max_over_alpha"], self.kind)
        return xr.Dataset(
            {"theta_max_over_alpha": ((*ex, "lam", "A_ratio", f), self.theta_max,
                                      theta_attrs),
             "outcome": ((*ex, "lam", "A_ratio", f), self.outcome,
                         {"long_name": "outcome class", **flag_attrs(OUTCOME_WORDS)}),
             "A_min": ((*ex, "lam", f), a_min,
                       {**fields.axis_attrs("A_ratio", self.kind),
                        "long_name": "smallest overturning amplitude ratio"}),
             "mode": ((*ex, "lam", f), mode, {"long_name": "overturning mode at A_min",
                                              **flag_attrs(MODE_WORDS)}),
             "A_min_method": ((*ex, "lam", f), method,
                              {"long_name": "how A_min was found",
                               "flag_meanings": ";".join(A_MIN_METHODS)})},
            coords={**{d: (d, v, fields.axis_attrs(d, self.kind)) for d, v in self.extra},
                    "lam": ("lam", self.lam, fields.axis_attrs("lam")),
                    "A_ratio": ("A_ratio", self.A, fields.axis_attrs("A_ratio", self.kind)),
                    f: (f, self.x, fields.axis_attrs(f))},
            attrs={KIND_ATTR: SPECTRA, "kind": self.kind, "title": self.name,
                   "rtol": self.rtol,
                   "search": int(self.search),
                   "runs": self.runs, "record": self.record})


def spectra(data, rtol: float = DEFAULT_RTOL, search: bool = True) -> Spectra:
    """The rocking and overturning spectra of a complete sweep result: a Dataset (what
    ``rocksweep.run`` / ``rocksweep.open`` return), a ``SweepResult`` or a file's path.
    search: A_min searched below the first overturning grid value too (``a_min``); False:
    the grid's bracket bisected only (faster; A_min then depends on the grid)."""
    rtol = check_rtol(rtol)
    search = check_search(search)
    result = as_result(data, [*RESPONSE, "status"])
    freq = "p" if "p" in result.dims else "w_over_p"
    missing = [d for d in (freq, "A_ratio") if d not in result.dims]
    if missing:
        raise SpectrumError(f"{result.path}: spectra need a sweep over p (a record) or "
                            f"w_over_p, and A_ratio; not swept: {', '.join(missing)} "
                            f"(swept: {', '.join(result.dims) or 'none'})")
    extra = [d for d in result.dims if d not in (freq, "A_ratio", "lam")]
    result.require_complete(SpectrumError, "a spectrum")
    A = np.asarray(result.coords["A_ratio"], float)
    if not np.all(np.diff(A) > 0):
        raise SpectrumError(f"{result.path}: A_ratio must increase along its axis")
    order = [d for d in (*extra, "lam", "A_ratio", freq) if d in result.dims]
    perm = [result.dims.index(d) for d in order]
    theta = np.transpose(result.arrays["theta_max_over_alpha"], perm)
    outcome = np.transpose(result.arrays["outcome"], perm)
    if "lam" not in result.dims:
        theta, outcome = theta[..., None, :, :], outcome[..., None, :, :]
        lam = np.array([float(result.scalars.get("lam", np.nan))])
    else:
        lam = np.asarray(result.coords["lam"], float)
    scene = result_scene(result)
    curves = a_min(scene, result.arrays["outcome"], rtol, axes=(freq, "A_ratio"),
                   evaluate=kernel_evaluator(scene), **grid_response(result), search=search)
    # the curves come in the grid's order of the other dims: as (*extra, lam)
    grid_order = [d for d in result.dims if d not in (freq, "A_ratio")]
    sizes = [len(result.coords[d]) for d in grid_order]
    pos = np.arange(len(curves)).reshape(sizes or [1])
    if grid_order:
        pos = np.transpose(pos, [grid_order.index(d) for d in (*extra, "lam")
                                 if d in grid_order])
    curves = [curves[int(i)] for i in pos.ravel()]
    rec = result.scene.get("record") or {}
    coords = tuple((d, np.asarray(result.coords[d])) for d in extra)
    return Spectra(result.name, freq, np.asarray(result.coords[freq], float), A, lam,
                   theta, outcome, curves, rtol, int(sum(c.runs.sum() for c in curves)),
                   rec.get("name", ""), result.kind, search, coords)
