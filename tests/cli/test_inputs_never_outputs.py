"""An output is never an input of its command: a run never destroys its own data.

Every file a command reads (the scene, its record, a suite's records and their listing, the
result an analysis reads and the records that result names) is refused as any of the
command's outputs, even with --overwrite / overwrite=True, whatever the spelling: the same
path, ``..``, a symbolic link, a hard link (compared by device and inode). Each refusal is
one line, and every input is left byte for byte as it was.
"""

from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path

import pytest
from bodies import FIG3_YAML
from helpers import one_line_error

import rocksweep
from rocksweep.cli import main
from rocksweep.errors import OutputError
from rocksweep.outputs import check_output, is_input
from rocksweep.physics.records import read_record

ROOT = Path(__file__).resolve().parents[2]
SUITE = ROOT / "records" / "suite"
BODY = FIG3_YAML + "impact: {lam: 0.0}\n"
REFUSED = "is this command's input; choose another output path"


def two_column(src: Path, n: int = 600) -> str:
    r = read_record(src)
    return "".join(f"{i * r.dt:.4f} {a:.7e}\n" for i, a in enumerate(r.acc[:n]))


@pytest.fixture()
def work(tmp_path, monkeypatch) -> Path:
    """A folder of inputs: a suite (r/*.AT2 and a listing of it), a two-column suite
    (c/*.csv), a single-record scene with an AT2 and one with a two-column record named
    .png (a name an output may take)."""
    (tmp_path / "r").mkdir()
    (tmp_path / "c").mkdir()
    for i in (1, 2):
        shutil.copy(SUITE / f"SYN0{i}.AT2", tmp_path / "r" / f"SYN0{i}.AT2")
        (tmp_path / "c" / f"c{i}.csv").write_text(two_column(SUITE / f"SYN0{i + 2}.AT2"))
    shutil.copy(SUITE / "SYN05.AT2", tmp_path / "rec.AT2")
    (tmp_path / "rec.csv").write_text(two_column(SUITE / "SYN06.AT2"))
    (tmp_path / "rec.png").write_text(two_column(SUITE / "SYN07.AT2"))
    (tmp_path / "suite.txt").write_text("r/SYN01.AT2\nr/SYN02.AT2\n")
    suite = ("ground:\n  records: {}\n  scale: {{im: PGA, values: [0.2, 0.6]}}\n  p: 2.0\n"
             "  periods: [0.5]\n")
    (tmp_path / "suite.yaml").write_text("name: s\n" + BODY + suite.format("r/*.AT2"))
    (tmp_path / "listed.yaml").write_text("name: l\n" + BODY + suite.format("suite.txt"))
    (tmp_path / "csvsuite.yaml").write_text("name: c\n" + BODY + suite.format("c/*.csv"))
    for name, rec in (("one", "rec.AT2"), ("csv", "rec.csv"), ("png", "rec.png")):
        (tmp_path / f"{name}.yaml").write_text(
            f"name: {name}\n" + BODY + f"ground: {{record: {rec}, A_ratio: [1, 3], "
            "p: [1.0, 2.0]}\n")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def digests(d: Path) -> dict[str, str]:
    return {str(p.relative_to(d)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(d.rglob("*")) if p.is_file() and not p.is_symlink()}


def refused(cli, args: list[str], work: Path, out: str) -> None:
    """The command refuses ``out`` in one line; no input changed, no file added."""
    before = digests(work)
    line = one_line_error(cli.invoke(main, args))
    assert line == f"Error: {out}: {REFUSED}", line
    assert digests(work) == before


# one case per command and kind of input: (command line, the output that is an input)
CASES = [
    (["sweep", "suite.yaml", "-o", "r/SYN01.AT2", "--overwrite", "-q"], "r/SYN01.AT2"),
    (["sweep", "listed.yaml", "-o", "suite.txt", "--overwrite", "-q"], "suite.txt"),
    (["sweep", "one.yaml", "-o", "rec.AT2", "--overwrite", "-q"], "rec.AT2"),
    (["sweep", "one.yaml", "-o", "r/../rec.AT2", "--overwrite", "-q"], "r/../rec.AT2"),
    (["sweep", "one.yaml", "-o", "rec.AT2", "--resume", "-q"], "rec.AT2"),
    (["simulate", "csv.yaml", "--set", "ground.A_ratio=2", "--set", "ground.p=2", "--csv",
      "rec.csv", "--overwrite"], "rec.csv"),
    (["simulate", "png.yaml", "--set", "ground.A_ratio=2", "--set", "ground.p=2", "--plot",
      "rec.png", "--overwrite"], "rec.png"),
    (["restitution", "png.yaml", "--plot", "rec.png", "--overwrite"], "rec.png"),
    (["accuracy", "csv.yaml", "--points", "2", "--ladder", "short", "-o", "rec.csv",
      "--overwrite"], "rec.csv"),
]


@pytest.mark.parametrize("args, out", CASES, ids=[" ".join(a[:1] + a[2:4]) for a, _ in CASES])
def test_a_command_never_writes_over_a_file_it_reads(cli, work, args, out):
    refused(cli, args, work, out)


def test_links_to_an_input_are_that_input(cli, work):
    os.symlink("rec.AT2", work / "soft.h5")
    os.link(work / "r" / "SYN02.AT2", work / "hard.h5")
    refused(cli, ["sweep", "one.yaml", "-o", "soft.h5", "--overwrite", "-q"], work, "soft.h5")
    refused(cli, ["sweep", "suite.yaml", "-o", "hard.h5", "--overwrite", "-q"], work,
            "hard.h5")
    assert is_input("soft.h5", [work / "rec.AT2"]) and is_input("hard.h5", ["r/SYN02.AT2"])
    assert not is_input("rec.csv", ["rec.AT2", None])


def test_analyses_never_write_over_the_result_or_its_records(cli, work):
    """A result's readers (boundaries, fragility, plot, spectrum) protect the result and
    the records it names."""
    assert cli.invoke(main, ["sweep", "csv.yaml", "-o", "c.h5", "-q"]).exit_code == 0
    assert cli.invoke(main, ["sweep", "csvsuite.yaml", "-o", "cs.h5", "-q"]).exit_code == 0
    refused(cli, ["boundaries", "c.h5", "-o", "rec.csv", "--overwrite"], work, "rec.csv")
    refused(cli, ["fragility", "cs.h5", "-o", "c/c1.csv", "--overwrite"], work, "c/c1.csv")
    refused(cli, ["fragility", "cs.h5", "-o", "cs.h5", "--overwrite"], work, "cs.h5")
    refused(cli, ["table", "cs.h5", "-o", "c/c2.csv", "--overwrite"], work, "c/c2.csv")
    refused(cli, ["efficiency", "cs.h5", "-o", "c/c2.csv", "--overwrite"], work, "c/c2.csv")
    (work / "hazard.csv").write_text("IM,rate\n0.1,0.01\n0.5,0.001\n1.0,0.0001\n")
    refused(cli, ["risk", "cs.h5", "--hazard", "hazard.csv", "-o", "c/c1.csv",
                  "--overwrite"], work, "c/c1.csv")
    refused(cli, ["risk", "cs.h5", "--hazard", "hazard.csv", "-o", "hazard.csv",
                  "--overwrite"], work, "hazard.csv")
    os.symlink("rec.csv", work / "rec-link.png")
    refused(cli, ["plot", "c.h5", "-o", "rec-link.png", "--overwrite"], work, "rec-link.png")


@pytest.mark.parametrize("scene", ["path", "dict", "text"])
def test_run_never_writes_over_the_scenes_records(work, scene):
    text = (work / "listed.yaml").read_text().replace("suite.txt", str(work / "suite.txt"))
    given = {"path": "listed.yaml", "dict": __import__("yaml").safe_load(text),
             "text": text}[scene]
    before = digests(work)
    for out in ("suite.txt", "r/SYN01.AT2", str(work / "r" / ".." / "r" / "SYN02.AT2")):
        with pytest.raises(OutputError, match="is this command's input"):
            rocksweep.run(given, output=out, overwrite=True)
    assert digests(work) == before


def test_the_scene_lists_every_file_it_read(work):
    from rocksweep.scene.parse import load_scene

    sc = load_scene(work / "listed.yaml")
    assert {Path(p).resolve() for p in sc.inputs} == {
        work / "listed.yaml", work / "suite.txt", work / "r" / "SYN01.AT2",
        work / "r" / "SYN02.AT2"}
    with pytest.raises(OutputError):
        check_output(work / "suite.txt", overwrite=True, inputs=sc.inputs)


def test_every_file_a_result_was_computed_from_is_guarded(cli, work):
    """ground.record, ground.h2 and ground.vertical of a result (issue 45: ``table -o`` of
    the vertical replaced it), and a PEER folder's H2 and UP files, which the result names
    beside their H1: refused by every command that writes, --overwrite or not."""
    import numpy as np

    from rocksweep.store.reader import resolved_inputs

    t = np.arange(0.0, 2.0 + 0.005, 0.01)
    for name, a in (("h.csv", 0.3 * np.sin(2 * np.pi * t) * (t <= 1.0)),
                    ("h2.csv", 0.2 * np.cos(2 * np.pi * t) * (t <= 1.0)),
                    ("v.csv", 0.1 * np.sin(6 * np.pi * t))):
        np.savetxt(work / name, np.c_[t, a], delimiter=",")
    (work / "three.yaml").write_text(
        "name: three\nbody: {kind: block, alpha: 0.2}\nimpact: {lam: 0.0}\n"
        "ground: {record: h.csv, h2: h2.csv, vertical: v.csv, angle: [0, 90], "
        "A_ratio: 2.5, p: 2.0}\n")
    assert cli.invoke(main, ["sweep", "three.yaml", "-o", "t.h5", "-q"]).exit_code == 0
    for out in ("h.csv", "h2.csv", "v.csv"):
        for over in (["--overwrite"], []):
            refused(cli, ["table", "t.h5", "-o", out, *over], work, out)
        refused(cli, ["boundaries", "t.h5", "-o", out, "--overwrite"], work, out)
        refused(cli, ["sweep", "three.yaml", "-o", out, "--overwrite", "-q"], work, out)
        refused(cli, ["simulate", "three.yaml", "--csv", out, "--overwrite"], work, out)
    # a PEER folder suite names its H2 and UP files (no suffix) beside its records' H1
    peer = {"suite": {"records": [{"name": "RSN1_E_S000.AT2",
                                   "source": str(work / "p" / "RSN1_E_S000.AT2")}],
                      "h2": [{"name": "RSN1_E_S090"}], "vertical": [{"name": "RSN1_E_S-UP"}]}}
    (work / "p").mkdir()
    for n in ("RSN1_E_S000.AT2", "RSN1_E_S090.AT2", "RSN1_E_S-UP.AT2", "other.AT2"):
        (work / "p" / n).write_text("x")
    assert {Path(p).name for p in resolved_inputs(peer)} == {
        "RSN1_E_S000.AT2", "RSN1_E_S090.AT2", "RSN1_E_S-UP.AT2"}
