"""The ``rocksweep`` command line (click)."""

from rocksweep.cli.main import main

__all__ = ["main"]
