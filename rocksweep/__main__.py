"""``python -m rocksweep``: the command line, with Ctrl-C during start-up answered as an
interrupt (exit 130), not a traceback from inside an import."""

import os
import sys

from rocksweep import interrupts

interrupts.install()
try:
    from rocksweep.cli import entry
except KeyboardInterrupt:
    sys.stderr.write("\ninterrupted\n")
    sys.stderr.flush()
    os._exit(130)  # half-imported modules: no teardown (nothing was written)

entry()
