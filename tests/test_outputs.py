"""One file-safety path: every output, result files included, is renamed into
place by ``outputs.publish`` with the mode ``outputs.new_file_mode`` reads from the umask,
and no other module renames files or reads the umask."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

from bodies import FIG3_YAML

PKG = Path(__file__).resolve().parents[1] / "rocksweep"
ROOT = PKG.parent


def calls(name: str) -> list[str]:
    """``module:line`` of every call of ``os.<name>`` in the package."""
    out = []
    for path in sorted(PKG.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr == name and isinstance(node.func.value, ast.Name)
                    and node.func.value.id == "os"):
                out.append(f"{path.relative_to(PKG)}:{node.lineno}")
    return out


def test_one_rename_and_one_umask_reader():
    for name in ("replace", "rename", "umask"):
        where = {c.split(":")[0] for c in calls(name)}
        assert where <= {"outputs.py"}, (name, where)
    assert calls("replace"), "outputs.publish renames with os.replace"


def test_every_output_gets_the_umask_mode(tmp_path):
    """A result file, a figure and a CSV made under umask 027 are 0640 (mkstemp's 0600
    would hide them from the group; 0644 would ignore the user's umask)."""
    scene = tmp_path / "p.yaml"
    scene.write_text("name: p\n" + FIG3_YAML + "impact: {lam: 0.0}\npulse: "
                     "{shape: sine, w_over_p: [1, 2], A_ratio: 3}\n")
    code = ("import os; os.umask(0o027); from rocksweep.cli import main; main()")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for args in (["sweep", "p.yaml", "-o", "r.h5", "-q"],
                 ["simulate", "p.yaml", "--set", "pulse.w_over_p=1", "--csv", "h.csv",
                  "--plot", "h.png"]):
        r = subprocess.run([sys.executable, "-c", code, *args], cwd=tmp_path, env=env,
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
    for name in ("r.h5", "h.csv", "h.png"):
        assert (tmp_path / name).stat().st_mode & 0o777 == 0o640, name
    assert not [p for p in tmp_path.iterdir() if "partial" in p.name]
