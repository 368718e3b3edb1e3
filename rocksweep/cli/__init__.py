"""The ``rocksweep`` command line (click): ``main`` (the group, ``cli/main.py``) and one
module per command, each attaching itself to ``main`` when ``cli/commands.py`` imports
it."""

import os

# The commands do no linear algebra; OpenBLAS's thread pools (numpy's, scipy's) would spin
# up at import and cost 0.1-0.2 s of CPU per command (docs/performance.md, start-up).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from rocksweep.cli import commands  # noqa: E402, F401  (attaches every command)
from rocksweep.cli.main import main  # noqa: E402

__all__ = ["main"]
