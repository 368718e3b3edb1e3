"""Every figure in docs/ is one that scripts/make_docs_figures.py makes (docs/diagrams.md
says so): a figure added by hand would never be regenerated when the code changes."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_docs_figure_is_made_by_the_script():
    sys.path.insert(0, str(ROOT / "scripts"))  # its _here import, as when run as a script
    try:
        spec = importlib.util.spec_from_file_location(
            "make_docs_figures", ROOT / "scripts" / "make_docs_figures.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    made = set(mod.PNGS)
    on_disk = {p.stem for p in (ROOT / "docs").glob("*.png")}
    assert on_disk <= made, sorted(on_disk - made)
    assert made <= on_disk, sorted(made - on_disk)
