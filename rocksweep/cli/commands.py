"""Imports every command module so that each attaches itself to ``main``."""

from rocksweep.cli import (  # noqa: F401
    accuracy,
    boundaries,
    calibrate,
    fragility,
    info,
    plot,
    restitution,
    simulate,
    spectrum,
    sweep,
)
