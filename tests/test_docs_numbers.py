"""The numbers of README.md and docs/ that a command produces are the rendering of what
that command computed (docs/numbers.json, written by scripts/make_docs_numbers.py, which
reruns the commands): no marked block is edited by hand or left stale."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _script():
    sys.path.insert(0, str(ROOT / "scripts"))  # its _here import, as when run as a script
    try:
        spec = importlib.util.spec_from_file_location(
            "make_docs_numbers", ROOT / "scripts" / "make_docs_numbers.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    return mod


def test_every_marked_block_is_the_rendering_of_the_computed_numbers():
    mod = _script()
    stored = json.loads((ROOT / "docs" / "numbers.json").read_text())
    assert set(stored) == set(mod.COMPUTE) == set(mod.RENDER)
    for path, text in mod.pages(stored).items():
        assert path.read_text() == text, f"{path}: run python scripts/make_docs_numbers.py"
        assert mod.blocks(text)  # the page has its blocks


def test_a_hand_edit_inside_a_block_is_caught():
    mod = _script()
    page = (ROOT / "docs" / "impact_laws.md").read_text()
    body = mod.blocks(page)["impact_laws"]
    edited = mod.with_block(page, "impact_laws", body.replace("%", " %", 1))
    assert edited != page and mod.blocks(edited)["impact_laws"] != body


def test_the_cheap_numbers_are_what_their_commands_compute_now():
    """The numbers of seconds (``CHEAP``: the shipped small scenes' point count, Figure 5's
    runs, Figure 2's restitution values) recomputed: a change of the code that moves one
    fails here, not only when someone reruns the script."""
    mod = _script()
    stored = json.loads((ROOT / "docs" / "numbers.json").read_text())
    assert mod.CHEAP and set(mod.CHEAP) <= set(mod.COMPUTE)
    for name in mod.CHEAP:
        assert mod.COMPUTE[name]() == stored[name], \
            f"{name} moved: run python scripts/make_docs_numbers.py"
