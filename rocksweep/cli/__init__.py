"""The ``rocksweep`` command line (click): ``main`` (the group, ``cli/main.py``) and one
module per command, each attaching itself to ``main`` when ``cli/commands.py`` imports
it. Importing it changes nothing in the process (no environment variable, no handler):
what the console command needs is done by ``entry``."""

import os
import sys

from rocksweep.cli import commands  # noqa: F401  (attaches every command)
from rocksweep.cli.main import main


def entry() -> None:
    """The ``rocksweep`` console command (and ``python -m rocksweep``): ``main``, then, after
    a command that succeeded, an exit without the interpreter's teardown.

    Two process-wide choices are made here, the console command's alone (``main`` itself,
    for tests and embedding, changes nothing and exits as click does):
    - ``OPENBLAS_NUM_THREADS=1`` unless set: the commands do no linear algebra, and
      OpenBLAS's thread pools (numpy's, scipy's) would spin up at import and cost 0.1-0.2 s
      of CPU per command (docs/performance.md, start-up). Set before numpy loads: importing
      this package loads no numpy.
    - ``os._exit`` after success: finalising numba and LLVM takes ~0.15 s, a fifth of a
      small sweep; every file is closed and renamed into place before a command returns,
      so nothing is left to do then (``atexit`` handlers do not run). Errors and
      interrupts exit as usual."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    # interrupts (signal, +2% of import rocksweep.cli): the console's alone
    from rocksweep import interrupts

    interrupts.install()  # a Ctrl-C is remembered even where a library swallows it
    try:
        main()
    except SystemExit as stop:
        if stop.code not in (None, 0):
            if interrupts.pending():  # files are closed; a library the interrupt hit
                sys.stderr.flush()    # may not survive its teardown
                os._exit(stop.code if isinstance(stop.code, int) else 1)
            raise
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


__all__ = ["entry", "main"]
