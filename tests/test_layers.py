"""The package's rooms and floors: an import never climbs to a higher floor.

Each module belongs to a floor (``FLOORS``, lowest first); it may import its own floor
and those below. Checked on every ``import``/``from ... import`` of rocksweep modules in
the source, module level and inside functions alike (only ``if TYPE_CHECKING:`` blocks,
which never run, are exempt). A new module must be placed on a floor here.
"""

from __future__ import annotations

import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "rocksweep"

# lowest first: errors, the vocabulary (rocksweep.vocab) and the version, kernel, the
# model, scenes, files, computing, analyses, figures, the facade, the command line
FLOORS: list[tuple[str, ...]] = [
    ("errors", "vocab", "_version"),
    ("outputs", "inputs", "interrupts", "kernel"),
    ("numerics",),
    ("schema",),
    ("physics",),
    ("fields",),
    ("scene",),
    ("store",),
    ("compute",),
    ("analysis",),
    ("figures",),
    ("api", "simulation", "accessor", "__init__"),
    ("cli", "__main__"),
]


def floor_of(module: str) -> int:
    """The floor of ``rocksweep.<room>...`` (its first component after rocksweep)."""
    parts = module.split(".")
    room = parts[1] if len(parts) > 1 else "__init__"
    for i, rooms in enumerate(FLOORS):
        if room in rooms:
            return i
    raise AssertionError(f"{module}: on no floor (place it in tests/test_layers.py FLOORS)")


def module_name(path: Path) -> str:
    rel = path.relative_to(PKG.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__" and len(parts) > 1:
        parts = parts[:-1] if len(parts) > 2 else [parts[0], "__init__"]
    return ".".join(parts)


def imports(tree: ast.AST, name: str) -> list[tuple[int, str]]:
    """(line, imported rocksweep module) of every import outside TYPE_CHECKING blocks."""
    out: list[tuple[int, str]] = []
    package = name.rsplit(".", 1)[0]

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                for orelse in child.orelse:
                    visit(orelse)
                continue
            if isinstance(child, ast.Import):
                out.extend((child.lineno, a.name) for a in child.names
                           if a.name.startswith("rocksweep"))
            elif isinstance(child, ast.ImportFrom):
                mod = child.module or ""
                if child.level:
                    mod = ".".join(package.split(".")[: len(package.split(".")) - child.level + 1]
                                   + ([mod] if mod else []))
                if mod == "rocksweep":  # from rocksweep import fields, kernel...
                    out.extend((child.lineno, f"rocksweep.{a.name}") for a in child.names)
                elif mod.startswith("rocksweep"):
                    out.append((child.lineno, mod))
            visit(child)

    visit(tree)
    return out


def test_no_import_climbs_a_floor():
    climbs = []
    for path in sorted(PKG.rglob("*.py")):
        name = module_name(path)
        here = floor_of(name)
        for line, target in imports(ast.parse(path.read_text()), name):
            if target in ("rocksweep", "rocksweep.__init__"):
                continue  # the package itself (its __version__)
            if floor_of(target) > here:
                climbs.append(f"{path.relative_to(PKG.parent)}:{line} imports {target}")
    assert not climbs, "imports that climb a floor:\n" + "\n".join(climbs)


def test_the_checker_sees_a_climb():
    """The check itself: a physics module importing the store is reported."""
    src = "def f():\n    from rocksweep.store.reader import read_result\n"
    found = imports(ast.parse(src), "rocksweep.physics.bodies")
    assert found == [(2, "rocksweep.store.reader")]
    assert floor_of(found[0][1]) > floor_of("rocksweep.physics.bodies")
    typed = "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import rocksweep.api\n"
    assert imports(ast.parse(typed), "rocksweep.physics.bodies") == []


def test_the_store_scenes_and_computing_take_no_private_name_from_another_module():
    """What a module of ``store/``, ``scene/`` or ``compute/`` takes from another module is
    public there: a leading underscore says "used here only", and nothing else does."""
    taken = []
    for room in ("store", "scene", "compute"):
        for path in sorted((PKG / room).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(
                        "rocksweep"):
                    taken += [f"{path.relative_to(PKG.parent)}:{node.lineno} {a.name}"
                              for a in node.names
                              if a.name.startswith("_") and not a.name.startswith("__")]
    assert not taken, "private names imported from another module:\n" + "\n".join(taken)


def unexplained_lazy_imports(source: str) -> list[int]:
    """Lines of the imports inside functions (outside ``if TYPE_CHECKING:``) that say
    nothing of why they are there: no comment on the statement, nor on another of the run
    of imports it belongs to (statements on consecutive lines), nor on the line above
    that run."""
    lines = source.splitlines()
    out: list[int] = []

    def commented(first: int, last: int) -> bool:  # 1-based, inclusive
        return any("#" in lines[i] for i in range(first - 1, last))

    def check(body: list[ast.stmt]) -> None:
        run: list[ast.stmt] = []
        for stmt in [*body, None]:
            if (isinstance(stmt, ast.Import | ast.ImportFrom) and run
                    and stmt.lineno == (run[-1].end_lineno or run[-1].lineno) + 1):
                run.append(stmt)
                continue
            if run:
                top = run[0].lineno
                said = (commented(top, run[-1].end_lineno or run[-1].lineno)
                        or (top >= 2 and lines[top - 2].strip().startswith("#")))
                if not said:
                    out.extend(s.lineno for s in run)
            run = [stmt] if isinstance(stmt, ast.Import | ast.ImportFrom) else []

    def visit(node: ast.AST, inside: bool) -> None:
        for field in ("body", "orelse", "finalbody", "handlers"):
            block = getattr(node, field, None)
            if isinstance(block, list) and inside and field != "handlers":
                check(block)
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                continue
            visit(child, inside or isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef))

    visit(ast.parse(source), False)
    return sorted(out)


def test_every_import_inside_a_function_says_why():
    """An import inside a function is there for a measured start-up cost (what it loads
    that its module's importers need not: ``python scripts/lazy_imports.py``), a cycle,
    or a guard, and its comment says which; every other import is at the top."""
    found = [f"{path.relative_to(PKG.parent)}:{line}"
             for path in sorted(PKG.rglob("*.py"))
             for line in unexplained_lazy_imports(path.read_text())]
    assert not found, "imports inside functions without a reason: " + ", ".join(found)


def test_the_reason_checker_sees_a_silent_import():
    src = ("import os\n\n\ndef f():\n    import json\n\n    return json\n\n\n"
           "def g():\n    import xarray as xr  # lazy: xarray (+0.3 s)\n    return xr\n\n\n"
           "def h():\n    # lazy: h5py (+0.1 s)\n    import h5py\n    from numpy import (\n"
           "        array,\n    )\n    import yaml\n\n    import scipy\n    return h5py\n")
    assert unexplained_lazy_imports(src) == [5, 23]
