"""Every name is imported from its home: no module re-exports what it imported (an old
import path kept open), and no module imports a name from a module that only imported
it. The package's ``__init__.py`` files are the public faces and may gather names; a
module imported for its side effects (``import pyarrow``, the command modules attaching
themselves) is not a name."""

from __future__ import annotations

import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "rocksweep"
ROOT = PKG.parent


def _module(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_module(name: str) -> bool:
    path = ROOT.joinpath(*name.split("."))
    return path.with_suffix(".py").exists() or (path / "__init__.py").exists()


def _imported_names(tree: ast.Module) -> dict[str, tuple[int, str]]:
    """Names bound by the module's top-level ``from rocksweep... import`` of names (not of
    modules): name -> (line, where it comes from)."""
    found = {}
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("rocksweep"):
            for a in node.names:
                if not _is_module(f"{node.module}.{a.name}"):
                    found[a.asname or a.name] = (node.lineno, f"{node.module}.{a.name}")
    return found


def _defined(tree: ast.Module) -> set[str]:
    names = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            names |= {t.id for t in node.targets if isinstance(t, ast.Name)}
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return names


def _all(tree: ast.Module) -> list[str]:
    for node in tree.body:
        if (isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__"
                                                 for t in node.targets)):
            return [e.value for e in node.value.elts]  # type: ignore[attr-defined]
    return []


def re_exports(src: str, where: str) -> list[str]:
    """Names ``src`` imports from a rocksweep module and does not use itself (or lists in
    ``__all__``): kept only for others to import from here."""
    tree = ast.parse(src)
    imported = _imported_names(tree)
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    for node in ast.walk(tree):  # names in string annotations ("Scene | None")
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            used |= {w for w in imported if w in node.value.split()}
    exported = set(_all(tree))
    return [f"{where}:{line}: {name} (from {home})" for name, (line, home) in imported.items()
            if name not in used or name in exported]


def test_no_module_re_exports_what_it_imported():
    found = []
    for path in sorted(PKG.rglob("*.py")):
        if path.name != "__init__.py":
            found += re_exports(path.read_text(), path.relative_to(ROOT).as_posix())
    assert not found, "re-exported (import these from their home):\n" + "\n".join(found)


def test_names_are_imported_from_their_home():
    """``from rocksweep.X import n`` where X only imported n (from its home H): import it
    from H. Checked over the package, the tests and the scripts."""
    doors = {}
    for path in PKG.rglob("*.py"):
        if path.name != "__init__.py":
            tree = ast.parse(path.read_text())
            doors[_module(path)] = {n: home for n, (_, home) in _imported_names(tree).items()
                                    if n not in _defined(tree)}
    found = []
    for folder in ("rocksweep", "tests", "scripts"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.ImportFrom) and node.module in doors:
                    found += [f"{path.relative_to(ROOT)}:{node.lineno}: {node.module}.{a.name}"
                              f" is {doors[node.module][a.name]}"
                              for a in node.names if a.name in doors[node.module]]
    assert not found, "imported through another module:\n" + "\n".join(found)


def test_the_checks_see_a_re_export_and_a_door():
    src = ("from rocksweep.errors import SceneError, StoreError\n"
           "from rocksweep.kernel import layout as L\n"
           "__all__ = ['StoreError']\n"
           "def f():\n    raise StoreError(L.N_OUT)\n")
    assert re_exports(src, "x.py") == ["x.py:1: SceneError (from rocksweep.errors.SceneError)",
                                       "x.py:1: StoreError (from rocksweep.errors.StoreError)"]
    assert not (PKG / "outcomes.py").exists()  # the old door to vocab.outcomes is gone
