"""``rocksweep accuracy``: what each accuracy setting costs in time and buys in accuracy."""

from __future__ import annotations

import shlex
from pathlib import Path

import click

from rocksweep.cli.main import load, main, user_errors
from rocksweep.cli.options import overwrite_option, scene_argument, seed_option, set_option
from rocksweep.figures import FORMATS
from rocksweep.vocab.settings import (
    DEFAULT_LADDER,
    DEFAULT_SAMPLE_SEED,
    LADDER_HELP,
    LADDER_NAMES,
)


@main.command()
@scene_argument
@set_option
@click.option("-o", "--output", "report_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Write the table and every per-point result to this HDF5 report.")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Draw the work-precision diagram to this file (PNG, PDF, SVG).")
@click.option("--points", "n_points", type=click.IntRange(min=1), default=200,
              show_default=True,
              help="Stratified sample size (every point if the scene has no more).")
@click.option("--ladder", "ladder_name",
              type=click.Choice(LADDER_NAMES),  # = accuracy.LADDERS (tests/test_vocab.py)
              default=DEFAULT_LADDER, show_default=True,
              help="Kernel settings to measure: " + ", ".join(
                  f"{k} ({v})" for k, v in LADDER_HELP.items()) + ".")
@seed_option(DEFAULT_SAMPLE_SEED, "Sampling seed.")
@click.option("--repeat", type=click.IntRange(min=1), default=5, show_default=True,
              help="Kernel timings are the best of this many rounds.")
@click.option("--check", is_flag=True,
              help="Also rerun each setting at half the step and score the per-point "
                   "error estimates of `sweep --check` against the true errors (which "
                   "points above 0.05 p*t and 1% they catch).")
@click.option("--quiet", "-q", is_flag=True, help="No progress lines (the table is printed).")
@overwrite_option
@user_errors
def accuracy(scene_path: Path, overrides: tuple[str, ...], report_path: Path | None,
             plot_path: Path | None, n_points: int, ladder_name: str, seed: int, repeat: int,
             check: bool, quiet: bool, overwrite: bool) -> None:
    """Measure what accuracy costs on SCENE.yaml: kernel settings against a reference.

    Runs a stratified sample of the scene's points (strata: outcome x on/off a boundary
    of the diagram, so every outcome is covered; weights make the figures estimates for
    the whole scene) with an independent reference (scipy DOP853, rtol 1e-10) and with
    the kernel at a ladder of settings (steps per period, event tolerance, presets).
    Prints, per setting, the time per point, the RK4 evaluations per point, the error in
    max |theta|/alpha_cg, first impact time, overturning time and number of impacts, and
    the share of points whose outcome agrees with the reference (with the flips), plus the
    observed order of convergence. The numerics section of the scene sets horizon,
    rest_rate, max_events and root for every run; the ladder sets steps_per_period and
    event_tol.
    """
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.outputs import check_distinct, check_output

    if not 0 <= seed < 2**63:
        raise click.ClickException(f"--seed {seed}: must be an integer in [0, 2^63) (the "
                                   "sampling seed)")
    # refuse a bad output before the (long) study
    check_distinct({"-o": report_path, "--plot": plot_path})  # by resolved path
    scene = load(scene_path, overrides)
    # the scene file, its records: never written over
    if report_path is not None:
        check_output(report_path, overwrite=overwrite, inputs=scene.inputs)
    if plot_path is not None:
        check_output(plot_path, overwrite=overwrite, inputs=scene.inputs, suffixes=FORMATS)

    # lazy, not on --help: numba, scipy (+0.6 s)
    from rocksweep.analysis.accuracy import accuracy_study, format_table, ladder
    from rocksweep.analysis.files import write_report

    def progress(stage: str, done: int, total: int) -> None:
        if quiet:
            return
        if stage == "classify" and done == 0:
            click.echo(f"classifying {scene.size} points at {scene.numerics.describe()} "
                       "(for the strata)...", err=True)
        elif stage == "reference" and (done == total or done % max(1, total // 10) == 0):
            click.echo(f"reference: {done}/{total} points", err=True)
        elif stage == "kernel" and done == total:
            click.echo(f"kernel: {total} settings done", err=True)

    study = accuracy_study(scene, n_points, ladder(ladder_name), seed=seed, repeat=repeat,
                           progress=progress, check=check)
    click.echo(format_table(study))
    if report_path is not None:
        words = ["rocksweep", "accuracy", str(scene_path), *(f"--set={o}" for o in overrides),
                 f"--points={n_points}", f"--ladder={ladder_name}", f"--seed={seed}",
                 f"--repeat={repeat}", *(["--check"] if check else []),
                 *(["--overwrite"] if overwrite else [])]
        command = " ".join(shlex.quote(w) for w in words)
        write_report(study, report_path, command, overwrite=overwrite)
        click.echo(f"wrote {report_path}")
    if plot_path is not None:
        # lazy, not on --help: numba, matplotlib (+0.9 s)
        from rocksweep.figures.accuracy import work_precision
        from rocksweep.figures.style import save_figure

        save_figure(work_precision(study), plot_path, overwrite=overwrite, inputs=scene.inputs)
        click.echo(f"wrote {plot_path}")
