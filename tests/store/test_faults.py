"""Fault injection for the result file: nothing lost, no traceback.

Full disks are real: a tmpfs of a few pages mounted in a private mount namespace
(``unshare --mount``, root or user namespaces; nobody else sees it), filled to the last
page. Read-only directories are real too: a read-only bind mount in such a namespace
(chmod does not stop root). Concurrent sweeps are two processes. Failures inside HDF5
that a real disk cannot be made to produce on cue (a flush failing mid-resume, a write
failing mid-sweep) are monkeypatched at the h5py call. Damaged files are ~40 deterministic
copies of one small result: attributes set to {} / null / non-JSON text, coordinates
truncated or changed, variables of the wrong type, seeded byte flips, truncation.

Every case asserts one line naming the file (exact text where it is deterministic), no
traceback, and that the points computed before are still there.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
import sys
import textwrap
import time
from functools import cache
from pathlib import Path

import h5py
import numpy as np
import pytest
from bodies import FIG3_YAML
from helpers import one_line_error

from rocksweep.cli import main
from rocksweep.compute.sweep import level, prepare
from rocksweep.errors import OutputError, StoreError
from rocksweep.fields import plain
from rocksweep.scene.grid import ChunkResult, Grid
from rocksweep.scene.parse import load_scene, parse_scene
from rocksweep.store.format import SESSION_ATTRS
from rocksweep.store.reader import peek_done, read_result
from rocksweep.store.writer import SweepFile

pytestmark = pytest.mark.faults

ROOT = Path(__file__).resolve().parents[2]
CI_SMALL = ROOT / "configs" / "ci-small.yaml"

# 2 x 3 x 4 x 5 = 120 points, synthetic results (no kernel)
TEXT = """name: fault test
""" + FIG3_YAML + """impact: {lam: [0.0, 0.2, 0.4]}
pulse: {shape: [sine, cosine], w_over_p: {start: 0.5, stop: 6, num: 5},
        A_ratio: {start: 1, stop: 8, num: 4}}
"""
SYNTH_DONE = 70  # points of the synthetic partial file computed


def fake_chunk(scene, a: int, b: int) -> ChunkResult:
    """Values that encode the flat index, so misplaced or lost writes show."""
    i = np.arange(a, b)
    arrays = {}
    for name, (dtype, _, _) in scene.variables().items():
        arrays[name] = ((i % 3) if name == "outcome" else i * 7 + len(name)).astype(dtype)
    return ChunkResult(a, b, arrays, 0.0)


def partial_file(path: Path, scene, n_done: int) -> None:
    """A result whose first n_done points (flat order) are computed, as if killed."""
    sf = SweepFile.create(path, scene)
    sf.write(fake_chunk(scene, 0, n_done))
    sf.close()


def one_line(result) -> str:
    """The single line of a failed CLI run: exit 2, no traceback (``one_line_error``)."""
    return one_line_error(result, code=2)


def arrays_of(path: Path) -> dict[str, np.ndarray]:
    """Raw variables straight from h5py (what is on disk, whatever rocksweep says)."""
    with h5py.File(path, "r", locking=False) as f:
        return {k: f[k][()] for k in f if f[k].ndim == 4}


# ---------------------------------------------------------------------------------------
# A private, small file system (real ENOSPC / EROFS)
# ---------------------------------------------------------------------------------------

_PREFIXES = (["unshare", "--mount", "--propagation", "private"],
             ["unshare", "--user", "--map-root-user", "--mount", "--propagation", "private"])


@cache
def _namespace_prefix() -> tuple[str, ...]:
    for prefix in _PREFIXES:
        try:
            r = subprocess.run([*prefix, "sh", "-c", "mount -t tmpfs -o size=8k tmpfs /mnt "
                                "|| mount -t tmpfs -o size=8k tmpfs /tmp"],
                               capture_output=True, timeout=30)
        except (OSError, subprocess.TimeoutExpired):
            continue
        if r.returncode == 0:
            return tuple(prefix)
    pytest.fail("the fault tests need a private mount namespace (run as root, or with "
                "unprivileged user namespaces): `unshare --mount` failed")


FILL = """import os
def fill(d):
    '''Fill the file system of d to its last byte (real ENOSPC from then on).'''
    fd = os.open(os.path.join(d, "filler"), os.O_WRONLY | os.O_CREAT)
    for size in (1 << 16, 4096, 1):
        try:
            while True:
                os.write(fd, b"\\0" * size)
        except OSError:
            pass
    os.close(fd)
