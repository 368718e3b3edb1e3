"""The kernel's variants as one table: an entry point per row, made on first use, cached on
disk per row, and none made for rows a scene does not ask for.

The compiled rows here are the ones the suite compiles anyway (the rigid outcome and
energy chunks, Figure 3(a)'s flexible outcome chunk): no variant is compiled for this file.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rocksweep.kernel import chunk_kernel, point_kernel, variants, warm_up
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel.ground import GROUNDS

ROOT = Path(__file__).resolve().parents[2]


def _python(code: str) -> str:
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout.strip().splitlines()[-1]


def _cells(entry) -> dict[str, object]:
    fn = getattr(entry, "py_func", entry)
    return dict(zip(fn.__code__.co_freevars, (c.cell_contents for c in fn.__closure__),
                    strict=True))


def test_every_row_of_the_table_makes_its_entry_point_named_after_it():
    """Each (kind, level, ground, contact) of the tables is an entry point whose literals
    are the row's flags; asked again (with numpy ints or a bool for the ground), the same
    one. Made, not compiled: nothing here runs."""
    seen = set()
    for kind, k in variants.KINDS.items():
        for level in (*variants.LEVELS, None):
            lvl = variants.HISTORY if level is None else variants.LEVELS[level]
            for ground, g in GROUNDS.items():
                for contact, c in variants.CONTACTS.items():
                    entry = (point_kernel(kind, ground, contact) if level is None
                             else chunk_kernel(kind, level, ground, contact))
                    name = entry.__name__
                    assert name.startswith("point_" if level is None else "chunk_")
                    assert k.name in name and name.endswith(lvl.name + g.name + c.name)
                    assert _cells(entry) == {
                        "FLEX": k.flex, "DAMPED": k.damped, "ENERGY": lvl.energy,
                        "REACTIONS": lvl.reactions, "GROUND": ground}
                    seen.add(name)
                    again = (point_kernel(np.int64(kind), ground, np.int64(contact))
                             if level is None else
                             chunk_kernel(np.int64(kind), np.int64(level), ground,
                                          np.int64(contact)))
                    assert again is entry
    # one name per row: numba's cache keys an entry point by its name
    n_rows = len(variants.KINDS) * (len(variants.LEVELS) + 1) * len(GROUNDS) * len(
        variants.CONTACTS)
    assert len(seen) == n_rows
    # the paper's rows keep their names
    assert chunk_kernel(L.KIND_FLEXIBLE, L.LEVEL_OUTCOME).__name__ == "chunk_flexible"
    assert chunk_kernel(L.KIND_RIGID, L.LEVEL_ENERGY, True).__name__ == "chunk_rigid_energy_ground"
    assert point_kernel(L.KIND_FLEXIBLE_UNDAMPED, L.GROUND_VERTICAL).__name__ == (
        "point_flexible_undamped_history_vertical")
    # the sliding base's: the same names, "_slide" after them
    assert chunk_kernel(L.KIND_RIGID, L.LEVEL_OUTCOME, L.GROUND_PULSE,
                        L.CONTACT_SLIDE).__name__ == "chunk_rigid_slide"
    with pytest.raises(ValueError, match="no kernel variant"):
        chunk_kernel(L.KIND_RIGID, 2)
    with pytest.raises(ValueError, match="no kernel variant"):
        chunk_kernel(L.KIND_RIGID, L.LEVEL_OUTCOME, 7)


def test_a_second_process_loads_each_row_from_the_cache():
    """Entry points made from the table by one factory are cached on disk one per row
    (the closure's flags are part of numba's cache key): a fresh process loads two rows
    that differ only in their ENERGY flag from the cache, compiles nothing, and gets each
    row's own code (the outcome row leaves the energy NaN, the energy row fills it)."""
    rows = [(L.KIND_RIGID, L.LEVEL_OUTCOME), (L.KIND_RIGID, L.LEVEL_ENERGY)]
    for kind, level in rows:
        warm_up(kind, level)  # compiled (or loaded) here: in the shared cache from now on
    out = _python(
        "import json, numpy as np\n"
        "from rocksweep.kernel import chunk_kernel, layout as L, warm_up\n"
        "from rocksweep.physics.bodies import BlockBody\n"
        "from rocksweep.physics.points import Point, point_row\n"
        "from rocksweep.numerics import Numerics\n"
        "row = point_row(Point(BlockBody(alpha=0.2), 0.0, 'sine', 2.0, 3.0), Numerics())\n"
        "res = []\n"
        f"for kind, level in {rows!r}:\n"
        "    f = chunk_kernel(kind, level)\n"
        "    o = np.empty((1, L.N_OUT)); f(row[None], o)\n"
        "    res.append([sum(f.stats.cache_hits.values()), sum(f.stats.cache_misses.values()),\n"
        "                float(o[0, L.OUT_W_IN]), int(o[0, L.OUT_OUTCOME])])\n"
        "print(json.dumps(res))")
    (hits0, misses0, w0, out0), (hits1, misses1, w1, out1) = json.loads(out)
    assert (hits0, misses0, hits1, misses1) == (1, 0, 1, 0)
    assert np.isnan(w0) and np.isfinite(w1)  # each row's own machine code
    assert out0 == out1  # the same run otherwise


def test_a_scene_makes_only_the_rows_it_runs():
    """A sweep of a sine-pulse scene makes (decorates, loads) its one row, no other: no
    vertical, no other ground kind, no other level."""
    out = _python(
        "import json\n"
        "from rocksweep.compute.driver import sweep_arrays\n"
        "from rocksweep.kernel import variants\n"
        "from rocksweep.scene.parse import load_scene\n"
        f"sweep_arrays(load_scene({str(ROOT / 'configs' / 'ci-small.yaml')!r}))\n"
        "print(json.dumps(sorted(f.__name__ for f in variants._MADE.values())))")
    assert json.loads(out) == ["chunk_flexible"]
