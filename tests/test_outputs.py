"""One file-safety path: every output, result files included, is renamed into
place by ``outputs.publish`` with the mode ``outputs.new_file_mode`` reads from the umask,
and no other module renames files or reads the umask."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest
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


def test_a_file_that_appears_meanwhile_is_never_replaced(tmp_path):
    """The one publish rule: a file made at the output path while the command computed is
    kept, with or without overwrite (only the file check_output saw may be replaced), and
    no temporary file is left."""
    from rocksweep.errors import OutputError
    from rocksweep.outputs import atomic_path, check_output

    out = tmp_path / "t.csv"
    for overwrite in (False, True):
        check_output(out, overwrite=overwrite)
        with pytest.raises(OutputError, match="another process meanwhile"):
            with atomic_path(out, overwrite=overwrite) as tmp:
                tmp.write_text("computed")
                out.write_text("mine")
        assert out.read_text() == "mine"
        out.unlink()
    out.write_text("old")  # told to overwrite "old": a different file in its place is kept
    check_output(out, overwrite=True)
    out.unlink()
    out.write_text("theirs")
    with pytest.raises(OutputError, match="replaced by another process meanwhile"):
        with atomic_path(out, overwrite=True) as tmp:
            tmp.write_text("computed")
    assert out.read_text() == "theirs"
    check_output(out, overwrite=True)  # the file that was seen is replaced
    with atomic_path(out, overwrite=True) as tmp:
        tmp.write_text("computed")
    assert out.read_text() == "computed"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]


def test_temporary_files_of_a_killed_writer_are_removed(tmp_path):
    """A command killed while writing leaves its temporary file; the next one writing the
    same path removes it (a dead writer's pid in the name, or, without a pid, an old
    file), and keeps a live writer's."""
    import time

    from rocksweep.outputs import write_atomic

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()
    stale = tmp_path / f".r.h5.{dead}-abcd1234.partial.h5"
    old = tmp_path / ".r.abcd_123.partial.h5"  # an older version's name, no pid
    live = tmp_path / f".r.h5.{os.getppid()}-abcd1234.partial.h5"
    for p in (stale, old, live):
        p.write_text("half")
    os.utime(old, (time.time() - 3600, time.time() - 3600))
    write_atomic(tmp_path / "r.h5", lambda tmp: tmp.write_text("done"))
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["r.h5", live.name])
