"""``rocksweep sweep``: a scene's grid across workers into a resumable HDF5 file (through
``rocksweep.compute.session.sweep`` into ``rocksweep.compute.driver``; this command parses
options and prints)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from rocksweep.cli.main import load, main, release_warnings, user_errors
from rocksweep.cli.options import (
    ADAPTIVE,
    backend_option,
    connect_timeout_option,
    overwrite_option,
    scene_argument,
    seed_option,
    set_option,
)
from rocksweep.compute.arguments import WRITE_EVERY, check_sweep_arguments


@main.command()
@scene_argument
@set_option
@click.option("-o", "--output", "out_path", type=click.Path(path_type=Path),
              help="Result file [default: SCENE.h5 in the current directory].")
@click.option("--jobs", "-j", default=-1, show_default=True, type=int,
              help="Local worker threads (-1: one per core; at most 4 per core).")
@click.option("--resume", is_flag=True,
              help="Finish an interrupted sweep of the same scene (computes only the "
                   "missing points).")
@overwrite_option
@click.option("--quiet", "-q", is_flag=True, help="No progress bar and no summary.")
@backend_option
@click.option("--scheduler", metavar="ADDRESS",
              help="dask scheduler address (with --backend dask), e.g. tcp://host:8786.")
@connect_timeout_option
@click.option("--chunk-size", type=click.IntRange(1, None), default=None,
              help="Points per chunk [default: about 32 chunks per worker, at most 1024].")
@click.option("--write-every", "write_every", type=float, default=WRITE_EVERY,
              show_default=True, metavar="SECONDS",
              help="Write finished chunks to the file at most this often; a killed sweep "
                   "loses at most this much computing (Ctrl-C loses nothing).")
@click.option("--adaptive", is_flag=True,
              help="Compute only near the class boundaries: a coarse lattice, then "
                   "refinement of every cell whose corners differ (and its neighbours), "
                   "then a random audit; the other points take the class of the uniform "
                   "cell around them (flag `computed` in the file).")
@click.option("--coarse", type=int, default=None, metavar="K", help=ADAPTIVE["coarse"])
@click.option("--audit", type=float, default=None, metavar="SHARE", help=ADAPTIVE["audit"])
@click.option("--axes", "adaptive_axes", metavar="X,Y", default=None, help=ADAPTIVE["axes"])
@click.option("--validate", is_flag=True,
              help="Adaptive: also compute the filled points of a uniform lattice (half a "
                   "coarse cell apart) and report those whose class differs from the "
                   "fill; the file keeps the adaptive result.")
@click.option("--margin", type=int, default=None, help=ADAPTIVE["margin"])
@click.option("--final-margin", "final_margin", type=int, default=None,
              help=ADAPTIVE["final_margin"])
@seed_option(None, ADAPTIVE["seed"])
@click.option("--threshold", type=float, default=None, help=ADAPTIVE["threshold"])
@click.option("--contact", is_flag=True,
              help="Also store the friction demand mu_required, the smallest normal force "
                   "and the impulse ratio per point (as outputs.contact: true).")
@click.option("--check", is_flag=True,
              help="Rerun every point at half the step and store the differences of the "
                   "outcome, overturning time and max |theta| (an error estimate per "
                   "point; as outputs.check: true). Costs about 2.5x the time.")
@click.option("--dry-run", "dry_run", is_flag=True,
              help="Say what the sweep would cost (points, RK4 evaluations, seconds on this "
                   "machine, whether the kernel must be compiled) and stop; writes nothing.")
@user_errors
def sweep(scene_path: Path, overrides: tuple[str, ...], out_path: Path | None, jobs: int,
          resume: bool, overwrite: bool, quiet: bool, backend: str, scheduler: str | None,
          connect_timeout: float, chunk_size: int | None, write_every: float,
          adaptive: bool, coarse: int | None, audit: float | None,
          adaptive_axes: str | None, margin: int | None,
          final_margin: int | None, seed: int | None, threshold: float | None,
          validate: bool, contact: bool, check: bool, dry_run: bool) -> None:
    """Compute the stability diagram of SCENE.yaml: every point of its grid.

    Writes outcome (0 safe, 1 mode 1, 2 mode 2, -1 not computed), impacts, uplifts,
    max |theta|/alpha_cg, the overturning time and status flags per point to an HDF5 file
    (open it with xarray, `rocksweep info` or `rocksweep plot`). Results are written as
    chunks finish; if the run is interrupted, run the same command with --resume.

    With --adaptive, only the points near the boundaries between classes are computed
    (a few % at 400 x 400 and more); the others get the class of the cell around them
    and keep the "not computed" values in every other variable.
    """
    if contact:
        overrides = (*overrides, "outputs.contact=true")
    if check:
        overrides = (*overrides, "outputs.check=true")
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.compute.adaptive import adaptive_options, check_settings
    from rocksweep.compute.driver import SweepInterrupted
    from rocksweep.compute.session import sweep as sweep_checked

    # the arguments that need no scene, before it is read (checked once: handed down)
    args = check_sweep_arguments(jobs=jobs, resume=resume, overwrite=overwrite,
                                 validate=validate, backend=backend, scheduler=scheduler,
                                 chunk_size=chunk_size, write_every=write_every,
                                 connect_timeout=connect_timeout)
    # the ranges of the scene's refine: section, one table
    check_settings({"coarse": coarse, "audit": audit, "margin": margin,
                    "final_margin": final_margin, "seed": seed, "threshold": threshold})
    settings = {"coarse": coarse, "audit": audit, "axes": adaptive_axes, "margin": margin,
                "final_margin": final_margin, "seed": seed, "threshold": threshold}
    given = [k for k, v in settings.items() if v is not None]
    if validate:
        given.append("validate")
    scene = load(scene_path, overrides)
    if given and not (adaptive or scene.refine is not None):
        raise click.ClickException(f"--{given[0].replace('_', '-')} is a setting of "
                                   "adaptive sweeps; add --adaptive")
    options = adaptive_options(adaptive, base=scene.refine, **settings)
    if dry_run:
        from rocksweep.compute.sweep import estimate  # lazy, not on --help: yaml (+0.1 s)

        est = estimate(scene, jobs=jobs if backend == "threads" else 1)
        click.echo(str(est) + (" (every point; an adaptive sweep computes a few % of them)"
                               if options is not None else ""))
        return
    out = out_path if out_path is not None else Path(scene_path.stem + ".h5")

    def say(line: str) -> None:
        release_warnings()  # the sweep starts (its first line): nothing left to refuse
        if not quiet:
            click.echo(line, err=True)

    try:
        report = sweep_checked(scene, out, args, overrides=overrides, progress=not quiet,
                               log=say, inputs=[scene_path], adaptive=options)
    except SweepInterrupted as stop:
        r = stop.report
        click.echo(f"\ninterrupted: {r.points_done} of {r.points_total} points saved in "
                   f"{out}; finish with: rocksweep sweep {scene_path} -o {out} --resume",
                   err=True)
        sys.exit(130)
    if quiet:
        return
    # lazy, not on --help: h5py, yaml (+0.1 s)
    from rocksweep.analysis.summary import (
        certification_share,
        check_info,
        counts_lines,
        format_check,
        read_info,
    )
    from rocksweep.store.reader import read_result

    # one read of the file: with error estimates, what info reports on them too
    result = read_info(out) if scene.check else read_result(out, ["outcome", "status"])
    for line in counts_lines(result):
        click.echo(line)
    from rocksweep.analysis.restitution import energy_note  # lazy, not on --help: numpy (+52 ms)

    note = energy_note(scene)
    if note:
        click.echo(note)
    a = report.attrs
    resumed = f" ({report.done_before} were done before)" if report.done_before else ""
    click.echo(f"computed {report.computed} points{resumed} in {report.wall_s:.2f} s wall "
               f"time: {report.rate:.0f} points/s (kernel compile/cache load: "
               f"{report.compile_s:.2f} s; workers' CPU time {report.cpu_s:.2f} s)")
    st = report.adaptive
    if st is not None:
        click.echo(f"adaptive: {st.computed} of {st.points} points computed "
                   f"({100 * st.computed_share:.2f}%), {st.points - st.computed} filled; "
                   f"audit: {st.audited} points, {st.audit_misses} disagreed with their "
                   "fill")
        if st.warning():
            click.echo(f"warning: {st.warning()}", err=True)
    v = report.validation
    if v is not None:
        click.echo(f"validate: {v.checked} filled points of the stride-{v.stride} lattice "
                   f"({v.points} points) computed: {v.differ.size} differ from their fill"
                   + (f" ({100 * v.differ.size / v.checked:.3f}%)" if v.checked else ""))
        if v.differ.size:
            vals = report_cells(scene, v.differ[:5])
            click.echo("  e.g. " + "; ".join(vals))
    if scene.check:
        for line in format_check(check_info(result)):
            click.echo(line)
    click.echo(f"accuracy: {scene.numerics.describe()}")
    click.echo(f"RK4 steps: {a['steps_total']} + {a['event_steps_total']} event "
               f"re-integrations (all points in the file)")
    if scene.numerics.refine > 0:
        share = certification_share(int(a.get("refine_evaluations", -1)),
                                    int(a["steps_total"]) + int(a["event_steps_total"]))
        click.echo(f"  certification of close calls: {share}")
    state = "complete" if a["complete"] else f"{a['points_done']} points done"
    click.echo(f"wrote {out} ({state})")


def report_cells(scene, flat) -> list[str]:
    """The swept values of some grid points, as 'key=value, ...' texts."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.scene.grid import Grid

    values = Grid(scene).index_values(flat)
    swept = [a.name for a in scene.swept]
    return [", ".join(f"{k}={values[k][i]:.4g}" if not isinstance(values[k][i], str)
                      else f"{k}={values[k][i]}" for k in swept)
            for i in range(len(flat))]
