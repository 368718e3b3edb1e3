"""``rocksweep table``: a result as a tidy table, one row per run (CSV or Parquet). A thin
wrapper on ``rocksweep.table``."""

from __future__ import annotations

from pathlib import Path

import click

import rocksweep
from rocksweep.cli.main import main, release_warnings, user_errors
from rocksweep.cli.options import overwrite_option, result_argument

TABLE_SUFFIXES = (".csv", ".parquet")


@main.command("table")
@result_argument
@click.option("-o", "--output", "out_path", required=True,
              type=click.Path(dir_okay=False, path_type=Path),
              help="runs.csv or runs.parquet (Parquet needs pyarrow).")
@overwrite_option
@user_errors
def table_command(result_path: Path, out_path: Path, overwrite: bool) -> None:
    """One row per run of a sweep (its coordinates, the unswept scene values, the result
    fields, the record and its IMs, as recorded and as scaled for the run), or one row
    per curve of an analysis's file (fragility, risk, efficiency -o .h5); no row
    repeated."""
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.outputs import check_output, write_atomic
    from rocksweep.store.reader import result_inputs

    suffix = out_path.suffix.lower()
    if suffix not in TABLE_SUFFIXES:
        raise click.ClickException(f"-o {out_path}: unsupported suffix "
                                   f"{out_path.suffix or '(none)'!r}; use .csv or .parquet")
    if suffix == ".parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise click.ClickException(f"-o {out_path}: Parquet needs pyarrow (pip install "
                                       "pyarrow); or write .csv") from None
    check_output(out_path, overwrite=overwrite, inputs=result_inputs(result_path))
    frame = rocksweep.table(rocksweep.open(result_path))
    release_warnings()  # a partial file's words before what is written
    units = frame.attrs.get("units", {})
    if suffix == ".csv":
        from rocksweep.analysis.files import csv_text  # lazy, not on --help: h5py, yaml (+0.1 s)

        # the units in the header: "name [unit]" (a dimensionless column, "1", or one
        # without units keeps its name)
        text = csv_text(frame.rename(columns={c: f"{c} [{units[c]}]" for c in frame.columns
                                              if units.get(c) not in (None, "", "1")}))
        write_atomic(out_path, lambda tmp: tmp.write_text(text), overwrite=overwrite)
    else:
        # lazy, not on --help: pyarrow (+92 ms)
        import pyarrow as pa
        import pyarrow.parquet as pq

        frame.attrs = {}  # pandas' attrs are not Parquet metadata: the units go in fields'
        tbl = pa.Table.from_pandas(frame, preserve_index=False)
        tbl = tbl.cast(pa.schema([f.with_metadata({"units": units.get(f.name, "")})
                                  for f in tbl.schema], metadata=tbl.schema.metadata))
        write_atomic(out_path, lambda tmp: pq.write_table(tbl, tmp), overwrite=overwrite)
    click.echo(f"wrote {out_path} ({len(frame):,} rows x {frame.shape[1]} columns)")
