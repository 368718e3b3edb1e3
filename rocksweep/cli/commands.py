"""Imports every command module so that each attaches itself to ``main``."""

from rocksweep.cli import (  # noqa: F401
    accuracy,
    boundaries,
    calibrate,
    efficiency,
    floors,
    fragility,
    info,
    plot,
    restitution,
    risk,
    simulate,
    spectrum,
    sweep,
    table,
)
