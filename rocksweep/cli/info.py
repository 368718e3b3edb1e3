"""``rocksweep info``: what a sweep result holds and where it came from."""

from __future__ import annotations

import json
import math
from pathlib import Path

import click

from rocksweep.cli.main import main, user_errors


def counts_lines(result) -> list[str]:
    """Table of mode 1 / mode 2 / safe / flagged counts per shape and lam."""
    rows = result.counts()
    lines = [f"{'shape':<8}{'lam':>8}{'mode1':>9}{'mode2':>9}{'safe':>9}{'flagged':>9}"
             + (f"{'missing':>9}" if any(r["not_computed"] for r in rows) else "")]
    for r in rows:
        line = (f"{str(r['shape']):<8}{r['lam']:>8g}{r['mode1']:>9}{r['mode2']:>9}"
                f"{r['safe']:>9}{r['flagged']:>9}")
        if any(q["not_computed"] for q in rows):
            line += f"{r['not_computed']:>9}"
        lines.append(line)
    return lines


def _json_value(v):
    """JSON has no inf: write it as the string "inf" (wn_over_p: .inf, a rigid body)."""
    if isinstance(v, float) and math.isinf(v):
        return "inf" if v > 0 else "-inf"
    if isinstance(v, float) and math.isnan(v):
        return None
    return v


def info_dict(result) -> dict:
    a = result.attrs
    done = result.done
    keys = {k.split(".", 1)[1]: k for k in result.scene["axes"]}
    dims = {}
    for d in result.dims:
        vals = result.coords[d]
        dims[d] = {"size": len(vals), "scene_key": keys[d],
                   "values": [v.item() if hasattr(v, "item") else v for v in vals]}
    return {
        "path": str(result.path),
        "title": result.name,
        "format_version": a.get("format_version"),
        "body_kind": result.kind,
        "dims": dims,
        "fixed": {k: _json_value(v) for k, v in result.scalars.items()},
        "points_total": int(done.size),
        "points_done": int(done.sum()),
        "complete": bool(done.all()),
        "counts": result.counts(),
        "accuracy": a.get("accuracy"),
        "numerics": json.loads(a.get("numerics", "{}")),
        "energy": bool(a.get("energy", False)),
        "steps_total": int(result.arrays["steps"].sum()),
        "event_steps_total": int(result.arrays["event_steps"].sum()),
        "provenance": {
            **{k: a.get(k) for k in ("rocksweep_version", "numba_version", "numpy_version",
                                     "h5py_version", "hdf5_version", "python_version",
                                     "started", "finished", "sessions")},
            "wall_time_s": a.get("wall_time"),
            "cpu_time_s": a.get("cpu_time"),
            "overrides": json.loads(a.get("overrides", "[]")),
        },
        "scene": a.get("scene"),
    }


@main.command()
@click.argument("result_path", metavar="OUT.h5", type=click.Path(path_type=Path))
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@user_errors
def info(result_path: Path, as_json: bool) -> None:
    """Dimensions, completeness, counts per class per lam and shape, and provenance of a
    sweep result."""
    from rocksweep.store import read_result

    result = read_result(result_path, ["outcome", "status", "steps", "event_steps"])
    d = info_dict(result)
    if as_json:
        click.echo(json.dumps(d, indent=2))
        return
    click.echo(f"{result_path}: {d['title']}")
    for name, dim in d["dims"].items():
        v = dim["values"]
        span = (", ".join(map(str, v)) if len(v) <= 6 else f"{v[0]:g} .. {v[-1]:g}")
        click.echo(f"  {name:<10} {dim['size']:>6}  [{span}]   ({dim['scene_key']})")
    if d["fixed"]:
        click.echo("  fixed: " + ", ".join(f"{k} = {v}" for k, v in d["fixed"].items()))
    pct = 100 * d["points_done"] / max(1, d["points_total"])
    state = "complete" if d["complete"] else "INCOMPLETE (finish it with rocksweep sweep " \
        "SCENE.yaml -o FILE --resume)"
    click.echo(f"points: {d['points_done']} of {d['points_total']} done ({pct:.1f}%), {state}")
    for line in counts_lines(result):
        click.echo("  " + line)
    p = d["provenance"]
    click.echo(f"accuracy: {d['accuracy']}")
    click.echo(f"RK4 steps: {d['steps_total']} + {d['event_steps_total']} event "
               "re-integrations")
    wall = p["wall_time_s"] or 0.0
    click.echo(f"run: started {p['started']}, finished {p['finished'] or '-'}, "
               f"{p['sessions']} session(s), {wall:.2f} s wall time, "
               f"{p['cpu_time_s'] or 0.0:.2f} s CPU time on the points")
    click.echo(f"versions: rocksweep {p['rocksweep_version']}, numba {p['numba_version']}, "
               f"numpy {p['numpy_version']}, h5py {p['h5py_version']} "
               f"(HDF5 {p['hdf5_version']}), Python {p['python_version']}")
    if p["overrides"]:
        click.echo("overrides: " + " ".join(f"--set {o}" for o in p["overrides"]))
