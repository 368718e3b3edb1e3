"""Imports every command module so that each attaches itself to ``main``."""

from rocksweep.cli import restitution, simulate  # noqa: F401
