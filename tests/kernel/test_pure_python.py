"""A kernel you can step through: with NUMBA_DISABLE_JIT=1 the same kernel code runs as
plain Python (a debugger, coverage) and gives the jitted results; and the cache loader's
private numba names each have a fallback."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import rocksweep

ROOT = Path(__file__).resolve().parents[2]

_RUN = """
import json, sys
import numba
from numba.core import config
assert config.DISABLE_JIT, "the kernel must run as plain Python here"
import rocksweep
from rocksweep.kernel import chunk_kernel, layout as L
# a plain function (the table's closure), no dispatcher
assert not hasattr(chunk_kernel(L.KIND_FLEXIBLE, L.LEVEL_OUTCOME), "py_func")
out = {}
for name in ("fig5", "fig5-rigid"):
    sims = rocksweep.simulate(f"configs/{name}.yaml")
    out[name] = [[s.summary["outcome"], s.summary["impacts"], s.summary["t_end"]]
                 for s in sims]
rk = rocksweep.simulate("configs/ricker.yaml", {"pulse.w_over_p": 2.0, "pulse.A_ratio": 3.0,
                                                "impact.lam": 0.4})
out["ricker"] = [[s.summary["outcome"], s.summary["impacts"], s.summary["t_end"]]
                 for s in (rk if isinstance(rk, list) else [rk])]
print(json.dumps(out))
"""


def _summaries():
    out = {}
    for name in ("fig5", "fig5-rigid"):
        out[name] = [[s.summary["outcome"], s.summary["impacts"], s.summary["t_end"]]
                     for s in rocksweep.simulate(ROOT / "configs" / f"{name}.yaml")]
    rk = rocksweep.simulate(ROOT / "configs" / "ricker.yaml",
                            {"pulse.w_over_p": 2.0, "pulse.A_ratio": 3.0, "impact.lam": 0.4})
    out["ricker"] = [[s.summary["outcome"], s.summary["impacts"], s.summary["t_end"]]
                     for s in (rk if isinstance(rk, list) else [rk])]
    return out


def test_figure_5_runs_as_plain_python_give_the_jitted_results():
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1", "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-c", _RUN], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    plain = json.loads(proc.stdout.strip().splitlines()[-1])
    jitted = _summaries()
    assert plain == json.loads(json.dumps(jitted))  # outcomes, impacts, end times
    assert [r[0] for r in plain["fig5"]] == ["safe", "safe", "mode1"]  # the paper's Fig. 5


def test_cache_install_falls_back_when_numba_lacks_its_private_names(monkeypatch):
    from numba.core import caching

    from rocksweep.kernel import _cache

    monkeypatch.delattr(caching, "_CacheLocator")
    assert _cache.install() == ()  # numba's own caching, nothing inserted
    # unknown jit options are dropped, known ones kept
    kept = _cache._supported({"_nrt": False, "no_such_option_of_numba": 1})
    assert kept == {"_nrt": False}


def test_entry_cache_falls_back_to_numbas_load(monkeypatch):
    """EntryCache reads two private methods; without them it is numba's load."""
    from numba.core import caching

    from rocksweep.kernel import _cache, chunk_kernel
    from rocksweep.kernel import layout as L  # noqa: N812

    calls = []

    def numba_load(self, sig, ctx):
        calls.append(sig)
        return None

    owner = next(c for c in caching.FunctionCache.__mro__
                 if "_guard_against_spurious_io_errors" in vars(c))
    monkeypatch.delattr(owner, "_guard_against_spurious_io_errors")
    monkeypatch.setattr(caching.FunctionCache, "load_overload", numba_load)
    cache = _cache.EntryCache(chunk_kernel(L.KIND_RIGID, L.LEVEL_OUTCOME).py_func)
    assert cache.load_overload("sig", None) is None and calls == ["sig"]


def test_in_cache_of_a_plain_function_needs_no_compile():
    from rocksweep.kernel import _cache, chunk_kernel
    from rocksweep.kernel import layout as L  # noqa: N812

    entry = chunk_kernel(L.KIND_RIGID, L.LEVEL_OUTCOME)
    assert _cache.in_cache(entry.py_func) is True
    assert _cache.in_cache(entry) in (True, False)