"""


def in_namespace(setup: str, script: str, env: dict[str, str], timeout: float = 300
                 ) -> dict:
    """Run ``setup`` (sh, e.g. mounts) then ``python -c script`` in a private mount
    namespace; the script prints one JSON object, returned."""
    cmd = f"{setup} || exit 97\nexec \"{sys.executable}\" -c \"$FAULT_SCRIPT\""
    full_env = {**os.environ, **env, "FAULT_SCRIPT": FILL + textwrap.dedent(script)}
    r = subprocess.run([*_namespace_prefix(), "sh", "-c", cmd], env=full_env,
                       capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, (r.returncode, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


# ---------------------------------------------------------------------------------------
# Full disk
# ---------------------------------------------------------------------------------------

def test_grid_larger_than_the_free_space_is_refused_before_writing(tmp_path):
    fs = tmp_path / "fs"
    fs.mkdir()
    out = in_namespace(f"mount -t tmpfs -o size=256k tmpfs {fs}", f"""
        import os, shutil, subprocess, sys, json
        free = shutil.disk_usage("{fs}").free
        r = subprocess.run([sys.executable, "-m", "rocksweep", "sweep", "{CI_SMALL}",
                            "-o", "{fs}/a.h5", "-q"], capture_output=True, text=True)
        print(json.dumps({{"rc": r.returncode, "err": r.stderr, "out": r.stdout,
                          "free": free, "left": os.listdir("{fs}")}}))
    """, {})
    assert out["rc"] == 2 and out["out"] == "" and out["left"] == []
    lines = out["err"].strip().splitlines()
    assert len(lines) == 1, out["err"]
    # 45 bytes per point (int8 + 3 int32 + 2 float64 + 2 int64) x 256 points, at least
    head = f"Error: {fs}/a.h5: not enough free space for a grid of 256 points: needs about "
    assert lines[0].startswith(head), lines[0]
    need = int(lines[0].split("(")[1].split()[0])
    assert need >= 45 * 256
    assert lines[0].endswith(f" ({need} bytes), {out['free'] / 2**20:.1f} MiB free in {fs}")
    assert need > out["free"]


def test_disk_full_while_the_file_is_made_leaves_nothing_and_no_crash(tmp_path):
    """The free-space check bypassed: HDF5 itself hits ENOSPC while initialising (this
    was three chained tracebacks and a segmentation fault)."""
    fs = tmp_path / "fs"
    fs.mkdir()
    out = in_namespace(f"mount -t tmpfs -o size=24k tmpfs {fs}", f"""
        import os, json
        import rocksweep.store.writer as st
        from rocksweep.scene.parse import load_scene
        st.check_space = lambda *a: None  # as if the disk filled up after the check
        try:
            st.SweepFile.create("{fs}/a.h5", load_scene("{CI_SMALL}"))
            msg = None
        except st.StoreError as err:
            msg = str(err)
        print(json.dumps({{"msg": msg, "left": os.listdir("{fs}")}}))
    """, {})
    assert out["msg"] == f"{fs}/a.h5: cannot write (no space left on the device); nothing " \
                         "written"
    assert out["left"] == []


def test_resume_on_a_full_disk_keeps_the_46_percent_and_finishes(tmp_path, cli):
    """The key end-to-end check: a sweep 46% done, the disk filled to the last byte, then
    `rocksweep sweep --resume`. Before, the metadata update corrupted the file (points
    unreadable, tracebacks in info/plot/--resume). Now the session's attributes are
    rewritten in place, the datasets were allocated at creation, so the resume needs no
    new space: it keeps the 46% and computes the rest, equal to an uninterrupted run."""
    sc = load_scene(CI_SMALL)
    prepare(Grid(sc), level(sc))  # compile here if need be; the subprocesses load the cache
    fs, keep = tmp_path / "fs", tmp_path / "keep"
    fs.mkdir()
    keep.mkdir()
    out = in_namespace(f"mount -t tmpfs -o size=2m tmpfs {fs}", f"""
        import os, shutil, subprocess, sys, json
        from rocksweep.scene.parse import load_scene
        from rocksweep.store.writer import SweepFile
        from rocksweep.compute.sweep import level, run_chunk
        sc = load_scene("{CI_SMALL}")
        path = "{fs}/a.h5"
        sf = SweepFile.create(path, sc, backend="test")
        n = round(0.46 * sf.grid.size)
        sf.write(run_chunk(sf.grid, 0, n, level(sc)))
        sf.close()
        shutil.copy(path, "{keep}/before.h5")
        fill("{fs}")
        free = shutil.disk_usage("{fs}").free
        r = subprocess.run([sys.executable, "-m", "rocksweep", "sweep", "{CI_SMALL}", "-o",
                            path, "--resume", "-j", "1", "-q"], capture_output=True,
                           text=True)
        shutil.copy(path, "{keep}/after.h5")
        print(json.dumps({{"n": n, "free": free, "rc": r.returncode, "err": r.stderr}}))
    """, {})
    assert out["free"] == 0  # really full
    assert out["rc"] == 0 and "Traceback" not in out["err"], out["err"]
    before, after = read_result(keep / "before.h5"), read_result(keep / "after.h5")
    n = out["n"]
    assert n == 118 and int(before.done.sum()) == n  # 46% of 256
    assert after.done.all() and after.attrs["complete"] == 1 and after.attrs["sessions"] == 2
    for name, arr in before.arrays.items():  # the 46% kept, bit for bit
        np.testing.assert_array_equal(after.arrays[name].reshape(-1)[:n],
                                      arr.reshape(-1)[:n], err_msg=name)
    whole = tmp_path / "whole.h5"
    res = cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(whole), "-q", "-j", "1"])
    assert res.exit_code == 0, res.output
    ref = read_result(whole)
    for name, arr in ref.arrays.items():
        np.testing.assert_array_equal(after.arrays[name], arr, err_msg=name)
    res = cli.invoke(main, ["info", str(keep / "after.h5")])
    assert res.exit_code == 0 and "256 of 256 done" in res.output, res.output


def _as_format_1(path: Path) -> None:
    """Give a file the attributes of format 1 (variable-length strings, HDF5 bools,
    no history/host/backend), as the first release wrote them."""
    with h5py.File(path, "r+") as f:
        a = f.attrs
        for name in SESSION_ATTRS:
            v = plain(a[name])
            del a[name]
            if name in ("history", "host", "backend"):
                continue
            a[name] = bool(v) if name == "complete" else v
        a["format_version"] = 1
        a["energy"] = False


def test_resume_of_a_format_1_file_on_a_full_disk_is_one_line_and_changes_nothing(
        tmp_path):
    """A file of the first format must change its attributes' types once (new space):
    on a full disk that is refused up front, the file left byte for byte as it was."""
    sc = parse_scene(TEXT)
    src = tmp_path / "v1.h5"
    partial_file(src, sc, SYNTH_DONE)
    _as_format_1(src)
    fs = tmp_path / "fs"
    fs.mkdir()
    out = in_namespace(f"mount -t tmpfs -o size=1m tmpfs {fs}", f"""
        import os, shutil, json, hashlib
        from rocksweep.scene.parse import parse_scene
        from rocksweep.errors import StoreError
        from rocksweep.store.writer import SweepFile
        path = "{fs}/v1.h5"
        shutil.copy("{src}", path)
        fill("{fs}")
        try:
            SweepFile.resume(path, parse_scene({TEXT!r}))
            msg = None
        except StoreError as err:
            msg = str(err)
        same = open(path, "rb").read() == open("{src}", "rb").read()
        print(json.dumps({{"msg": msg, "same": same}}))
    """, {})
    assert out["msg"] == (f"{fs}/v1.h5: not enough free space for updating its attributes: "
                          f"needs about 1.0 MiB (1048576 bytes), 0.0 MiB free in {fs}")
    assert out["same"]
    # with space, the same file resumes and keeps its points
    sf = SweepFile.resume(src, sc)
    sf.finish(0.0, 0.0)
    sf.close()
    r = read_result(src)
    assert int(r.done.sum()) == SYNTH_DONE and r.attrs["sessions"] == 2
    np.testing.assert_array_equal(r.arrays["impacts"].reshape(-1)[:SYNTH_DONE],
                                  fake_chunk(sc, 0, SYNTH_DONE).arrays["impacts"])


def _enospc_flush(self):
    raise RuntimeError("Unable to synchronously flush file (file write failed: time = ..., "
                       "filename = 'x', file descriptor = 3, errno = 28, error message = "
                       "'No space left on device', buf = 0x0, total write size = 628)")


def test_metadata_update_failing_on_resume_is_one_line_and_keeps_points(
        tmp_path, monkeypatch, cli):
    """HDF5 failing to flush the session's attributes (as it did on a full disk): one
    line; the points, the scene and the file's readability are intact."""
    sc = parse_scene(TEXT)
    path = tmp_path / "r.h5"
    partial_file(path, sc, SYNTH_DONE)
    before = arrays_of(path)
    with monkeypatch.context() as m:
        m.setattr(h5py.File, "flush", _enospc_flush)
        with pytest.raises(StoreError) as err:
            SweepFile.resume(path, sc)
    assert str(err.value) == (f"{path}: cannot update its attributes (no space left on the "
                              "device); its points are kept")
    r = read_result(path)
    assert int(r.done.sum()) == SYNTH_DONE
    for name, arr in before.items():
        np.testing.assert_array_equal(r.arrays[name], arr, err_msg=name)
    res = cli.invoke(main, ["info", str(path)])
    assert res.exit_code == 0 and f"{SYNTH_DONE} of 120 done" in res.output, res.output


