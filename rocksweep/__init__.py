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
  every IM (which IM explains overturning best); ``rocksweep.floor_spectrum(ds)`` ->
  Dataset of the response against a building's period; ``rocksweep.table(ds)`` ->
  DataFrame, one row per run.
  Each analysis takes what ``run`` and ``open`` return.
- ``rocksweep.calibrate(scene, measured, fit=["impact.lam"], bounds=)`` -> Dataset of the
  fitted keys (estimate, lo, hi, misfit) of a measured history;
  ``rocksweep.calibrated_overrides(fit)``: overrides that sweep the scene at the estimate
  and the interval's ends.
- ``rocksweep.RocksweepError``: the base of every error a user can fix (one line).

Importing the package is light: the functions above are ``rocksweep.api``'s, loaded on
first use (as SciPy's subpackages, PEP 562), and numba, h5py, xarray and matplotlib load
when a function needs them: the command line's start-up pays for none of them.
``ds.rocksweep`` (``rocksweep.accessor``: every analysis above as a method) is there as soon
as both rocksweep and xarray are imported, in either order.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from rocksweep._version import __version__
from rocksweep.accessor import watch
from rocksweep.errors import RocksweepError

if TYPE_CHECKING:  # what __getattr__ gives, for type checkers and editors
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
        risk,
        run,
        simulate,
        spectra,
        table,
    )
    from rocksweep.simulation import Simulation

__all__ = ["RocksweepError", "Simulation", "__version__", "boundaries", "boundary_lines",
           "calibrate", "calibrated_overrides", "estimate", "felt_motion", "floor_spectrum",
           "fragility", "ida", "im_efficiency", "open", "plot", "risk", "run", "simulate",
           "spectra", "table"]
#: ``rocksweep.api``'s names (the functions, and ``Simulation``, what simulate returns)
_API = frozenset(__all__) - {"RocksweepError", "__version__"}

watch()  # ds.rocksweep once xarray is imported (it is never imported here)


def __getattr__(name: str) -> object:
    """The API's functions and ``Simulation`` on first use (``rocksweep.api``: ~25 kB of
    source the command line's start-up need not compile), the modules ``import rocksweep``
    used to load (``rocksweep.api``, ...)."""
    if name == "Simulation":
        from rocksweep import simulation  # lazy: on first use (the docstring)

        value = simulation.Simulation
    elif name in ("api", "simulation", "analysis"):  # bound by import rocksweep before
        value = importlib.import_module(f"rocksweep.{name}")
    elif name in _API:
        from rocksweep import api  # lazy: on first use (the docstring)

        value = getattr(api, name)
    else:
        raise AttributeError(f"module 'rocksweep' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
