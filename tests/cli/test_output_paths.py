"""One policy for every file a command writes (rocksweep.outputs), through every command.

Each case: one line naming the path and the reason, exit code 2, no traceback, and nothing
written.
"""

import os
import stat
from pathlib import Path

import pytest
from helpers import one_line_error

from rocksweep.cli import main
from rocksweep.errors import OutputError
from rocksweep.outputs import check_output, write_atomic

ROOT = Path(__file__).resolve().parents[2]
ONE_POINT = ["--set", "pulse.shape=sine", "--set", "impact.lam=0", "--set",
             "pulse.w_over_p=2", "--set", "pulse.A_ratio=3"]


def one_line(result) -> str:
    """The single line of a failed CLI run: exit 2, no traceback (``one_line_error``)."""
    return one_line_error(result, code=2)


@pytest.fixture()
def scene(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text((ROOT / "configs" / "ci-small.yaml").read_text())
    return path


def test_a_300_character_name_is_one_line_for_every_command(cli, scene, tmp_path):
    name = "a" * 300
    shown = f"{tmp_path}/{'a' * 60}"[:60]
    for args in (["sweep", str(scene), "-o", str(tmp_path / f"{name}.h5")],
                 ["simulate", str(scene), *ONE_POINT, "--csv", str(tmp_path / f"{name}.csv")],
                 ["simulate", str(scene), *ONE_POINT, "--plot", str(tmp_path / f"{name}.png")]):
        line = one_line(cli.invoke(main, args))
        assert line.startswith(f"Error: {shown}"), line
        assert line.endswith("file name too long)") or "file name too long" in line, line
        assert len(line) < 200
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]


def test_outputs_into_a_missing_directory(cli, scene, tmp_path):
    missing = tmp_path / "no"
    for flag, suffix in (("--csv", "csv"), ("--plot", "png")):
        out = missing / f"f.{suffix}"
        line = one_line(cli.invoke(main, ["simulate", str(scene), *ONE_POINT, flag, str(out)]))
        assert line == f"Error: {out}: directory {missing} does not exist"
    assert not missing.exists()


def test_an_unknown_figure_type_is_refused_before_computing(cli, scene, tmp_path):
    out = tmp_path / "f.xyz"
    line = one_line(cli.invoke(main, ["simulate", str(scene), *ONE_POINT, "--plot", str(out)]))
    assert line == f"Error: {out}: unsupported file type '.xyz'; use one of .png, .pdf, .svg"


def test_the_scene_itself_is_never_an_output(cli, scene):
    before = scene.read_bytes()
    for extra in ([], ["--overwrite"]):
        line = one_line(cli.invoke(main, ["simulate", str(scene), *ONE_POINT, "--csv",
                                          str(scene), *extra]))
        assert line == f"Error: {scene}: is this command's input; choose another output path"
    assert scene.read_bytes() == before


def test_check_output_policy(tmp_path, device_node):
    f = tmp_path / "a.txt"
    write_atomic(f, lambda tmp: tmp.write_text("first"))
    assert f.read_text() == "first"
    # a new file gets the mode any new file gets (umask), not mkstemp's 0600
    mask = os.umask(0o022)
    os.umask(mask)
    assert stat.S_IMODE(os.stat(f).st_mode) == 0o666 & ~mask
    with pytest.raises(OutputError, match="already exists; use overwrite=True to replace it"):
        check_output(f)
    assert check_output(f, overwrite=True) == f
    with pytest.raises(OutputError, match="is this command's input"):
        check_output(f, overwrite=True, inputs=[tmp_path / "x", f])
    with pytest.raises(OutputError, match="is a directory"):
        check_output(tmp_path)
    dev = device_node("d.h5")
    with pytest.raises(OutputError, match="not a regular file"):
        check_output(dev, overwrite=True)
    fifo = tmp_path / "p.h5"
    os.mkfifo(fifo)
    with pytest.raises(OutputError, match="not a regular file"):
        check_output(fifo, overwrite=True)


def test_write_atomic_leaves_nothing_when_the_writer_fails(tmp_path):
    f = tmp_path / "a.txt"
    f.write_text("old")

    def fail(tmp):
        tmp.write_text("half")
        raise OSError(28, "No space left on device")

    with pytest.raises(OutputError, match=r"a.txt: cannot be written \(no space left on the "
                                          r"device\)"):
        write_atomic(f, fail)
    assert f.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
