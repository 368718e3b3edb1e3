"""``rocksweep sweep``: a scene's grid across workers into a resumable HDF5 file."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from rocksweep.cli.main import load, main, scene_argument, set_option, user_errors

# Finished chunks are written to the file at most this often [s] by default: a write
# (several hyperslabs per variable, two flushes) costs ~10 ms, as much as a chunk of easy
# points, and holds the GIL that worker threads need between kernel calls.
WRITE_EVERY = 1.0


@main.command()
@scene_argument
@set_option
@click.option("-o", "--output", "out_path", type=click.Path(path_type=Path),
              help="Result file [default: SCENE.h5 in the current directory].")
@click.option("--jobs", "-j", default=-1, show_default=True, type=int,
              help="Local worker threads (-1: all cores).")
@click.option("--resume", is_flag=True,
              help="Finish an interrupted sweep of the same scene (computes only the "
                   "missing points).")
@click.option("--overwrite", is_flag=True, help="Replace an existing result file.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar and no summary.")
@click.option("--backend", type=click.Choice(["threads", "dask"]), default="threads",
              show_default=True,
              help="Local worker threads (the kernel runs outside the GIL) or a "
                   "dask.distributed cluster.")
@click.option("--scheduler", metavar="ADDRESS",
              help="dask scheduler address (with --backend dask), e.g. tcp://host:8786.")
@click.option("--chunk-size", type=click.IntRange(1, None), default=None,
              help="Points per chunk [default: about 32 chunks per worker, at most 1024].")
@click.option("--write-every", "write_every", type=click.FloatRange(0.0, None),
              default=WRITE_EVERY, show_default=True, metavar="SECONDS",
              help="Write finished chunks to the file at most this often; a killed sweep "
                   "loses at most this much computing (Ctrl-C loses nothing).")
@user_errors
def sweep(scene_path: Path, overrides: tuple[str, ...], out_path: Path | None, jobs: int,
          resume: bool, overwrite: bool, quiet: bool, backend: str, scheduler: str | None,
          chunk_size: int | None, write_every: float) -> None:
    """Compute the stability diagram of SCENE.yaml: every point of its grid.

    Writes outcome (0 safe, 1 mode 1, 2 mode 2, -1 not computed), impacts, uplifts,
    max |theta|/alpha_cg, the overturning time and status flags per point to an HDF5 file
    (open it with xarray, `rocksweep info` or `rocksweep plot`). Results are written as
    chunks finish; if the run is interrupted, run the same command with --resume.
    """
    if resume and overwrite:
        raise click.ClickException("--resume and --overwrite exclude each other")
    if backend == "dask":
        if not scheduler:
            raise click.ClickException("--backend dask needs --scheduler ADDRESS")
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise click.ClickException("--backend dask needs dask and distributed: "
                                       "pip install 'rocksweep[dask]'") from None
    elif scheduler:
        raise click.ClickException("--scheduler works with --backend dask only")
    if jobs == 0 or jobs < -1:
        raise click.ClickException(f"--jobs {jobs}: give a number >= 1, or -1 for all cores")
    scene = load(scene_path, overrides)
    out = out_path if out_path is not None else Path(scene_path.stem + ".h5")
    if backend == "dask":  # before any file is made
        from distributed import Client

        try:
            Client(scheduler, timeout="10s").close()
        except (OSError, TimeoutError, ValueError) as err:
            raise click.ClickException(f"--scheduler {scheduler}: cannot reach a dask "
                                       f"scheduler there ({type(err).__name__})") from None

    from rocksweep import sweep as sw
    from rocksweep.store import SweepFile, read_result

    t0 = time.perf_counter()
    if resume and out.exists():
        sf = SweepFile.resume(out, scene, overrides)
    else:
        sf = SweepFile.create(out, scene, overrides, overwrite=overwrite)
    cpu_time = t_prep = 0.0
    n_done_before = 0
    n_new = 0
    pending: list = []  # finished chunks not yet in the file

    def write_pending() -> None:
        for merged in sw.merge_contiguous(pending):
            sf.write(merged)
        pending.clear()

    try:
        done = sf.done()
        n_done_before = int(done.sum())
        todo = int((~done).sum())
        n_workers = sw.effective_jobs(jobs) if backend == "threads" else 1
        size = chunk_size or sw.auto_chunk_size(todo, n_workers)
        chunks = sw.plan_chunks(~done, size)
        if not quiet:
            where = (f"{n_workers} worker{'s' * (n_workers > 1)}" if backend == "threads"
                     else f"dask cluster {scheduler}")
            dims = " x ".join(f"{len(a.values)} {a.name}" for a in scene.swept) or "1 point"
            click.echo(f"{scene.name}: {sf.grid.size} points ({dims}); "
                       f"{n_done_before} done, {todo} to compute on {where}; "
                       f"accuracy {scene.numerics.describe()}", err=True)
        t_prep = time.perf_counter()
        if todo:
            sw.prepare(sf.grid, sw.level(scene))  # compile, or load numba's cache, once
        t_prep = time.perf_counter() - t_prep
        if not quiet and t_prep > 1.0:
            click.echo(f"kernel compiled or loaded from numba's cache in {t_prep:.1f} s",
                       err=True)
        from tqdm import tqdm

        with tqdm(total=todo, unit="pt", disable=quiet, file=sys.stderr, smoothing=0.1,
                  dynamic_ncols=True) as bar:
            t_write = time.perf_counter()
            for res in sw.run_chunks(sf.grid, chunks, sw.level(scene), jobs, backend,
                                     scheduler):
                pending.append(res)
                cpu_time += res.cpu_seconds
                n_new += res.stop - res.start
                bar.update(res.stop - res.start)
                if time.perf_counter() - t_write >= write_every:
                    write_pending()
                    t_write = time.perf_counter()
            write_pending()
    except KeyboardInterrupt:
        write_pending()
        wall = time.perf_counter() - t0
        sf.finish(wall, cpu_time)
        sf.close()
        click.echo(f"\ninterrupted: {n_done_before + n_new} of {sf.grid.size} points saved "
                   f"in {out}; finish with: rocksweep sweep {scene_path} -o {out} --resume",
                   err=True)
        sys.exit(130)
    wall = time.perf_counter() - t0
    attrs = sf.finish(wall, cpu_time)
    sf.close()
    if quiet:
        return
    result = read_result(out, ["outcome", "status"])
    from rocksweep.cli.info import counts_lines

    for line in counts_lines(result):
        click.echo(line)
    rate = n_new / wall if wall > 0 else float("nan")
    resumed = f" ({n_done_before} were done before)" if n_done_before else ""
    click.echo(f"computed {n_new} points{resumed} in {wall:.2f} s wall time: "
               f"{rate:.0f} points/s (kernel compile/cache load: {t_prep:.2f} s; workers' "
               f"CPU time {cpu_time:.2f} s)")
    click.echo(f"accuracy: {scene.numerics.describe()}")
    click.echo(f"RK4 steps: {attrs['steps_total']} + {attrs['event_steps_total']} event "
               f"re-integrations (all points in the file)")
    state = "complete" if attrs["complete"] else f"{attrs['points_done']} points done"
    click.echo(f"wrote {out} ({state})")
