"""A kernel function compiled without a Python entry point is called from jitted code only.

``_cache.INTERNAL`` and ``_cache.INLINE`` functions have no CPython wrapper (it was a tenth
of a variant's cold compile): calling one from Python does not raise, it crashes the
interpreter. So no Python code may call one: every call of such a function, in the package
outside the kernel, the scripts or the tests, must sit inside a jitted function
(``@njit``/``@jit``); a bare name handed on (``python_entry(events.hermite_root)``) is no
call. The kernel's own plain functions are not checked: they are what numba compiles (the
entries of ``_static.chosen``'s tables, the closures ``variants`` jits). Python callers use
the ``INLINE_PUBLIC``/``PUBLIC`` functions, tests the others through small @njit wrappers.
Checked statically, on the source.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
KERNEL = ROOT / "rocksweep" / "kernel"
WRAPPERLESS = ("INTERNAL", "INLINE")


def wrapperless() -> set[tuple[str, str]]:
    """(module, name) of the kernel's functions compiled without a Python entry point."""
    found = set()
    opts = "|".join(WRAPPERLESS)
    for path in KERNEL.glob("*.py"):
        mod = f"rocksweep.kernel.{path.stem}"
        src = path.read_text()
        for m in re.finditer(rf"@njit\([^)]*\*\*({opts})\)\ndef (\w+)\(", src):
            found.add((mod, m.group(2)))
        for m in re.finditer(rf"^(\w+) = njit\([^)]*\*\*({opts})\)", src, re.M):
            found.add((mod, m.group(1)))
    return found


def _jitted(fn: ast.AST) -> bool:
    for d in getattr(fn, "decorator_list", []):
        call = d.func if isinstance(d, ast.Call) else d
        name = call.attr if isinstance(call, ast.Attribute) else getattr(call, "id", "")
        if name in ("njit", "jit", "overload", "register_jitable", "intrinsic"):
            return True
    return False


def python_calls(src: str, module: str, targets: set[tuple[str, str]]) -> list[str]:
    """Calls of ``targets`` in ``src`` (the module ``module``) outside any jitted function:
    ``'line: name'``."""
    tree = ast.parse(src)
    own = {n for m, n in targets if m == module}
    names: dict[str, str] = {n: n for n in own}  # local name -> function name
    modules: dict[str, str] = {}  # local alias -> kernel module
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            for a in node.names:
                if (node.module, a.name) in targets:
                    names[a.asname or a.name] = a.name
                elif node.module == "rocksweep.kernel":
                    modules[a.asname or a.name] = f"rocksweep.kernel.{a.name}"
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("rocksweep.kernel."):
                    modules[a.asname or a.name] = a.name
    bad: list[str] = []

    def visit(node: ast.AST, jitted: bool) -> None:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            jitted = jitted or _jitted(node)
        if isinstance(node, ast.Call) and not jitted:
            f = node.func
            if isinstance(f, ast.Name) and f.id in names:
                bad.append(f"{node.lineno}: {f.id}")
            elif (isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name)
                  and (modules.get(f.value.id), f.attr) in targets):
                bad.append(f"{node.lineno}: {f.value.id}.{f.attr}")
        for child in ast.iter_child_nodes(node):
            visit(child, jitted)

    visit(tree, False)
    return bad


def module_of(path: Path) -> str:
    return ".".join(path.relative_to(ROOT).with_suffix("").parts)


def test_functions_without_a_python_entry_are_called_from_jitted_code_only():
    targets = wrapperless()
    assert ("rocksweep.kernel.events", "hermite_newton") in targets  # the finder works
    assert ("rocksweep.kernel.loop", "simulate_point") in targets
    bad = []
    for top in ("rocksweep", "scripts", "tests"):
        for path in sorted((ROOT / top).rglob("*.py")):
            if path.parent == KERNEL:
                continue
            calls = python_calls(path.read_text(), module_of(path), targets)
            bad += [f"{path.relative_to(ROOT)}:{c}" for c in calls]
    assert not bad, "called from Python without a Python entry point:\n" + "\n".join(bad)


def test_the_checker_sees_a_python_call():
    targets = {("rocksweep.kernel.events", "hermite_newton")}
    src = ("from numba import njit\n"
           "from rocksweep.kernel import events as ev\n"
           "from rocksweep.kernel.events import hermite_newton as hn\n"
           "@njit\n"
           "def ok(a):\n"
           "    return hn(a, a, a, a, a, a), ev.hermite_newton(a, a, a, a, a, a)\n"
           "def bad(a):\n"
           "    return hn(a, a, a, a, a, a), ev.hermite_newton(a, a, a, a, a, a)\n")
    assert python_calls(src, "tests.x", targets) == ["8: hn", "8: ev.hermite_newton"]
