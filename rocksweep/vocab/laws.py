"""Impact laws (scene key ``impact.law``; ``rocksweep.physics.impact`` has the physics).

- ``vertical`` (code name ``EQ1``, kernel code ``LAW_EQ1``: "vertical" is the user's word
  for the impulse's direction, not the ground's vertical component): eq. (1) as printed, the
  vertical impulse at lam*b from the future corner, the top mass keeps its momentum;
- ``locked``: the top mass moves with the base through the impact (u' kept);
- ``constant``: e = ``impact.e`` whatever the body; the top mass keeps its momentum.
"""

from __future__ import annotations

EQ1, LOCKED, CONSTANT = "vertical", "locked", "constant"
LAWS: tuple[str, ...] = (EQ1, LOCKED, CONSTANT)
DEFAULT_LAW = EQ1
#: the kernel's PAR_LAW code of each law (float64 parameter row entry)
LAW_CODE: dict[str, float] = {EQ1: 0.0, LOCKED: 1.0, CONSTANT: 2.0}
#: where each law's e comes from, for labels and reports
LAW_ORIGIN: dict[str, str] = {
    EQ1: "eq. (1)",
    LOCKED: "top mass locked to the base",
    CONSTANT: "impact.e",
}


def law_origin(law: str, e: float | None = None) -> str:
    """Where the e of ``law`` comes from: "eq. (1)", "top mass locked to the base" or
    "e = 0.9" (``constant`` with its e given)."""
    if law == CONSTANT and e is not None:
        return f"e = {e:g}"
    return LAW_ORIGIN[law]
