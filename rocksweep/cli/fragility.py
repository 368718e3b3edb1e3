"""``rocksweep fragility``: lognormal fragility curves of a record-suite sweep, as a table,
JSON, CSV or HDF5 and a figure. A thin wrapper: the file is opened as a Dataset
(``rocksweep.open``), fitted by ``rocksweep.fragility`` and written or drawn."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import click

import rocksweep
from rocksweep.analysis.resampling import DEFAULT_BOOTSTRAP, DEFAULT_SEED, MAX_BOOTSTRAP
from rocksweep.cli.helpers import check_table_outputs, write_table
from rocksweep.cli.main import main, release_warnings, user_errors, warning_line
from rocksweep.cli.options import (
    ci_option,
    dpi_option,
    json_option,
    overwrite_option,
    result_argument,
    rtol_option,
    seed_option,
    width_option,
)
from rocksweep.errors import FragilityWarning
from rocksweep.vocab.kinds import FRAGILITY
from rocksweep.vocab.outcomes import (
    MODE1,
    MODE2,
    OVERTURN,
    SLIDE_STATE,
    STATES,
    THETA_STATE,
    UPLIFT,
)

CURVE_SUFFIXES = (".csv", ".h5", ".hdf5", ".nc")


def curve_rows(frag) -> list[dict]:
    """One flat row per curve (``curves_json`` with the intervals as columns)."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.analysis.fragility import curves_json

    rows = []
    for c in curves_json(frag)["curves"]:
        row = {k: v for k, v in c.items() if k not in ("im_median_ci", "beta_ci")}
        row["im_median_lo"], row["im_median_hi"] = c["im_median_ci"]
        row["beta_lo"], row["beta_hi"] = c["beta_ci"]
        rows.append(row)
    return rows


def _g(v) -> str:
    return "-" if v is None else f"{v:.4g}"


@main.command()
@result_argument
@click.option("-o", "--output", "out_path", type=click.Path(dir_okay=False, path_type=Path),
              help="The curves as CSV (.csv: one row per curve) or the whole fragility "
                   "Dataset as netCDF-4/HDF5 (.h5, .hdf5, .nc: curves, bands, fractions, "
                   "per-record first levels).")
@click.option("--plot", "fig_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Figure of the curves with their bootstrap bands and the fraction at "
                   "each stripe, .png, .pdf or .svg.")
@click.option("--state", default="overturn", show_default=True,
              help="What the curve gives the probability of: " + ", ".join(STATES)
              + f", {THETA_STATE} (max|theta|/alpha_cg >= X, 0 < X <= 1) or {SLIDE_STATE} "
              "(the base's sliding displacement slide_max >= D, D > 0 in base half-widths "
              "b; a scene with body.mu); several separated by commas, each "
              "fitted alone (the same curve whatever else is asked for).")
@click.option("--joint", is_flag=True,
              help=f"Fit damage states of one chain ({UPLIFT}, {THETA_STATE}, {OVERTURN}; or "
                   f"{SLIDE_STATE}, {OVERTURN}) with one beta so their curves never cross "
                   f"(the likelihood-ratio test of that beta is stored), {MODE1},{MODE2} as "
                   "competing risks.")
@click.option("--im", default=None,
              help="Unscaled suites (clouds): the IM, PGA (default), PGV or Sa; stripes use "
                   "the IM they were scaled to.")
@click.option("--period", type=float, default=None,
              help="With --im Sa: the period [s] (one of the stored ground.periods).")
@click.option("--bootstrap", type=click.IntRange(0, MAX_BOOTSTRAP), default=DEFAULT_BOOTSTRAP,
              show_default=True,
              help="Bootstrap resamples over records for the intervals and bands (0: none).")
@seed_option(DEFAULT_SEED, "Seed of the bootstrap's random generator.")
@ci_option
@json_option('the curves ({"curves": [...]}) instead of a table')
@width_option("single")
@rtol_option(None, "Also refine each record's first level reaching a --state (overturning "
                   "when it is one of them, else the first), by bisection to this "
                   "relative tolerance (an IDA per record, kernel runs at the sweep's "
                   "accuracy): variables ida_im, ida_lo, ida_hi along record in -o "
                   "(.h5/.nc) and the spread in the table "
                   "[default: stripes only]")
