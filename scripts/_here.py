"""Imported first by the scripts: they run this checkout's package, not an installed one
(an editable ``pip install -e`` of another checkout is found after sys.path, so a script run
from a second worktree measured the first), unless PYTHONPATH names another copy: its
entries stay first (``PYTHONPATH=/path/to/copy python scripts/...`` measures that copy)."""

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_given = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
if str(ROOT) not in sys.path[: 1 + len(_given)]:
    sys.path.insert(1 + len(_given), str(ROOT))
