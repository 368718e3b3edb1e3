"""The motion the body feels at one point of a scene, as samples (``rocksweep.felt_motion``):
the ground motion through the orientation and the building (``physics.path``), scaled to
the point's amplitude, and the vertical component the kernel applies with it; no run.

For a record (one, a suite's, or a motion of the excitation path) the samples are the
record's: the kernel runs exactly them, linear between samples, with one factor on the
horizontal and the vertical (``points.with_record``: the point's A over the record's peak).
A pulse is sampled as a building receives it (``floor.pulse_record``: 64 points per 2 pi of
its phase, the last at its end), its ``pulse.vertical`` harmonic at the same times while
the pulse acts.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from rocksweep.errors import ApiError
from rocksweep.physics.bodies import G
from rocksweep.physics.floor import pulse_record
from rocksweep.scene.model import Scene
from rocksweep.vocab.ground import FREE, RECORD


def felt_motion(scene: Scene) -> Any:
    """The motion the body feels at the scene's one point (module docstring) as an
    ``xarray.Dataset`` over ``t`` ([s] for a record, a physical body's pulse; [1/p]
    otherwise): ``a_h`` [g] the horizontal acceleration the body feels, ``a_v`` [g] its
    vertical (only with one), ``a_ground`` [g] the ground's horizontal at the same scale
    (before the orientation and the building; only with ``ground.h2`` or ``floor``); attrs
    name the point, its record and the path. A scene of several points is an ApiError."""
    import xarray as xr  # lazy: xarray, pandas (+0.4 s)

    if scene.size != 1:
        swept = ", ".join(f"{a.key} ({len(a.values)})" for a in scene.swept)
        raise ApiError(f"felt_motion: the scene has {scene.size} points (swept: {swept}); "
                       "give one value of each with overrides")
    values = {a.name: a.values[0] for a in scene.axes}
    point = scene.point(values)
    if point.shape == FREE:
        raise ApiError("felt_motion: a free-rocking scene has no ground motion")
    attrs: dict[str, Any] = {"title": scene.name, **{
        k: float(values[k]) for k in ("A_ratio", "angle", "floor.period") if k in values}}
    data: dict[str, Any] = {}
    if point.shape == RECORD:
        rec = point.record
        factor = point.A / (G * rec.pga)  # the kernel's one factor, in g
        t = np.arange(rec.npts) * rec.dt
        unit = "s"
        a_h = rec.acc * factor
        vertical = point.excitation.vertical_acc
        # one factor for both components; A's sign turns the horizontal round only
        a_v = None if vertical is None else np.asarray(vertical, float) * abs(factor)
        attrs.update(record=rec.name, dt=float(rec.dt), p=float(point.p))
        if scene.path is not None:
            _, _, r = scene.path_motion(values)
            ground = scene.suite.records[r] if scene.suite is not None else scene.record
            # the ground is linear between its samples and at rest after them
            g = np.interp(t, np.arange(ground.npts) * ground.dt, ground.acc, right=0.0)
            g = g * factor
            data["a_ground"] = ("t", g, {"units": "g", "long_name": "the ground's "
                                         "horizontal acceleration (H1), same scale"})
            attrs["path"] = rec.name
    else:
        acc, dt = pulse_record(point.pulse, point.omega)
        t = np.arange(acc.size) * dt
        physical = scene.physical is not None
        unit = "s" if physical else "1/p"
        a_h = acc * point.A / G
        pv = point.excitation.harmonic
        a_v = None
        if pv is not None:
            p = point.body.p
            a_v = pv.amplitude * np.sin(pv.w_over_p * p * t + math.radians(pv.phase))
        attrs.update(shape=point.shape, w_over_p=float(point.w_over_p), dt=float(dt))
    data["a_h"] = ("t", np.asarray(a_h, float), {"units": "g", "long_name": "horizontal "
                                                  "acceleration the body feels"})
    if a_v is not None:
        data["a_v"] = ("t", np.asarray(a_v, float), {"units": "g", "long_name": "vertical "
                                                      "ground acceleration (g + a_v acts)"})
    return xr.Dataset(data, coords={"t": ("t", t, {"units": unit, "long_name": "time"})},
                      attrs=attrs)
