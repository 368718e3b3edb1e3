"""One definition of every result: the fields of a run's result row and the columns of
its time history.

``FIELDS`` lists what the kernel reports per point (its ``OUT_*`` slots) under the names
users see: in sweep files (``rocksweep sweep``, ``rocksweep.run``), in single runs
(``Run.summary``, ``rocksweep simulate --json``) and in the accuracy report. Each field
says its dtype, the fill value of a point not computed, its unit, its meaning, the kernel
slot it comes from and the per-point scale it is divided by (theta by alpha_ref, energies
by E_ref). ``HISTORY`` does the same for the columns of a time history (``HIST_*``).

Units follow the conventions of ``rocksweep.physics.bodies``: times are p*t (unit ``1/p``),
rotations theta/alpha_ref (unit ``alpha_ref``: alpha_cg of a flexible body, alpha of a
block), lateral displacements u/u_cr, energies E/E_ref; ``1`` is a count, a code or a
pure number.

"steps" means the regular RK4 steps everywhere; the RK4 re-integrations spent locating
events are ``event_steps`` (their sum is the evaluations a run cost).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.numerics import EVENT_TOL_REFINE, MIN_EVENT_TOL
from rocksweep.physics.bodies import G, u_cr
from rocksweep.vocab.axes import AXES, alpha_symbol
from rocksweep.vocab.ground import AVGSA_POINTS, RECORD_IMS, SA, SA_DAMPING, SCALE_IMS
from rocksweep.vocab.phases import PHASE_CODE

#: the regime variable's bits, in words (``vocab.phases``: bit 1 << code of each phase)
REGIME_BITS = ", ".join(f"{1 << c} {w}" for w, c in PHASE_CODE.items())


@dataclass(frozen=True)
class Field:
    """One quantity of the kernel's result row.

    name: the user-facing name; dtype: numpy dtype in files; fill: value of a point not
    computed; unit: see the module docstring; meaning: one line; slot: index into the
    kernel's result row (``layout.OUT_*``); scale: per-point divisor, "" (none),
    "alpha_ref", "E_ref" or "b" (the base's half-width); stored: kept in sweep files;
    slide: the sliding base's (a scene that gives body.mu, docs/sliding.md); energy: needs the
    energy-accounting kernel (sweeps with ``outputs: {energy: true}``, single runs);
    contact: needs the ground-reaction kernel (``outputs: {contact: true}``, stored and
    reported only when asked); check: an error estimate from the point's rerun at half the
    step (``outputs: {check: true}``, see ``check_rows``): "value" stores the rerun's
    ``slot``, "diff" the rerun's value minus the run's.
    """

    name: str
    dtype: str
    fill: float
    unit: str
    meaning: str
    slot: int
    scale: str = ""
    stored: bool = True
    energy: bool = False
    contact: bool = False
    slide: bool = False
    check: str = ""
    label: str = ""
    symbol: str = ""

    @property
    def long_name(self) -> str:
        """Short name without units (the ``long_name`` attribute); ``meaning`` is the
        ``description``."""
        return self.label or self.meaning


_FLAGGED = "status & (horizon | step_cap | event_cap | nonfinite | uncertified | airborne)"

FIELDS: tuple[Field, ...] = (
    Field("outcome", "int8", L.OUTCOME_NOT_RUN, "1",
          "-1 not computed, 0 safe, 1 mode 1 (overturned after impacts), "
          "2 mode 2 (overturned without impact)", L.OUT_OUTCOME,
          label="outcome class"),
    Field("impacts", "int32", -1, "1",
          "number of impacts (of a 'bounded' run: up to its end, where its class was decided)",
          L.OUT_IMPACTS, label="impacts"),
    Field("uplifts", "int32", -1, "1", "number of uplifts (rocking starts from full contact; "
          "of a 'bounded' run: up to its end)", L.OUT_UPLIFTS,
          label="uplifts"),
    Field("theta_max_over_alpha", "float64", math.nan, "alpha_ref", "max |theta| / alpha_ref",
          L.OUT_THETA_MAX, "alpha_ref",
          label="largest rotation", symbol="max|theta|/alpha_ref"),
    Field("t_overturn", "float64", math.nan, "1/p", "overturning time p*t (NaN if none)",
          L.OUT_T_OVERTURN,
          label="overturning time", symbol="p t_overturn"),
    Field("status", "int32", 0, "1",
          f"bit flags (rocksweep.vocab.outcomes.STATUS_WORDS); flagged = {_FLAGGED}", L.OUT_STATUS,
          label="status flags"),
    Field("steps", "int64", 0, "1", "regular RK4 steps taken", L.OUT_STEPS,
          label="RK4 steps"),
    Field("event_steps", "int64", 0, "1", "RK4 re-integrations spent locating events",
          L.OUT_EVENT_STEPS,
          label="RK4 event re-integrations"),
    Field("work_in_over_Eref", "float64", math.nan, "E_ref",
          "work of the ground motion / E_ref", L.OUT_W_IN, "E_ref", energy=True,
          label="work of the ground motion", symbol="W_in/E_ref"),
    Field("damper_loss_over_Eref", "float64", math.nan, "E_ref",
          "energy dissipated by the damper / E_ref", L.OUT_D_DAMP, "E_ref", energy=True,
          label="energy dissipated by the damper", symbol="E_damp/E_ref"),
    Field("impact_loss_over_Eref", "float64", math.nan, "E_ref",
          "energy lost in impacts (net) / E_ref", L.OUT_E_IMPACT, "E_ref", energy=True,
          label="energy lost in impacts", symbol="E_d/E_ref"),
    # single runs and the accuracy report only (not stored in sweep files)
    Field("t_end", "float64", math.nan, "1/p", "time p*t at which the run stopped",
          L.OUT_T_END, stored=False),
    Field("t_first_impact", "float64", math.nan, "1/p", "first impact time p*t (NaN if none)",
          L.OUT_T_FIRST_IMPACT, stored=False),
    Field("e_max", "float64", math.nan, "1",
          "largest coefficient of restitution seen (of the point's impact law, impact.law: "
          "eq. (1) for vertical; times impact.e_factor)",
          L.OUT_E_MAX, stored=False),
    Field("returns_to_contact", "int64", -1, "1",
          "returns to full contact (e <= 0, or settling below the rest rate)", L.OUT_CONTACTS,
          stored=False),
    Field("impact_gain_over_Eref", "float64", math.nan, "E_ref",
          "energy gained in impacts with E_d < 0 / E_ref", L.OUT_E_GAINED, "E_ref",
          stored=False, energy=True),
    Field("energy_gaining_impacts", "int64", -1, "1", "impacts that gained energy",
          L.OUT_N_GAINING, stored=False, energy=True),
    Field("energy_end_over_Eref", "float64", math.nan, "E_ref",
          "mechanical energy at the end, relative to rest / E_ref", L.OUT_E_END, "E_ref",
          stored=False, energy=True),
    # where the model holds (outputs.contact; rocksweep.kernel.contact)
    Field("mu_required", "float64", math.nan, "1",
          "friction demand max |H|/N of the ground reactions over the run (inf: N <= 0)",
          L.OUT_MU_REQ, contact=True,
          label="friction demand", symbol="max|H|/N"),
    Field("normal_min_over_Mg", "float64", math.nan, "1",
          "smallest normal reaction N/(M g) over the run (< 0: the body would lift off)",
          L.OUT_N_MIN, contact=True,
          label="smallest normal reaction", symbol="N_min/(M g)"),
    Field("refine_evaluations", "int64", 0, "1",
          "RK4 evaluations (regular + event) of the certification's checks and reruns of a "
          "close call (rocksweep.compute.certify), counted in steps and event_steps too; a "
          "sweep file keeps their total (attribute refine_evaluations)",
          L.OUT_REFINE_EVALS, stored=False,
          label="RK4 evaluations of the certification"),
    Field("saddle_margin", "float64", math.nan, "alpha_ref",
          "closest approach of the free rocking to the overturning saddle (inf: never "
          "within 0.5); below 0.05 (an overturn: 0.1) at 5 steps per period the run is "
          "near its threshold, re-run or checked finer (rocksweep.compute.certify)",
          L.OUT_MARGIN, stored=False,
          label="closest approach to the overturning saddle"),
    Field("impulse_ratio_max", "float64", math.nan, "1",
          "largest |horizontal|/vertical ground impulse of an impact (0: no impact)",
          L.OUT_IMPULSE_MAX, contact=True,
          label="largest impulse ratio", symbol="max|P_H|/P_V"),
    # the sliding base (a scene that gives body.mu; docs/sliding.md)
    Field("slide_max", "float64", math.nan, "b",
          "largest sliding displacement max |x| / b over the run (x: how far the base "
          "slipped along the ground; b the base's half-width)", L.OUT_SLIDE_MAX, "b",
          slide=True, label="largest sliding displacement", symbol="max|x|/b"),
    Field("slide_final", "float64", math.nan, "b",
          "sliding displacement |x| / b at the end of the run (where the base came to rest)",
          L.OUT_SLIDE_FINAL, "b", slide=True,
          label="final sliding displacement", symbol="|x_end|/b"),
    Field("regime", "int8", -1, "1",
          "contact phases the run visited, a bit mask: bit (1 << code) of each phase "
          f"entered ({REGIME_BITS}; -1 not computed)", L.OUT_REGIME, slide=True,
          label="contact phases visited"),
    Field("friction_loss_over_Eref", "float64", math.nan, "E_ref",
          "energy dissipated by friction (sliding and friction impulses) / E_ref",
          L.OUT_D_FRIC, "E_ref", slide=True, energy=True,
          label="energy dissipated by friction", symbol="E_fric/E_ref"),
    # per-point error estimates (outputs.check): the same point rerun at half the step
    Field("check_outcome", "int8", L.OUTCOME_NOT_RUN, "1",
          "outcome of the point rerun at half the step (differs from outcome: not resolved "
          "at this step)", L.OUT_OUTCOME, check="value",
          label="outcome at half the step"),
    Field("check_t_overturn_diff", "float64", math.nan, "1/p",
          "overturning time at half the step minus t_overturn (NaN unless both overturn): "
          "an estimate of t_overturn's error", L.OUT_T_OVERTURN, check="diff",
          label="overturning time error estimate", symbol="p dt_overturn"),
    Field("check_theta_max_diff", "float64", math.nan, "alpha_ref",
          "max |theta| at half the step minus theta_max, / alpha_ref: an estimate of "
          "theta_max_over_alpha's error", L.OUT_THETA_MAX, "alpha_ref", check="diff",
          label="largest rotation error estimate", symbol="d max|theta|/alpha_ref"),
)

BY_NAME: dict[str, Field] = {f.name: f for f in FIELDS}
UNITS: dict[str, str] = {f.name: f.unit for f in FIELDS}
"""name -> unit of every result field (the ``units`` attribute of a file's variable)."""

SWEEP_FIELDS: tuple[Field, ...] = tuple(
    f for f in FIELDS if f.stored and not f.energy and not f.contact and not f.check
    and not f.slide)
ENERGY_FIELDS: tuple[Field, ...] = tuple(
    f for f in FIELDS if f.stored and f.energy and not f.slide)
SLIDE_FIELDS: tuple[Field, ...] = tuple(
    f for f in FIELDS if f.stored and f.slide and not f.energy)
SLIDE_ENERGY_FIELDS: tuple[Field, ...] = tuple(
    f for f in FIELDS if f.stored and f.slide and f.energy)
CONTACT_FIELDS: tuple[Field, ...] = tuple(f for f in FIELDS if f.stored and f.contact)
CHECK_FIELDS: tuple[Field, ...] = tuple(f for f in FIELDS if f.check)
RUN_FIELDS: tuple[Field, ...] = tuple(f for f in FIELDS if not f.check)
"""The fields of one run's own result row (single runs, the accuracy report)."""


def sweep_fields(energy: bool, contact: bool = False, check: bool = False,
                 slide: bool = False) -> tuple[Field, ...]:
    """The fields a sweep file stores (``energy``, ``contact``, ``check``: the scene's
    ``outputs.energy``, ``outputs.contact`` and ``outputs.check``; ``slide``: the scene
    gives body.mu, its base slides)."""
    return (SWEEP_FIELDS + (ENERGY_FIELDS if energy else ())
            + (CONTACT_FIELDS if contact else ()) + (CHECK_FIELDS if check else ())
            + (SLIDE_FIELDS if slide else ())
            + (SLIDE_ENERGY_FIELDS if slide and energy else ()))


#: the per-point variable of a scene with a ``floor:`` (not a kernel output: the peak of
#: the floor motion the point's body was driven by, ``rocksweep.physics.floor``) [g]
FLOOR_PFA = "floor_pfa"
FLOOR_PFA_VARIABLE = ("float64", math.nan,
                      "peak floor acceleration: max |a_f| of the floor motion that drove "
                      "the body (the building's response to the scaled ground motion, its "
                      "ring-down included), in g")


def variables(energy: bool = False, contact: bool = False, check: bool = False,
              floor: bool = False, slide: bool = False) -> dict[str, tuple[str, float, str]]:
    """The per-point variables a sweep stores: name -> (dtype, fill value of a point not
    computed, meaning), from ``sweep_fields`` (the one table, ``FIELDS``), and
    ``floor_pfa`` [g] with ``floor`` (a scene with a building)."""
    out = {f.name: (f.dtype, f.fill, f.meaning)
           for f in sweep_fields(energy, contact, check, slide)}
    if floor:
        out[FLOOR_PFA] = FLOOR_PFA_VARIABLE
    return out


# Relative max|theta| errors (the accuracy study's theta_rel, the error estimates' tails in
# ``rocksweep info``) are taken where max|theta| >= this x alpha_ref: below, the body barely
# leaves the ground and a relative error says nothing.
THETA_REL_FLOOR = 1e-2


# Row slots a half-step rerun (outputs.check) changes, and by what factor: the RK4 steps
# after and while the ground moves (PAR_DT, PAR_DT_ON; PAR_REC_H, the step while a record
# acts, stays a whole fraction of its sample interval), the rotation limit of one rocking
# step, the evaluation budget, which the halved step doubles, the close-call margin
# (``numerics.close_margin``) and the event tolerance (``numerics.EVENT_TOL_REFINE``,
# down to MIN_EVENT_TOL). Powers of 2 are exact in float64, so the rerun is the run at
# twice the steps_per_period and pulse_steps, half the rotation_step and a 16th of the
# event_tol, bit for bit.
CHECK_SCALE: dict[int, float] = {L.PAR_DT: 0.5, L.PAR_DT_ON: 0.5, L.PAR_REC_H: 0.5,
                                 L.PAR_ROT_STEP: 0.5, L.PAR_MAXSTEPS: 2.0,
                                 L.PAR_CLOSE: 0.5 ** 2.5, L.PAR_TOL: EVENT_TOL_REFINE}


def refined_rows(rows: np.ndarray, level: int) -> np.ndarray:
    """Parameter rows (float64[n, >= N_PAR]) of the same points at 2**level times the
    steps (``CHECK_SCALE``; ``Numerics.refined``): a close call's rerun at that refinement
    (``compute.certify``); level 1 is the half-step rerun of outputs.check."""
    out = rows.copy()
    for slot, factor in CHECK_SCALE.items():
        out[:, slot] *= factor ** level
    np.maximum(out[:, L.PAR_TOL], MIN_EVENT_TOL, out=out[:, L.PAR_TOL])
    return out


def check_rows(rows: np.ndarray) -> np.ndarray:
    """Parameter rows (float64[n, >= N_PAR]) of the half-step rerun of the same points."""
    return refined_rows(rows, 1)


def convert(outs: np.ndarray, alpha_ref: np.ndarray | float, E_ref: np.ndarray | float,
            fields: tuple[Field, ...] | list[Field], b: np.ndarray | float = math.nan
            ) -> dict[str, np.ndarray]:
    """Kernel result rows -> named arrays in the fields' units and dtypes.

    outs: float64[n, N_OUT]; alpha_ref [rad], E_ref [J], b [m]: float64[n] or scalars (the
    per-point scales; b the base's half-width, for the sliding base's fields). Returns
    name -> array[n] (fresh arrays, not views of ``outs``).
    """
    scales = {"": None, "alpha_ref": alpha_ref, "E_ref": E_ref, "b": b}
    arrays = {}
    for f in fields:
        if f.check:
            continue
        col = outs[:, f.slot]
        s = scales[f.scale]
        arrays[f.name] = (col / s if s is not None else col).astype(f.dtype, copy=True)
    return arrays


def convert_check(outs: np.ndarray, half: np.ndarray, alpha_ref: np.ndarray | float
                  ) -> dict[str, np.ndarray]:
    """The error estimates ``CHECK_FIELDS`` from the result rows of the runs (outs) and of
    their half-step reruns (half), both float64[n, N_OUT]; alpha_ref [rad]: float64[n] or a
    scalar. Returns name -> array[n]."""
    scales = {"": 1.0, "alpha_ref": alpha_ref}
    arrays = {}
    for f in CHECK_FIELDS:
        col = half[:, f.slot] if f.check == "value" else half[:, f.slot] - outs[:, f.slot]
        arrays[f.name] = (col / scales[f.scale]).astype(f.dtype, copy=True)
    return arrays


def plain(v: Any, *, nan_to_none: bool = False) -> Any:
    """A stored value as plain Python: bytes as text (UTF-8, bad bytes replaced), a numpy
    scalar or 0-d array as its Python number or string; with ``nan_to_none`` a non-finite
    float as None (JSON). Anything else unchanged."""
    if isinstance(v, bytes | np.bytes_):
        return bytes(v).decode("utf-8", "replace")
    if isinstance(v, np.generic) or (isinstance(v, np.ndarray) and v.ndim == 0):
        v = v.item()
    if nan_to_none and isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def value(out: np.ndarray, f: Field, alpha_ref: float, E_ref: float, b: float = math.nan
          ) -> int | float | None:
    """One field of one result row as a plain Python number (NaN -> None for optional
    times and energies); b [m]: the base's half-width (the sliding base's fields)."""
    v = float(out[f.slot])
    if math.isnan(v):
        return None
    v /= {"": 1.0, "alpha_ref": alpha_ref, "E_ref": E_ref, "b": b}[f.scale]
    return int(v) if np.dtype(f.dtype).kind == "i" else v


# ---------------------------------------------------------------------------------------
# Axes: the swept keys' names, units and the paper's symbols
# ---------------------------------------------------------------------------------------

# (``AxisMeta`` and ``AXES``, the one table of axis names, units and symbols, live in
# ``rocksweep.vocab.axes``; re-exported here for the readers of fields)


# the units of the record IMs' variables (``vocab.ground.RECORD_IMS``, Sa's: ``SCALE_IMS``)
_IM_UNIT = {var: unit for var, unit, _ in RECORD_IMS.values()} | {"record_sa": SCALE_IMS[SA]}

# Per-record variables of a suite's result (along ``record``; ``record_sa`` along
# (record, period); ``scale_factor`` along (record, stripe) and what the factor depends
# on): name -> (long_name, CF units or None for words and counts, description).
RECORD_VARIABLES: dict[str, tuple[str, str | None, str]] = {
    "record_pga": ("peak ground acceleration of the record as recorded",
                   _IM_UNIT["record_pga"],
                   "max |acc| of the samples (exact for the piecewise-linear record)"),
    "record_pgv": ("peak ground velocity of the record as recorded", _IM_UNIT["record_pgv"],
                   "max |v|, v the trapezoidal integral of the record as given (no baseline "
                   "correction, no filtering), extrema between samples included"),
    "record_sa": ("spectral acceleration of the record as recorded", _IM_UNIT["record_sa"],
                  f"pseudo-spectral acceleration at {100 * SA_DAMPING:g}% damping, exact "
                  "recurrence for the piecewise-linear record (Nigam & Jennings 1969), free "
                  "vibration after the record included"),
    "record_arias": ("Arias intensity of the record as recorded", _IM_UNIT["record_arias"],
                     "pi/(2g) integral of a^2 dt, exact for the piecewise-linear record"),
    "record_cav": ("cumulative absolute velocity of the record as recorded",
                   _IM_UNIT["record_cav"],
                   "integral of |a| dt, exact for the piecewise-linear record"),
    "record_d5_95": ("significant duration D5-95 of the record", _IM_UNIT["record_d5_95"],
                     "time between 5% and 95% of the Arias intensity (Trifunac & Brady "
                     "1975); unchanged by scaling"),
    "record_pgv_over_pga": ("PGV/PGA of the record", _IM_UNIT["record_pgv_over_pga"],
                            "PGV / (PGA g): a pulse-period proxy; unchanged by scaling"),
    "record_avgsa": ("average spectral acceleration of the record as recorded",
                     _IM_UNIT["record_avgsa"],
                     f"geometric mean of Sa ({100 * SA_DAMPING:g}% damping) at {AVGSA_POINTS} "
                     "periods evenly spaced in ln T over the attribute avgsa_periods [s] "
                     "(ground.avgsa; default 0.2-3 x the scale period, or 0.2-3 x 2 pi/p)"),
    "record_v_end": ("ground velocity at the end of the record", "m/s",
                     "the trapezoidal integral of the record as given at its last sample; far "
                     "from 0: the record drifts (not baseline-corrected)"),
    "record_pga_v": ("peak vertical ground acceleration of the record", "g",
                     "max |acc| of the vertical component (UP) as recorded"),
    "record_v_over_h": ("vertical to horizontal peak ratio", "1",
                        "PGA_v / PGA_h, PGA_h of the component the suite scales (H1's, or "
                        "RotD50's with ground.scale.component: RotD50 and a PGA stripe)"),
    "record_rotd50": ("RotD50 of the stripe IM", None,
                      "the median over orientations 0-179 deg of the stripe IM of the two "
                      "horizontals projected (Boore 2010): what scales the records with "
                      "ground.scale.component: RotD50"),
    "record_npts": ("number of samples of the record", "1", "NPTS"),
    "record_dt": ("sample interval of the record", "s", "DT"),
    "record_duration": ("duration of the record", "s", "(NPTS - 1) DT"),
    "record_sha256": ("SHA-256 of the record file's bytes", None,
                      "a resume refuses a suite whose files changed"),
    "scale_factor": ("factor multiplying the record", "1",
                     "the record's accelerations times this factor make the point's ground "
                     "motion (stripes: its IM equals the stripe's value)"),
}


# Swept axes whose values are words (stored as strings), and their scene keys (a record
# scene's shape is "record", under ground.record or, for a suite, ground.shape)
WORD_AXES = ("shape", "law", "record")
WORD_KEYS = ("pulse.shape", "ground.shape", "ground.record", "impact.law")


def axis_attrs(name: str, kind: str = "flexible") -> dict[str, str]:
    """The attributes of a swept key's coordinate: long_name, units (none for words) and
    symbol, with alpha_ref written as the body kind's slenderness (alpha_cg, alpha)."""
    meta = AXES.get(name)
    if meta is None:
        return {"long_name": name, "units": "1", "symbol": name}
    alpha = alpha_symbol(kind)
    out = {"long_name": meta.long_name, "symbol": meta.symbol.replace("alpha_ref", alpha)}
    if meta.units:
        out["units"] = meta.units
    return out


def field_attrs(f: Field, kind: str = "flexible") -> dict[str, str]:
    """The attributes of a result variable: long_name (short), description, rocksweep's
    unit (``unit``, alpha_ref written as the body kind's slenderness) and the symbol."""
    alpha = alpha_symbol(kind)
    out = {"long_name": f.long_name, "description": f.meaning,
           "rocksweep_units": f.unit.replace("alpha_ref", alpha)}
    if f.symbol:
        out["symbol"] = f.symbol.replace("alpha_ref", alpha)
    return out


# ---------------------------------------------------------------------------------------
# Time history columns
# ---------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Column:
    """One column of a time history.

    name: user-facing, normalised name; raw: key in ``Run.history`` (SI, p = 1 rad/s);
    slot: the kernel's ``HIST_*`` column; scale: per-run divisor ("" none, "alpha_ref",
    "u_cr", "E_ref", "g"); unit, meaning: as for ``Field``.
    """

    name: str
    raw: str
    slot: int
    scale: str
    unit: str
    meaning: str


HISTORY: tuple[Column, ...] = (
    Column("p_t", "t", L.HIST_T, "", "1/p", "time p*t"),
    Column("theta_over_alpha", "theta", L.HIST_THETA, "alpha_ref", "alpha_ref",
           "rotation theta/alpha_ref (> 0: rocking on the corner at x = +b)"),
    Column("u_over_ucr", "u", L.HIST_U, "u_cr", "u_cr",
           "lateral displacement of the top mass u/u_cr (eq. 4; NaN for a rigid body)"),
    Column("E_over_Eref", "E", L.HIST_E, "E_ref", "E_ref",
           "mechanical energy relative to rest / E_ref"),
    Column("theta_dot_over_alpha", "theta_dot", L.HIST_THETA_DOT, "alpha_ref", "p alpha_ref",
           "rotation rate theta'/(p alpha_ref)"),
    Column("u_dot_over_ucr", "u_dot", L.HIST_U_DOT, "u_cr", "p u_cr",
           "lateral velocity u'/(p u_cr) (NaN for a rigid body)"),
    Column("phase", "phase", L.HIST_PHASE, "", "1",
           "-1 / +1 rocking on the corner at x = -b / +b, 0 full contact"),
    Column("W_in_over_Eref", "W_in", L.HIST_W_IN, "E_ref", "E_ref",
           "work of the ground motion so far / E_ref"),
    Column("D_damp_over_Eref", "D_damp", L.HIST_D_DAMP, "E_ref", "E_ref",
           "energy dissipated by the damper so far / E_ref"),
    Column("E_impact_over_Eref", "E_impact", L.HIST_E_IMPACT, "E_ref", "E_ref",
           "energy lost in impacts so far (net) / E_ref"),
    Column("xg_over_g", "xg", L.HIST_XG, "g", "g", "ground acceleration x_g''/g (eq. 2)"),
)

#: the sliding base's columns (a point that gives body.mu: its runs write them)
SLIDE_HISTORY: tuple[Column, ...] = (
    Column("x_over_b", "x", L.HIST_X, "b", "b",
           "sliding displacement x/b: how far the base slipped along the ground"),
    Column("contact_phase", "contact_phase", L.HIST_CONTACT, "", "1",
           "contact phase code: " + ", ".join(f"{c} {w}" for w, c in PHASE_CODE.items())),
    Column("D_fric_over_Eref", "D_fric", L.HIST_D_FRIC, "E_ref", "E_ref",
           "energy dissipated by friction so far / E_ref"),
)

HISTORY_RAW: tuple[str, ...] = tuple(c.raw for c in sorted(HISTORY, key=lambda c: c.slot))
"""Keys of ``Run.history`` in kernel column order."""


def history_columns(raw: dict[str, np.ndarray], body) -> dict[str, np.ndarray]:
    """A run's raw history (``Run.history``) -> name -> normalised float64 array, in
    ``HISTORY`` order. body: the run's body (alpha_ref, u_cr, E_ref)."""
    # a rigid body (welded, a block) has no u_cr: its u column (0) is NaN
    scales = {"": 1.0, "alpha_ref": body.alpha_ref, "u_cr": u_cr(body) or math.nan,
              "E_ref": body.E_ref, "g": G, "b": body.b}
    cols = HISTORY + (SLIDE_HISTORY if SLIDE_HISTORY[0].raw in raw else ())
    return {c.name: np.asarray(raw[c.raw], float) / scales[c.scale] for c in cols}