def test_room_to_create_but_not_to_open_leaves_no_file(tmp_path, monkeypatch):
    """The file is complete and its session recorded before it gets its name: a failure
    there leaves neither the file nor a temporary (was: a corrupt file later called
    "not a rocksweep result")."""
    sc = parse_scene(TEXT)
    path = tmp_path / "r.h5"
    calls = {"n": 0}
    real = h5py.File.flush

    def flush_then_fail(self):
        calls["n"] += 1
        if calls["n"] > 1:  # the first flush (initialisation) works
            _enospc_flush(self)
        real(self)

    monkeypatch.setattr(h5py.File, "flush", flush_then_fail)
    with pytest.raises(StoreError) as err:
        SweepFile.create(path, sc)
    assert str(err.value) == (f"{path}: cannot write (no space left on the device); "
                              "nothing written")
    assert list(tmp_path.iterdir()) == []


def test_disk_full_mid_sweep_is_one_line_and_keeps_written_chunks(tmp_path, monkeypatch,
                                                                 cli):
    """A write failing in the 4th chunk (a full disk on a file system that allocates
    lazily): `rocksweep sweep` prints one line and exits 1; the 3 chunks written before
    are in the file, and --resume finishes it equal to an uninterrupted run."""
    sc = load_scene(CI_SMALL)
    prepare(Grid(sc), level(sc))
    path = tmp_path / "r.h5"
    real = h5py.Dataset.__setitem__
    outcome_writes = {"n": 0}

    def setitem(self, index, value):
        name = self.name.lstrip("/")
        if name == "impacts" and outcome_writes["n"] >= 3:
            raise OSError(28, "No space left on device")
        if name == "outcome" and not np.all(np.asarray(value) == -1):
            outcome_writes["n"] += 1
        real(self, index, value)

    with monkeypatch.context() as m:
        m.setattr(h5py.Dataset, "__setitem__", setitem)
        res = cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(path), "-q", "-j", "1",
                                "--chunk-size", "16", "--write-every", "0"])
    assert one_line(res) == (f"Error: {path}: cannot write results (no space left on the "
                             "device); the points written before are kept, finish with "
                             "--resume")
    r = read_result(path)
    assert np.flatnonzero(r.done.reshape(-1)).tolist() == list(range(48))
    res = cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(path), "-q", "-j", "1",
                            "--resume"])
    assert res.exit_code == 0, res.output
    whole = tmp_path / "whole.h5"
    assert cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(whole), "-q", "-j", "1"]
                      ).exit_code == 0
    a, b = read_result(path), read_result(whole)
    for name in b.arrays:
        np.testing.assert_array_equal(a.arrays[name], b.arrays[name], err_msg=name)


