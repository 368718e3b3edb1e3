"""How a suite's ``ground.records`` is read: listings, glob characters in file
names, links, and the files that are not what they claim.

- a listing is UTF-8 text (a byte-order mark, as Notepad saves it, is read); UTF-16 or
  binary bytes (a NUL) are refused in one line naming the listing;
- an entry that is not a record (the listing itself, another listing, a file '123' that
  is not a record) is refused naming the listing and its line;
- a path that exists is that path, even with glob characters (``r[1].AT2``); a listed
  path is never a glob;
- a loop of symbolic links, as a record, a listing or an output, is one line;
- a record's peak must be a normal number of g.
"""

from __future__ import annotations

import os
import shutil
import warnings
from pathlib import Path

import pytest
from bodies import FIG3_YAML

from rocksweep.errors import RecordError, SceneError
from rocksweep.physics.records import parse_record
from rocksweep.scene.parse import load_scene

ROOT = Path(__file__).resolve().parents[2]
SUITE = ROOT / "records" / "suite"
BODY = FIG3_YAML + "impact: {lam: 0.0}\n"


def scene(d: Path, records: str, extra: str = "  scale: {im: PGA, values: [0.2, 0.6]}\n"
          ) -> Path:
    path = d / "s.yaml"
    path.write_text("name: s\n" + BODY + f"ground:\n  records: {records}\n{extra}"
                    "  p: 2.0\n  periods: [0.5]\n")
    return path


@pytest.fixture()
def d(tmp_path) -> Path:
    (tmp_path / "r").mkdir()
    for i in (1, 2):
        shutil.copy(SUITE / f"SYN0{i}.AT2", tmp_path / "r" / f"SYN0{i}.AT2")
    return tmp_path


def names(path: Path) -> list[str]:
    return list(load_scene(path).suite.names)


@pytest.mark.parametrize("head, end", [(b"", b"\n"), (b"\xef\xbb\xbf", b"\r\n")],
                         ids=["utf8", "bom-crlf"])
def test_a_utf8_listing_is_read_with_or_without_a_bom(d, head, end):
    (d / "l.txt").write_bytes(head + b"# my suite" + end + b"r/SYN01.AT2" + end + end +
                              b"r/SYN02.AT2" + end)
    assert names(scene(d, "l.txt")) == ["SYN01.AT2", "SYN02.AT2"]


@pytest.mark.parametrize("data, words", [
    ("r/SYN01.AT2\nr/SYN02.AT2\n".encode("utf-16"), "UTF-16"),
    ("r/SYN01.AT2\n".encode("utf-16-be"), "a NUL byte"),
    (bytes(range(1, 256)) * 2, "is not UTF-8"),
    (b"r/SYN01.AT2\x00\nr/SYN02.AT2\n", "line 1: a NUL byte"),
    (b"r/SYN01.AT2\nr/SYN02.AT2\x1b[0m\n", "line 2: character 0x1b"),
])
def test_a_listing_that_is_not_utf8_text_is_refused_naming_it(d, data, words):
    (d / "l.txt").write_bytes(data)
    with pytest.raises(SceneError) as e:
        load_scene(scene(d, "l.txt"))
    msg = str(e.value)
    assert "ground.records: l.txt" in msg and words in msg and "\n" not in msg, msg


@pytest.mark.parametrize("listing, line, words", [
    ("l.txt\nr/SYN01.AT2\n", 1, "l.txt is the listing itself"),
    ("r/SYN01.AT2\nother.txt\n", 2, "other.txt is a listing"),
    ("123\nr/SYN02.AT2\n", 1, "expected 2 columns"),
    ("r/SYN01.AT2\nnothere.AT2\n", 2, "no such file"),
])
def test_a_listed_entry_that_is_no_record_names_the_listing_and_line(d, listing, line, words):
    (d / "other.txt").write_text("r/SYN02.AT2\n")
    (d / "123").write_text("hello\n")
    (d / "l.txt").write_text(listing)
    with pytest.raises(SceneError) as e:
        load_scene(scene(d, "l.txt"))
    msg = str(e.value)
    assert f"ground.records: l.txt, line {line}: " in msg and words in msg, msg


def test_glob_characters_in_an_existing_name_are_a_path(d):
    shutil.copy(d / "r" / "SYN01.AT2", d / "r" / "r[1].AT2")
    assert names(scene(d, "['r/r[1].AT2', r/SYN02.AT2]")) == ["r[1].AT2", "SYN02.AT2"]
    (d / "l.txt").write_text("r/r[1].AT2\nr/SYN02.AT2\n")
    assert names(scene(d, "l.txt")) == ["r[1].AT2", "SYN02.AT2"]
    # a glob still globs, and finds the file whose name holds the characters
    assert names(scene(d, "'r/*.AT2'")) == ["SYN01.AT2", "SYN02.AT2", "r[1].AT2"]
    # a listed path is never a glob: r[1] does not match 'r1'
    (d / "l.txt").write_text("r/SYN0[1].AT2\n")
    with pytest.raises(SceneError, match=r"l.txt, line 1: .*SYN0\[1\].AT2: no such file"):
        load_scene(scene(d, "l.txt"))


@pytest.mark.parametrize("where", ["record", "listing", "single"])
def test_a_loop_of_symbolic_links_is_one_line(d, where):
    name = "loop.txt" if where == "listing" else "loop.AT2"
    os.symlink(name, d / name)
    if where == "single":
        path = d / "s.yaml"
        path.write_text("name: s\n" + BODY + "ground: {record: loop.AT2, A_ratio: 2, p: 2}\n")
    else:
        path = scene(d, f"[{name}, r/SYN01.AT2]" if where == "record" else name)
    with pytest.raises(SceneError, match=f"{name}: a loop of symbolic links$"):
        load_scene(path)


def test_a_loop_of_symbolic_links_as_an_output_is_one_line(cli, tmp_path):
    from helpers import one_line_error

    from rocksweep.cli import main

    (tmp_path / "p.yaml").write_text("name: p\n" + BODY + "pulse: {shape: sine, w_over_p: 2, "
                                     "A_ratio: 3}\n")
    os.symlink("loop.h5", tmp_path / "loop.h5")
    out = tmp_path / "loop.h5"
    line = one_line_error(cli.invoke(main, ["sweep", str(tmp_path / "p.yaml"), "-o", str(out),
                                            "--overwrite", "-q"]))
    assert line == f"Error: {out}: cannot be written (a loop of symbolic links)"


@pytest.mark.parametrize("im", ["[PGA]", "{a: 1}", "1", "null"])
def test_a_scale_im_that_is_not_a_name(d, im):
    with pytest.raises(SceneError, match="ground.scale.im = .*: must be one of PGA"):
        load_scene(scene(d, "r/*.AT2", f"  scale: {{im: {im}, values: [0.2]}}\n"))


@pytest.mark.parametrize("peak", [1e-310, 1e-101, 1e101, 1e300])
def test_a_record_whose_peak_is_no_number_of_g(peak):
    rows = "".join(f"{i * 0.01:.2f} {peak * (-1) ** i:.6e}\n" for i in range(50)).encode()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's RuntimeWarning before the error fails
        with pytest.raises(RecordError, match=r"x.csv: PGA = .* g: the peak must be in"):
            parse_record(rows, "x.csv")
    # the bounds are far from any ground motion: 1e-90 g and 1e90 g are still read
    for ok in (1e-90, 1e90):
        rows = "".join(f"{i * 0.01:.2f} {ok * (-1) ** i:.6e}\n" for i in range(50))
        assert parse_record(rows.encode(), "x.csv").pga == pytest.approx(ok)
