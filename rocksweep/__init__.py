"""rocksweep: stability (overturning) diagrams of flexible rocking oscillators (Zhu,
Chatzis & Acikgoz).

The Python API (see the README's "Python API"):

- ``rocksweep.run(scene, *, jobs=1, output=None, overrides=(), progress=False,
  overwrite=False, resume=False)``: every point of a scene's grid -> xarray.Dataset
  (the same variables, dims, coords and attributes as ``rocksweep sweep``'s HDF5 file).
- ``rocksweep.open(path)``: a result file -> xarray.Dataset.
- ``rocksweep.simulate(scene, overrides=(), **keys)``: one point with its time history
  -> ``Simulation`` (``.summary`` dict, ``.history`` Dataset over p*t, ``.figure()``).
- ``rocksweep.plot(ds, x=, y=, ax=, width=)`` -> Figure; ``rocksweep.boundaries(ds,
  rtol=)`` -> Dataset of A_min; ``rocksweep.boundary_lines(ds)`` -> DataFrame;
  ``rocksweep.spectra(ds)`` -> Dataset; ``rocksweep.estimate(scene)``: the cost of a run;
  ``rocksweep.fragility(ds, state=, bootstrap=)`` -> Dataset of lognormal fragility
  curves of a record-suite sweep; ``rocksweep.risk(fr, hazard, years=50)`` -> Dataset of
  the annual rate and probability of each state over a hazard curve;
  ``rocksweep.im_efficiency(ds)`` -> Dataset of the dispersion of a suite's fragility in
  every IM (which IM explains overturning best); ``rocksweep.table(ds)`` -> DataFrame, one
  row per run.
  Each analysis takes what ``run`` and ``open`` return.
- ``rocksweep.calibrate(scene, measured, fit=["impact.lam"], bounds=)`` -> Dataset of the
  fitted keys (estimate, lo, hi, misfit) of a measured history;
  ``rocksweep.calibrated_overrides(fit)``: overrides that sweep the scene at the estimate
  and the interval's ends.
- ``rocksweep.RocksweepError``: the base of every error a user can fix (one line).

Importing the package is light: numba, h5py, xarray and matplotlib load on first use.
``ds.rocksweep`` (``rocksweep.api.RocksweepAccessor``) is there after ``import xarray,
rocksweep``, and after any call of the API.
"""

from __future__ import annotations

from rocksweep.api import (  # noqa: A004
    boundaries,
    boundary_lines,
    calibrate,
    calibrated_overrides,
    estimate,
    felt_motion,
    floor_spectrum,
    fragility,
    ida,
    im_efficiency,
    open,
    plot,
    register_accessor,
    risk,
    run,
    simulate,
    spectra,
    table,
)
from rocksweep.errors import RocksweepError
from rocksweep.simulation import Simulation

register_accessor()  # ds.rocksweep, if xarray is already imported (it is never imported here)


def _version() -> str:
    """The installed distribution's version; from pyproject.toml in a source tree."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("rocksweep")
    except PackageNotFoundError:
        import re
        from pathlib import Path

        pyproject = Path(__file__).resolve().parent.parent / "pyproject.toml"
        try:
            m = re.search(r'^version\s*=\s*"([^"]+)"', pyproject.read_text(), re.M)
        except OSError:
            m = None
        return f"{m.group(1)}+source" if m else "0+unknown"


def __getattr__(name: str) -> str:
    """``__version__`` on first use (importlib.metadata costs ~20 ms of every command)."""
    if name == "__version__":
        global __version__
        __version__ = _version()
        return __version__
    raise AttributeError(f"module 'rocksweep' has no attribute {name!r}")


__all__ = ["RocksweepError", "Simulation", "__version__", "boundaries", "boundary_lines",
           "calibrate", "calibrated_overrides", "estimate", "felt_motion", "floor_spectrum",
           "fragility",
           "ida", "im_efficiency", "open", "plot", "risk", "run", "simulate", "spectra", "table"]
