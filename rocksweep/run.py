"""Single runs: a point in, a result with words and (optionally) a time history out."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from rocksweep.kernel import chunk_kernel, point_kernel, warm_up
from rocksweep.kernel import layout as L
from rocksweep.numerics import Numerics
from rocksweep.outcomes import outcome_word, status_words
from rocksweep.points import Point, kernel_kind, point_row


@dataclass
class Run:
    """Result of one point. Times in p*t, energies in units of E_ref.

    history: dict of float64 arrays (t, theta, theta_dot, u, u_dot, phase, E, W_in, D_damp,
    E_impact, xg) when a history was asked for, else None.
    """

    point: Point
    numerics: Numerics
    out: np.ndarray
    history: dict | None
    wall_time: float

    def _get(self, index: int) -> float:
        return float(self.out[index])

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
        return int(self.out[L.OUT_IMPACTS])

    @property
    def uplifts(self) -> int:
        return int(self.out[L.OUT_UPLIFTS])

    @property
    def theta_max_over_alpha(self) -> float:
        return self._get(L.OUT_THETA_MAX) / self.point.body.alpha_ref

    @property
    def t_overturn(self) -> float | None:
        t = self._get(L.OUT_T_OVERTURN)
        return None if math.isnan(t) else t

    @property
    def t_end(self) -> float:
        return self._get(L.OUT_T_END)

    def energy(self, index: int) -> float:
        return self._get(index) / self.point.body.E_ref

    def summary(self) -> dict:
        """Plain-JSON summary (the keys of ``rocksweep simulate --json``)."""
        o = self.out
        d = {
            "outcome": self.outcome,
            "impacts": self.impacts,
            "uplifts": self.uplifts,
            "theta_max_over_alpha": self.theta_max_over_alpha,
            "t_overturn": self.t_overturn,
            "t_end": self.t_end,
            "status": self.status,
            "t_first_impact": None if math.isnan(o[L.OUT_T_FIRST_IMPACT])
            else float(o[L.OUT_T_FIRST_IMPACT]),
            "e_max": float(o[L.OUT_E_MAX]),
            "returns_to_contact": int(o[L.OUT_CONTACTS]),
            "accuracy": self.numerics.describe(),
            "steps": int(o[L.OUT_STEPS]),
            "event_steps": int(o[L.OUT_EVENT_STEPS]),
            "wall_time_s": self.wall_time,
        }
        if not math.isnan(o[L.OUT_W_IN]):
            d.update({
                "work_in_over_Eref": self.energy(L.OUT_W_IN),
                "damper_loss_over_Eref": self.energy(L.OUT_D_DAMP),
                "impact_loss_over_Eref": self.energy(L.OUT_E_IMPACT),
                "impact_gain_over_Eref": self.energy(L.OUT_E_GAINED),
                "energy_gaining_impacts": int(o[L.OUT_N_GAINING]),
                "energy_end_over_Eref": self.energy(L.OUT_E_END),
            })
        return d


_HIST_NAMES = ("t", "theta", "theta_dot", "u", "u_dot", "phase", "E", "W_in", "D_damp",
               "E_impact", "xg")


def history_capacity(row: np.ndarray) -> int:
    """Rows a full history of this point can need: every step plus 3 rows per event."""
    steps = math.ceil(row[L.PAR_TEND] / row[L.PAR_DT])
    return int(steps + 3 * row[L.PAR_MAXEVENTS] + 16)


def simulate(point: Point, numerics: Numerics, history: bool = True) -> Run:
    """Run one point. With ``history`` the energy-accounting kernel records every step;
    without, the outcome-only kernel of the point's kind runs (what sweeps run)."""
    row = point_row(point, numerics)
    out = np.empty(L.N_OUT)
    kind = kernel_kind(point.body)
    warm_up(kind, None if history else L.LEVEL_OUTCOME)  # wall_time excludes compilation
    t0 = time.perf_counter()
    if history:
        hist = np.empty((history_capacity(row), L.N_HIST))
        point_kernel(kind)(row, out, hist)
        n = int(out[L.OUT_HIST_ROWS])
        hist_d = {name: hist[:n, i].copy() for i, name in enumerate(_HIST_NAMES)}
    else:
        outs = out[None, :]
        chunk_kernel(kind, L.LEVEL_OUTCOME)(row[None, :], outs)
        hist_d = None
    return Run(point, numerics, out, hist_d, time.perf_counter() - t0)
