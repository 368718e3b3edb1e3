"""Hostile input, every input answered: each case answers in one line.

Every case runs the command line in a subprocess with a timeout (a hang fails the test
by the timeout, not by a timed assertion) and asserts a non-zero exit, one line on
stderr naming the key, argument or path, no traceback and no output left behind. The
Python API's cases assert a ``RocksweepError`` (or a ``TypeError`` for a wrong type)
and that an existing result is left exactly as it was.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import socket
import subprocess
import sys
import threading
from pathlib import Path

import h5py
import numpy as np
import pytest
from bodies import FIG3_YAML

import rocksweep
from rocksweep.physics.records import at2_text

pytestmark = pytest.mark.faults

ROOT = Path(__file__).resolve().parents[2]
RECORD = ROOT / "records" / "synthetic_nearfault.AT2"
BODY = FIG3_YAML + "impact: {lam: 0.0}\n"
SCENE = ("name: hostile\n" + BODY + "pulse: {shape: sine, w_over_p: {start: 0.5, stop: 6, "
         "num: 4}, A_ratio: {start: 1, stop: 8, num: 4}}\n")
ONE = "name: one\n" + BODY + "pulse: {shape: sine, w_over_p: 2, A_ratio: 4}\n"
TIMEOUT = 60  # [s] a case that takes longer hangs


def run_cli(args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "rocksweep", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=TIMEOUT)


def refused(args: list[str], cwd: Path, *words: str) -> str:
    """Run the CLI; assert exit 1, one line on stderr holding ``words``, no traceback,
    nothing on stdout and no new file in ``cwd``; return the line."""
    before = set(os.listdir(cwd))
    r = run_cli(args, cwd)
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr and r.stdout == "", (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert set(os.listdir(cwd)) == before, set(os.listdir(cwd)) ^ before
    return lines[0]


@pytest.fixture()
def work(tmp_path: Path) -> Path:
    (tmp_path / "s.yaml").write_text(SCENE)
    (tmp_path / "one.yaml").write_text(ONE)
    return tmp_path


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


# --- data loss: every argument before the output is touched -----------------------------

@pytest.fixture(scope="module")
def result(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("result")
    (d / "s.yaml").write_text(SCENE)
    rocksweep.run(str(d / "s.yaml"), output=d / "o.h5")
    return d / "o.h5"


@pytest.mark.parametrize("kw, error, words", [
    ({"jobs": float("nan"), "overwrite": True}, TypeError, "jobs = nan"),
    ({"jobs": "2", "overwrite": True}, TypeError, "jobs = '2'"),
    ({"jobs": None, "overwrite": True}, TypeError, "jobs = None"),
    ({"jobs": 2.5, "overwrite": True}, TypeError, "jobs = 2.5"),
    ({"jobs": 0, "overwrite": True}, rocksweep.RocksweepError, "jobs = 0"),
    ({"validate": True, "overwrite": True}, rocksweep.RocksweepError, "validate=True"),
    ({"validate": True}, rocksweep.RocksweepError, "validate=True"),
    ({"overwrite": "yes"}, TypeError, "overwrite = 'yes'"),
    ({"overwrite": True, "resume": True}, rocksweep.RocksweepError, "exclude"),
    ({"overrides": 5, "overwrite": True}, TypeError, "overrides = 5"),
    ({"overrides": b"impact.lam=1", "overwrite": True}, TypeError, "overrides = b'impact"),
    ({"overrides": [b"impact.lam=1"], "overwrite": True}, TypeError, "KEY=VALUE string"),
    ({"overrides": {"impact.lam": 1j}, "overwrite": True}, rocksweep.RocksweepError, "1j"),
    ({"margin": 9, "adaptive": True, "overwrite": True}, rocksweep.RocksweepError,
     "margin = 9: must be an integer in [0, 8]"),
    ({"seed": 2**70, "adaptive": True, "overwrite": True}, rocksweep.RocksweepError,
     "seed = 1180591620717411303424"),
])
def test_run_refuses_bad_arguments_and_keeps_the_file(result, kw, error, words):
    before = digest(result)
    out = result if "validate" not in kw or kw.get("overwrite") else \
        result.with_name("new.h5")
    with pytest.raises(error) as info:
        rocksweep.run(str(result.with_name("s.yaml")), output=out, **kw)
    assert words in str(info.value) and "\n" not in str(info.value)
    assert digest(result) == before
    assert sorted(p.name for p in result.parent.iterdir()) == ["o.h5", "s.yaml"]


@pytest.mark.parametrize("value", [object(), 1j, {1, 2}])
def test_a_dict_scene_with_a_foreign_value(value):
    scene = {"name": "x", "body": {"kind": "block", "alpha": 0.2},
             "pulse": {"shape": "sine", "w_over_p": 2.0, "A_ratio": value}}
    with pytest.raises(rocksweep.RocksweepError, match=r"scene\['pulse'\]\['A_ratio'\]"):
        rocksweep.run(scene)


@pytest.mark.parametrize("args, words", [
    (["--jobs", "0", "--overwrite"], ["--jobs 0"]),
    (["--adaptive", "--validate", "--margin", "9", "--overwrite"], ["--margin 9"]),
    (["--validate", "--overwrite"], ["--validate"]),
    (["--resume", "--overwrite"], ["--resume and --overwrite"]),
])
def test_cli_refuses_bad_arguments_and_keeps_the_file(work, args, words):
    rocksweep.run(str(work / "s.yaml"), output=work / "o.h5")
    before = digest(work / "o.h5")
    refused(["sweep", "s.yaml", "-o", "o.h5", "-q", *args], work, *words)
    assert digest(work / "o.h5") == before


def test_stale_partial_file_of_a_killed_sweep_is_removed(work):
    stale = work / ".o.h5.999999999-abcd1234.partial"  # no such process
    stale.write_bytes(b"\0" * 100_000)
    live = work / f".o.h5.{os.getpid()}-abcd1234.partial"  # this process: a live writer
    live.write_bytes(b"\0")
    r = run_cli(["sweep", "s.yaml", "-o", "o.h5"], work)
    assert r.returncode == 0, r.stderr
    said = [line for line in r.stderr.splitlines() if "stale" in line]
    assert len(said) == 1 and stale.name in said[0], r.stderr
    assert not stale.exists() and live.exists()


@pytest.mark.parametrize("cmd", [
    ["simulate", "one.yaml", "--plot", "a.png", "--csv", "{abs}/a.png"],
    ["accuracy", "one.yaml", "-o", "x.h5", "--plot", "{abs}/x.h5", "--ladder", "short"],
])
def test_one_file_under_two_spellings(work, cmd):
    refused([c.format(abs=work) for c in cmd], work, "given to both")


# --- hangs --------------------------------------------------------------------------------

def test_fifo_scene_and_fifo_record(work):
    os.mkfifo(work / "scene.fifo")
    refused(["sweep", "scene.fifo", "-o", "o.h5"], work, "scene.fifo", "FIFO")
    os.mkfifo(work / "rec.fifo")
    (work / "r.yaml").write_text("name: r\n" + BODY + "ground: {record: rec.fifo, "
                                 "A_ratio: [1, 2], p: [1, 2]}\n")
    refused(["sweep", "r.yaml", "-o", "o.h5"], work, "ground.record", "rec.fifo", "FIFO")
    with pytest.raises(rocksweep.RocksweepError, match="FIFO"):
        rocksweep.run(str(work / "scene.fifo"))


def test_scheduler_that_accepts_and_never_answers(work):
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    port = srv.getsockname()[1]
    held: list = []
    stop = threading.Event()

    def accept() -> None:
        srv.settimeout(0.2)
        while not stop.is_set():
            try:
                held.append(srv.accept()[0])
            except OSError:
                pass

    t = threading.Thread(target=accept, daemon=True)
    t.start()
    try:
        address = f"tcp://127.0.0.1:{port}"
        refused(["sweep", "s.yaml", "-o", "o.h5", "--backend", "dask", "--scheduler",
                 address, "--connect-timeout", "1"], work, address, "--resume",
                "no dask scheduler answered within 1 s")
    finally:
        stop.set()
        t.join()
        for c in held:
            c.close()
        srv.close()


# --- tracebacks ---------------------------------------------------------------------------

@pytest.mark.parametrize("char", ["\x07", "\x1b", "\x00"])
def test_control_characters_in_yaml_and_set(work, char):
    (work / "c.yaml").write_text(SCENE.replace("name: hostile", f"name: a{char}b"))
    refused(["sweep", "c.yaml", "-o", "o.h5"], work, f"character {ord(char):#04x}")
    if char != "\x00":  # no NUL in an argv
        refused(["sweep", "s.yaml", "-o", "o.h5", "--set", f"name=a{char}b"], work,
                "--set name", f"character {ord(char):#04x}")


def test_nul_inside_name(work):
    (work / "n.yaml").write_text(SCENE.replace("name: hostile", 'name: "a\\0b"'))
    refused(["sweep", "n.yaml", "-o", "o.h5"], work, "name = 'a\\x00b'", "control")


def _bomb(levels: int) -> str:
    items = ["&a [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    for i in range(1, levels + 1):
        items.append(f"&{chr(97 + i)} [" + ", ".join([f"*{chr(96 + i)}"] * 9) + "]")
    return "[" + ", ".join(items) + "]"


@pytest.mark.parametrize("where", ["name: hostile", "w_over_p: {start: 0.5, stop: 6, num: 4}"])
def test_alias_bomb(work, where):
    key = where.split(":")[0]
    (work / "b.yaml").write_text(SCENE.replace(where, f"{key}: {_bomb(10)}"))
    refused(["sweep", "b.yaml", "-o", "o.h5"], work, "expands to more than")
    with pytest.raises(rocksweep.RocksweepError, match="expands to more than"):
        rocksweep.run((work / "b.yaml").read_text())


@pytest.mark.parametrize("args, words", [
    (["sweep", "s.yaml", "-o", "o.h5", "--adaptive", "--seed", str(2**70)], ["--seed"]),
    (["sweep", "s.yaml", "-o", "o.h5", "--adaptive", "--seed", "2147483648"],
     ["--seed 2147483648", "2^31"]),
    (["sweep", "s.yaml", "-o", "o.h5", "--adaptive", "--margin", "9"], ["--margin 9"]),
    (["sweep", "s.yaml", "-o", "o.h5", "--adaptive", "--final-margin", "9"],
     ["--final-margin 9"]),
    (["sweep", "s.yaml", "-o", "o.h5", "--adaptive", "--margin", "1e12"], []),
    (["accuracy", "s.yaml", "--seed", "-1"], ["--seed -1"]),
    (["restitution", "one.yaml", "--n-lam", "100001", "--n-u", "100001"], ["n_lam x n_u"]),
])
def test_options_out_of_range(work, args, words):
    if "1e12" in args:  # not an integer: click's usage error, exit 2
        r = run_cli(args, work)
        assert r.returncode == 2 and "Traceback" not in r.stderr
        return
    refused(args, work, *words)


def test_cli_and_scene_refine_share_one_table(work):
    """The same value is refused with the same reason either way in."""
    line = refused(["sweep", "s.yaml", "-o", "o.h5", "--adaptive", "--margin", "9"], work)
    (work / "r.yaml").write_text(SCENE + "refine: {margin: 9}\n")
    scene_line = refused(["sweep", "r.yaml", "-o", "o.h5"], work, "refine.margin = 9")
    assert line.split(": ", 2)[2] == scene_line.split("= 9: ", 1)[1]


# --- accepted nonsense --------------------------------------------------------------------

@pytest.mark.parametrize("sets, words", [
    (["pulse.gamma=2"], ["pulse.gamma = 2", "mp pulses only", "shape is sine"]),
    (["pulse.nu=30", "pulse.shape=cosine"], ["pulse.nu = 30", "shape is cosine"]),
    (["pulse.cycles=2", "pulse.shape=mp"], ["pulse.cycles = 2", "sine and cosine"]),
    (["pulse.gamma=2", "pulse.shape=[sine, ricker]"], ["shapes are sine, ricker"]),
])
def test_keys_that_mean_nothing_for_the_shape(work, sets, words):
    args = [a for s in sets for a in ("--set", s)]
    refused(["sweep", "s.yaml", "-o", "o.h5", *args], work, *words)


def test_a_key_that_applies_to_one_of_the_swept_shapes_is_accepted():
    sc = rocksweep.run(SCENE.replace("shape: sine", "shape: [sine, mp]") + "\n",
                       overrides={"pulse.gamma": 2.0, "pulse.cycles": 2})
    assert list(sc.shape.values) == ["sine", "mp"]


def test_dotted_axes_are_accepted(work):
    r = run_cli(["sweep", "s.yaml", "-o", "o.h5", "-q", "--adaptive", "--axes",
                 "pulse.w_over_p,pulse.A_ratio"], work)
    assert r.returncode == 0, r.stderr
    assert rocksweep.open(work / "o.h5").attrs["adaptive_axes"] == "w_over_p A_ratio"


def test_output_path_with_a_newline(work):
    line = refused(["sweep", "s.yaml", "-o", "no_dir/a\nb.h5"], work, "a\\nb.h5")
    assert "\n" not in line


@pytest.mark.parametrize("attr, value", [("units", "days since never"),
                                         ("scale_factor", "abc")])
def test_open_a_damaged_variable_attribute(result, tmp_path, attr, value):
    bad = tmp_path / "bad.h5"
    shutil.copy(result, bad)
    with h5py.File(bad, "r+") as f:
        f["t_overturn"].attrs[attr] = value
    with pytest.raises(rocksweep.RocksweepError) as info:
        rocksweep.open(bad)
    assert "damaged" in str(info.value) and "\n" not in str(info.value)


def _record_scene(work: Path, dt: float, npts: int = 81) -> Path:
    t = np.arange(npts) * dt
    (work / "r.AT2").write_text(at2_text(0.3 * np.sin(2 * np.pi * t / (10 * dt)), dt, "r"))
    (work / "r.yaml").write_text("name: r\n" + BODY + "ground: {record: r.AT2, "
                                 "A_ratio: [1, 2], p: [1, 2]}\n")
    return work / "r.yaml"


@pytest.mark.parametrize("dt", ["1e300", "1e-300"])
def test_record_dt_out_of_range_names_dt_and_the_file(work, dt):
    _record_scene(work, 0.01)
    text = (work / "r.AT2").read_text().splitlines()
    text[3] = f"NPTS=    81, DT= {dt} SEC"
    (work / "r.AT2").write_text("\n".join(text) + "\n")
    line = refused(["sweep", "r.yaml", "-o", "o.h5"], work, "r.AT2", "DT = ")
    assert line.index("r.AT2") < line.index("DT = ")


def test_a_short_record_at_100_khz_runs(work):
    _record_scene(work, 1e-5)
    r = run_cli(["sweep", "r.yaml", "-o", "o.h5", "-q"], work)
    assert r.returncode == 0, r.stderr
    assert (rocksweep.open(work / "o.h5").outcome.values >= 0).all()


# --- a result file stands alone -----------------------------------------------------------

def test_a_record_result_moved_to_an_empty_folder(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    shutil.copy(RECORD, src / "rec.AT2")
    (src / "r.yaml").write_text(
        "name: r\n" + BODY + "ground: {record: rec.AT2, A_ratio: {start: 0.5, stop: 6, "
        "num: 5}, p: {start: 0.5, stop: 5, num: 5}}\n")
    r = run_cli(["sweep", "r.yaml", "-o", "r.h5", "-q"], src)
    assert r.returncode == 0, r.stderr
    alone = tmp_path / "alone"
    alone.mkdir()
    shutil.move(src / "r.h5", alone / "r.h5")
    shutil.rmtree(src)
    for args in (["info", "r.h5"], ["plot", "r.h5", "-o", "p.png"],
                 ["boundaries", "r.h5", "-o", "b.csv"], ["spectrum", "r.h5", "-o", "s.png"]):
        r = run_cli(args, alone)
        assert r.returncode == 0, (args, r.stderr)
    assert {"p.png", "b.csv", "s.png"} <= set(os.listdir(alone))
    ds = rocksweep.open(alone / "r.h5")
    assert rocksweep.boundaries(ds).sizes["p"] == 5


def test_simulate_and_open_answer_in_one_line(work):
    os.mkfifo(work / "f.h5")
    cases = [(lambda: rocksweep.simulate(str(work / "one.yaml"), 5), TypeError, "overrides"),
             (lambda: rocksweep.simulate(str(work / "one.yaml"), impact__lam=1j),
              rocksweep.RocksweepError, "impact__lam = 1j"),
             (lambda: rocksweep.simulate(str(work / "one.yaml"), name="a\x07b"),
              rocksweep.RocksweepError, "name = 'a\\x07b'"),
             (lambda: rocksweep.open(work / "f.h5"), rocksweep.RocksweepError, "f.h5")]
    for call, error, words in cases:
        with pytest.raises(error) as info:
            call()
        assert words in str(info.value) and "\n" not in str(info.value), str(info.value)


@pytest.mark.parametrize("args", [["table", "RESULT", "-o", "out.csv"],
                                  ["plot", "RESULT", "-o", "out.png"]])
def test_a_file_made_meanwhile_at_the_output_is_kept(result, tmp_path, monkeypatch, args):
    """The command checks its output, computes, then publishes: a file made at that path
    in between (here: when the command makes its temporary file) is the user's and is
    kept; the command refuses in one line and leaves no temporary file."""
    import tempfile

    from click.testing import CliRunner

    from rocksweep.cli import main

    out = tmp_path / args[-1]
    real = tempfile.mkstemp

    def mkstemp(*a, **k):
        if not out.exists():
            out.write_text("mine")
        return real(*a, **k)

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    r = CliRunner().invoke(main, [str(result) if a == "RESULT" else
                                  str(out) if a == args[-1] else a for a in args])
    assert r.exit_code == 2, r.output
    assert "made by another process meanwhile" in r.output
    assert out.read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]


# --- a refusal is one line, whatever the library warned before it -------------------------

SUITE_DIR = ROOT / "records" / "suite"


def _suite_scene(work: Path, stripes: str) -> Path:
    """A 2-record suite (its records copied next to it) at the PGA ``stripes``."""
    for name in ("SYN01.AT2", "SYN02.AT2"):
        shutil.copy(SUITE_DIR / name, work / name)
    path = work / "suite.yaml"
    path.write_text("name: suite\n" + BODY + "ground:\n  records: [SYN01.AT2, SYN02.AT2]\n"
                    f"  scale: {{im: PGA, values: {stripes}}}\n  p: 2.0\n")
    return path


def test_a_refused_sweep_says_no_warning_of_its_scene_first(work):
    """The scene's records are scaled 100x (a RecordWarning when it is read); the output
    exists: the refusal is one line, and the same scene swept says its warning."""
    scene = _suite_scene(work, "[0.2, 60]")
    (work / "taken.h5").write_bytes(b"x")
    refused(["sweep", scene.name, "-o", "taken.h5"], work, "taken.h5: already exists")
    r = run_cli(["sweep", scene.name, "-o", "new.h5", "--dry-run"], work)
    assert r.returncode == 0, r.stderr
    assert r.stderr.startswith("Warning: ground.scale: 2 of 2 records are scaled by more "
                               "than 5x"), r.stderr


def test_risk_of_a_sweep_refuses_its_hazard_without_the_fits_warning(work):
    """risk of a suite sweep fits the fragility first (no record overturns: a
    no_failures warning); a hazard in another IM is then refused in one line, and a
    good hazard gets the warning before the rates."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rocksweep.run(str(_suite_scene(work, "[0.1, 0.2]")), output=work / "s.h5")
    (work / "pgv.csv").write_text("PGV [m/s],annual_rate\n0.1,1e-2\n1.0,1e-4\n")
    (work / "pga.csv").write_text("PGA [g],annual_rate\n0.1,1e-2\n1.0,1e-4\n")
    refused(["risk", "s.h5", "--hazard", "pgv.csv"], work,
            "pgv.csv: hazard IM PGV [m/s] is not the fragility's IM PGA [g]")
    r = run_cli(["risk", "s.h5", "--hazard", "pga.csv"], work)
    assert r.returncode == 0, r.stderr
    assert r.stderr.strip() == "Warning: fragility, state overturn: no_failures", r.stderr
