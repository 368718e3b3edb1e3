"""``rocksweep plot``: the stability diagram of a sweep result (Figures 3 and 4)."""

from __future__ import annotations

from pathlib import Path

import click

from rocksweep.cli.main import main, user_errors


@main.command()
@click.argument("result_path", metavar="OUT.h5", type=click.Path(path_type=Path))
@click.option("-o", "--output", "fig_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Figure file, .png, .pdf or .svg [default: OUT.png].")
@user_errors
def plot(result_path: Path, fig_path: Path | None) -> None:
    """Draw the stability diagram of a sweep: x = omega/p, y = A/(g tan alpha_cg), mode 1 /
    mode 2 / safe regions, one panel per pulse shape (and per other swept body key), the
    growth of the mode 1 area with lam in shades of red."""
    from rocksweep.diagrams import FORMATS, stability_figure
    from rocksweep.store import read_result

    fig = fig_path if fig_path is not None else result_path.with_suffix(".png")
    if fig.suffix.lower() not in FORMATS:
        raise click.ClickException(f"{fig}: unknown figure format {fig.suffix or '(none)'!r}; "
                                   f"use {', '.join(FORMATS)}")
    if not fig.parent.is_dir():
        raise click.ClickException(f"{fig}: directory {fig.parent} does not exist")
    result = read_result(result_path, ["outcome", "status"])
    for w in stability_figure(result, fig):
        click.echo(f"warning: {w}", err=True)
    click.echo(f"wrote {fig}")
