"""``rocksweep calibrate``: fit scene numbers to a measured history (``rocksweep.calibrate``)."""

from __future__ import annotations

import warnings
from pathlib import Path

import click

import rocksweep
from rocksweep.cli.helpers import check_table_outputs, write_table
from rocksweep.cli.main import load, main, release_warnings, user_errors, warning_line
from rocksweep.cli.options import dpi_option, overwrite_option, scene_argument, set_option
from rocksweep.vocab.kinds import CALIBRATION


def _bounds(items: tuple[str, ...]) -> dict[str, tuple[str, str]]:
    """--bounds KEY=LO,HI items -> {key: (lo, hi)} (numbers checked by the API)."""
    out: dict[str, tuple[str, str]] = {}
    for item in items:
        key, sep, rng = item.partition("=")
        parts = rng.split(",")
        if not sep or not key.strip() or len(parts) != 2:
            raise click.ClickException(f"--bounds {item!r}: expected KEY=LO,HI, e.g. "
                                       "impact.lam=0,1")
        try:
            out[key.strip()] = (float(parts[0]), float(parts[1]))
        except ValueError:
            raise click.ClickException(f"--bounds {item!r}: LO and HI must be numbers"
                                       ) from None
    return out


@main.command()
@scene_argument
@click.argument("measured_path", metavar="MEASURED.csv",
                type=click.Path(dir_okay=False, path_type=Path))
@click.option("--fit", "fit", multiple=True, metavar="KEY", required=True,
              help="A scene number to fit: impact.lam, impact.e (law constant), "
                   "impact.e_factor, body.zeta, ... (repeatable).")
@click.option("--bounds", "bounds", multiple=True, metavar="KEY=LO,HI",
              help="Search range of a fitted key, inside its admissible range (repeatable).")
@click.option("--p", "p", type=float, default=None,
              help="The body's p [rad/s], to read a CSV with physical columns t [s], "
                   "theta [rad] (a physical body or a record scene gives it).")
@click.option("--noise", "noise", type=float, default=None,
              help="The measurement noise's standard deviation [theta/alpha_ref] the misfit "
                   "is judged against [default: estimated from the history].")
@click.option("-o", "--output", "out_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Write the fit (estimate, interval, histories) to this file (.h5, .nc).")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Draw measured against fitted history (.png, .pdf, .svg).")
@set_option
@dpi_option
@overwrite_option
@user_errors
def calibrate(scene_path: Path, measured_path: Path, fit: tuple[str, ...],
              bounds: tuple[str, ...], p: float | None, noise: float | None,
              out_path: Path | None,
              plot_path: Path | None, overrides: tuple[str, ...], dpi: int,
              overwrite: bool) -> None:
    """Fit scene numbers of SCENE.yaml to the rocking history in MEASURED.csv (columns
    p_t, theta_over_alpha as simulate --csv writes, or t [s], theta [rad]).

    The misfit compares the half-cycle peaks (robust to the phase drift of many impacts);
    the interval is a 95% profile likelihood. Prints the estimate, the interval and the
    misfit; -o keeps the fit, --plot draws it."""
    # the scene file and what it reads (a record), the measured CSV: never written over
    scene = load(scene_path, overrides)
    inputs = [*scene.inputs, measured_path]
    check_table_outputs(out_path, plot_path, (".h5", ".nc"), inputs, overwrite)
    # run time, not --help: numpy, h5py, numba, matplotlib (0.1-2 s each), outputs (+7%)
    from rocksweep.analysis.calibrate import CalibrationWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CalibrationWarning)
        ds = rocksweep.calibrate(scene_path, measured_path, list(fit),
                                 bounds=_bounds(bounds) or None, overrides=list(overrides),
                                 p=p, noise=noise, progress=True)
    release_warnings()  # fitted: the scene's warnings before the fit's verdicts
    for w in caught:
        if issubclass(w.category, CalibrationWarning):
            click.echo(warning_line(w.message), err=True)
        else:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    for key in ds["parameter"].values.tolist():
        s = ds.sel(parameter=key)
        edge = (" (lo at the bound)" if bool(s["lo_at_bound"]) else "") + (
            " (hi at the bound)" if bool(s["hi_at_bound"]) else "")
        click.echo(f"{key} = {float(s['estimate']):.5g}   {ds.attrs['ci']:.0%} interval "
                   f"[{float(s['lo']):.5g}, {float(s['hi']):.5g}]{edge}")
    click.echo(f"misfit {float(ds['misfit']):.4g} (RMS error of {ds.attrs['n_peaks']} "
               f"half-cycle peaks, theta/alpha; {int(ds['dof'])} dof); noise "
               f"{float(ds['noise']):.3g}; fit {ds['reason'].item()}; "
               f"{ds.attrs['runs']} runs in {ds.attrs['wall_time_s']:.2f} s")
    if ds.attrs["notes"]:
        click.echo(f"measured: {ds.attrs['notes']}")
    if out_path is not None:
        write_table(out_path, None, ds, CALIBRATION, overwrite)
        click.echo(f"wrote {out_path}")
    if plot_path is not None:
        # lazy, not on --help: matplotlib (+0.4 s)
        from rocksweep.figures.calibration import calibration_figure
        from rocksweep.figures.style import save_figure

        save_figure(calibration_figure(ds), plot_path, dpi, overwrite=overwrite,
                    inputs=inputs)
        click.echo(f"wrote {plot_path}")

