"""What a command pays at start-up for the compiled kernel: a cached variant
loads without numba's registries (``kernel._cache.EntryCache``), and reading a result
loads no numba at all.

Each check runs in a fresh interpreter (a module, once imported, stays imported) that
shares this process's numba cache, filled here first.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from rocksweep.compute import sweep as sw
from rocksweep.compute.driver import sweep_arrays
from rocksweep.scene.grid import Grid
from rocksweep.scene.parse import load_scene

ROOT = Path(__file__).resolve().parents[2]
CI_SMALL = ROOT / "configs" / "ci-small.yaml"

# numba imports this module only when it refreshes its CPU target context (it registers
# the implementations of numpy's functions): the refresh a cache load no longer needs.
REFRESHED = "numba.np.arraymath"


def _python(code: str) -> str:
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.strip().splitlines()[-1]


def test_a_cached_variant_loads_without_a_refresh_and_gives_the_same_outcomes():
    scene = load_scene(CI_SMALL)
    sw.prepare(Grid(scene), sw.level(scene))  # in numba's cache from here on
    here = sweep_arrays(scene)[0]
    out = _python(
        "import sys, json; from rocksweep.compute.driver import sweep_arrays; "
        "from rocksweep.scene.parse import load_scene; "
        f"r = sweep_arrays(load_scene({str(CI_SMALL)!r}))[0]; "
        f"print(json.dumps([{REFRESHED!r} in sys.modules, r['outcome'].ravel().tolist(), "
        "r['theta_max_over_alpha'].ravel().tolist()]))")
    refreshed, outcome, theta = json.loads(out)
    assert not refreshed
    assert outcome == here["outcome"].ravel().tolist()
    # bit for bit: the same machine code, loaded either way
    assert np.array_equal(np.array(theta), here["theta_max_over_alpha"].ravel(), equal_nan=True)


def test_a_process_that_loaded_a_variant_still_compiles_new_code():
    """The context left unrefreshed by a cache load is refreshed by the next compile
    (numba's compiler refreshes it first): a function using numpy's implementations, not
    cached, compiles and runs after a variant was loaded from the cache."""
    scene = load_scene(CI_SMALL)
    sw.prepare(Grid(scene), sw.level(scene))
    out = _python(
        "import sys, numpy as np, numba; from rocksweep.compute import sweep as sw; "
        "from rocksweep.scene.grid import Grid; from rocksweep.scene.parse import load_scene; "
        f"sc = load_scene({str(CI_SMALL)!r}); sw.prepare(Grid(sc), sw.level(sc)); "
        f"before = {REFRESHED!r} in sys.modules; "
        "f = numba.njit(lambda a: np.cumsum(a)[-1] + np.linalg.norm(a)); "
        "print(before, f(np.array([3.0, 4.0])))")
    assert out == "False 12.0"


def test_reading_a_result_loads_no_numba(tmp_path):
    """``rocksweep info``, ``plot`` and ``rocksweep.open`` read files: no numba import
    (~0.1 s) nor kernel."""
    scene = load_scene(CI_SMALL)
    path = tmp_path / "r.h5"
    from rocksweep.compute.session import sweep_file

    sweep_file(scene, path)
    out = _python(
        "import sys, rocksweep; from rocksweep.store import read_result; "
        f"ds = rocksweep.open({str(path)!r}); r = read_result({str(path)!r}); "
        "print(int(ds.outcome.size), sorted(m for m in sys.modules if m.split('.')[0] == 'numba'))")
    assert out == f"{scene.size} []"
