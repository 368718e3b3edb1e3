"""Measured rocking histories: a CSV or a DataFrame -> normalised samples.

Two forms of the columns are read:

- dimensionless, the names ``rocksweep simulate --csv`` writes: ``p_t`` (p t) and
  ``theta_over_alpha`` (theta / alpha_ref), optionally ``u_over_ucr``;
- physical: ``t`` [s] and ``theta`` [rad] (optionally ``u`` [m]), made dimensionless with
  the body's p [rad/s] and alpha_ref [rad] (and u_cr [m]) that the caller gives.

What a laboratory file holds is accepted and stated (``Measured.notes``): uneven sampling,
NaN gaps (rows whose theta is NaN are dropped), a leading quiet part (the samples before
the motion starts, kept: the calibration aligns the starts, ``rocksweep.analysis.calibrate``),
repeated times (``simulate --csv`` writes the rows before and after an event at one time: the
last of them is kept), a ``run`` column with one run. What cannot be used is a one-line
``MeasuredError`` naming the column or value and what is allowed: missing columns, time
that decreases, all-NaN theta, non-finite time, several runs in one file, fewer than
MIN_SAMPLES samples.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rocksweep.errors import Arg, MeasuredError
from rocksweep.inputs import check_columns, csv_table, number_column, read_text
from rocksweep.outputs import shown

MIN_SAMPLES = 8  # fewer samples describe no rocking history
# largest file read [bytes]: 1e7 samples of a few columns (a test at 1 kHz for hours)
MAX_BYTES = 2_000_000_000


@dataclass(frozen=True)
class Measured:
    """A measured history, dimensionless (kernel units, p = 1).

    t: p t, float64[n], strictly increasing; theta: theta / alpha_ref, float64[n] finite;
    u: u / u_cr float64[n] or None (NaN where not measured); source: where it came from;
    notes: what was accepted (uneven sampling, gaps, a quiet start...), one sentence each;
    physical: whether the columns were t [s], theta [rad] (made dimensionless here).
    """

    t: np.ndarray
    theta: np.ndarray
    u: np.ndarray | None
    source: str
    notes: tuple[str, ...] = field(default=())
    physical: bool = False  # read from t [s], theta [rad] (with p and alpha_ref)

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])


def _columns(measured: Any) -> tuple[dict[str, Any], list[str], str]:
    """({column: values}, each row's place in messages, source words) of a CSV path or a
    DataFrame; the file read through ``rocksweep.inputs`` (a regular UTF-8 file of at
    most MAX_BYTES, comma-separated, each column named once)."""
    if isinstance(measured, pd.DataFrame):
        src = "measured DataFrame"
        cols = check_columns(list(measured.columns), src, MeasuredError)
        values = {c: measured.iloc[:, k].to_numpy() for k, c in enumerate(cols)}
        return values, [f"{src}, row {i + 1}" for i in range(len(measured))], src
    if not isinstance(measured, str | Path):
        raise TypeError(f"measured = {measured!r}: give a CSV path or a pandas DataFrame")
    path = Path(measured)
    src = shown(path)
    text = read_text(path, "measured history (CSV)", MeasuredError, max_bytes=MAX_BYTES)
    table = csv_table(text, src, MeasuredError, "measured history",
                      expect="'p_t,theta_over_alpha' or 't,theta'")
    return ({c: table.column(c) for c in table.columns},
            [f"{src}, line {ln}" for ln in table.lines], src)


def read_measured(measured: Any, *, p: float | None = None, alpha_ref: float | None = None,
                  u_cr: float | None = None) -> Measured:
    """A measured history from a CSV path or a DataFrame (see the module docstring).

    p [rad/s], alpha_ref [rad], u_cr [m]: the body's, to read physical columns t, theta,
    u (None: not known; then only the dimensionless columns are accepted).
    """
    frame, where, src = _columns(measured)
    cols = list(frame)
    notes: list[str] = []

    def column(name: str, gaps: bool = False) -> np.ndarray:
        return number_column(frame[name], where, name, MeasuredError, gaps=gaps)

    if "run" in cols:
        runs = np.unique(column("run", gaps=True))
        runs = runs[~np.isnan(runs)]
        if runs.size > 1:
            raise MeasuredError(f"{src}: column run holds {runs.size} runs "
                                f"({', '.join(f'{r:g}' for r in runs[:4])}...); give one "
                                "run's rows (the history CSV of one point)")
    if "p_t" in cols and "theta_over_alpha" in cols:
        t = column("p_t")
        theta = column("theta_over_alpha", gaps=True)
        u = column("u_over_ucr", gaps=True) if "u_over_ucr" in cols else None
        tname, thname = "p_t", "theta_over_alpha"
    elif "t" in cols and "theta" in cols:
        if p is None or alpha_ref is None:
            raise MeasuredError("{src}: columns t [s], theta [rad] need the body's p "
                                "[rad/s]: give {p} (a number), or a physical body (kind: "
                                "physical) or a record scene's ground.p; or give columns "
                                "p_t, theta_over_alpha", src=src, p=Arg("p", kind="keyword"))
        t = column("t") * p
        theta = column("theta", gaps=True) / alpha_ref
        u = None
        if "u" in cols and u_cr:
            u = column("u", gaps=True) / u_cr
        tname, thname = "t", "theta"
        notes.append(f"physical columns t [s], theta [rad] read with p = {p:.6g} rad/s, "
                     f"alpha = {alpha_ref:.6g} rad")
    else:
        have = ", ".join(cols[:8]) + ("..." if len(cols) > 8 else "") or "none"
        missing = "theta_over_alpha" if "p_t" in cols else (
            "theta" if "t" in cols else "p_t, theta_over_alpha")
        raise MeasuredError(f"{src}: no column {missing} (columns: {have}); a measured "
                            "history needs p_t and theta_over_alpha (as a simulated "
                            "history's CSV has), or t [s] and theta [rad]")
    if t.size == 0:
        raise MeasuredError(f"{src}: no rows")
    if not np.all(np.isfinite(t)):
        i = int(np.flatnonzero(~np.isfinite(t))[0])
        raise MeasuredError(f"{where[i]}: {tname} = {float(t[i])!r}; time must be a "
                            "finite number in every row")
    dec = np.flatnonzero(np.diff(t) < 0)
    if dec.size:
        i = int(dec[0]) + 1
        raise MeasuredError(f"{where[i]}: {tname} = {float(t[i])!r} after "
                            f"{float(t[i - 1])!r}; time must not decrease")
    keep = np.isfinite(theta)
    if not keep.any():
        raise MeasuredError(f"{src}: column {thname} is NaN in every row; nothing measured")
    if np.isinf(theta).any():
        i = int(np.flatnonzero(np.isinf(theta))[0])
        raise MeasuredError(f"{where[i]}: {thname} = {float(theta[i])!r}; must be "
                            "finite (NaN for a gap)")
    n_gap = int((~keep).sum())
    if n_gap:
        notes.append(f"{n_gap} row(s) with NaN {thname} dropped (gaps)")
    t, theta = t[keep], theta[keep]
    u = u[keep] if u is not None else None
    same = np.flatnonzero(np.diff(t) == 0)
    if same.size:  # rows before and after an event: the last of each time
        last = np.ones(t.size, bool)
        last[same] = False
        t, theta = t[last], theta[last]
        u = u[last] if u is not None else None
        notes.append(f"{same.size} repeated time(s) (event rows): the last row of each kept")
    if t.size < MIN_SAMPLES:
        raise MeasuredError(f"{src}: {t.size} usable samples; at least {MIN_SAMPLES}")
    dt = np.diff(t)
    if dt.max() > 1.01 * dt.min():
        notes.append(f"uneven sampling (steps {dt.min():.3g} to {dt.max():.3g} p*t)")
    if u is not None and np.isnan(u).all():
        u = None
    if u is not None:
        notes.append("u_over_ucr read (shown, not fitted: the misfit is on theta)")
    return Measured(t, theta, u, src, tuple(notes), physical=tname == "t")


def noise_level(t: np.ndarray, theta: np.ndarray) -> float:
    """Robust estimate of the measurement noise's standard deviation in theta's unit.

    Each inner sample is compared with the straight line through its two neighbours:
    r_i = theta_i - interpolated, whose variance is sigma^2 (1 + w^2 + (1 - w)^2) for
    independent noise (w the sample's position between its neighbours); sigma is
    1.4826 x the median of |r_i| / sqrt(1 + w^2 + (1 - w)^2) (a median: the kinks at
    impacts and the curvature at peaks touch few samples)."""
    if t.size < 3:
        return 0.0
    span = t[2:] - t[:-2]
    w = (t[1:-1] - t[:-2]) / span
    r = theta[1:-1] - (theta[:-2] + (theta[2:] - theta[:-2]) * w)
    scale = np.sqrt(1 + w * w + (1 - w) ** 2)
    return float(1.4826 * np.median(np.abs(r) / scale))
