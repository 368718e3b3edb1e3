"""What compiling the kernel costs, said before it is paid: the kernel variants a run needs
that numba's cache lacks, named, and the seconds one took to compile on this machine.

Each variant (``kernel.chunk_kernel`` of a sweep's kinds and level, ``kernel.point_kernel``
of a single run or a calibration) is compiled once per machine and kernel source, then
loaded from numba's cache. Before a compile the command says how many variants it needs,
which, and how long: the seconds this machine took for that variant when it last compiled
it (measured at every compile, kept in ``compile_seconds.json`` beside numba's cache, per
variant name), else for any variant here (the median of those measured), else
``BENCH_SECONDS``, a quiet 2-core machine's figure (``scripts/bench_compile.py --quick``,
2026-11-29: Figure 3(a)'s variant 10.1 s CPU, 0.5 s more for the kernel's import; the
README's first sweep compiled in 12.1 s; a busy machine takes 2-5x, a vertical variant
~1.15x); a sliding variant never
measured here is forecast at ``RELATIVE`` times that. After it, the time taken.
"""

from __future__ import annotations

import json
import os
import statistics
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from rocksweep import kernel
from rocksweep.outputs import write_atomic

#: [s] a variant's cold compile on a quiet 2-core machine (scripts/bench_compile.py)
BENCH_SECONDS = 11.0
#: a variant's compile relative to its no-slip row's, by the table's name of its contact
#: model (``kernel.variants.CONTACTS``): the sliding loop, 1.2-1.8x (docs/sliding.md,
#: ``scripts/bench_compile.py --slide``)
RELATIVE = {"_slide": 1.5}
#: [s] a "compile" quicker than this was a load (the variant was in memory): not kept
MIN_COMPILE = 0.5
_FILE = "compile_seconds.json"


def _store() -> Path:
    """The file of measured compile times: beside numba's cache (``$NUMBA_CACHE_DIR/
    rocksweep`` or ``$XDG_CACHE_HOME/rocksweep``, default ``~/.cache/rocksweep``)."""
    numba_dir = os.environ.get("NUMBA_CACHE_DIR")
    if numba_dir:
        return Path(numba_dir) / "rocksweep" / _FILE
    xdg = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(xdg) / "rocksweep" / _FILE


def measured() -> dict[str, float]:
    """{variant name: seconds its last compile took here}; {} when none is kept (or the
    file cannot be read: it is only a forecast)."""
    try:
        data = json.loads(_store().read_text())
    except (OSError, ValueError):
        return {}
    if not isinstance(data, dict):
        return {}
    return {str(k): float(v) for k, v in data.items()
            if isinstance(v, int | float) and not isinstance(v, bool) and 0 < v < 1e5}


def record(names: Sequence[str], seconds: float) -> None:
    """Keep ``seconds`` (the compile of ``names`` together) as each one's share; nothing
    said if the file cannot be written."""
    if not names or not seconds > 0:
        return
    data = measured()
    for n in names:
        data[n] = round(seconds / len(names), 2)
    path = _store()
    text = json.dumps(data, sort_keys=True)
    try:  # the one publish rule (a writer at the same time: its numbers are as good)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, lambda tmp: tmp.write_text(text), overwrite=True)
    except OSError:
        pass


def forecast(names: Sequence[str]) -> tuple[float, str]:
    """(seconds to compile ``names``, where the figure comes from)."""
    if not names:
        return 0.0, ""
    known = measured()
    if all(n in known for n in names):
        return sum(known[n] for n in names), "as measured here"
    if known:
        each = statistics.median(known.values())
        return (sum(known.get(n, each * _relative(n)) for n in names),
                f"~{each:.0f} s a variant as measured here")
    return (BENCH_SECONDS * sum(_relative(n) for n in names),
            f"~{BENCH_SECONDS:.0f} s a variant on a quiet 2-core machine, more on a busy one")


def _relative(name: str) -> float:
    """A variant's compile relative to a no-slip one's (``RELATIVE``), by its name."""
    return next((f for tag, f in RELATIVE.items() if name.endswith(tag)), 1.0)


def variant_name(dispatcher: Any) -> str:
    return str(getattr(dispatcher, "__name__", type(dispatcher).__name__))


def in_cache(dispatcher: Any) -> bool | None:
    """``kernel._cache.in_cache`` (numba's private cache names stay there)."""
    from rocksweep.kernel._cache import in_cache as cached  # lazy: numba, scipy (+0.2 s)

    return cached(dispatcher)


def compiling_words(names: Sequence[str]) -> str:
    """'compiling 2 kernel variants (chunk_rigid_vertical, ...), once per machine: ~45 s
    (as measured here)...'"""
    seconds, source = forecast(names)
    n = len(names)
    return (f"compiling {n} kernel variant{'s' * (n > 1)} this run needs "
            f"({', '.join(names)}), once per machine: ~{seconds:.0f} s ({source})...")


def prepare(dispatchers: Sequence[Any], warm: Callable[[], None],
            say: Callable[[str], None], compiles_only: bool = False) -> float:
    """``warm()`` (compiling or loading ``dispatchers``), said: before, the variants to
    compile and their forecast (or "loading or compiling" when numba's cache cannot tell);
    after, the time taken; a compile's time kept (``record``). ``compiles_only``: say
    nothing unless a variant compiles (a command whose output is its answer). Returns the
    seconds."""
    states = [in_cache(d) for d in dispatchers]
    missing = [variant_name(d) for d, s in zip(dispatchers, states, strict=True)
               if s is False]
    unknown = any(s is None for s in states) and not compiles_only
    if missing:
        say(compiling_words(missing))
    elif unknown:
        say("loading or compiling the kernel...")
    t0 = time.perf_counter()
    warm()
    took = time.perf_counter() - t0
    if missing and took >= MIN_COMPILE:
        record(missing, took)
    if missing or unknown or (took > 1.0 and not compiles_only):
        how = "compiled" if missing else "compiled or loaded from numba's cache"
        say(f"kernel {how} in {took:.1f} s")
    return took


def prepare_point(kind: int, ground: Any, say: Callable[[str], None], contact: int = 0
                  ) -> float:
    """The single-run (history) variant of ``kind``, ``ground`` and ``contact``
    (``layout.CONTACT_*``) compiled or loaded now, said when it compiles (``prepare``):
    what ``rocksweep simulate`` and ``rocksweep calibrate`` run."""
    return prepare([kernel.point_kernel(kind, ground, contact)],
                   lambda: kernel.warm_up(kind, None, ground, contact), say,
                   compiles_only=True)
