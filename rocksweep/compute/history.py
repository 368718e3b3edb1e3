"""A single run's time history as a Dataset over p*t and as CSV (``rocksweep simulate``,
``rocksweep.simulate``): columns ``rocksweep.fields.HISTORY``."""

from __future__ import annotations

import csv
from collections.abc import Sequence
from itertools import product
from pathlib import Path
from typing import TYPE_CHECKING

from rocksweep import fields
from rocksweep.compute.single import Run, run_point
from rocksweep.errors import ApiError, SceneError, set_key
from rocksweep.outputs import atomic_path

# `rocksweep simulate` overlays a few runs; larger grids are for sweeps.
MAX_RUNS = 12
# `rocksweep.simulate` returns one history per point: a notebook's worth, not a grid.
API_MAX_RUNS = 100

if TYPE_CHECKING:
    import xarray as xr

    from rocksweep.scene.model import Scene

def history_dataset(run: Run, title: str = "") -> xr.Dataset:
    """A run's time history as an xarray Dataset over p_t (see ``Simulation``)."""
    import xarray as xr  # ~0.4 s that ``rocksweep simulate`` (no Dataset) does not pay

    cols = run.history_columns()
    spec = {c.name: c for c in fields.HISTORY + fields.SLIDE_HISTORY}
    t = cols.pop("p_t")
    ds = xr.Dataset(
        {k: ("p_t", v, {"units": spec[k].unit, "long_name": spec[k].meaning})
         for k, v in cols.items()},
        coords={"p_t": ("p_t", t, {"units": spec["p_t"].unit,
                                   "long_name": spec["p_t"].meaning})})
    s = run.summary()
    ds.attrs = {"title": title, "outcome": s["outcome"], "accuracy": s["accuracy"],
                "lam": run.point.lam, "shape": run.point.shape,
                "w_over_p": run.point.w_over_p, "A_ratio": run.point.A_ratio}
    return ds


def swept_values(run: Run, swept: Sequence[str]) -> list:
    """The run's value of each swept key, as plain Python (str for shape and a suite's
    record, else float)."""
    p = run.point
    out = []
    for k in swept:
        if run.where is not None and k in run.where:
            v = run.where[k]
        else:
            v = getattr(p, k) if hasattr(p, k) else getattr(p.body, k)
        out.append(str(v) if isinstance(v, str) else float(v))
    return out


def write_history_csv(runs: Sequence[Run], swept: Sequence[str], path: str | Path, *,
                      overwrite: bool = False) -> None:
    """The runs' time histories to one CSV file, atomically: columns run, the swept
    keys, then ``rocksweep.fields.HISTORY`` (p_t, theta_over_alpha, u_over_ucr,
    E_over_Eref, ...) and, where the base may slide, ``fields.SLIDE_HISTORY`` (x_over_b,
    contact_phase, D_fric_over_Eref); plain numbers (``repr`` of Python floats: nan, inf as such).
    Check the path first with ``rocksweep.outputs.check_output``; an existing file is
    replaced only with ``overwrite`` (``outputs.publish``)."""
    with atomic_path(path, overwrite=overwrite) as tmp, tmp.open("w", newline="") as f:
        w = csv.writer(f)
        names = list(runs[0].history_columns()) if runs else [c.name for c in fields.HISTORY]
        w.writerow(["run", *swept, *names])
        for i, r in enumerate(runs):
            fixed = swept_values(r, swept)
            cols = list(r.history_columns().values())
            for j in range(len(cols[0])):
                w.writerow([i, *fixed, *(repr(float(c[j])) for c in cols)])


def run_points(scene: Scene, max_runs: int = MAX_RUNS) -> list[Run]:
    """Each point of a small scene as a single run with history (``rocksweep simulate``
    overlays them); a SceneError naming the longest swept key if there are more than
    ``max_runs`` points."""
    if scene.size > max_runs:
        big = max(scene.swept, key=lambda a: len(a.values))
        raise SceneError(f"{scene.size} points; simulate runs at most {max_runs} (sweep "
                         "the scene, or pick a value with {fix})",
                         fix=set_key(big.key, "set_fix"))
    names = [a.name for a in scene.axes]
    runs = []
    for combo in product(*(a.values for a in scene.axes)):
        values = dict(zip(names, combo, strict=True))
        run = run_point(scene.point(values), scene.single_numerics, contact=scene.contact)
        run.where = values
        runs.append(run)
    return runs


def titled_runs(scene: Scene, max_runs: int = MAX_RUNS) -> list[tuple[Run, xr.Dataset, str]]:
    """``rocksweep.simulate``'s runs: (run, its history Dataset, its title) of every point
    of ``scene``, in grid order. One point: the scene's own point and accuracy
    (``Scene.single_point``, ``single_numerics``), titled with the scene's name; more:
    ``run_points``, each titled with its swept values ("lam = 0.2, A_ratio = 3"). More
    than ``max_runs`` points: an ApiError naming the longest swept key (in the API's
    words: an override, or ``rocksweep.run`` for a grid)."""
    if scene.size > max_runs:
        big = max(scene.swept, key=lambda a: len(a.values))
        raise ApiError(f"the scene has {scene.size} points ({big.key} has {len(big.values)} "
                       f"values): simulate runs at most {max_runs}; pass {{fix}}, or use "
                       "rocksweep.run for a grid", fix=set_key(big.key, "set_fix"))
    if scene.size == 1:
        r = run_point(scene.single_point(), scene.single_numerics, contact=scene.contact)
        return [(r, history_dataset(r, scene.name), scene.name)]
    swept = [a.name for a in scene.swept]
    out = []
    for r in run_points(scene, max_runs):
        title = ", ".join(f"{k} = {v}" for k, v in zip(swept, swept_values(r, swept),
                                                        strict=True))
        out.append((r, history_dataset(r, title), title))
    return out
