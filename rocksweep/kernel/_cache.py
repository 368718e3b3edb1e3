"""Where numba caches the compiled kernel, and the stamp that says it is fresh.

numba's on-disk cache checks only the file that defines a function. The kernel's entry
points are compiled together with functions from every module of this package and the
codes of ``rocksweep.vocab``, so an edit (or an upgrade) of one file must invalidate the
cached code of all of them: every kernel function is stamped with one hash of all these
sources.

numba also keys its cache directory by the source file's path, so two copies of the same
sources (the repository run by ``python -m pytest`` and a non-editable ``pip install .`` in
site-packages) would each compile every variant again. The cache is therefore one
per-user directory per kernel hash, ``$NUMBA_CACHE_DIR/rocksweep/<hash>`` if
NUMBA_CACHE_DIR is set, else ``$XDG_CACHE_HOME/rocksweep/numba/<hash>`` (default
``~/.cache/rocksweep/numba/<hash>``), shared by every copy of the same sources; if it
cannot be made or written, the kernel's own ``__pycache__`` (same stamp). Imported first by
``rocksweep.kernel``, before any ``@njit(cache=True)`` runs.

The entry points load from it without refreshing numba's target context first
(``EntryCache``; its price in start-up is measured in docs/performance.md).
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from numba.core import caching, config

_KERNEL_DIR = Path(__file__).resolve().parent


def _supported(options: dict) -> dict:
    """The jit options this numba knows (``_nrt``, ``no_cpython_wrapper``,
    ``no_cfunc_wrapper`` and ``forceinline`` are private or internal): an unknown one is
    dropped (the kernel then compiles with numba's default for it: slower, same results)
    instead of failing every ``@njit`` at import."""
    try:
        from numba.core.cpu import CPUTargetOptions  # numba's internals: guarded
    except ImportError:  # pragma: no cover (a numba without the class: keep them all)
        return dict(options)
    return {k: v for k, v in options.items() if hasattr(CPUTargetOptions, k)}


# No kernel function allocates: every one is compiled without numba's reference counting
# (``_nrt=False``), so passing the parameter row or the result row to a function costs no
# atomic increment and decrement (with them, a call inside the step loop cost ~40% of the
# run time even once inlined: numba's refcount pruning cannot pair them across branches).
#
# Every kernel function divides as IEEE does (``error_model="numpy"``): numba's default
# ("python") tests every float divisor for zero to raise ZeroDivisionError, a compare and
# a branch at each of the right-hand side's divisions. Where no divisor is zero the
# results are the same to the bit (``scripts/fingerprint.py check``: 709 arrays); a zero
# divisor gives inf or NaN, which the loop's finiteness check ends the run on
# (STATUS_NONFINITE), where it raised in a worker before. Under callgrind a sweep takes
# 0.80x the time; on the wall clock 0-10% less (docs/performance.md).
_IEEE = {"error_model": "numpy"}
#
# No kernel function is called through a C function pointer (numba's first-class function
# values, ``cfunc``): none builds the C entry point numba makes for every jitted function
# by default (``no_cfunc_wrapper``). Each is lowered, optimised and compiled to machine code
# with its function: 5.3% of the instructions of Figure 3(a)'s cold compile (callgrind,
# 43.1G -> 40.8G), results unchanged (the wrapper is not on any path a run takes).
_BASE = {**_IEEE, "no_cfunc_wrapper": True}
#
# Options of the functions only ever called from jitted code: no Python or C entry point
# to build (tests reach them through small @njit wrappers). They are calls (the work of
# events, once per event): ``forceinline`` set False, else numba would pass on the flag of
# the function whose compilation compiles them (an event search inlined into every copy
# of the screening doubles the code and the compile time, for nothing measurable).
INTERNAL = _supported({**_BASE, "no_cpython_wrapper": True, "_nrt": False,
                       "forceinline": False})
# Options of the small functions on the path of every step: compiled once per signature
# and inlined by LLVM (``forceinline``: LLVM's alwaysinline), not by numba (``inline=
# "always"`` copies and retypes the callee's IR at every call site: 2/3 of the compile
# time). Called from jitted code only, as INTERNAL: no Python entry point (the CPython
# wrapper boxes and unboxes every argument and result, and was lowered, optimised and
# compiled to machine code for each of them: 9% of the instructions of Figure 3(a)'s
# cold compile, 40.8G -> 37.1G). A Python call of one crashes the interpreter, so none is made
# (``tests/kernel/test_python_entry.py``); tests reach them through @njit wrappers
# (``tests/helpers.py``: ``python_entry``).
INLINE = _supported({**_BASE, "forceinline": True, "_nrt": False, "no_cpython_wrapper": True})
# INLINE, with a Python entry point: the equations that the reference path (``physics.
# reference``, ``physics.sliding_reference``) and the tests' derivations also call from
# Python.
INLINE_PUBLIC = _supported({**_BASE, "forceinline": True, "_nrt": False})
# Options of the other functions called from jitted code and from Python.
PUBLIC = _supported({**_BASE, "_nrt": False})
# Options of the entry points (``variants``): called from Python.
ENTRY = _supported({**_BASE, "_nrt": False})


def _kernel_hash() -> str:
    h = hashlib.sha1()
    # the vocabulary's codes (rocksweep.vocab, read by ``layout``) are compiled in too
    vocab = sorted((_KERNEL_DIR.parent / "vocab").glob("*.py"))
    for f in [*sorted(_KERNEL_DIR.glob("*.py")), *vocab]:
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


_STAMP = _kernel_hash()


def shared_cache_dir() -> Path:
    """The per-user cache directory of these kernel sources (see the module docstring)."""
    if config.CACHE_DIR:
        root = Path(config.CACHE_DIR) / "rocksweep"
    else:
        xdg = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
        root = Path(xdg) / "rocksweep" / "numba"
    return root / _STAMP[:20]


def install() -> tuple[type, ...]:
    """Put the kernel's cache locators first in numba's list; the classes installed.

    The one place that touches numba's private caching names (``_CacheLocator``,
    ``_SourceFileBackedLocatorMixin``, ``CacheImpl._locator_classes``): if this numba
    lacks any of them, nothing is installed and numba caches each function its own way
    (beside its source file, stamped by that file alone: an edit of another kernel module
    is then not seen until ``__pycache__`` is cleared; results are the same). Called once,
    at import, before any ``@njit(cache=True)`` of the kernel runs.
    """
    try:
        mixin, base = caching._SourceFileBackedLocatorMixin, caching._CacheLocator
        registry = caching.CacheImpl._locator_classes
        in_tree = caching.InTreeCacheLocator
    except AttributeError:
        return ()

    class _KernelStampMixin:
        def get_source_stamp(self):
            return _STAMP

        @classmethod
        def from_function(cls, py_func, py_file):
            if Path(py_file).resolve().parent != _KERNEL_DIR:
                return None
            return super().from_function(py_func, py_file)

    class KernelSharedLocator(_KernelStampMixin, mixin, base):
        """Cache in ``shared_cache_dir()``, stamped by the hash of all kernel sources.

        Index and data files are named after the module, the function and its line
        (numba's ``CacheImpl``), never the path, so every copy of the same sources finds
        them.
        """

        def __init__(self, py_func, py_file):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            self._cache_path = str(shared_cache_dir())

        def get_cache_path(self):
            return self._cache_path

        @classmethod
        def from_function(cls, py_func, py_file):
            try:
                shared_cache_dir()
            except (RuntimeError, KeyError):  # no home directory to cache in
                return None
            return super().from_function(py_func, py_file)

    class KernelInTreeLocator(_KernelStampMixin, in_tree):
        """Fallback: the kernel's __pycache__, stamped by the hash of all kernel sources."""

    installed = (KernelInTreeLocator, KernelSharedLocator)
    for cls in installed:  # inserted first: tried first
        if not any(c.__name__ == cls.__name__ and c.__module__ == cls.__module__
                   for c in registry):
            registry.insert(0, cls)
    return installed


LOCATORS = install()


class EntryCache(caching.FunctionCache):
    """numba's cache of a compiled function, loading without a refresh of the target
    context first.

    numba's ``Cache.load_overload`` first refreshes the CPU target context: it imports
    and registers every implementation numba has (``numba.np.arraymath``, which imports
    ``scipy.linalg`` to look for BLAS, the typed containers, the random generators, ...),
    about half of a warm ``rocksweep sweep``'s start-up, none of it used: rebuilding cached
    machine code (``CompileResult._rebuild``) types and lowers nothing. It needs the
    context's code generator, the C helpers and math symbols that the context installs
    when it is made, and NRT's symbols (the array arguments' unboxing), installed here.
    A miss falls through to numba's compile, which refreshes both contexts itself
    (``CompilerBase.__init__``), so a compile sees what it always did. Every private name
    it reads has a fallback: numba's own ``load_overload``.
    """

    def load_overload(self, sig, target_context):
        try:
            guard, load = self._guard_against_spurious_io_errors, self._load_overload
            from numba.core.runtime import rtsys  # numba's internals: guarded
        except (AttributeError, ImportError):  # a numba whose cache is built otherwise
            return super().load_overload(sig, target_context)
        rtsys.initialize(target_context)
        with guard():
            return load(sig, target_context)


def in_cache(dispatcher) -> bool | None:
    """Whether numba has this entry point in memory or in its on-disk cache for this
    machine (True for NUMBA_DISABLE_JIT=1's plain function: nothing to compile); None if
    that cannot be told (numba's private cache names changed)."""
    if not hasattr(dispatcher, "py_func"):
        return True
    try:
        if dispatcher.signatures:
            return True
        index = dispatcher._cache._cache_file._load_index()  # {(sig, machine): file}
        machine = dispatcher.targetdescr.target_context.codegen().magic_tuple()
        return any(key[1] == machine for key in index)
    except Exception:  # private numba API: any change means "unknown"
        return None


def loads_fast(dispatcher):
    """Give a cached entry point (a ``@njit(cache=True)`` dispatcher called from Python)
    ``EntryCache``; returns the dispatcher (as is where it has no numba cache to replace:
    NUMBA_DISABLE_JIT=1's plain function, or a numba whose dispatchers keep it otherwise)."""
    if LOCATORS and hasattr(dispatcher, "py_func") and hasattr(dispatcher, "_cache"):
        dispatcher._cache = EntryCache(dispatcher.py_func)
    return dispatcher