# ---------------------------------------------------------------------------------------
# Paths that are not regular files, read-only and missing directories
# ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("minor", [3, 7])  # /dev/null, /dev/full
def test_device_paths_are_refused_even_with_overwrite(minor, device_node, cli):
    dev = device_node(f"dev{minor}.h5", minor)
    before = os.stat(dev)
    msg = (f"{dev}: not a regular file (a device, FIFO or socket); outputs are written to "
           "regular files only")
    with pytest.raises(OutputError) as err:  # an output path's problem, as from run
        SweepFile.create(dev, parse_scene(TEXT), overwrite=True)
    assert str(err.value) == msg
    assert one_line(cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(dev), "--overwrite"])) \
        == f"Error: {msg}"
    after = os.stat(dev)
    assert stat.S_ISCHR(after.st_mode) and after.st_rdev == before.st_rdev


def test_fifo_is_refused(tmp_path):
    fifo = tmp_path / "pipe.h5"
    os.mkfifo(fifo)
    with pytest.raises(OutputError) as err:
        SweepFile.create(fifo, parse_scene(TEXT), overwrite=True)
    assert str(err.value) == (f"{fifo}: not a regular file (a device, FIFO or socket); "
                              "outputs are written to regular files only")
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe.h5"]


def test_missing_directory(tmp_path, cli):
    path = tmp_path / "nope" / "r.h5"
    with pytest.raises(OutputError) as err:
        SweepFile.create(path, parse_scene(TEXT))
    assert str(err.value) == f"{path}: directory {path.parent} does not exist"
    assert one_line(cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(path)])) == \
        f"Error: {path}: directory {path.parent} does not exist"
    assert not path.parent.exists()


