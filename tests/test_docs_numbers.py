"""The numbers of README.md and docs/ that a command produces are the rendering of what
that command computed (docs/numbers.json, written by scripts/make_docs_numbers.py, which
reruns the commands): no marked block is edited by hand or left stale."""

from __future__ import annotations

import json
from pathlib import Path

from helpers import load_script

ROOT = Path(__file__).resolve().parents[1]


def _script():
    return load_script("make_docs_numbers")


def _pages_on_disk() -> dict[Path, str]:
    return {path: path.read_text() for path in [ROOT / "README.md",
                                                *sorted((ROOT / "docs").glob("*.md"))]}


def test_every_marked_block_is_the_rendering_of_the_computed_numbers():
    mod = _script()
    stored = json.loads((ROOT / "docs" / "numbers.json").read_text())
    assert set(stored) == set(mod.COMPUTE) == set(mod.RENDER)
    for path, text in mod.pages(stored).items():
        assert path.read_text() == text, f"{path}: run python scripts/make_docs_numbers.py"
        assert mod.blocks(text)  # the page has its blocks


def test_every_block_of_the_pages_is_written_by_the_script():
    """A marked block that no computation renders would never be regenerated."""
    mod = _script()
    stored = json.loads((ROOT / "docs" / "numbers.json").read_text())
    rendered = {(path, name) for path, text in mod.pages(stored).items()
                for name in mod.blocks(text)}
    on_disk = {(path, name) for path, text in _pages_on_disk().items()
               for name in mod.blocks(text)}
    assert on_disk == rendered
    # and every marker opened is closed (a broken block is not silently skipped)
    for path, text in _pages_on_disk().items():
        assert text.count("<!-- numbers:") == text.count("<!-- end numbers:") == len(
            mod.blocks(text)), path


def test_a_hand_edit_of_any_number_inside_any_block_is_caught():
    """Each block with a digit in it, one digit changed by hand: the page no longer is
    the rendering of the stored numbers (what the first test compares)."""
    mod = _script()
    stored = json.loads((ROOT / "docs" / "numbers.json").read_text())
    checked = 0
    for path, text in mod.pages(stored).items():
        for name, body in mod.blocks(text).items():
            i = next((k for k, ch in enumerate(body) if ch.isdigit()), None)
            if i is None:
                continue
            edited = mod.with_block(text, name, body[:i] + str((int(body[i]) + 1) % 10)
                                    + body[i + 1:])
            assert edited != text and mod.pages(stored)[path] != edited, (path, name)
            checked += 1
    assert checked >= len(mod.RENDER)


def test_the_cheap_numbers_are_what_their_commands_compute_now():
    """The numbers of seconds (``CHEAP``: the shipped small scenes' point count, Figure 5's
    runs, Figure 2's restitution values, the four figures' mode 1 points, the calibration
    examples, the demo suite's fragility verdicts, README's Python example) recomputed: a
    change of the code that moves one fails here, not only when someone reruns the
    script."""
    mod = _script()
    stored = json.loads((ROOT / "docs" / "numbers.json").read_text())
    assert mod.CHEAP and set(mod.CHEAP) <= set(mod.COMPUTE)
    moved = {}
    for name in mod.CHEAP:
        fresh = mod.COMPUTE[name]()
        if fresh != stored[name]:
            moved[name] = {k: (stored[name].get(k), v) for k, v in fresh.items()
                           if stored[name].get(k) != v}
    assert not moved, f"moved (stored, computed): {moved}: run python " \
        "scripts/make_docs_numbers.py"
