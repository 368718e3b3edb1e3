"""``rocksweep efficiency``: which IM explains overturning best for this body (the fragility's
dispersion in every IM of a record suite). A thin wrapper on ``rocksweep.im_efficiency``."""

from __future__ import annotations

import json
from pathlib import Path

import click

import rocksweep
from rocksweep.cli.helpers import check_table_outputs, write_table
from rocksweep.cli.main import main, release_warnings, user_errors
from rocksweep.cli.options import (
    dpi_option,
    json_option,
    overwrite_option,
    result_argument,
    width_option,
)
from rocksweep.vocab.kinds import IM_EFFICIENCY
from rocksweep.vocab.outcomes import SLIDE_STATE, STATES, THETA_STATE

SUFFIXES = (".csv", ".h5", ".hdf5", ".nc")


@main.command()
@result_argument
@click.option("--state", default="overturn", show_default=True,
              help=", ".join((*STATES, THETA_STATE)) + " or " + SLIDE_STATE + ".")
@click.option("-o", "--output", "out_path", type=click.Path(dir_okay=False, path_type=Path),
              help="The table as CSV (.csv) or the Dataset (.h5, .hdf5, .nc).")
@click.option("--plot", "fig_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Bar chart of beta per IM (.png, .pdf, .svg).")
@json_option("the table")
@width_option("single")
@dpi_option
@overwrite_option
@user_errors
def efficiency(result_path: Path, state: str, out_path: Path | None, fig_path: Path | None,
               as_json: bool, width: str, dpi: int, overwrite: bool) -> None:
    """IM efficiency of a record-suite sweep: for every IM of its records (PGA, PGV, Sa(T),
    AvgSa, Arias, CAV, D5-95, PGV/PGA, PGA/(g tan alpha), PGV p/(g tan alpha)) the
    lognormal dispersion beta of the state's fragility in that IM, best first (lower beta
    = the IM explains the state better)."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    import numpy as np

    # lazy, not on --help: matplotlib, h5py (+0.4 s)
    from rocksweep.figures.style import save_figure
    from rocksweep.store.reader import result_inputs

    inputs = result_inputs(result_path)  # the result and its records: never written over
    check_table_outputs(out_path, fig_path, SUFFIXES, inputs, overwrite)
    eff = rocksweep.im_efficiency(rocksweep.open(result_path), state=state)
    release_warnings()  # a partial file's words and the fits' verdicts before the ranking
    frame = rocksweep.table(eff)  # one row per (IM, curve), every column once
    others = [d for d in eff["beta"].dims if d != "im"]
    frame = frame.sort_values([*others, "beta_scale"])
    if as_json:
        click.echo(json.dumps({"state": state, "rows": json.loads(
            frame.to_json(orient="records"))}))
    else:
        click.echo(f"IM efficiency for {state} ({eff.attrs['stripe_im']} stripes; beta per "
                   "unit of ln scale factor, best first; [why] where a beta cannot rank):")
        for key, grp in (frame.groupby(others, sort=False) if others else [((), frame)]):
            where = ", ".join(f"{d} = {v}" for d, v in zip(others, np.atleast_1d(key),
                                                         strict=False))
            best = "  ".join(f"{r.im} {r.beta_scale:.3f}" + (
                f" [{r.reason}]" if r.reason != "ok" else "")
                for r in grp.itertuples() if r.beta_scale == r.beta_scale)
            held = sorted({w for r in grp.itertuples() if r.beta_scale != r.beta_scale
                           for w in r.reason.split(",") if w != "ok"})
            none = ("no IM has a finite beta" + (f" ({', '.join(held)})" if held else
                                                 " (no record reaches the state, or all at "
                                                 "once)"))
            click.echo(f"  {where or 'all'}: {best or none}")
    say = click.echo if not as_json else (lambda m: click.echo(m, err=True))
    fig = rocksweep.plot(eff, width=width) if fig_path is not None else None
    if out_path is not None:
        write_table(out_path, frame, eff, IM_EFFICIENCY, overwrite)
        say(f"wrote {out_path}")
    if fig is not None:
        save_figure(fig, fig_path, dpi, overwrite=overwrite, inputs=inputs)
        say(f"wrote {fig_path}")

