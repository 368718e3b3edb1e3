"""``python -m rocksweep``: the console command (``rocksweep.cli.entry``), with Ctrl-C during
start-up answered as an interrupt (exit 130), not a traceback from inside an import."""

import sys

from rocksweep import interrupts

interrupts.install()
try:
    from rocksweep.cli import entry
except KeyboardInterrupt:  # only click and the command modules load here: nothing written
    sys.stderr.write("\ninterrupted\n")
    raise SystemExit(130) from None

entry()