def test_read_only_directory_really_read_only(tmp_path):
    """A read-only bind mount (root ignores chmod): creating, resuming and the cleanup
    after a failed temporary file each give one line; the existing result is intact."""
    sc = parse_scene(TEXT)
    ro = tmp_path / "ro"
    ro.mkdir()
    partial_file(ro / "old.h5", sc, SYNTH_DONE)
    before = arrays_of(ro / "old.h5")
    out = in_namespace(f"mount --bind {ro} {ro} && mount -o remount,bind,ro {ro}", f"""
        import json, os, subprocess, sys
        import rocksweep.store.writer as st
        from rocksweep.errors import RocksweepError
        from rocksweep.scene.parse import parse_scene
        sc = parse_scene({TEXT!r})
        msgs = {{}}
        for key, call in [
                ("create", lambda: st.SweepFile.create("{ro}/new.h5", sc)),
                ("resume", lambda: st.SweepFile.resume("{ro}/old.h5", sc))]:
            try:
                call()
                msgs[key] = None
            except RocksweepError as err:  # OutputError (create), StoreError (resume)
                msgs[key] = str(err)
        st.check_output = lambda *a, **k: None  # past the check: mkstemp itself fails
        try:
            st.SweepFile.create("{ro}/new.h5", sc)
        except st.StoreError as err:
            msgs["mkstemp"] = str(err)
        r = subprocess.run([sys.executable, "-m", "rocksweep", "sweep", "{CI_SMALL}", "-o",
                            "{ro}/cli.h5"], capture_output=True, text=True)
        msgs["cli"] = r.stderr
        msgs["rc"] = r.returncode
        print(json.dumps(msgs))
    """, {})
    assert out["create"] == f"{ro}/new.h5: directory {ro} is not writable"
    assert out["resume"] == (f"{ro}/old.h5: cannot be written (permission denied "
                             "(read-only location?))")
    assert out["mkstemp"] == (f"{ro}/new.h5: cannot write (permission denied (read-only "
                              "location?)); nothing written")
    assert out["rc"] == 2 and out["cli"] == f"Error: {ro}/cli.h5: directory {ro} is not " \
                                            "writable\n"
    assert sorted(p.name for p in ro.iterdir()) == ["old.h5"]
    after = arrays_of(ro / "old.h5")
    for name, arr in before.items():
        np.testing.assert_array_equal(after[name], arr, err_msg=name)


# ---------------------------------------------------------------------------------------
# Two processes on one path
# ---------------------------------------------------------------------------------------

# fake_chunk for the scripts of other processes (they import rocksweep only)
FAKE_CHUNK = """
import numpy as np
from rocksweep.scene.grid import ChunkResult
def fake_chunk(scene, a, b):
    i = np.arange(a, b)
    return ChunkResult(a, b, {n: ((i % 3) if n == "outcome" else i * 7 + len(n)).astype(d)
                              for n, (d, _, _) in scene.variables().items()}, 0.0)
"""

