"""Single runs: a point in, a result with words and (optionally) a time history out."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from rocksweep import fields
from rocksweep.compute.dispatch import run_variant
from rocksweep.kernel import layout as L
from rocksweep.kernel import warm_up
from rocksweep.numerics import Numerics
from rocksweep.physics.points import Point, kernel_contact, kernel_kind, point_row
from rocksweep.vocab.ground import FREE
from rocksweep.vocab.outcomes import outcome_word, status_words
from rocksweep.vocab.phases import PHASE_WORDS

# What a Run made without its history says when one is asked of it: only Python makes such
# a Run (``run_point(..., history=False)``, as sweeps and the IDA run points); every command
# and ``rocksweep.simulate`` record the history, so the words are Python's.
NO_HISTORY = ("this run has no history: run_point(..., history=True) records one "
              "(rocksweep.simulate always does)")


@dataclass
class Run:
    """Result of one point. Times in p*t, energies in units of E_ref.

    history: dict of float64 arrays in SI units with p = 1 rad/s (keys
    ``fields.HISTORY_RAW``: t, theta, theta_dot, u, u_dot, phase, E, W_in, D_damp,
    E_impact, xg) when a history was asked for, else None; ``history_columns()`` gives
    them normalised.
    """

    point: Point
    numerics: Numerics
    out: np.ndarray
    history: dict | None
    wall_time: float
    contact: bool = False  # the contact fields were asked for (outputs.contact)
    # the scene's value of each axis at this point (by name), when a scene's grid made it
    # (``compute.history.run_points``): a suite's record name and stripe level, which the
    # point holds as a record and an amplitude
    where: dict | None = None

    def get(self, name: str) -> int | float | None:
        """One result field by name (``rocksweep.fields.FIELDS``) in its unit; None for
        a time or energy that does not exist (no overturning, no energy accounting)."""
        body = self.point.body
        return fields.value(self.out, fields.BY_NAME[name], body.alpha_ref, body.E_ref,
                            body.b)

    @property
    def slides(self) -> bool:
        """Whether the point gives body.mu: its base may slide (the sliding base's
        fields, history columns and ``phases`` are reported)."""
        return not math.isnan(self.point.mu)

    def phases(self) -> list[str]:
        """The contact phases the run entered, in order, as words (``vocab.phases``):
        from the history where there is one, else the visited ones (``regime``) in code
        order."""
        if self.history is not None and "contact_phase" in self.history:
            codes = np.asarray(self.history["contact_phase"]).astype(np.int64)
            keep = np.concatenate(([True], codes[1:] != codes[:-1])) if codes.size else codes
            return [PHASE_WORDS[int(c)] for c in codes[keep.astype(bool)]]
        bits = int(self.out[L.OUT_REGIME])
        return [w for c, w in PHASE_WORDS.items() if bits & (1 << c)]

    @property
    def outcome(self) -> str:
        return outcome_word(int(self.out[L.OUT_OUTCOME]))

    @property
    def status(self) -> list[str]:
        return status_words(int(self.out[L.OUT_STATUS]))

    @property
    def flagged(self) -> bool:
        return bool(int(self.out[L.OUT_STATUS]) & L.STATUS_FLAGGED)

    @property
    def impacts(self) -> int:
        return self.get("impacts")

    @property
    def uplifts(self) -> int:
        return self.get("uplifts")

    @property
    def theta_max_over_alpha(self) -> float:
        return self.get("theta_max_over_alpha")

    @property
    def t_overturn(self) -> float | None:
        return self.get("t_overturn")

    @property
    def t_end(self) -> float:
        return self.get("t_end")

    def summary(self) -> dict:
        """Plain-JSON summary (the keys of ``rocksweep simulate --json``): every field of
        ``rocksweep.fields.FIELDS`` (the energy fields when energy was accounted, the
        contact fields mu_required, normal_min_over_Mg, impulse_ratio_max when asked:
        ``outputs.contact``; an infinite mu_required, N <= 0, prints as null), the
        outcome and status as words, the accuracy setting and the wall time [s].

        Times are p*t, theta_max in alpha_ref, energies in E_ref; a time that did not
        happen (no overturning, no impact) is None. "steps" are the regular RK4 steps,
        "event_steps" the re-integrations spent locating events.
        """
        energy = not math.isnan(self.out[L.OUT_W_IN])
        slides = self.slides
        d = {f.name: self.get(f.name) for f in fields.RUN_FIELDS
             if (energy or not f.energy) and (self.contact or not f.contact)
             and (slides or not f.slide)}
        d["outcome"] = self.outcome
        d["status"] = self.status
        if slides:
            d["phases"] = self.phases()
        if energy and self.history is not None:
            E_ref = self.point.body.E_ref
            d["impact_losses_over_Eref"] = [float(v) / E_ref for v in self.impact_losses()]
        d["accuracy"] = self.numerics.describe()
        d["wall_time_s"] = self.wall_time
        return d

    def impact_losses(self) -> np.ndarray:
        """The energy [J] each impact dissipated (eq. 6 under the run's impact law; < 0:
        that impact gained energy), in order: float64[impacts]. From the history, where an
        impact is the pair of rows at one time whose first rocks (phase != 0) and whose
        second does not rock on the same corner (the sliding base's stick breaks, slip
        stops and jams keep it): the jump of the impacts' cumulative loss across it."""
        if self.history is None:
            raise ValueError(NO_HISTORY)
        t = np.asarray(self.history["t"])
        phase = np.asarray(self.history["phase"])
        lost = np.asarray(self.history["E_impact"])
        at = np.flatnonzero((t[1:] == t[:-1]) & (phase[:-1] != 0) & (phase[1:] != phase[:-1]))
        return lost[at + 1] - lost[at]

    def history_columns(self) -> dict[str, np.ndarray]:
        """The time history normalised (``rocksweep.fields.HISTORY``: p_t,
        theta_over_alpha, u_over_ucr, E_over_Eref, ...): name -> float64[rows]."""
        if self.history is None:
            raise ValueError(NO_HISTORY)
        return fields.history_columns(self.history, self.point.body)


