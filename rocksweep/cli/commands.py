"""Imports every command module so that each attaches itself to ``main``."""

from rocksweep.cli import accuracy, info, plot, restitution, simulate, spectrum, sweep  # noqa: F401