HOLDER = FAKE_CHUNK + """
import sys
from rocksweep.scene.parse import parse_scene
from rocksweep.store.writer import SweepFile
sc = parse_scene(@TEXT@)
sf = SweepFile.@HOW@
print("holding", flush=True)
sys.stdin.readline()  # the other process tries its luck meanwhile
sf.write(fake_chunk(sc, 0, sf.grid.size))
sf.finish(1.0, 1.0)
sf.close()
print("done", flush=True)
"""


def _hold(path: Path, how: str) -> subprocess.Popen:
    code = HOLDER.replace("@TEXT@", repr(TEXT)).replace("@HOW@", how)
    proc = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "holding", proc.stderr.read()
    return proc


def _release(proc: subprocess.Popen) -> None:
    out, err = proc.communicate("go\n", timeout=120)
    assert proc.returncode == 0 and out.strip() == "done", (out, err)


@pytest.mark.parametrize("how", ["create(path, sc)", "resume(path, sc)"])
def test_overwrite_and_resume_refused_while_another_process_writes(tmp_path, cli, how):
    """A sweep holds the file (just made, or resumed); `--overwrite` and `--resume` from
    another process are refused in one line and the holder's work survives (before,
    --overwrite replaced the file under it and both exited 0)."""
    sc = parse_scene(TEXT)
    path = tmp_path / "r.h5"
    scene_file = tmp_path / "s.yaml"
    scene_file.write_text(TEXT)
    if how.startswith("resume"):
        partial_file(path, sc, SYNTH_DONE)
    proc = _hold(path, how.replace("path", repr(str(path))))
    try:
        inode = os.stat(path).st_ino
        busy = f"{path}: open for writing by another process (a sweep still running?)"
        assert one_line(cli.invoke(main, ["sweep", str(scene_file), "-o", str(path),
                                          "--overwrite", "-q"])) == \
            f"Error: {busy}; not overwritten"
        assert one_line(cli.invoke(main, ["sweep", str(scene_file), "-o", str(path),
                                          "--resume", "-q"])) == f"Error: {busy}"
        with pytest.raises(StoreError, match="open for writing by another process"):
            SweepFile.create(path, sc, overwrite=True)
        assert os.stat(path).st_ino == inode
        assert peek_done(path)[1] == 120  # readers do not wait for the writer
    finally:
        _release(proc)
    r = read_result(path)
    assert r.done.all() and r.attrs["complete"] == 1
    np.testing.assert_array_equal(r.arrays["impacts"].reshape(-1),
                                  fake_chunk(sc, 0, 120).arrays["impacts"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5", "s.yaml"]
    # once it is done, --overwrite replaces it
    res = cli.invoke(main, ["sweep", str(CI_SMALL), "-o", str(path), "--overwrite", "-q",
                            "-j", "1"])
    assert res.exit_code == 0, res.output


RACER = FAKE_CHUNK + """
import json, sys, time
from rocksweep.scene.parse import parse_scene
from rocksweep.errors import RocksweepError
from rocksweep.store.writer import SweepFile
sc = parse_scene(@TEXT@)
while time.time() < @START@:
    pass
try:
    sf = SweepFile.create(@PATH@, sc, overwrite=@OVERWRITE@)
except RocksweepError as err:  # OutputError (made meanwhile), StoreError (locked)
    print(json.dumps({"error": str(err)}))
    sys.exit(0)
time.sleep(0.5)  # a sweep: the other one must not take the path meanwhile
sf.write(fake_chunk(sc, 0, sf.grid.size))
sf.finish(0.0, 0.0)
sf.close()
print(json.dumps({"error": None}))
"""


@pytest.mark.parametrize("overwrite", [False, True])
def test_two_sweeps_started_at_the_same_instant(tmp_path, overwrite):
    """Two processes create one path at the same instant (3 rounds): exactly one gets
    it, the other a one-line error; no temporary file is shared or left behind, and the
    file is the winner's, complete (before: a shared temporary name, each deleting the
    other's file)."""
    path = tmp_path / "r.h5"
    for k in range(3):
        if path.exists() and not overwrite:
            path.unlink()
        start = time.time() + 2.0  # both have imported rocksweep by then
        code = (RACER.replace("@TEXT@", repr(TEXT)).replace("@START@", repr(start))
                .replace("@PATH@", repr(str(path))).replace("@OVERWRITE@", repr(overwrite)))
        procs = [subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True) for _ in range(2)]
        outs = [p.communicate(timeout=120) for p in procs]
        for p, (o, e) in zip(procs, outs, strict=True):
            assert p.returncode == 0 and "Traceback" not in e, (k, o, e)
        errors = [json.loads(o)["error"] for o, _ in outs]
        assert errors.count(None) == 1, (k, errors)
        msg = next(e for e in errors if e)
        assert msg in (
            f"{path}: already exists; use --resume to finish it or --overwrite to replace it",
            f"{path}: made by another process meanwhile (the same command started at the "
            "same time?); not overwritten",
            f"{path}: open for writing by another process (a sweep still running?); not "
            "overwritten",
            f"{path}: replaced by another process meanwhile; not overwritten"), (k, msg)
        assert [p.name for p in tmp_path.iterdir()] == ["r.h5"], k
        r = read_result(path)
        assert r.done.all(), k


# ---------------------------------------------------------------------------------------
# Damaged files that are still HDF5 (and some that are not)
# ---------------------------------------------------------------------------------------

def _set_attr(name, value):
    def damage(f):
        if name in f.attrs:
            del f.attrs[name]
        f.attrs[name] = value
    return damage


def _replace_dataset(name, data):
    def damage(f):
        del f[name]
        f[name] = data
    return damage


def _set_point(name, index, value):
    def damage(f):
        f[name][index] = value
    return damage


def _retype(name, dtype):
    def damage(f):
        data = f[name][()]
        del f[name]
        f[name] = data.astype(dtype)
    return damage


D = "damaged rocksweep result"
ATTRIBUTE_CASES = {
    # attribute damage: exact messages
    "scene_resolved={}": (_set_attr("scene_resolved", "{}"),
                          f"{D} (attribute scene_resolved: 'name' is None, not a str)"),
    "scene_resolved=null": (_set_attr("scene_resolved", "null"),
                            f"{D} (attribute scene_resolved: None is not a JSON object)"),
    "scene_resolved=text": (_set_attr("scene_resolved", "not json"),
                            f"{D} (attribute scene_resolved is not JSON: 'not json')"),
    "scene_resolved axes": (_set_attr("scene_resolved", json.dumps(
        {"name": "x", "kind": "flexible", "energy": False, "numerics": {},
         "axes": {"impact.lam": {"values": [], "swept": True}}})),
        f"{D} (attribute scene_resolved: axis 'impact.lam' is {{'values': [], 'swept': "
        "True})"),
    "scene_resolved missing": (lambda f: f.attrs.__delitem__("scene_resolved"),
                               f"{D} (attribute scene_resolved missing)"),
    "numerics=null": (_set_attr("numerics", "null"),
                      f"{D} (attribute numerics is 'null', not a JSON object)"),
    "numerics=text": (_set_attr("numerics", "not json"),
                      f"{D} (attribute numerics is not JSON: 'not json')"),
    "overrides={}": (_set_attr("overrides", "{}"),
                     f"{D} (attribute overrides is '{{}}', not a JSON list)"),
    "overrides=null": (_set_attr("overrides", "null"),
                       f"{D} (attribute overrides is 'null', not a JSON list)"),
    "overrides=text": (_set_attr("overrides", "not json"),
                       f"{D} (attribute overrides is not JSON: 'not json')"),
    "wall_time={}": (_set_attr("wall_time", "{}"), f"{D} (attribute wall_time is '{{}}')"),
    "sessions=null": (_set_attr("sessions", "null"), f"{D} (attribute sessions is 'null')"),
    "energy=text": (_set_attr("energy", "not json"), f"{D} (attribute energy is 'not json')"),
    "complete=7": (_set_attr("complete", np.int8(7)), f"{D} (attribute complete is 7)"),
    "scene=1.5": (_set_attr("scene", 1.5), f"{D} (attribute scene is 1.5)"),
    "format_version=null": (_set_attr("format_version", "null"),
                            f"{D} (format_version = 'null')"),
    "rocksweep_format={}": (_set_attr("rocksweep_format", "{}"),
                            f"{D} (attribute rocksweep_format is '{{}}')"),
    # coordinates and variables
    "lam truncated": (_replace_dataset("lam", np.array([0.0, 0.2])),
                      f"{D} (coordinate 'lam' has shape (2,), the scene 3 values)"),
    "A_ratio changed": (_replace_dataset("A_ratio", np.array([1.0, 2.0, 3.0, 4.0])),
                        f"{D} (coordinate 'A_ratio' holds [1.0, 2.0, 3.0, 4.0], the scene "
                        "[1.0, 3.3333333333333335, 5.666666666...)"),
    "shape as numbers": (_replace_dataset("shape", np.array([1.0, 2.0])),
                         f"{D} (coordinate 'shape' holds [1.0, 2.0], the scene ['sine', "
                         "'cosine'])"),
    "impacts missing": (lambda f: f.__delitem__("impacts"),
                        f"{D} (variable 'impacts' missing)"),
    "outcome as int32": (_retype("outcome", np.int32),
                         f"{D} (variable 'outcome' has dtype int32, expected int8)"),
    "outcome code 7": (_set_point("outcome", (1, 2, 3, 4), 7),
                       f"{D} (variable 'outcome' holds 1 invalid codes, e.g. 7 (valid: -1, "
                       "0, 1, 2))"),
}
FLIP_SEEDS = list(range(15))


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory) -> Path:
    """A small result, 70 of its 120 points computed."""
    path = tmp_path_factory.mktemp("base") / "base.h5"
    partial_file(path, parse_scene(TEXT), SYNTH_DONE)
    return path


