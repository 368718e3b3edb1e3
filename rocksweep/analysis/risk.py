"""Seismic risk of a fragility: the mean annual rate of each state and its probability in N
years, from a hazard curve.

The mean annual rate of a state (the total probability theorem over the IM; Cornell &
Krawinkler 2000, eq. 1 of the PEER framework):

    lambda_state = integral P(state | im) |d lambda_im(im)|,

P(state | im) the fragility (``rocksweep.analysis.fragility``: Phi(ln(im / im_median) /
beta), or for mode 1 and mode 2 fitted jointly their competing-risk probabilities,
``fragility.probability``)
and lambda_im(x) the hazard curve, the mean annual rate of IM > x. The probability of at
least one occurrence in N years (Poisson): 1 - exp(-lambda_state N).

Integration. The hazard is interpolated linearly in (ln x, ln lambda) between its points
(a power law is exact; a segment that ends at rate 0 is linear in lambda), so |d lambda|
= |lambda'(u)| du in u = ln x is known in closed form on each segment; each segment is
cut into ``SUB`` pieces evenly in u and integrated by 2-point Gauss-Legendre on each
(fourth order: ~1e-7 relative on the tests' power laws).

Beyond the hazard curve's range the tool BOUNDS, it does not extrapolate the hazard:

- above its largest IM x_max: events with IM > x_max happen at the rate lambda(x_max); they
  reach the state with a probability between P(x_max) (the fragility increases) and 1, so
  ``annual_rate`` adds the certain part P(x_max) lambda(x_max) (a lower bound) and
  ``annual_rate_max`` adds lambda(x_max) (the upper bound); the verdict ``above_hazard``
  says when the two differ by more than ``TAIL_SHARE`` of the rate.
- below its smallest IM x_min the hazard says nothing (the rate of small events is not
  given): they add at most P(x_min) times an unknown rate, nothing is added, and the
  verdict ``below_hazard`` says when P(x_min) > ``LOW_P`` (the rate is then a lower bound).

Hazard inputs (``read_hazard``): a two-column CSV with the header ``IM [unit],annual_rate``
(e.g. ``PGA [g],annual_rate``; ``Sa(1.0) [g]`` for Sa at 1 s; ``AvgSa [g]``, ``CAV
[m/s]``, ``Arias [m/s]``; lines starting with # are comments), the IM checked against the
fragility's and the unit converted to the fragility's where both are known (``UNIT_SI``:
g, m/s^2, cm/s^2 or gal; m/s, cm/s, mm/s, g s; the factor is kept in the attribute
``hazard_unit``); or OpenQuake's hazard-curve
CSV (``oq export hcurves``: a comment line
``#,,,,,"generated_by=..., investigation_time=50.0, imt='PGA'"``, then
``lon,lat,depth,poe-<level>,...`` and one row per site): probabilities of exceedance in the
investigation time T converted to rates lambda = -ln(1 - poe) / T; OpenQuake's PGA, SA
and AvgSA are in g, its PGV in cm/s (converted to m/s), IA (Arias) in m/s, CAV in g s
(converted to m/s); levels with poe = 1 (a rate without bound) are left out. An AvgSa
hazard curve does not say its periods: it must be over the fragility's (the attribute
``avgsa_periods``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from rocksweep.analysis.kinds import dataset_kind
from rocksweep.errors import Arg, RiskError
from rocksweep.inputs import check_columns, csv_table, number, number_column, read_text
from rocksweep.outputs import shown
from rocksweep.physics.bodies import G
from rocksweep.vocab.ground import ARIAS, AVGSA, CAV, PGA, PGV, SA, SCALE_IMS
from rocksweep.vocab.kinds import KIND_ATTR, RISK

__all__ = ["Hazard", "fragility_median", "hazard_frame", "read_hazard",
           "risk"]

SUB = 8  # at most this many pieces per hazard segment, 2 Gauss-Legendre nodes each
PIECE = 0.05  # [ln IM] widest piece (a 40-level curve over 1e-4-100 g: 8 a segment)
TAIL_SHARE = 0.01  # above_hazard when the unknown tail exceeds this share of the rate
LOW_P = 1e-3  # below_hazard when the fragility at the hazard's smallest IM exceeds this
PLOT_POINTS = 200  # the figure's grid over the hazard's range
MAX_HAZARD_BYTES = 200 << 20  # [bytes] largest hazard file read (~4 million levels of CSV)
MAX_LEVELS = 1_000_000  # hazard levels of one curve (the integral's memory: docs/faults.md)
#: the integral takes the quadrature nodes in chunks of at most this many (curve, node)
#: values: memory ~ 8 x this x a few temporaries, whatever the hazard's length
CHUNK_ELEMENTS = 1 << 21
Z_TAIL = 8.0  # a lognormal curve's transition: median exp(+-Z_TAIL beta) (1e-15 beyond)
Z_PIECES = 16  # pieces of it (``_narrow``), cut also at the hazard levels inside
Z_PIECE_NODES = 8  # Gauss-Legendre nodes a piece
MAX_INNER = 16  # the levels inside a transition integrated that way (more: the shared rule)
RATE_COLUMN = "annual_rate"
#: OpenQuake's IMTs (upper case) -> (rocksweep's IM, its unit, the factor from
#: OpenQuake's unit to it): PGA, SA and AvgSA in g, PGV in cm/s, IA (Arias) in m/s, CAV
#: in g s (``openquake.hazardlib.imt``)
OQ_IMTS: dict[str, tuple[str, str, float]] = {
    PGA: (PGA, "g", 1.0), SA.upper(): (SA, "g", 1.0), PGV: (PGV, "m/s", 0.01),
    AVGSA.upper(): (AVGSA, "g", 1.0), "IA": (ARIAS, "m/s", 1.0), CAV: (CAV, "m/s", G)}
#: Units a hazard curve may give its IM in: the factor to SI (accelerations to m/s^2,
#: velocities to m/s); a hazard in another unit of the same kind is converted. g is G,
#: the gravity of the model and of the records' PGV (9.81 m/s^2, not g_n = 9.80665)
UNIT_SI: dict[str, tuple[str, float]] = {
    "g": ("acceleration", G), "m/s^2": ("acceleration", 1.0), "m/s2": ("acceleration", 1.0),
    "cm/s^2": ("acceleration", 0.01), "cm/s2": ("acceleration", 0.01),
    "gal": ("acceleration", 0.01), "m/s": ("velocity", 1.0), "cm/s": ("velocity", 0.01),
    "mm/s": ("velocity", 0.001), "g s": ("velocity", G), "g-s": ("velocity", G),
    "g*s": ("velocity", G), "g-sec": ("velocity", G)}
_HEADER = re.compile(r"^\s*(?P<im>[A-Za-z][A-Za-z0-9_]*)\s*(?:\(\s*(?P<T>[0-9.eE+-]+)\s*\))?"
                     r"\s*\[(?P<unit>[^\]]*)\]\s*$")



@dataclass(frozen=True)
class Hazard:
    """A hazard curve: im [unit] float64[n] increasing (> 0), rate [1/yr] float64[n]
    non-increasing (>= 0), the IM's name (PGA, PGV, Sa, ...), its unit, Sa's period [s]
    (NaN otherwise) and where it came from."""

    im: np.ndarray
    rate: np.ndarray
    name: str
    unit: str
    period: float
    source: str
    notes: str = ""  # what reading it left out (OpenQuake's poe = 1 levels)


# ---------------------------------------------------------------------------------------
# reading a hazard curve
# ---------------------------------------------------------------------------------------


def _im_name(text: str) -> str:
    """An IM name as rocksweep spells it (the stripe IMs, ``SCALE_IMS``, in any case: SA ->
    Sa, AVGSA -> AvgSa; OpenQuake's IA -> Arias); another name as given."""
    t = text.strip()
    spelled = {k.lower(): k for k in SCALE_IMS} | {"ia": ARIAS}
    return spelled.get(t.lower(), t)


def _checked(im: np.ndarray, rate: np.ndarray, name: str, unit: str, period: float,
             where: str, rows: list[str]) -> Hazard:
    """The one validation of a hazard curve (bad input: one line naming it and the row,
    ``rows[i]``: the file and line of level i)."""
    if im.size < 2:
        raise RiskError(f"{where}: {im.size} hazard level{'s' * (im.size != 1)}; a hazard "
                        "curve needs at least 2 (IM, annual rate) rows")
    if im.size > MAX_LEVELS:
        raise RiskError(f"{where}: {im.size:,} hazard levels; at most {MAX_LEVELS:,} (a "
                        "hazard curve is smooth: thin it)")
    if np.any(im <= 0.0):
        i = int(np.argmax(im <= 0.0))
        raise RiskError(f"{rows[i]}: IM = {float(im[i])!r}: must be > 0")
    if np.any(rate < 0.0):
        i = int(np.argmax(rate < 0.0))
        raise RiskError(f"{rows[i]}: {RATE_COLUMN} = {float(rate[i])!r}: must be >= 0 "
                        "(an annual rate of exceedance)")
    if np.any(np.diff(im) <= 0.0):
        i = int(np.argmax(np.diff(im) <= 0.0)) + 1
        raise RiskError(f"{rows[i]}: IM = {float(im[i])!r} after {float(im[i - 1])!r}: the IM "
                        "levels must increase")
    if np.any(np.diff(rate) > 0.0):
        i = int(np.argmax(np.diff(rate) > 0.0)) + 1
        raise RiskError(f"{rows[i]}: {RATE_COLUMN} = {float(rate[i])!r} after "
                        f"{float(rate[i - 1])!r}: the rates of exceedance must not increase with "
                        "the IM")
    if not rate[0] > 0.0:
        raise RiskError(f"{where}: every {RATE_COLUMN} is 0: no hazard")
    return Hazard(im, rate, name, unit, period, where)


def _two_columns(cols: list[str], im_vals: Any, rate_vals: Any, rows: list[str],
                 where: str) -> Hazard:
    """A hazard curve from its header ``IM [unit]``, ``annual_rate`` and the two columns'
    values (``rows[i]`` names row i in messages)."""
    if len(cols) != 2:
        raise RiskError(f"{where}: {len(cols)} columns ({', '.join(cols)}); a hazard curve "
                        f"has 2: 'IM [unit]' and '{RATE_COLUMN}' (e.g. 'PGA [g],"
                        f"{RATE_COLUMN}')")
    m = _HEADER.match(cols[0])
    period = _positive(m["T"]) if m is not None and m["T"] else math.nan
    if m is None or (m["T"] and math.isnan(period)):
        raise RiskError(f"{where}: first column {cols[0]!r}: must name the IM and its unit, "
                        "e.g. 'PGA [g]', 'PGV [m/s]' or 'Sa(1.0) [g]'")
    if cols[1] != RATE_COLUMN:
        raise RiskError(f"{where}: second column {cols[1]!r}: must be '{RATE_COLUMN}' (mean "
                        "annual rate of exceedance [1/yr])")
    im = number_column(im_vals, rows, "IM", RiskError)
    rate = number_column(rate_vals, rows, RATE_COLUMN, RiskError)
    return _checked(im, rate, _im_name(m["im"]), m["unit"].strip(), period, where, rows)


def hazard_frame(df: Any, where: str = "hazard") -> Hazard:
    """A hazard curve from a two-column pandas DataFrame: ``IM [unit]`` (e.g. ``PGA [g]``,
    ``Sa(1.0) [g]``) and ``annual_rate`` [1/yr], one row per IM level."""
    cols = check_columns(list(df.columns), where, RiskError)
    if len(cols) != 2:
        return _two_columns(cols, [], [], [], where)  # its one-line refusal
    rows = [f"{where}: row {i + 1}" for i in range(len(df))]
    return _two_columns(cols, df.iloc[:, 0].to_numpy(), df.iloc[:, 1].to_numpy(), rows,
                        where)


_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def _positive(text: str) -> float:
    """A number > 0 written plainly (``50.0``, ``1e-1``), else NaN (``50.0.1``, ``e``)."""
    t = text.strip()
    if not re.fullmatch(_NUM, t):
        return math.nan
    x = float(t)
    return x if math.isfinite(x) and x > 0.0 else math.nan


def _openquake(text: str, where: str, site: int | None) -> Hazard:
    """OpenQuake's hazard-curve CSV (module docstring) -> Hazard in rates."""
    head_line, _, rest = text.partition("\n")
    meta = head_line.strip()
    t = re.search(r"investigation_time\s*=\s*'?([^,'\"\s]*)", meta)
    imt = re.search(r"imt\s*=\s*['\"]([^'\"]*)['\"]", meta)  # 'PGA' (3.x), "PGA" (2.x)
    missing = [k for k, v in (("investigation_time", t), ("imt", imt)) if v is None]
    if missing:  # only what is missing
        raise RiskError(f"{where}, line 1: the OpenQuake header has no "
                        f"{' and no '.join(missing)}: {meta[:80]!r}")
    T = _positive(t.group(1))
    if math.isnan(T):
        raise RiskError(f"{where}, line 1: investigation_time = {t.group(1)!r}: must be a "
                        "number of years > 0")
    mi = re.fullmatch(r"\s*([A-Za-z]+)\s*(?:\(\s*([^)]*?)\s*\))?\s*", imt.group(1))
    if mi is None or mi.group(1).upper() not in OQ_IMTS or (
            mi.group(2) is not None and math.isnan(_positive(mi.group(2)))):
        known = ", ".join(k if k != SA.upper() else "SA(T)" for k in OQ_IMTS)
        raise RiskError(f"{where}, line 1: imt = {imt.group(1)!r}: rocksweep reads {known} "
                        "(T a period > 0 [s])")
    name, unit, factor = OQ_IMTS[mi.group(1).upper()]
    # the table starts on line 2: its line numbers are the file's minus one
    table = csv_table(rest, where, RiskError, "hazard curve")
    lines = [ln + 1 for ln in table.lines]
    levels = [h for h in table.columns if h.startswith("poe-")]
    if not levels:
        raise RiskError(f"{where}: no poe-<level> columns in "
                        f"{','.join(table.columns)[:80]!r}")
    if not table.rows:
        raise RiskError(f"{where}: no site rows")
    if site is None and len(table.rows) > 1:
        raise RiskError(f"{where}: {len(table.rows)} sites; choose one with {{site}} (0 to "
                        f"{len(table.rows) - 1}, the row order)", site=Arg("site"))
    k = 0 if site is None else site
    if not 0 <= k < len(table.rows):
        raise RiskError(f"{where}: site = {site!r}: the file has sites 0 to "
                        f"{len(table.rows) - 1}")
    row = dict(zip(table.columns, table.rows[k], strict=True))
    at = f"{where}, line {lines[k]}"
    x = np.array([number(h[4:], f"{where}, line 2", "level", RiskError)
                  for h in levels]) * factor
    poe = np.array([number(row[h], at, h, RiskError) for h in levels])
    names = [f"{at}, {h}" for h in levels]
    bad = (poe < 0.0) | (poe > 1.0)
    if bad.any():
        raise RiskError(f"{names[int(np.argmax(bad))]}: poe = {float(poe[bad][0])!r}: a "
                        "probability in [0, 1]")
    # every level is checked, poe = 1 too, before those are left out: a poe that rises
    # with the IM is refused wherever it rises
    if np.any(np.diff(x) <= 0.0):
        i = int(np.argmax(np.diff(x) <= 0.0)) + 1
        raise RiskError(f"{where}, line 2: level {levels[i]} after {levels[i - 1]}: the IM "
                        "levels must increase")
    if np.any(np.diff(poe) > 0.0):
        i = int(np.argmax(np.diff(poe) > 0.0)) + 1
        raise RiskError(f"{names[i]}: poe = {float(poe[i])!r} after {float(poe[i - 1])!r}: the "
                        "probabilities of exceedance must not increase with the IM")
    keep = poe < 1.0  # poe = 1: the rate has no bound there
    rate = -np.log1p(-poe[keep]) / T
    period = _positive(mi.group(2)) if mi.group(2) and name == SA else math.nan
    hz = _checked(x[keep], rate, name, unit, period, where,
                  [n for n, kept in zip(names, keep, strict=True) if kept])
    if not keep.all():
        hz = replace(hz, notes=f"{int((~keep).sum())} level(s) with poe = 1 left out (no "
                               f"finite rate): {name} <= {float(x[~keep].max()):.4g} {unit}")
    return hz


def read_hazard(source: Any, *, site: int | None = None) -> Hazard:
    """A hazard curve from a path (a two-column CSV ``IM [unit],annual_rate`` or
    OpenQuake's hazard-curve CSV, told apart by its ``#`` first line), a pandas DataFrame
    of the two columns, or a ``Hazard``. site: the row of an OpenQuake file with several
    sites. Bad input is a one-line ``RiskError`` naming the file, the line and the value
    (the file read through ``rocksweep.inputs``: a regular UTF-8 file of at most
    ``MAX_HAZARD_BYTES``, comma-separated)."""
    if isinstance(source, Hazard):
        return source
    if hasattr(source, "columns") and hasattr(source, "iloc"):
        return hazard_frame(source)
    if not isinstance(source, str | Path):  # a wrong type: a TypeError, as every argument's
        raise TypeError(f"hazard = {type(source).__name__}: must be a CSV path or a pandas "
                        f"DataFrame ('IM [unit]', '{RATE_COLUMN}')")
    path = Path(source)
    where = shown(path)
    text = read_text(path, "hazard curve", RiskError, max_bytes=MAX_HAZARD_BYTES)
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines:
        raise RiskError(f"{where}: empty hazard file")
    if lines[0].lstrip().startswith("#") and any(
            ln.replace(" ", "").startswith("lon,lat") for ln in lines[1:3]):
        return _openquake(text.lstrip("\n\r \t"), where, site)
    if site is not None:  # one curve: a site to choose means another file was meant
        raise RiskError(f"site = {site!r}: {where} is one hazard curve (IM, {RATE_COLUMN}); "
                        "a site is chosen in OpenQuake's files of several sites")
    table = csv_table(text, where, RiskError, "hazard curve",
                      expect=f"'IM [unit],{RATE_COLUMN}'")
    rows = [f"{where}, line {ln}" for ln in table.lines]
    if len(table.columns) != 2:
        return _two_columns(table.columns, [], [], [], where)  # its one-line refusal
    return _two_columns(table.columns, table.column(table.columns[0]),
                        table.column(table.columns[1]), rows, where)


# ---------------------------------------------------------------------------------------
# the fragility's names (29a renames median -> im_median; both are read, here only)
# ---------------------------------------------------------------------------------------


def check_fragility(ds: Any, src: str, suites: bool = False) -> None:
    """Refuse (one line naming ``src``, the file or argument) a Dataset that is no
    fragility: another analysis's, or a sweep (with ``suites``, a record-suite sweep is
    let through: the command line fits it first)."""
    kind = dataset_kind(ds)
    if kind == "fragility":
        return
    if kind == "sweep":
        if suites and "record" in ds["outcome"].dims:
            return
        what = ("a record-suite sweep" if "record" in ds["outcome"].dims else
                "a sweep without records (a pulse or one-record sweep)")
    else:
        what = f"a {kind} Dataset" if kind else "not a rocksweep Dataset"
    raise RiskError(f"{src}: {what}, not a fragility; risk takes what rocksweep.fragility "
                    "returns (rocksweep fragility -o FRAG.h5) of a record-suite sweep")


def fragility_median(fr: xr.Dataset) -> tuple[xr.DataArray, str]:
    """(the fitted median DataArray, its name): ``im_median``, or ``median`` in fragility
    Datasets made before that variable was renamed."""
    for name in ("im_median", "median"):
        if name in fr.data_vars:
            return fr[name], name
    raise RiskError("not a fragility Dataset (no im_median and beta; make one with "
                    "rocksweep.fragility)")


# ---------------------------------------------------------------------------------------
# the integral
# ---------------------------------------------------------------------------------------


def _density(hz: Hazard, x: np.ndarray) -> np.ndarray:
    """|d lambda / d ln x| of the log-log interpolated hazard at x (inside its range)."""
    lx = np.log(hz.im)
    u = np.log(x)
    i = np.clip(np.searchsorted(lx, u, side="right") - 1, 0, lx.size - 2)
    r0, r1 = hz.rate[i], hz.rate[i + 1]
    du = lx[i + 1] - lx[i]
    pos = r1 > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(pos, (np.log(np.where(pos, r1, 1.0)) - np.log(r0)) / du, 0.0)
        out = np.where(pos, -slope * r0 * np.exp(slope * (u - lx[i])), (r0 - r1) / du)
    return out


def _fragility_p(x: np.ndarray, median: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Phi(ln(x / median) / beta) over (curves..., x); beta = 0: the step at the median."""
    from scipy.special import ndtr  # lazy: scipy (+0.1 s)

    med = median[..., None]
    b = beta[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.log(x / med) / b
    step = (x >= med).astype(np.float64)
    return np.where(b > 0.0, ndtr(z), np.where(np.isfinite(med), step, np.nan))


def _nodes(hz: Hazard) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes x_j and weights w_j (2 per piece; a hazard segment cut evenly in
    u = ln x into pieces of at most ``PIECE`` in u, at most ``SUB`` of them) with
    sum_j f(x_j) w_j ~ integral f |d lambda| over the hazard's range: w_j = the quadrature
    weight times |d lambda / d u| at the node (exact for the log-log interpolant:
    lambda' = s lambda on a segment of log-log slope s; a segment that ends at rate 0 is
    linear in lambda: constant lambda'). Vectorised: a dense hazard (many narrow segments)
    gets one piece a segment, so the nodes grow as 2 x its levels."""
    g = np.array([-1.0, 1.0]) / math.sqrt(3.0)  # 2-point Gauss-Legendre on [-1, 1]
    lx = np.log(hz.im)
    width = np.diff(lx)
    pieces = np.clip(np.ceil(width / PIECE), 1, SUB).astype(np.int64)
    seg = np.repeat(np.arange(width.size), pieces)  # the segment of every piece
    k = np.arange(seg.size) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    du = width[seg] / pieces[seg]
    centres = lx[seg] + du * (k + 0.5)
    u = (centres[:, None] + 0.5 * du[:, None] * g[None, :]).ravel()
    s2 = np.repeat(seg, 2)
    r0, r1 = hz.rate[s2], hz.rate[s2 + 1]
    pos = r1 > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = (np.log(np.where(pos, r1, 1.0)) - np.log(r0)) / width[s2]
        dens = np.where(pos, -slope * r0 * np.exp(slope * (u - lx[s2])),
                        (r0 - r1) / width[s2])
    return np.exp(u), 0.5 * np.repeat(du, 2) * dens


def _curve_p(fr: xr.Dataset, med: xr.DataArray, beta: xr.DataArray, dims: list[str]):
    """x -> P(state | x) float[..., x] over ``dims`` (+ any extra dims of med, e.g.
    ``sample``, last before x): the fragility's own model (``fragility.probability``: the
    competing-risk probabilities for mode1 with mode2 fitted jointly, the lognormal CDF
    otherwise) when the Dataset says which (``fit``), else the lognormal CDF."""
    extra = [d for d in med.dims if d not in dims]
    order = [*dims, *extra]
    if "fit" in fr.data_vars and "state" in fr.coords:
        from rocksweep.analysis.fragility import probability  # lazy: scipy, yaml (+0.2 s)

        like = xr.Dataset({"im_median": med, "beta": beta, "fit": fr["fit"]},
                          coords={"state": fr["state"]})

        def p(x: np.ndarray) -> np.ndarray:
            return np.asarray(probability(like, x).transpose(*order, "im").values,
                              np.float64)
        return p
    m = np.asarray(med.transpose(*order).values, np.float64)
    b = np.asarray(beta.transpose(*order).values, np.float64)
    return lambda x: _fragility_p(x, m, b)


def _rates(hz: Hazard, p, lognormal: tuple[np.ndarray, np.ndarray] | None = None
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(annual_rate, annual_rate_max, P at x_min, P at x_max) for the fragility curves
    x -> p(x) float[..., x] (module docstring). The quadrature nodes are taken in chunks
    of at most ``CHUNK_ELEMENTS`` / curves (memory: ``CHUNK_ELEMENTS`` x 8 bytes a few
    times, whatever the hazard's length). lognormal: the curves' (median, beta) when they
    are lognormal: a curve whose transition median exp(+-Z_TAIL beta) lies between two
    hazard levels is integrated exactly there instead (``_narrow``)."""
    x, w = _nodes(hz)
    ends = p(hz.im[[0, -1]])
    n_curves = max(1, int(np.prod(ends.shape[:-1])))
    step = max(1, CHUNK_ELEMENTS // n_curves)
    inside = np.zeros(ends.shape[:-1])
    for k in range(0, x.size, step):
        inside = inside + p(x[k:k + step]) @ w[k:k + step]
    p_lo, p_hi = ends[..., 0], ends[..., 1]
    top = hz.rate[-1]
    rate = inside + p_hi * top
    if lognormal is not None:
        narrow = _narrow(hz, *lognormal)
        if narrow is not None:
            use, value = narrow
            rate = np.where(use, value, rate)
            inside = np.where(use, value - p_hi * top, inside)
    return rate, inside + top, p_lo, p_hi


def _hazard_at(hz: Hazard, x: np.ndarray) -> np.ndarray:
    """lambda(x) of the log-log interpolated hazard inside its range (a segment ending at
    rate 0: linear in lambda)."""
    lx = np.log(hz.im)
    u = np.log(x)
    i = np.clip(np.searchsorted(lx, u, side="right") - 1, 0, lx.size - 2)
    r0, r1 = hz.rate[i], hz.rate[i + 1]
    f = (u - lx[i]) / (lx[i + 1] - lx[i])
    with np.errstate(divide="ignore", invalid="ignore"):
        pos = r1 > 0.0
        loglin = np.exp(np.log(r0) + f * (np.log(np.where(pos, r1, 1.0)) - np.log(r0)))
    return np.where(pos, loglin, r0 + f * (r1 - r0))


def _narrow(hz: Hazard, med: np.ndarray, beta: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray] | None:
    """The rate of lognormal curves whose transition is narrow, by parts: annual_rate =
    P(x_min) lambda(x_min) + integral lambda dP over the hazard's range, dP the lognormal
    density, integrated over z = ln(x / median) / beta in [-Z_TAIL, Z_TAIL] by
    Gauss-Legendre, cut at the hazard levels inside (between them the hazard is a power
    law: the rule converges exponentially); exact for beta = 0 (lambda(median)). Used for
    the curves whose transition median exp(+-Z_TAIL beta) lies inside the hazard's range
    and holds at most ``MAX_INNER`` hazard levels: the steep curves, the shared
    quadrature's worst case. Returns (use, rate) or None when no curve qualifies."""
    from scipy.special import ndtr  # lazy: scipy (+0.1 s)

    med = np.asarray(med, np.float64)
    beta = np.asarray(beta, np.float64)
    ok = np.isfinite(med) & (med > 0) & np.isfinite(beta) & (beta >= 0)
    if not ok.any():
        return None
    m = np.where(ok, med, 1.0)
    b = np.where(ok, beta, 0.0)
    lx = np.log(hz.im)
    lo_u, hi_u = np.log(m) - Z_TAIL * b, np.log(m) + Z_TAIL * b
    first = np.searchsorted(lx, lo_u, side="right")  # the levels strictly inside
    inner = np.searchsorted(lx, hi_u, side="left") - first
    use = ok & (inner <= MAX_INNER) & (lo_u >= lx[0]) & (hi_u <= lx[-1])
    if not use.any():
        return None
    tail = ndtr(-Z_TAIL)  # beyond +-Z_TAIL: lambda at the ends' values
    out = np.zeros(med.shape)
    zs, ws = np.polynomial.legendre.leggauss(Z_PIECE_NODES)
    grid = np.linspace(-Z_TAIL, Z_TAIL, Z_PIECES + 1)  # pieces of 1 in z: phi is smooth there

    def rule(edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Nodes z and weights w phi(z) of the rule on the pieces between ``edges``."""
        half, mid = 0.5 * np.diff(edges), 0.5 * (edges[1:] + edges[:-1])
        zz = (mid[:, None] + half[:, None] * zs[None, :]).ravel()
        return zz, (half[:, None] * ws[None, :]).ravel() * np.exp(-0.5 * zz * zz) / \
            math.sqrt(2.0 * math.pi)

    one = use & (inner <= 0)  # no level inside: one rule for all of them at once
    z, w = rule(grid)
    mu, bu = m[one], b[one]
    out[one] = _hazard_at(hz, np.clip(mu[:, None] * np.exp(bu[:, None] * z[None, :]),
                                      hz.im[0], hz.im[-1])) @ w
    for idx in zip(*np.nonzero(use & (inner > 0)), strict=True):  # cut at the levels too
        lm, bi = math.log(m[idx]), b[idx]
        cuts = (lx[first[idx]:first[idx] + inner[idx]] - lm) / bi
        z, w = rule(np.union1d(grid, cuts))
        out[idx] = _hazard_at(hz, np.clip(m[idx] * np.exp(bi * z), hz.im[0],
                                          hz.im[-1])) @ w
    out = out + tail * (_hazard_at(hz, np.exp(np.clip(lo_u, lx[0], lx[-1])))
                        + _hazard_at(hz, np.exp(np.clip(hi_u, lx[0], lx[-1]))))
    return use, np.where(use, out, 0.0)


def _check_curves(fr: xr.Dataset, med: xr.DataArray, dims: list[str]) -> None:
    """Refuse (one line) a fragility whose numbers no fit gives: a median <= 0 or
    infinite, a beta < 0 or infinite (NaN: no fit, carried as such)."""
    beta = fr["beta"]
    for name, da, bad in (
            ("im_median", med, lambda v: np.isinf(v) | (v <= 0.0)),
            ("beta", beta, lambda v: np.isinf(v) | (v < 0.0))):
        v = np.asarray(da.values, np.float64)
        with np.errstate(invalid="ignore"):
            wrong = bad(v) & ~np.isnan(v)
        if wrong.any():
            k = np.unravel_index(int(np.argmax(wrong)), v.shape)
            at = ", ".join(f"{d} = {da[d].values[i]}" for d, i in zip(da.dims, k, strict=True)
                           if d in da.coords)
            src = fr.attrs.get("source") or "the fragility Dataset"
            raise RiskError(f"{src}: {name} = {float(v[k])!r}{f' at {at}' if at else ''}: "
                            f"must be {'> 0' if name == 'im_median' else '>= 0'} and finite "
                            "(a fragility from rocksweep.fragility)")


def _interval(v: np.ndarray, ci: float) -> tuple[np.ndarray, np.ndarray]:
    """Percentile interval at level ci over the last axis, finite values only."""
    q = 100.0 * np.array([(1.0 - ci) / 2.0, (1.0 + ci) / 2.0])
    out = np.full((2,) + v.shape[:-1], np.nan)
    for idx in np.ndindex(*v.shape[:-1]):
        w = v[idx]
        w = w[np.isfinite(w)]
        if w.size:
            out[(slice(None),) + idx] = np.percentile(w, q)
    return out[0], out[1]


def _check_years(years: Any) -> float:
    if isinstance(years, bool) or not isinstance(years, int | float | np.integer |
                                                  np.floating):
        raise RiskError(f"years = {years!r}: must be a number of years > 0")
    y = float(years)
    if not (math.isfinite(y) and y > 0.0):
        raise RiskError(f"years = {years!r}: must be a finite number of years > 0")
    return y


def _unit_factor(frm: str, to: str) -> float | None:
    """x [frm] times this is x [to]; None when either unit is unknown or their kinds
    differ (``UNIT_SI``)."""
    a, b = UNIT_SI.get(frm.strip().lower()), UNIT_SI.get(to.strip().lower())
    if a is None or b is None or a[0] != b[0]:
        return None
    return a[1] / b[1]


def _check_match(fr: xr.Dataset, hz: Hazard) -> Hazard:
    """The hazard curve in the fragility's IM units (converted where both units are known),
    or a RiskError naming what does not match."""
    im, unit = str(fr.attrs.get("im", "")), str(fr.attrs.get("im_units", ""))
    if not im:
        raise RiskError("the fragility Dataset has no attribute im (the IM its curves are "
                        "over)")
    if hz.name != im:
        raise RiskError(f"{hz.source}: hazard IM {hz.name} [{hz.unit}] is not the "
                        f"fragility's IM {im} [{unit}]; use a hazard curve of {im}")
    if hz.unit != unit:
        factor = _unit_factor(hz.unit, unit)
        if factor is None:
            known = ", ".join(UNIT_SI)
            raise RiskError(f"{hz.source}: hazard unit [{hz.unit}] for {hz.name} is not the "
                            f"fragility's [{unit}] and cannot be converted to it (known "
                            f"units: {known}); convert the hazard curve to {unit}")
        hz = replace(hz, im=hz.im * factor, unit=unit)
    if im == "Sa":
        per = float(fr.attrs.get("period", math.nan))
        if not (math.isfinite(hz.period) and math.isfinite(per)
                and math.isclose(hz.period, per, rel_tol=1e-6)):
            raise RiskError(f"{hz.source}: hazard Sa period {hz.period:g} s is not the "
                            f"fragility's {per:g} s")
    return hz


def risk(fr: xr.Dataset, hazard: Any, years: float = 50.0, *,
         site: int | None = None) -> xr.Dataset:
    """Mean annual rate and probability in ``years`` of each state of a fragility Dataset.

    fr: what ``rocksweep.fragility`` returns (``im_median`` or ``median`` [IM units],
    ``beta``, attrs ``im``, ``im_units``; with bootstrap, ``im_median_samples`` and
    ``beta_samples`` over ``sample``); hazard: a path (two-column CSV ``IM [unit],
    annual_rate`` or OpenQuake's hazard-curve CSV), a DataFrame or a ``Hazard``; years:
    N > 0; site: the row of an OpenQuake file with several sites.

    Returns a Dataset over the fragility's dims (state, lam, ...): ``annual_rate``
    [1/yr] (the integral over the hazard's range plus the certain tail above it: a lower
    bound, module docstring), ``annual_rate_max`` (the tail above at its largest),
    ``probability`` = 1 - exp(-annual_rate years), their ``_lo``/``_hi`` (the bootstrap
    percentile interval at the fragility's ``ci`` from its resamples; NaN without them),
    ``reason`` ("ok", or "above_hazard", "below_hazard", "no_fit", and the fragility's
    own non-ok reasons as "fit_<reason>", joined by ","); for the
    figure ``hazard_rate`` over ``hazard_im`` (the curve read), and over ``im_level`` (a
    grid over the hazard's range) ``fragility`` and ``rate_density`` = P(state | x)
    |d lambda / d ln x| [1/yr], the integrand. attrs: rocksweep_kind = "risk", years, im,
    im_units, hazard_source, extrapolation, ci.
    """
    if not isinstance(fr, xr.Dataset):
        raise RiskError(f"fr = {type(fr).__name__}: a fragility Dataset "
                        "(rocksweep.fragility)")
    med_da, med_name = fragility_median(fr)
    if "beta" not in fr.data_vars:
        raise RiskError("not a fragility Dataset (no beta)")
    N = _check_years(years)
    read = read_hazard(hazard, site=site)
    hz = _check_match(fr, read)
    dims = list(med_da.dims)
    _check_curves(fr, med_da, dims)
    curve = _curve_p(fr, med_da, fr["beta"], dims)
    competing = "fit" in fr.data_vars and "competing" in np.atleast_1d(
        np.asarray(fr["fit"].values)).astype(str)
    logn = None if competing else (
        np.asarray(med_da.transpose(*dims).values, np.float64),
        np.asarray(fr["beta"].transpose(*dims).values, np.float64))
    rate, rate_max, p_lo, p_hi = _rates(hz, curve, logn)
    ci = float(fr.attrs.get("ci", 0.9))
    lo = hi = np.full(rate.shape, np.nan)
    samples = f"{med_name}_samples"
    if samples in fr.data_vars and "beta_samples" in fr.data_vars:
        ms, bs = fr[samples], fr["beta_samples"]
        ok = np.isfinite(ms) & np.isfinite(bs)
        order = [*dims, *[d for d in ms.dims if d not in dims]]
        r_s, _, _, _ = _rates(hz, _curve_p(fr, ms.where(ok), bs.where(ok), dims), None if
                              competing else (np.asarray(ms.where(ok).transpose(*order).values),
                                              np.asarray(bs.where(ok).transpose(*order).values)))
        lo, hi = _interval(r_s, ci)
    reasons = np.empty(rate.shape, dtype=object)
    unknown_top = rate_max - rate
    fit_reason = (np.asarray(fr["reason"].transpose(*dims).values, dtype=str)
                  if "reason" in fr.data_vars and set(fr["reason"].dims) == set(dims)
                  else np.full(rate.shape, "ok"))
    for idx in np.ndindex(*rate.shape):
        bits = [f"fit_{r}" for r in str(fit_reason[idx]).split(",")
                if r and r != "ok"]  # the fragility's own verdict carries over
        if not math.isfinite(rate[idx]):
            bits.append("no_fit" if not bits else "no_rate")
        else:
            if unknown_top[idx] > TAIL_SHARE * rate[idx]:
                bits.append("above_hazard")
            if p_lo[idx] > LOW_P:
                bits.append("below_hazard")
        reasons[idx] = ",".join(bits) or "ok"

    def prob(r: np.ndarray) -> np.ndarray:
        return -np.expm1(-r * N)

    coords: dict[str, Any] = {d: fr[d] for d in dims if d in fr.coords}
    if "state" in fr.coords and "state" not in dims:
        coords["state"] = fr["state"]
    grid = np.geomspace(hz.im[0], hz.im[-1], PLOT_POINTS)
    dens = _density(hz, grid)
    p_grid = curve(grid)
    unit = hz.unit
    data: dict[str, Any] = {
        "annual_rate": (dims, rate, {"units": "1/yr", "long_name": "mean annual rate of the "
                                     "state (hazard range + certain tail above)"}),
        "annual_rate_max": (dims, rate_max, {"units": "1/yr", "long_name": "mean annual rate "
                                             "with the tail above the hazard at its largest"}),
        "annual_rate_lo": (dims, lo, {"units": "1/yr", "long_name": f"bootstrap {ci:g} "
                                      "interval, lower"}),
        "annual_rate_hi": (dims, hi, {"units": "1/yr", "long_name": f"bootstrap {ci:g} "
                                      "interval, upper"}),
        "probability": (dims, prob(rate), {"units": "1", "long_name": f"probability in "
                                           f"{N:g} years"}),
        "probability_lo": (dims, prob(lo), {"units": "1"}),
        "probability_hi": (dims, prob(hi), {"units": "1"}),
        "reason": (dims, reasons.astype(str), {"long_name": "ok, or above_hazard, "
                                               "below_hazard, no_fit, fit_<the fit's "
                                               "reason>"}),
        "hazard_rate": (("hazard_im",), hz.rate, {"units": "1/yr", "long_name": "hazard "
                                                  "curve: annual rate of IM > x"}),
        "fragility": ([*dims, "im_level"], p_grid, {"units": "1"}),
        "rate_density": ([*dims, "im_level"], p_grid * np.maximum(dens, 0.0),
                         {"units": "1/yr", "long_name": "P(state | x) |d lambda / d ln x|: "
                          "the integrand over ln x"}),
    }
    coords["hazard_im"] = ("hazard_im", hz.im, {"units": unit})
    coords["im_level"] = ("im_level", grid, {"units": unit})
    attrs = {KIND_ATTR: RISK, "years": N, "im": hz.name, "im_units": unit,
             "hazard_source": hz.source, "ci": ci,
             "extrapolation": "bound: above the hazard's largest IM the certain tail "
                              "P(x_max) lambda(x_max) is added (annual_rate_max: "
                              "lambda(x_max)); below its smallest IM nothing is added",
             "reference": "Cornell & Krawinkler (2000), Progress and challenges in "
                          "seismic performance assessment, PEER Center News 3(2)"}
    if math.isfinite(hz.period):
        attrs["period"] = hz.period
    if hz.notes:
        attrs["hazard_notes"] = hz.notes
    if read.unit != hz.unit:
        attrs["hazard_unit"] = (f"{read.unit}, converted to {hz.unit} "
                                f"(x {_unit_factor(read.unit, hz.unit):.6g})")
    for k in ("title", "states"):
        if k in fr.attrs:
            attrs[k] = fr.attrs[k]
    return xr.Dataset(data, coords=coords, attrs=attrs)
