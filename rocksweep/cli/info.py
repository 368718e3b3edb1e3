"""``rocksweep info``: what a sweep result holds and where it came from (the summary is
``rocksweep.analysis.summary.info_dict``; this command prints it)."""

from __future__ import annotations

import json
from pathlib import Path

import click

from rocksweep.cli.main import main, user_errors
from rocksweep.cli.options import json_option
from rocksweep.errors import one_line


@main.command()
@click.argument("result_path", metavar="OUT.h5", type=click.Path(path_type=Path))
@json_option("one object")
@user_errors
def info(result_path: Path, as_json: bool) -> None:
    """Dimensions, completeness, counts per class (per pulse shape and lam, and per swept
    key; long axes in ranges) and provenance of a sweep result; for an adaptive sweep,
    the points computed, filled and audited (and the audit points that disagreed); with
    per-point error estimates (sweep --check), their tails."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.analysis.summary import format_info, info_dict, read_info

    d = info_dict(read_info(result_path))
    if as_json:
        click.echo(json.dumps(d, indent=2))
        return

    for line in format_info(d):  # a damaged file's strings may hold undecodable bytes
        click.echo(one_line(line))
