"""Readable units: no function in the package longer than ``MAX_FUNCTION`` lines and no
module longer than ``MAX_MODULE`` lines (an AST scan of every module of rocksweep/)."""

from __future__ import annotations

import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "rocksweep"
MAX_FUNCTION = 150
MAX_MODULE = 900


def long_units(src: str, where: str) -> list[str]:
    """'where: N lines (what)' for the module and every function of ``src`` over the
    limits (a function's lines: from its ``def`` (decorators excluded) to its last)."""
    found = []
    n = len(src.splitlines())
    if n > MAX_MODULE:
        found.append(f"{where}: {n} lines (module, at most {MAX_MODULE})")
    for node in ast.walk(ast.parse(src)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            length = node.end_lineno - node.lineno + 1
            if length > MAX_FUNCTION:
                found.append(f"{where}:{node.lineno}: {length} lines ({node.name}, at most "
                             f"{MAX_FUNCTION})")
    return found


def test_no_long_function_or_module_in_the_package():
    found = []
    for path in sorted(PKG.rglob("*.py")):
        found += long_units(path.read_text(), path.relative_to(PKG.parent).as_posix())
    assert not found, "too long:\n" + "\n".join(found)


def test_the_scan_sees_a_long_function_and_a_long_module():
    body = "".join(f"    x{i} = {i}\n" for i in range(MAX_FUNCTION))
    src = "def short():\n    return 1\n\n\n@decorated\ndef long():\n" + body
    assert long_units(src, "m.py") == [f"m.py:6: {MAX_FUNCTION + 1} lines (long, at most "
                                       f"{MAX_FUNCTION})"]
    big = "x = 1\n" * (MAX_MODULE + 1)
    assert long_units(big, "m.py") == [f"m.py: {MAX_MODULE + 1} lines (module, at most "
                                       f"{MAX_MODULE})"]
    assert long_units("x = 1\n" * MAX_MODULE, "m.py") == []
