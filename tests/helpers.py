"""Helpers shared by test modules (``from helpers import one_line_error``; pytest puts
tests/ on sys.path, there being no package)."""

from __future__ import annotations

import ast
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[1]


def one_line_error(result, code: int | None = None) -> str:
    """The single line a failed CLI run printed (a click ``Result``): a non-zero exit
    (exactly ``code`` if given), no traceback, no exception but the exit, one line."""
    assert result.exit_code != 0, result.output
    if code is not None:
        assert result.exit_code == code, (result.exit_code, result.output)
    assert result.exception is None or isinstance(result.exception, SystemExit), \
        result.exception
    assert "Traceback" not in result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1, result.output
    return lines[0]


def kill_sweep_when(args: list[str], cwd, ready, timeout: float = 300.0) -> None:
    """Run ``rocksweep sweep ARGS`` in a subprocess and SIGKILL it as soon as ``ready()``
    is true (polled); assert it was killed, not finished. Compile the kernel in the test
    first, so that the subprocess loads numba's cache and starts at once."""
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    # the package under test (this tree), not whichever rocksweep is installed
    root = str(Path(__file__).resolve().parents[1])
    env = {**os.environ,
           "PYTHONPATH": os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH"))
                                         if p)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "rocksweep", "sweep", *args],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=cwd, env=env)
    try:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and proc.poll() is None:
            if ready():
                break
            time.sleep(0.005)
        assert proc.poll() is None, "the sweep ended before it could be killed"
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.communicate(timeout=30)
    assert proc.returncode == -signal.SIGKILL


def docstring_ids(tree: ast.AST) -> set[int]:
    """ids of the docstring constants of a module's, classes' and functions' bodies (scans
    of message strings leave them out)."""
    ids = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                ids.add(id(body[0].value))
    return ids


def load_script(name: str) -> ModuleType:
    """scripts/NAME.py imported as a module (its ``_here`` import found as when it runs as
    a script), without running its ``main``."""
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    return mod


def python_entry(fn):
    """A Python entry to a kernel function compiled without one (``_cache.INLINE`` or
    ``INTERNAL``: a direct call from Python would crash the interpreter): an @njit wrapper
    taking the same arguments."""
    from numba import njit  # not at the top: most tests compile nothing

    @njit(cache=False)
    def call(*args):
        return fn(*args)

    return call