def run_point(point: Point, numerics: Numerics, history: bool = True,
              contact: bool = False) -> Run:
    """Run one point. With ``history`` the energy-accounting kernel records every step
    (it tracks the ground reactions too); without, the outcome-only kernel of the point's
    kind runs (what sweeps run), or the contact kernel with ``contact``. ``contact``: the
    summary reports the contact fields."""
    row = point_row(point, numerics)
    if history and point.shape == FREE:
        row[L.PAR_TO_REST] = 1.0  # free rocking's history goes on past a rigid bound to rest
    kind = kernel_kind(point.body)
    ground = point.ground
    lvl = L.LEVEL_CONTACT if contact else L.LEVEL_OUTCOME
    # wall_time excludes compilation
    warm_up(kind, None if history else lvl, ground, kernel_contact(point.mu))
    t0 = time.perf_counter()
    # the close calls certified, as in sweeps (``compute.certify``): the finest run's
    # result and history are kept
    hists = [None] if history else None
    out = run_variant(row[None, :], kind, lvl, ground, numerics.refine, histories=hists)[0]
    hist_d = None
    if history:
        if not contact:  # tracked by the history variants anyway; reported when asked
            # (on a base that may slide, lifts_off is the model's own word, as in sweeps)
            words = L.STATUS_SLIDES | (L.STATUS_LIFTS_OFF if math.isnan(point.mu) else 0)
            out[L.OUT_STATUS] = int(out[L.OUT_STATUS]) & ~words
            out[[L.OUT_MU_REQ, L.OUT_N_MIN, L.OUT_IMPULSE_MAX]] = np.nan
        n = int(out[L.OUT_HIST_ROWS])
        columns = fields.HISTORY + (fields.SLIDE_HISTORY if not math.isnan(point.mu) else ())
        hist_d = {c.raw: hists[0][:n, c.slot].copy() for c in columns}
    return Run(point, numerics, out, hist_d, time.perf_counter() - t0, contact)
