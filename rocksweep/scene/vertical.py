"""The vertical ground acceleration's scene keys (docs/vertical.md): ``pulse.vertical``'s
mapping, and the scene-wide checks of a vertical (g + a_v > 0 at t = 0, the harmonic's
steps within the step cap)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from rocksweep.errors import SceneError
from rocksweep.outputs import shown
from rocksweep.scene.admission import check_vertical_cost
from rocksweep.scene.model import Scene
from rocksweep.schema import KEYS, VERTICAL_KEYS, fmt
from rocksweep.vocab.axes import alpha_symbol


def pulse_vertical(pulse: dict) -> dict | None:
    """The raw keys of ``pulse.vertical`` (a mapping of VERTICAL_KEYS; amplitude and
    w_over_p required), checked as a section's are; None when not given."""
    spec = pulse.get("vertical")
    if spec is None:
        return None
    if not isinstance(spec, dict):
        raise SceneError(f"pulse.vertical = {fmt(spec)}: {KEYS['pulse.vertical'].allowed}")
    for k in spec:
        if k not in VERTICAL_KEYS:
            raise SceneError(f"pulse.vertical.{k}: unknown key (allowed: "
                             f"{', '.join(VERTICAL_KEYS)})")
    for k in VERTICAL_KEYS:
        if KEYS[f"pulse.vertical.{k}"].required and spec.get(k) is None:
            raise SceneError(f"pulse.vertical.{k}: missing required key (a number, a list "
                             "of numbers or a range {start, stop, num})")
    return spec


def check_vertical_start(scene: Scene) -> None:
    """Refuse (one line) a vertical with g + a_v <= 0 at t = 0 for some point: the body
    would leave the ground before anything else happens (``airborne`` is for a run that
    gets there later). A harmonic: 1 + a sin(phase) <= 0; a record: its first sample
    scaled with the largest |A_ratio| g tan(alpha_ref) of the grid."""
    if "vertical.amplitude" in {a.name for a in scene.axes}:
        amp = np.asarray(scene.axis("vertical.amplitude").values, float)
        phase = np.asarray(scene.axis("vertical.phase").values, float)
        a0 = amp[:, None] * np.sin(np.radians(phase))[None, :]
        i, j = np.unravel_index(np.argmin(a0), a0.shape)
        if 1.0 + a0[i, j] <= 0.0:
            raise SceneError(f"pulse.vertical.amplitude = {fmt(float(amp[i]))}: with "
                             f"pulse.vertical.phase = {fmt(float(phase[j]))} deg, a_v = "
                             f"{a0[i, j]:.4g} g at t = 0, so g + a_v <= 0 (the body leaves "
                             "the ground); a sin(phase) must be > -1 at t = 0")
        check_vertical_cost(scene)
    su = scene.suite
    if su is not None and su.vertical_acts:
        _check_suite_start(scene)
    if scene.vertical is not None:
        first = float(scene.vertical.acc[0]) / scene.record.pga  # a_v(0) per unit of A
        a_ratio = float(np.max(np.abs(scene.axis("A_ratio").values)))
        alpha = float(np.max(scene.axis(alpha_symbol(scene.kind)).values))
        a0 = a_ratio * math.tan(alpha) * first
        if 1.0 + a0 <= 0.0:
            raise SceneError(f"ground.vertical = {shown(scene.vertical.source)}: its first "
                             f"sample scaled with ground.A_ratio = {fmt(a_ratio)} is a_v = "
                             f"{a0:.4g} g at t = 0, so g + a_v <= 0 (the body leaves the "
                             "ground); the vertical at t = 0 must be > -1 g")


def _check_suite_start(scene: Scene) -> None:
    """A folder suite's verticals at t = 0: each record's first vertical sample (a_v at t
    = 0, on any samples) times the largest factor the grid gives that record
    (``Suite.factors`` over stripes, alpha_ref and p) must be > -1 g."""
    su = scene.suite
    alpha = np.asarray(scene.axis(alpha_symbol(scene.kind)).values, float)
    p = np.asarray(scene.axis("p").values, float)
    stripes = np.arange(max(len(su.levels), 1))
    for r, v in enumerate(su.vertical):
        first = float(v.acc[0]) if v is not None else 0.0
        if first >= 0.0:
            continue
        s, a, pp = (x.ravel() for x in np.meshgrid(stripes, alpha, p, indexing="ij"))
        f = float(np.max(su.factors(np.full(s.size, r), None if su.im is None else s, a,
                                    pp)))
        if 1.0 + f * first <= 0.0:
            raise SceneError(f"ground.records: {Path(str(v.source)).name} (the vertical "
                             f"of {su.names[r]}) "
                             f"scaled by the factor {f:.4g} of its record is a_v = "
                             f"{f * first:.4g} g at t = 0, so g + a_v <= 0 (the body leaves "
                             "the ground); the vertical at t = 0 must be > -1 g (or "
                             "ground.vertical: false)")
