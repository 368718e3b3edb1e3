"""A scene's excitation path: from its ground motion (a record, a suite's records or a
pulse) through the orientation and the building to what the body feels (no numba here).

``GroundPath.motion`` gives the record the kernel runs for one combination of the path's
values (the ground motion r, the angle [deg], the floor's modes, a pulse's shape and
w_over_p): ``floor.project`` then ``floor.floor_motion`` (``rocksweep.physics.floor``),
as a ``GroundRecord`` of peak ``pga`` = max |what the body feels| per unit of the ground
motion. Scaling stays the ground motion's: a point's A_ratio (or a suite's factor) sets
the ground's peak, and the kernel's peak is that times ``motion.pga`` over the ground's
peak (the record's H1 PGA; 1 for a pulse, whose A_ratio is its peak:
``Excitation.ground_pga``, ``Scene.drive_ratio``).

Each motion is computed once a run: it becomes an excitation that the scene keeps
(``physics.ground_motion``, ``Scene.excitation``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rocksweep.physics.floor import Mode, derived_record, floor_motion, project, pulse_record
from rocksweep.physics.records import GroundRecord


@dataclass(eq=False)
class GroundPath:
    """The excitation path of a scene (module docstring).

    h2: the second horizontal component of each ground record (in the order of the
    scene's records; None where it has none); modes: the building's modes when the scene
    gives them as ``floor.modes`` (None: one mode from the floor axes, or no floor);
    floor: whether a building stands between the ground and the body; p: the body's
    frequency parameter [rad/s] that times a pulse (1: the pulse scene's time unit 1/p).
    """

    h2: tuple[GroundRecord | None, ...] = ()
    modes: tuple[Mode, ...] | None = None
    floor: bool = False
    p: float = 1.0

    def building(self, values: tuple[float, float, float] | None) -> tuple[Mode, ...] | None:
        """The modes at one point: ``modes``, or the one mode (period, damping,
        participation) of the floor axes' values; None without a floor."""
        if not self.floor:
            return None
        if self.modes is not None:
            return self.modes
        return (Mode(*(float(v) for v in values)),)

    def motion(self, ground: GroundRecord | None, r: int, angle: float,
               floor: tuple[float, float, float] | None,
               pulse: tuple | None = None) -> GroundRecord:
        """What the body feels per unit of ground motion (module docstring). ground: the
        record r of the scene (None for a pulse); angle [deg]; floor: the one mode's
        (period, damping, participation) (unused with ``modes``); pulse: (PulseShape, w
        [rad/s]) for a pulse scene."""
        if pulse is not None:
            acc, dt = pulse_record(pulse[0], pulse[1] * self.p)
            parts: tuple = ("pulse", pulse[0], float(pulse[1]), self.p)
            name = f"{pulse[0].shape} w_over_p={float(pulse[1]):g}"
        else:
            acc, dt = ground.acc, ground.dt
            parts = (ground.sha256,)
            name = ground.name
            h2 = self.h2[r] if self.h2 else None
            if h2 is not None:
                acc = project(ground.acc, h2.acc, angle)
                parts += (h2.sha256, float(angle))
                name += f" at {float(angle):g} deg"
        modes = self.building(floor)
        if modes is not None:
            acc, dt = floor_motion(acc, dt, modes)
            parts += tuple((m.period, m.damping, m.participation) for m in modes)
            name += " on the floor"
        key = (r, float(angle), None if floor is None else tuple(map(float, floor)),
               None if pulse is None else (pulse[0], float(pulse[1])))
        return derived_record(acc, dt, name, parts + (key,))


def check_pair(h1: GroundRecord, h2: GroundRecord) -> str | None:
    """Why two horizontal components cannot be paired (None: they can): they must share
    one DT (a component at another DT is refused, not resampled: resampling one of them
    would change its motion between samples)."""
    if not math.isclose(h1.dt, h2.dt, rel_tol=1e-9, abs_tol=0.0):
        return (f"DT = {h2.dt:g} s differs from the first component's {h1.dt:g} s "
                f"({h1.name}); the two horizontal components must share one DT "
                "(refused, not resampled)")
    return None


def rotd50_peaks(a1: np.ndarray, a2: np.ndarray, n_angles: int = 180) -> float:
    """RotD50 of the peak of a two-component series: the median over the angles 0, 1,
    ..., 179 deg of max_t |a1 cos + a2 sin| (Boore 2010), float."""
    n = max(a1.size, a2.size)
    x = np.zeros(n)
    y = np.zeros(n)
    x[:a1.size] = a1
    y[:a2.size] = a2
    th = np.radians(np.arange(n_angles) * 180.0 / n_angles)
    peaks = np.max(np.abs(np.outer(np.cos(th), x) + np.outer(np.sin(th), y)), axis=1)
    return float(np.median(peaks))
