"""numba cache stamps that cover the whole kernel package.

numba's on-disk cache checks only the file that defines a function. The kernel's entry
points are compiled together with functions from ``equations`` and ``integrate``, so an
edit (or an upgrade) of one file must invalidate the cached code of all of them. This
locator stamps every kernel function with a hash of all kernel sources. Imported first by
``rocksweep.kernel``, before any ``@njit(cache=True)`` runs.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from numba.core import caching, config

_KERNEL_DIR = Path(__file__).resolve().parent


def _kernel_hash() -> str:
    h = hashlib.sha1()
    for f in sorted(_KERNEL_DIR.glob("*.py")):
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


_STAMP = _kernel_hash()


class _KernelStampMixin:
    def get_source_stamp(self):
        return _STAMP

    @classmethod
    def from_function(cls, py_func, py_file):
        if Path(py_file).resolve().parent != _KERNEL_DIR:
            return None
        return super().from_function(py_func, py_file)


class KernelInTreeLocator(_KernelStampMixin, caching.InTreeCacheLocator):
    """Cache in the kernel's __pycache__, stamped by the hash of all kernel sources."""

    @classmethod
    def from_function(cls, py_func, py_file):
        if config.CACHE_DIR:  # NUMBA_CACHE_DIR set: the user's directory wins
            return None
        return super().from_function(py_func, py_file)


class KernelUserDirLocator(_KernelStampMixin, caching.UserProvidedCacheLocator):
    """Cache in NUMBA_CACHE_DIR, stamped by the hash of all kernel sources."""


for _cls in (KernelInTreeLocator, KernelUserDirLocator):
    if _cls not in caching.CacheImpl._locator_classes:
        caching.CacheImpl._locator_classes.insert(0, _cls)

assert os.path.isdir(_KERNEL_DIR)
