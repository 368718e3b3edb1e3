"""The ``rocksweep`` command line (click)."""

import os

# The commands do no linear algebra; OpenBLAS's thread pools (numpy's, scipy's) would spin
# up at import and cost 0.1-0.2 s of CPU per command (docs/performance.md, start-up).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from rocksweep.cli.main import main  # noqa: E402

__all__ = ["main"]
