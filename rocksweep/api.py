"""The Python API, a thin facade: run a scene's grid, open a result, simulate one point,
and the analyses of a Dataset. Each function hands over to the room that does the work
and checks its arguments: scenes (``rocksweep.scene.inputs``), the sweep session
(``rocksweep.compute.session``), a result as a Dataset (``rocksweep.store.dataset``), a
run's history (``rocksweep.compute.history``), the analyses (``rocksweep.analysis``), the
figures (``rocksweep.figures``). Errors name the API's arguments (``rocksweep.errors.Arg``).
The functions of a Dataset (``@analysis``: ``ANALYSES``) are also its methods,
``ds.rocksweep.<analysis>(...)`` (``rocksweep.accessor``).

Each function imports its room when called: the rooms load numba, h5py, xarray, scipy and
matplotlib, 0.1-2 s each (docs/performance.md), and one function needs a few of them.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rocksweep.analysis.resampling import DEFAULT_CI, DEFAULT_SEED
from rocksweep.analysis.tolerance import DEFAULT_RTOL, DEFAULT_RTOL_MANY
from rocksweep.compute.arguments import check_flag
from rocksweep.errors import ApiError, check_type, is_integer, is_real
from rocksweep.outputs import shown
from rocksweep.simulation import Simulation  # what simulate returns

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from rocksweep.scene.inputs import Overrides, SceneLike

#: the functions whose first argument is a Dataset (or its file), in the order
#: ``ds.rocksweep`` lists them as methods (``rocksweep.accessor``)
ANALYSES: list[Callable[..., Any]] = []


def analysis(fn: Callable[..., Any]) -> Callable[..., Any]:
    """Mark a function of a Dataset: ``ds.rocksweep.<name>(...)`` is ``<name>(ds, ...)``."""
    ANALYSES.append(fn)
    return fn


# --- rocksweep.run and rocksweep.open ----------------------------------------------------

def run(scene: SceneLike, *, jobs: int = 1, output: str | Path | None = None,
        overrides: Overrides = (), progress: bool = False, overwrite: bool = False,
        resume: bool = False, client: Any = None, adaptive: bool = False,
        validate: bool = False, coarse: int | None = None, audit: float | None = None,
        axes: Sequence[str] | None = None, margin: int | None = None,
        final_margin: int | None = None, seed: int | None = None,
        threshold: float | None = None) -> xr.Dataset:
    """Compute every point of a scene's grid; return the results as an xarray Dataset.

    scene: a path to a scene YAML file, YAML text, or a dict with the YAML's structure.
    jobs: worker threads (-1: one per core). output: also keep the HDF5 result file
    there (written exactly as ``rocksweep sweep SCENE -o OUTPUT`` writes it; an existing
    file is refused unless ``overwrite``; ``resume`` finishes an interrupted file of the
    same scene). overrides: ``["impact.lam=0.2"]`` or ``{"impact.lam": 0.2}``.
    progress: print the header and a progress bar (``tqdm.auto``: a widget in notebooks).
    client: a ``dask.distributed.Client``: the points run on its cluster (e.g. a
    ``LocalCluster``'s workers) instead of local threads (jobs is then not used).

    The Dataset has the file's variables (outcome: -1 not computed, 0 safe, 1 mode 1, 2
    mode 2; impacts, uplifts, theta_max_over_alpha, t_overturn, status, steps,
    event_steps, and energies with ``outputs: {energy: true}``), one dimension per swept
    key (coordinates named after the keys: shape, lam, A_ratio, w_over_p, body keys),
    the unswept keys as scalar coordinates and the file's attributes (see ``open``). It
    is loaded in memory; without ``output`` no file is kept.

    adaptive: compute only near the class boundaries (``rocksweep sweep --adaptive``),
    with the settings of ``rocksweep.compute.adaptive.Options`` (None: the scene's
    ``refine`` or the default): coarse, the coarse level; audit, the share of filled
    points computed as a check; axes, the two diagram axes; margin and final_margin, cells
    refined around a boundary; seed, of the audit sample; threshold, the share of
    disagreeing audits that warns. validate: check the fill on a coarse uniform lattice
    (printed with ``progress``). The Dataset then also has ``computed`` (0 filled, 1
    computed, 2/3 audit point that agreed/disagreed); filled points hold "not computed"
    values in every variable but outcome.

    Raises a one-line ``RocksweepError`` for a bad scene, option or output path;
    KeyboardInterrupt (``SweepInterrupted``) after saving the finished points to
    ``output``. A wrong type (``jobs="2"``, ``overrides=5``) is a TypeError naming the
    argument; every argument is checked before the output is touched.
    """
    from rocksweep.compute.session import run_session  # checks every argument first

    return run_session(scene, output, overrides=overrides, jobs=jobs, resume=resume,
                       overwrite=overwrite, progress=progress, client=client,
                       adaptive=adaptive, validate=validate,
                       settings={"coarse": coarse, "audit": audit, "axes": axes,
                                 "margin": margin, "final_margin": final_margin,
                                 "seed": seed, "threshold": threshold})


def open(path: str | Path) -> xr.Dataset:  # noqa: A001 (rocksweep.open, like xarray's)
    """Any file rocksweep writes as an xarray Dataset, loaded in memory (the file is
    closed): a sweep result, or what an analysis wrote (fragility, risk, IM efficiency,
    calibration ``-o .h5``, boundaries and accuracy HDF5), whose ``attrs["rocksweep_kind"]``
    names its kind (``rocksweep.analysis.files``).

    A sweep result: each variable carries its unit (``rocksweep_units``:
    ``rocksweep.fields.UNITS``, e.g. alpha_ref, 1/p, E_ref; CF ``units`` "1") and a
    description; ``outcome`` its codes and words as CF flags (``flag_values`` -1 0 1 2,
    ``flag_meanings`` "not_run safe mode1 mode2"), ``status`` its bits (``flag_masks``,
    ``flag_meanings``, ``flagged_mask``). The attributes are the file's provenance (all of
    them: ``rocksweep.store.format``): ``scene`` (the YAML verbatim), ``scene_resolved``,
    ``overrides``, ``numerics``, ``accuracy``, versions, times, ``complete``. Works
    while a sweep is still writing the file (no lock is taken). A file that is not a
    rocksweep file is a one-line ``RocksweepError``.
    """
    from rocksweep.analysis.files import open_any  # lazy: h5py, yaml (+0.2 s)

    check_type("path", path, isinstance(path, str | os.PathLike),
               "a path (str or pathlib.Path)")
    return open_any(path)


def _dataset_arg(ds: Any, what: str) -> xr.Dataset:
    """A Dataset, or a path to one opened (``analysis.files.as_dataset``)."""
    from rocksweep.analysis.files import as_dataset  # lazy: h5py, yaml (+0.2 s)

    _check_dataset(what, ds)
    return as_dataset(ds, what)


def _check_dataset(name: str, ds: Any) -> None:
    import xarray as xr  # lazy: xarray, pandas (+0.4 s)

    check_type(name, ds, isinstance(ds, xr.Dataset | str | Path),
               "an xarray Dataset (rocksweep.run, rocksweep.open or an analysis) or a path "
               "to one")


# --- Analyses: a result Dataset in, a Dataset, a DataFrame or a Figure out ---------------

@analysis
def plot(ds: xr.Dataset, x: str | None = None, y: str | None = None, *, ax: Any = None,
         curves: bool = False, show_computed: bool = False, mu: bool = False,
         width: str | None = None, compare: str | None = None,
         regime: bool = False) -> Figure:
    """The figure of any rocksweep Dataset, pyplot-free: a sweep's stability diagram
    (Figures 3 and 4; the options below), or the figure of a fragility (curves, stripe
    fractions sized by record count, bands, beta in the legend, IM on a log axis), IDA,
    spectra, risk (hazard, fragility, the rate's integrand) or IM-efficiency Dataset
    (``rocksweep.figures.by_kind``; ``ax`` and ``width`` apply to all). A record-suite
    sweep is drawn as its overturning fragility (stripe fractions and the fitted curve).

    ds: what ``run`` or ``open`` returns. x, y: the swept keys on the axes (default
    w_over_p and A_ratio, or the two swept keys besides lam); one panel per value of the
    other swept keys, the lam values overlaid; a result with one swept key besides lam is
    a line plot. ax: an Axes (or one per panel) to draw into; the legend then goes outside
    the axes, once per figure. curves: the class boundary lines; show_computed: shade
    the points an adaptive sweep computed. mu: the friction demand ``mu_required`` (a
    result with contact outputs) as a contour map instead of the classes. width:
    "single" or "double" (journal column widths with fonts to match), None for
    matplotlib's defaults. compare: a swept key (e.g. "impact.law" or "lam") whose values
    are compared on one diagram, coloured by which of them overturn each cell. A result
    with per-point error estimates rings the points whose outcome changes at half the step.
    regime: the contact phases each run of a sliding base (``body.mu``) visited instead
    of the classes, e.g. x = "body.mu", y = "A_ratio" (Shenton's diagram;
    ``rocksweep.figures.regimes``).
    """
    from rocksweep.figures.by_kind import plot_any  # lazy: numba, matplotlib (+0.9 s)

    _check_dataset("ds", ds)
    return plot_any(ds, x, y, ax=ax, curves=curves, show_computed=show_computed, mu=mu,
                    width=width, compare=compare, regime=regime)


@analysis
def boundaries(ds: xr.Dataset, rtol: float = DEFAULT_RTOL, mode: int | None = None,
               search: bool = True) -> xr.Dataset:
    """A_min: the smallest amplitude (A_ratio) that overturns, for every x (w_over_p or
    p) of the diagram to the relative tolerance ``rtol`` (in (0, 0.1]), whatever the grid's
    spacing: a search below the first overturning grid value (near the uplift threshold
    and where the response came close) and a bisection, with kernel runs at the sweep's
    accuracy; ``A_min_method`` says how each value was found. search=False: the bisection
    between the grid's first overturning value and the one below only (faster, but A_min
    then depends on the grid).

    ds: a complete result (``run`` / ``open``) with a diagram over (w_over_p, A_ratio).
    mode: 1 or 2 for that overturning mode only. Returns a Dataset: ``A_min`` (NaN: none
    found), ``mode``, ``A_min_method`` (``rocksweep.analysis.boundaries.A_MIN_METHODS``;
    "first grid value" is an upper bound), the final bracket ``lo``/``hi`` and the kernel
    ``runs``, over every other swept key (e.g. shape, lam) and x. The class boundary
    polylines: ``boundary_lines(ds)``.
    """
    from rocksweep.analysis.boundaries import boundaries_dataset  # lazy: numba, scipy (+0.3 s)

    _check_dataset("ds", ds)
    return boundaries_dataset(ds, rtol, mode, search)


@analysis
def boundary_lines(ds: xr.Dataset) -> Any:
    """The lines between classes of a complete result's diagrams as a tidy
    ``pandas.DataFrame``: one row per vertex with the panel's other swept keys, ``line``,
    ``classes`` (e.g. "safe|mode1"), ``closed``, ``vertex``, ``x``, ``y`` (axis values)."""
    from rocksweep.analysis.boundaries import boundary_lines_frame  # lazy: numba, scipy (+0.3 s)

    _check_dataset("ds", ds)
    return boundary_lines_frame(ds)


@analysis
def spectra(ds: xr.Dataset, rtol: float = DEFAULT_RTOL, search: bool = True) -> xr.Dataset:
    """Rocking and overturning spectra of a complete sweep over p (a record) or w_over_p,
    A_ratio and optionally lam: ``theta_max_over_alpha`` and ``outcome`` over (lam,
    A_ratio, p), ``A_min`` and ``mode`` over (lam, p), A_min to ``rtol`` whatever the grid
    (search=False: the grid's bracket bisected only, as for ``boundaries``)."""
    from rocksweep.analysis.spectrum import spectra as compute_spectra  # lazy: numba (+0.7 s)

    _check_dataset("ds", ds)
    return compute_spectra(ds, rtol, search).to_dataset()


@analysis
def floor_spectrum(ds: xr.Dataset, rtol: float = DEFAULT_RTOL_MANY, search: bool = True
                   ) -> xr.Dataset:
    """The floor spectrum of a complete sweep over ``floor.period``: a record suite's
    P(overturn) over (floor.period, stripe, ...) (with an ``angle`` axis for each
    orientation answer: ``orientation`` each/worst), or one record's or a pulse's A_min
    over floor.period, bisected to ``rtol`` (in (0, 0.1]; search=False: the grid's bracket
    only, as for ``spectra``) (``rocksweep.analysis.floors``). ds: what ``run`` or ``open``
    returns, or a result file's path. Its figure: ``rocksweep.plot``; its table:
    ``rocksweep.table``."""
    from rocksweep.analysis.floors import floor_spectrum as compute  # lazy: xarray, pandas (+0.4 s)

    _check_dataset("ds", ds)
    return compute(ds, rtol, search)


@analysis
def ida(ds: xr.Dataset, rtol: float = DEFAULT_RTOL_MANY, *, state: str = "overturn"
        ) -> xr.Dataset:
    """Incremental dynamic analysis per record of a scaled record-suite sweep: the
    smallest IM (the stripe IM: PGA [g], PGV [m/s], Sa [g], ...) that overturns each
    record, bisected to ``rtol`` between the last stripe below the first overturning one
    and that stripe (kernel runs at the sweep's accuracy), and whether a higher stripe is
    safe again (``resurrection``). state: another damage state in overturning's place, as
    ``fragility``'s (e.g. "slide:0.5": the smallest IM that slides the base 0.5 b, or
    overturns it; "theta:0.5"). ds: what ``run`` or ``open`` returns. Returns a Dataset
    over the other swept keys and ``record`` (``rocksweep.analysis.ida.ida``) with the
    IDA curves ``rocksweep.plot`` draws. A sweep over ``angle``: every (record, angle) a
    sample, and ``ida_im_worst`` / ``worst_angle`` each record's worst orientation."""
    from rocksweep.analysis.floors import worst_ida  # lazy: numba (+0.7 s)
    from rocksweep.analysis.ida import ida_dataset

    _check_dataset("ds", ds)
    return worst_ida(ida_dataset(ds, rtol, state))


@analysis
def fragility(ds: xr.Dataset, *, state: str | Sequence[str] = "overturn",
              im: str | None = None, period: float | None = None,
              bootstrap: int | None = None, seed: int = DEFAULT_SEED,
              ci: float = DEFAULT_CI, joint: bool = False) -> xr.Dataset:
    """Lognormal fragility curves P(state | IM = x) = Phi(ln(x / im_median) / beta) of a
    record-suite sweep (a scene with ``ground.records``), fitted by maximum likelihood
    (Baker 2015) to the counts at each stripe of a scaled suite ("stripes-mle") or to the
    (IM, 0/1) pairs of an unscaled one ("cloud-mle"); one curve per value of every other
    swept key (lam, p, body keys). The states, fits and variables in full:
    ``rocksweep.analysis.fragility.fragility``.

    ds: what ``run`` or ``open`` returns (or a result file's path). state: "overturn"
    (either mode), "mode1", "mode2", "uplift", "theta:X" (max|theta|/alpha_cg >= X, or
    overturned, 0 < X <= 1), "slide:D" (the base's sliding displacement slide_max >= D, or
    overturned, D > 0 in base half-widths b, slide_max's units; a scene with
    body.mu), or a list of them (a ``state`` dimension; each state fitted
    alone, its numbers the same whatever else is asked for; nested curves that cross in
    the data say "crossing"). joint: damage states share one beta (an ordinal fit, its
    likelihood-ratio test stored: ``parallel_rejected``), mode1 with mode2 a
    competing-risk fit. im: a cloud's IM, "PGA"
    (default), "PGV" or "Sa" with period [s] one of the stored periods. bootstrap:
    resamples over records for the intervals and bands (0: none; None:
    ``rocksweep.analysis.resampling.DEFAULT_BOOTSTRAP``, 200); seed: their generator's
    seed; ci: the interval's level. Points flagged undecided are left out, counted.

    Returns a Dataset: ``im_median`` [IM units], ``beta``, their intervals, ``reason``
    ("ok" or why the curve should not be trusted: also a ``FragilityWarning``), the counts
    and the fitted ``curve`` over ``im_grid`` (in full: the analysis's docstring). A sweep
    over ``angle`` gives an ``orientation`` dimension: "each" (every (record, angle) a
    sample, records resampled with all their angles) and "worst" (the worst angle per record).
    """
    from rocksweep.analysis.floors import by_orientation  # lazy: scipy (+0.5 s)
    from rocksweep.analysis.fragility import fragility as fit

    ds = _dataset_arg(ds, "ds")
    if "angle" in getattr(ds, "dims", ()):  # every orientation a sample, and the worst
        return by_orientation(ds, lambda d: fit(
            d, state=state, im=im, period=period, bootstrap=bootstrap, seed=seed, ci=ci,
            joint=joint))
    return fit(ds, state=state, im=im, period=period, bootstrap=bootstrap, seed=seed, ci=ci,
               joint=joint)


@analysis
def risk(fr: xr.Dataset, hazard: Any, years: float = 50, *, site: int | None = None
         ) -> xr.Dataset:
    """Mean annual rate and probability in ``years`` of each state of a fragility:
    lambda = integral P(state | im) |d lambda_im| over the hazard curve, 1 - exp(-lambda N)
    (``rocksweep.analysis.risk``). fr: what ``rocksweep.fragility`` returns (or its file);
    hazard: a CSV path (``PGA [g],annual_rate``, or OpenQuake's hazard-curve CSV, ``site``
    its row) or a DataFrame of those two columns. Returns a Dataset: ``annual_rate``,
    ``probability`` per state and lam, their ``_lo``/``_hi`` from the fragility's
    bootstrap resamples, ``annual_rate_max`` (the tail above the hazard at its largest),
    ``reason``; beyond the hazard's range the rate is bounded, never extrapolated."""
    from rocksweep.analysis.risk import check_fragility  # lazy: xarray (+0.4 s)
    from rocksweep.analysis.risk import risk as compute

    _check_dataset("fr", fr)
    check_type("years", years, is_real(years), "a number of years > 0")
    check_type("site", site, site is None or is_integer(site),
               "an integer row number (0 = the first site) or None")
    ds = _dataset_arg(fr, "fr")
    check_fragility(ds, shown(fr) if isinstance(fr, str | Path) else "fr")
    return compute(ds, hazard, years, site=site)


@analysis
def im_efficiency(ds: xr.Dataset, *, state: str = "overturn") -> xr.Dataset:
    """Which IM explains ``state`` (as ``fragility``'s) best: for every IM of a
    record-suite sweep's records (``rocksweep.physics.suite.RECORD_IMS``) the lognormal
    dispersion ``beta`` of the fragility in that IM and ``beta_scale`` (comparable across
    IMs; lower is better), per value of the other swept keys
    (``rocksweep.analysis.efficiency``)."""
    from rocksweep.analysis.efficiency import im_efficiency as compute  # lazy: scipy (+0.8 s)

    return compute(_dataset_arg(ds, "ds"), state=state)


@analysis
def table(ds: xr.Dataset) -> Any:
    """A tidy ``pandas.DataFrame`` of any rocksweep Dataset (or its file): one row per run
    of a sweep with its coordinates, unswept scene values, result fields, record, the
    record's IMs as recorded (``record_*``) and as the run saw them (times
    scale_factor^n: ``pga``, ``pgv``, ``arias``, ...); one row per curve of an analysis.
    No row is repeated (``ds.to_dataframe()`` repeats a suite's runs per Sa period).
    ``.attrs["units"]`` gives each column's units (``rocksweep.analysis.table``)."""
    from rocksweep.analysis.table import table as make  # lazy: xarray, pandas (+0.4 s)

    return make(_dataset_arg(ds, "ds"))


def estimate(scene: SceneLike, *, jobs: int = 1, overrides: Overrides = ()) -> Any:
    """What ``run`` of this scene (``overrides`` as for ``run``) costs here, without running
    it: points, RK4 steps and evaluations expected, seconds with ``jobs`` workers, any
    kernel variant to compile first (measured on 256 points, ~10 ms; uncompiled: the step
    bound). Returns ``rocksweep.compute.sweep.Estimate`` (``str()``: one line)."""
    from rocksweep.compute.sweep import estimate as sweep_estimate  # lazy: yaml (+0.1 s)
    from rocksweep.scene.inputs import load

    sc, _ = load(scene, overrides)
    return sweep_estimate(sc, jobs=jobs)


# --- rocksweep.simulate and the motion a point feels --------------------------------------

def simulate(scene: SceneLike, overrides: Overrides = (), /,
             **keys: Any) -> Simulation | list[Simulation]:
    """Run one point of a scene with its energy balance and time history.

    scene: a path, YAML text or a dict (as for ``run``). Overrides as a mapping or
    ``KEY=VALUE`` strings (``{"impact.lam": 0.4}``), or as keywords with ``__`` for the
    dot: ``simulate("fig5.yaml", impact__lam=0.4)``. The accuracy is the scene's preset,
    ``default`` if it names none, as a sweep's (one point, one answer). Returns a ``Simulation``
    (summary dict, history Dataset over p*t, and ``.figure()``); a scene with lists gives
    one ``Simulation`` per combination, in grid order (at most
    ``rocksweep.compute.history.API_MAX_RUNS``, 100; sweeps are for ``run``).
    """
    from rocksweep.compute.history import API_MAX_RUNS, titled_runs  # lazy: numba (+0.3 s)
    from rocksweep.scene.inputs import load, override_strings

    sc, _ = load(scene, [*override_strings(overrides), *override_strings(keys)])
    out = [Simulation({**r.summary(), **sc.physical_summary(), **sc.floor_summary(r.point),
                       **sc.slide_metres(r.summary())},
                      hist, r, title)
           for r, hist, title in titled_runs(sc, API_MAX_RUNS)]
    return out[0] if sc.size == 1 else out


def felt_motion(scene: SceneLike, overrides: Overrides = (), /, **keys: Any) -> xr.Dataset:
    """The motion the body feels at one point of a scene, as samples (no run): ``a_h`` [g]
    the horizontal acceleration after the orientation (``ground.angle``) and the building
    (``floor``), scaled as the point runs it, ``a_v`` [g] the vertical acting with it,
    ``a_ground`` [g] the ground's H1 at the same scale (with an excitation path), over
    ``t`` [s] (``rocksweep.compute.motion``). scene and overrides as for ``simulate`` (one
    point). The kernel runs exactly these samples, linear between them
    (``rocksweep.physics.records.write_at2`` keeps one as a record)."""
    from rocksweep.compute.motion import felt_motion as felt  # lazy: yaml (+94 ms)
    from rocksweep.scene.inputs import load, override_strings

    sc, _ = load(scene, [*override_strings(overrides), *override_strings(keys)])
    return felt(sc)


# --- Calibration: scene numbers fitted to a measured history ------------------

def calibrate(scene: SceneLike, measured: Any, fit: str | Sequence[str] = ("impact.lam",),
              *, bounds: Mapping[str, Sequence[float]] | None = None,
              overrides: Overrides = (), ci: float = 0.95, p: float | None = None,
              noise: float | None = None, progress: bool = False) -> xr.Dataset:
    """Fit scene numbers to a measured rocking history.

    scene, overrides: as for ``run``. fit: the key or distinct keys to fit (``impact.lam``,
    ``impact.e`` under law constant, ``impact.e_factor``, ``body.zeta``, ...). measured: a
    CSV path or a pandas DataFrame with columns p_t, theta_over_alpha (as ``simulate
    --csv`` writes), or t [s], theta [rad] (then p [rad/s]: the keyword, a physical
    body's or a record scene's ground.p). bounds: {key: (lo, hi)} inside each key's
    admissible range (default: ``analysis.fit_keys.DEFAULT_BOUNDS`` or the range). ci:
    the interval's level, in [0.5, 1). Returns a Dataset over ``parameter`` (the fitted
    keys): ``estimate``, ``lo``, ``hi`` (profile likelihood), ``misfit`` with ``noise``
    and ``dof``, ``reason`` ("ok" or why not, also a ``CalibrationWarning``) and the
    measured and fitted histories (in full: ``rocksweep.analysis.calibrate``).
    progress: say on stderr when the fit's kernel variant must be compiled first (once per
    machine) and what that costs.
    """
    from rocksweep.analysis.calibrate import calibrate_scene  # lazy: pandas, pyarrow (+0.3 s)

    check_flag("progress", progress)
    say = (lambda m: print(m, file=sys.stderr, flush=True)) if progress else None
    return calibrate_scene(scene, measured, fit, bounds, ci, p, overrides, noise, say)


def calibrated_overrides(fit: xr.Dataset, which: str = "all") -> dict[str, Any]:
    """Overrides {key: value} of a calibration (``calibrate``'s Dataset) to sweep a scene
    at the estimate and at both ends of the interval: ``which="all"`` gives [lo, estimate,
    hi] per key (a swept dimension), "estimate", "lo" or "hi" one value.
    ``rocksweep.run(scene, overrides=rocksweep.calibrated_overrides(fit))``."""
    import xarray as xr  # lazy: xarray, pandas (+0.4 s)

    # lazy: pandas, pyarrow (+0.3 s)
    from rocksweep.analysis.calibrate import calibrated_overrides as overrides_of

    check_type("fit", fit, isinstance(fit, xr.Dataset),
               "the Dataset rocksweep.calibrate returns")
    if "parameter" not in fit.coords or "estimate" not in fit.variables:
        raise ApiError("fit: not a calibration (no parameter and estimate; what "
                       "rocksweep.calibrate returns)")
    return overrides_of(fit, which)