@pytest.mark.parametrize("case", list(ATTRIBUTE_CASES))
def test_damaged_attributes_coordinates_variables(synthetic, tmp_path, cli, case):
    damage, what = ATTRIBUTE_CASES[case]
    path = tmp_path / "d.h5"
    shutil.copy(synthetic, path)
    with h5py.File(path, "r+") as f:
        damage(f)
    for cmd in (["info", str(path)], ["info", "--json", str(path)],
                ["plot", str(path), "-o", str(tmp_path / "f.png")],
                ["sweep", str(tmp_path / "s.yaml"), "-o", str(path), "--resume"]):
        (tmp_path / "s.yaml").write_text(TEXT)
        assert one_line(cli.invoke(main, cmd)) == f"Error: {path}: {what}", cmd
    with pytest.raises(StoreError) as err:
        peek_done(path) or read_result(path)
    assert str(err.value) == f"{path}: {what}"
    # reporting did not write: the points are on disk as before
    if "outcome" not in case and "impacts" not in case:
        raw = arrays_of(path)
        assert int((raw["outcome"] >= 0).sum()) == SYNTH_DONE
    assert not (tmp_path / "f.png").exists()


@pytest.mark.parametrize("seed", FLIP_SEEDS)
def test_random_byte_flips(synthetic, tmp_path, cli, seed):
    """Four bytes flipped at seeded offsets: `info` either reads the file or says in one
    line what is wrong with it; never a traceback or a crash."""
    data = bytearray(synthetic.read_bytes())
    rng = np.random.default_rng(1600 + seed)
    for off in rng.integers(0, len(data), 4):
        data[off] ^= 0xFF
    path = tmp_path / "flip.h5"
    path.write_bytes(bytes(data))
    res = cli.invoke(main, ["info", str(path)])
    if res.exit_code == 0:
        assert "of 120 done" in res.output, res.output
    else:
        line = one_line(res)
        assert line.startswith(f"Error: {path}: ") and any(
            w in line for w in ("damaged", "not an HDF5 file")), line


@pytest.mark.parametrize("keep", [0, 100, 2000, 0.5])
def test_truncated_files(synthetic, tmp_path, cli, keep):
    data = synthetic.read_bytes()
    n = int(len(data) * keep) if isinstance(keep, float) else keep
    path = tmp_path / "t.h5"
    path.write_bytes(data[:n])
    line = one_line(cli.invoke(main, ["info", str(path)]))
    want = {0: "empty file (expected a rocksweep sweep result)",
            100: "damaged or truncated HDF5 file, cannot be opened ("}
    if n in want:
        assert line.startswith(f"Error: {path}: {want[n]}"), line
        # the remedy for a file that may hold results is never to write over it
        assert "overwrite" not in line, line
    else:
        assert line.startswith(f"Error: {path}: damaged"), line
