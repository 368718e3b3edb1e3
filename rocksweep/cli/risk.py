"""``rocksweep risk``: the mean annual rate and the probability in N years of each state of
a fragility over a hazard curve. A thin wrapper on ``rocksweep.risk``: the fragility file
(or a suite sweep, fitted first) and the hazard are read, everything computed, then
written (nothing is written when anything is wrong)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import click

import rocksweep
from rocksweep.cli.helpers import check_table_outputs, write_table
from rocksweep.cli.main import main, release_warnings, user_errors
from rocksweep.cli.options import dpi_option, json_option, overwrite_option, width_option
from rocksweep.vocab.kinds import RISK

RISK_SUFFIXES = (".csv", ".h5", ".hdf5", ".nc")


def risk_rows(rk) -> list[dict]:
    """One flat row per curve: the fragility's dims, annual_rate (and _lo, _hi, _max),
    probability (and _lo, _hi), reason; NaN as None."""

    dims = list(rk["annual_rate"].dims)
    stacked = rk.stack(_k=dims) if dims else rk.expand_dims(_k=[0])
    names = ("annual_rate", "annual_rate_lo", "annual_rate_hi", "annual_rate_max",
             "probability", "probability_lo", "probability_hi")
    rows = []
    for k in range(stacked.sizes["_k"]):
        one = stacked.isel(_k=k)
        row = {d: one[d].item() for d in dims}
        if "state" not in dims and "state" in rk.coords:
            row["state"] = str(rk["state"].item())
        for n in names:
            v = float(one[n])
            row[n] = v if math.isfinite(v) else None
        row["reason"] = str(one["reason"].values)
        rows.append(row)
    return rows


def _g(v) -> str:
    return "-" if v is None else f"{v:.3g}"


@main.command()
@click.argument("frag_path", metavar="FRAG.h5", type=click.Path(path_type=Path))
@click.option("--hazard", "hazard_path", required=True,
              type=click.Path(dir_okay=False, path_type=Path),
              help="Hazard curve: CSV with the header 'IM [unit],annual_rate' (e.g. "
                   "'PGA [g],annual_rate'), or OpenQuake's hazard-curve CSV.")
@click.option("--years", type=float, default=50.0, show_default=True,
              help="N: the probability of at least one occurrence in N years.")
@click.option("--site", type=click.IntRange(0), default=None,
              help="OpenQuake files with several sites: the row to use (0 = first).")
@click.option("--state", default=None,
              help="When FRAG.h5 is a suite sweep, the states to fit first (as "
                   "rocksweep fragility --state; default overturn).")
@click.option("--joint", is_flag=True,
              help="When FRAG.h5 is a suite sweep: fit the states jointly (as rocksweep "
                   "fragility --joint).")
@click.option("-o", "--output", "out_path", type=click.Path(dir_okay=False, path_type=Path),
              help="The rates as CSV (.csv, one row per curve) or the whole risk Dataset "
                   "(.h5, .hdf5, .nc).")
@click.option("--plot", "fig_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Figure: hazard curve, fragility and the rate's integrand (.png, .pdf, "
                   ".svg).")
@json_option("the rows")
@width_option("double")
@dpi_option
@overwrite_option
@user_errors
def risk(frag_path: Path, hazard_path: Path, years: float, site: int | None,
         state: str | None, joint: bool, out_path: Path | None, fig_path: Path | None,
         as_json: bool, width: str, dpi: int, overwrite: bool) -> None:
    """Mean annual rate lambda = integral P(state | im) |d lambda_im| of each state of a
    fragility (FRAG.h5 from rocksweep fragility -o, or a record-suite sweep) over a
    hazard curve, and the probability 1 - exp(-lambda N) in N years, with the band of the
    fragility's bootstrap. Beyond the hazard curve's range the rate is bounded (the
    certain tail above its largest IM is added), never extrapolated."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.analysis.kinds import dataset_kind
    from rocksweep.figures.style import save_figure
    from rocksweep.store.reader import result_inputs

    # the fragility or sweep file (and a sweep's records), the hazard curve: never written
    inputs = [*result_inputs(frag_path), hazard_path]
    check_table_outputs(out_path, fig_path, RISK_SUFFIXES, inputs, overwrite)
    # lazy, not on --help: xarray, pandas (+0.4 s)
    from rocksweep.analysis.risk import check_fragility
    from rocksweep.outputs import shown

    ds = rocksweep.open(frag_path)
    check_fragility(ds, shown(frag_path), suites=True)
    if dataset_kind(ds) != "sweep" and (state is not None or joint):
        given = f"--state {state}" if state is not None else "--joint"
        raise click.ClickException(f"{given}: {frag_path} is a fitted fragility (its states "
                                   "are fixed); it applies to a record-suite sweep")
    if dataset_kind(ds) == "sweep":
        states = [s.strip() for s in (state or "overturn").split(",") if s.strip()]
        ds = rocksweep.fragility(ds, state=states[0] if len(states) == 1 else states,
                                 joint=joint)
    # a sweep's fragility warns (no_failures, incomplete...) before the hazard is read:
    # said once the rates are computed, so that a refused hazard is one line
    rk = rocksweep.risk(ds, hazard_path, years, site=site)
    release_warnings()
    rows = risk_rows(rk)
    if as_json:
        click.echo(json.dumps({"years": rk.attrs["years"], "im": rk.attrs["im"],
                               "rows": rows}, allow_nan=False))
    else:
        a = rk.attrs
        click.echo(f"risk over {a['hazard_source']} ({a['im']} [{a['im_units']}]), "
                   f"{a['years']:g} years; {a['extrapolation']}")
        if a.get("hazard_notes"):
            click.echo(f"hazard: {a['hazard_notes']}")
        keys = [k for k in rows[0] if k not in ("annual_rate", "annual_rate_lo",
                                                 "annual_rate_hi", "annual_rate_max",
                                                 "probability", "probability_lo",
                                                 "probability_hi", "reason")]
        head = [*keys, "annual rate [1/yr]", "(lo, hi)", f"P in {a['years']:g} yr",
                "(lo, hi)", "verdict"]
        lines = [head] + [[*(str(r[k]) for k in keys), _g(r["annual_rate"]),
                           f"({_g(r['annual_rate_lo'])}, {_g(r['annual_rate_hi'])})",
                           _g(r["probability"]),
                           f"({_g(r['probability_lo'])}, {_g(r['probability_hi'])})",
                           r["reason"]] for r in rows]
        widths = [max(len(line[i]) for line in lines) for i in range(len(head))]
        for line in lines:
            click.echo("  ".join(c.ljust(w) for c, w in zip(line, widths, strict=True))
                       .rstrip())
    say = click.echo if not as_json else (lambda m: click.echo(m, err=True))
    fig = None
    if fig_path is not None:  # drawn before anything is written
        fig = rocksweep.plot(rk, width=width)
    if out_path is not None:
        write_table(out_path, rows, rk, RISK, overwrite)
        say(f"wrote {out_path}")
    if fig is not None:
        save_figure(fig, fig_path, dpi, overwrite=overwrite, inputs=inputs)
        say(f"wrote {fig_path}")