@dpi_option
@overwrite_option
@user_errors
def fragility(result_path: Path, out_path: Path | None, fig_path: Path | None, state: str,
              joint: bool, im: str | None, period: float | None, bootstrap: int, seed: int,
              ci: float, as_json: bool, width: str, dpi: int, overwrite: bool,
              rtol: float | None) -> None:
    """Fragility curves of a record-suite sweep (a scene with ground.records): the
    lognormal P(state | IM = x) = Phi(ln(x/median)/beta) fitted by maximum likelihood to
    the counts at each stripe of a scaled suite, or to the (IM, 0/1) pairs of an unscaled
    one (Baker 2015), one curve per value of every other swept key (lam first), with
    bootstrap intervals over records. Points flagged undecided are left out and counted.
    A curve that should not be trusted as it is (extrapolated, beta undetermined,
    non-monotone fractions, censored by the other mode, points missing...) says why in
    its "fit" column and in a warning line on stderr."""

    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.figures.style import save_figure

    states = [s.strip() for s in state.split(",") if s.strip()]
    if not states:
        raise click.ClickException(f"--state {state!r}: give at least one state")
    from rocksweep.store.reader import result_inputs  # lazy, not on --help: h5py, yaml (+0.1 s)

    inputs = result_inputs(result_path)  # the result and its records: never written over
    check_table_outputs(out_path, fig_path, CURVE_SUFFIXES, inputs, overwrite)

    ds = rocksweep.open(result_path)
    # --rtol's IDA first: refused, it says so in one line before any word about the fit
    # overturning where asked (as before sliding's states), else the first state
    bisected = OVERTURN if OVERTURN in states else states[0]
    refined = rocksweep.ida(ds, rtol, state=bisected) if rtol is not None else None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", FragilityWarning)
        frag = rocksweep.fragility(ds, state=states[0] if len(states) == 1 else states,
                                   im=im, period=period, bootstrap=bootstrap, seed=seed,
                                   ci=ci, joint=joint)
    release_warnings()  # fitted: the warnings before the fit's verdicts and the table
    for w in caught:
        if issubclass(w.category, FragilityWarning):
            click.echo(warning_line(w.message), err=True)
        else:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    frag.attrs["source"] = str(result_path)
    if refined is not None:
        for name in ("ida_im", "ida_lo", "ida_hi", "runs", "n_flagged", "unresolved"):
            frag[name if name in ("ida_im", "ida_lo", "ida_hi") else f"ida_{name}"] = \
                refined[name]
    rows = curve_rows(frag)
    if as_json:
        # lazy, not on --help: scipy, xarray (+0.6 s)
        from rocksweep.analysis.fragility import curves_json

        click.echo(json.dumps(curves_json(frag), allow_nan=False))
    else:
        _print_table(frag, rows)
        if refined is not None:
            _print_ida(refined)
    say = click.echo if not as_json else (lambda m: click.echo(m, err=True))
    if out_path is not None:
        write_table(out_path, rows, frag, FRAGILITY, overwrite)
        say(f"wrote {out_path} ({len(rows)} curve{'s' * (len(rows) != 1)})")
    if fig_path is not None:
        # lazy, not on --help: matplotlib, scipy (+0.8 s)
        from rocksweep.figures.fragility import fragility_figure

        fig = fragility_figure(frag, width=width)
        save_figure(fig, fig_path, dpi, overwrite=overwrite, inputs=inputs)
        say(f"wrote {fig_path}")


def _print_ida(refined) -> None:
    """One line per value of the other swept keys: the records' first levels reaching the
    IDA's state (bisected; overturning by default), their median and range,
    resurrections."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    import numpy as np

    a = refined.attrs
    other = [d for d in refined.ida_im.dims if d != "record"]
    stacked = refined.stack(_k=other) if other else refined.expand_dims(_k=[0])
    first = (f"first overturning {a['im']}" if a["state"] == OVERTURN
             else f"first {a['im']} reaching {a['state']}")
    click.echo(f"IDA per record ({first} [{a['im_units']}], bisected to "
               f"rtol {a['rtol']:g}, {int(refined.runs.sum())} kernel runs):")
    verb = "overturn" if a["state"] == OVERTURN else f"reach {a['state']}"
    verbs = "overturns" if a["state"] == OVERTURN else f"reaches {a['state']}"
    for k in range(stacked.sizes["_k"]):
        one = stacked.isel(_k=k)
        where = ", ".join(f"{d} = {one[d].item()}" for d in other) or "all"
        v = one.ida_im.values
        ok = v[~np.isnan(v)]
        if ok.size:
            click.echo(f"  {where}: median {np.median(ok):.4g}, range {ok.min():.4g} to "
                       f"{ok.max():.4g} ({ok.size} of {v.size} records {verb}; "
                       f"{int(one.resurrection.sum())} resurrect above it)")
        else:
            click.echo(f"  {where}: no record {verbs} at any stripe")
        flagged, stopped = int(one.n_flagged.sum()), int(one.unresolved.sum())
        if flagged or stopped:
            click.echo(f"    {flagged} flagged stripe points (neither safe nor overturning); "
                       f"{stopped} bisections stopped at a flagged run (bracket wider than "
                       "rtol)")


def _print_table(frag, rows: list[dict]) -> None:
    a = frag.attrs
    im = a.get("im")
    unit = a.get("im_units", "")
    per = f" at T = {a['period']:g} s" if "period" in a else ""
    click.echo(f"{a.get('title') or 'fragility'}: {a.get('method')} on {im}{per} [{unit}], "
               f"bootstrap {a.get('bootstrap')} (seed {a.get('seed')}, {a.get('ci'):g} "
               "intervals)")
    if not rows:
        return
    fixed = ("state", "im", "method", "fit", "im_median", "beta", "im_median_lo",
             "im_median_hi", "beta_lo", "beta_hi", "n_records", "n_excluded", "n_not_run",
             "n_boot_undefined", "reason")
    keys = [k for k in rows[0] if k not in fixed]
    head = [*keys, "state", "im_median", "(lo, hi)", "beta", "(lo, hi)", "records",
            "excluded", "not run", "fit"]
    lines = [head]
    for r in rows:
        lines.append([*(str(r[k]) for k in keys), r["state"], _g(r["im_median"]),
                      f"({_g(r['im_median_lo'])}, {_g(r['im_median_hi'])})", _g(r["beta"]),
                      f"({_g(r['beta_lo'])}, {_g(r['beta_hi'])})", str(r["n_records"]),
                      str(r["n_excluded"]), str(r["n_not_run"]), r["reason"]])
    widths = [max(len(line[i]) for line in lines) for i in range(len(head))]
    for line in lines:
        click.echo("  ".join(c.ljust(w) for c, w in zip(line, widths, strict=True)).rstrip())
