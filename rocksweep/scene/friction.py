"""The friction keys of the body section: ``body.mu`` (kinetic) and ``body.mu_static``
(static, at least mu, default mu), axes like any key (docs/sliding.md).

Each value is checked by its key's range (``schema.KEYS``: > 0, <= 10, a number); here the
two together: mu_static needs mu, and no point of the grid may have mu_static < mu (both
are axes of one product grid, so the smallest mu_static must reach the largest mu).
Every impact law carries a tangential impulse (``kernel.sliding.friction_impact``: each
law is a vertical impulse at the locus its e implies, friction by Routh's process), so no
``impact`` key is refused with friction.
"""

from __future__ import annotations

from typing import Any

from rocksweep.errors import SceneError
from rocksweep.scene.model import Axis
from rocksweep.scene.sections import axis_spec
from rocksweep.schema import fmt


def friction_specs(body: dict) -> list[tuple[str, str, str, Any]]:
    """(name, key, form, spec) of the friction axes the body section gives (mu, then
    mu_static), their forms checked; mu_static without mu refused."""
    specs = []
    for name in ("mu", "mu_static"):
        spec = body.get(name)
        if spec is None:
            continue
        if name == "mu_static" and body.get("mu") is None:
            raise SceneError(f"body.mu_static = {fmt(spec)}: needs body.mu, the kinetic "
                             "friction coefficient (mu_static >= mu; without mu_static the "
                             "static coefficient is mu)")
        specs.append((name, f"body.{name}", *axis_spec(f"body.{name}", spec)[:2]))
    return specs


def check_friction(axes: list[Axis]) -> None:
    """Refuse a grid with a point whose mu_static is below its mu (the axes' values are
    checked one by one already)."""
    by = {a.name: a for a in axes}
    if "mu_static" not in by:
        return
    mu_s, mu = min(by["mu_static"].values), max(by["mu"].values)
    if mu_s < mu:
        raise SceneError(f"body.mu_static = {fmt(mu_s)}: must be at least body.mu "
                         f"({fmt(mu)} in this scene: static friction holds at least what "
                         "kinetic friction does); raise mu_static or lower mu")
