"""Every figure in docs/ is one that scripts/make_docs_figures.py makes (docs/diagrams.md
says so): a figure added by hand would never be regenerated when the code changes."""

from __future__ import annotations

from pathlib import Path

from helpers import load_script

ROOT = Path(__file__).resolve().parents[1]


def test_every_docs_figure_is_made_by_the_script():
    mod = load_script("make_docs_figures")
    made = set(mod.PNGS)
    on_disk = {p.stem for p in (ROOT / "docs").glob("*.png")}
    assert on_disk <= made, sorted(on_disk - made)
    assert made <= on_disk, sorted(made - on_disk)
