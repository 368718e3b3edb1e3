"""What each import inside a function saves at start-up: the measure behind its comment.

An import inside a function (``tests/test_layers.py``: every one says why) is worth it only
where it keeps a start-up from loading something. For each such import in rocksweep/, in a
fresh interpreter: import its module (and, for a module the command line's ``--help``
loads, ``rocksweep.cli.main`` first), then the import's target, and count the modules and
the time the target adds (best of ``--rounds``). An import that adds no module belongs at
the top of its module; one that adds numba, matplotlib, xarray, scipy or h5py (0.1-1 s)
to a path that needs none of them is what the comments name.

    python scripts/lazy_imports.py              # every import inside a function, ~2-3 min
    python scripts/lazy_imports.py --free       # only those that add nothing (move them)

Measured 2026-11-29 (2 shared cores): 220 imports inside functions before, 49 of them
adding no module or only a rocksweep module of < 1 ms off the ``--help`` path (moved to the
top); the 167 left add 0.1 ms-1 s each (most: numpy, h5py, numba, matplotlib, xarray).
"""

from __future__ import annotations

import argparse
import ast
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "rocksweep"
HEAVY = ("numba", "matplotlib", "scipy", "xarray", "pandas", "h5py", "pyarrow", "distributed",
         "dask", "yaml", "tqdm", "joblib", "numpy")

PROBE = r'''
import importlib, json, sys, time
M, T, base = sys.argv[1:4]
if base:
    importlib.import_module(base)
importlib.import_module(M)
before = set(sys.modules)
t = time.perf_counter()
importlib.import_module(T)
print(json.dumps({"dt": time.perf_counter() - t, "new": sorted(set(sys.modules) - before)}))
'''


def module_of(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def lazy_imports() -> list[tuple[Path, int, str, str]]:
    """(file, line, its module, the imported module) of every import inside a function."""
    out = []
    for path in sorted(PKG.rglob("*.py")):
        mod = module_of(path)
        pkg = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]

        def visit(node: ast.AST, inside: bool, path=path, mod=mod, pkg=pkg) -> None:
            for ch in ast.iter_child_nodes(node):
                if inside and isinstance(ch, ast.Import):
                    out.extend((path, ch.lineno, mod, a.name) for a in ch.names)
                elif inside and isinstance(ch, ast.ImportFrom):
                    base = ch.module or ""
                    if ch.level:
                        up = pkg.split(".")[: len(pkg.split(".")) - ch.level + 1]
                        base = ".".join(up + ([base] if base else []))
                    sub = [f"{base}.{a.name}" for a in ch.names
                           if (ROOT / Path(*f"{base}.{a.name}".split("."))).with_suffix(".py")
                           .exists()]
                    out.append((path, ch.lineno, mod, sub[0] if sub else base))
                visit(ch, inside or isinstance(ch, ast.FunctionDef | ast.AsyncFunctionDef))

        visit(ast.parse(path.read_text()), False)
    return out


def probe(mod: str, target: str, base: str, rounds: int) -> dict:
    best: dict = {}
    for _ in range(rounds):
        r = subprocess.run([sys.executable, "-c", PROBE, mod, target, base], cwd=ROOT,
                           capture_output=True, text=True)
        d = json.loads(r.stdout.strip().splitlines()[-1]) if r.returncode == 0 else {}
        if d and (not best or d["dt"] < best["dt"]):
            best = d
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--free", action="store_true", help="only imports that add no module")
    args = ap.parse_args()
    on_help = set(json.loads(subprocess.run(
        [sys.executable, "-c", "import json, sys, rocksweep.cli.main; "
         "print(json.dumps(sorted(sys.modules)))"], cwd=ROOT, capture_output=True,
        text=True).stdout))
    rows = lazy_imports()
    seen: dict[tuple[str, str], dict] = {}
    free = 0
    print(f"{len(rows)} imports inside functions")
    print("| file:line | imports | adds (modules, ms) | heaviest | on --help's path |")
    print("|---|---|---|---|---|")
    for path, line, mod, target in rows:
        key = (mod, target)
        if key not in seen:
            seen[key] = probe(mod, target, "rocksweep.cli.main" if mod in on_help else "",
                              args.rounds)
        d = seen[key]
        if not d:
            print(f"| {path.relative_to(ROOT)}:{line} | {target} | failed | | |")
            continue
        tops = {m.split(".")[0] for m in d["new"]}
        heavy = ", ".join(h for h in HEAVY if h in tops) or "-"
        free += not d["new"]
        if args.free and d["new"]:
            continue
        print(f"| {path.relative_to(ROOT)}:{line} | {target} | {len(d['new'])}, "
              f"{1e3 * d['dt']:.1f} | {heavy} | {'yes' if mod in on_help else 'no'} |")
    print(f"{free} of {len(rows)} add no module: they belong at the top of their module, "
          "unless guarded (an ImportError caught: numba's internals)")


if __name__ == "__main__":
    main()
