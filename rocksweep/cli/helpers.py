"""Helpers shared by the analysis commands (fragility, risk, efficiency, calibrate): their
``-o``/``--plot`` checks and their ``-o`` writer (``rocksweep.analysis.files`` writes the
file)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import click

from rocksweep.errors import RocksweepError
from rocksweep.figures import FORMATS


def check_table_outputs(out_path: Path | None, fig_path: Path | None,
                        suffixes: tuple[str, ...], inputs: Iterable[Any],
                        overwrite: bool) -> None:
    """An analysis command's ``-o`` (a table: one of ``suffixes``) and ``--plot`` (a
    figure), refused in one line before anything is computed: the same file twice, an
    unknown suffix, an existing file without --overwrite, or one of the command's
    ``inputs`` (``outputs.check_output``)."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.outputs import check_distinct, check_output

    inputs = list(inputs)
    check_distinct({"-o": out_path, "--plot": fig_path})
    if out_path is not None:
        if out_path.suffix.lower() not in suffixes:
            raise click.ClickException(
                f"-o {out_path}: unsupported suffix {out_path.suffix or '(none)'!r}; use "
                f"{', '.join(suffixes[:-1])} or {suffixes[-1]}")
        check_output(out_path, overwrite=overwrite, inputs=inputs)
    if fig_path is not None:
        check_output(fig_path, overwrite=overwrite, inputs=inputs, suffixes=FORMATS)


def write_table(out_path: Path, rows: Sequence[Mapping[str, Any]] | Any, ds: Any,
                kind: str, overwrite: bool) -> None:
    """An analysis's ``-o``: ``rows`` (dicts, or a DataFrame) as CSV for a .csv path, else
    the Dataset ``ds`` as netCDF-4 (.h5, .hdf5, .nc) marked with its ``kind``; published by
    ``outputs.write_atomic`` (complete or absent; a file that appeared meanwhile is
    kept)."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.analysis.files import csv_text, write_dataset
    from rocksweep.outputs import write_atomic

    if out_path.suffix.lower() == ".csv":
        text = csv_text(rows)
        write_atomic(out_path, lambda tmp: tmp.write_text(text), overwrite=overwrite)
    else:
        write_dataset(ds, out_path, kind, overwrite=overwrite)


def prepare_point_kernel(scene: Any) -> None:
    """The single-run kernel variant of the scene's first point compiled (or loaded) now,
    said on stderr when it compiles: how long it will take (``compile_cost``); ``simulate``
    and ``calibrate`` run it. A point the scene cannot make is left to the command's own
    refusal."""
    # lazy, not on --help: numpy (+0.1 s)
    from rocksweep.compute.compile_cost import prepare_point
    from rocksweep.physics.points import kernel_kind

    try:
        point = scene.point({a.name: a.values[0] for a in scene.axes})
        kind = kernel_kind(point.body)
    except (RocksweepError, ValueError):
        return
    prepare_point(kind, point.ground, lambda m: click.echo(m, err=True), scene.contact_model)
