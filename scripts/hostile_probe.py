"""Hostile probe of issue 32: every case of the issue (except the fragility/IDA argument
errors), run against the command line or the Python API in a fresh directory.

    python scripts/hostile_probe.py            # every case
    python scripts/hostile_probe.py -k 'listing|lock'  # the cases whose name holds one
    python scripts/hostile_probe.py -v         # also print each case's answer

Each case is classified:
- ok: it worked as it should (exit 0, or the expected result);
- clean: refused in one line (``Error: ...`` and a non-zero exit, or a one-line
  RocksweepError), nothing written, every input intact;
- dataloss: an input file changed or vanished;
- traceback: a traceback, a warning or several lines, a hang (timeout), or a refusal
  where the case must work (reported as such).
The counts are printed last; the exit status is 1 if any case is neither ok nor clean.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SUITE_DIR = ROOT / "records" / "suite"
TIMEOUT = 120  # [s] longer is a hang

BODY = ("body: {wn_over_p: 2.43, zeta: 0.05, alpha_cg: 0.15, alpha_A: 0.28, mA_over_m: 0.47, "
        "IA_ratio: 0.56}\nimpact: {lam: 0.0}\n")
PULSE = "name: pulse\n" + BODY + "pulse: {shape: sine, w_over_p: [1, 2], A_ratio: [2, 4]}\n"


def suite_scene(records: str, name: str = "suite") -> str:
    return (f"name: {name}\n" + BODY + f"ground:\n  records: {records}\n"
            "  scale: {im: PGA, values: [0.2, 0.6]}\n  p: 2.0\n  periods: [0.5]\n")


def record_scene(record: str, name: str = "one") -> str:
    return (f"name: {name}\n" + BODY + f"ground: {{record: {record}, A_ratio: [1, 3], "
            "p: [1.0, 2.0]}\n")


def two_column(src: Path) -> str:
    """A two-column copy (t [s], a [g]) of an AT2 record (its first 1000 samples)."""
    sys.path.insert(0, str(ROOT))
    from rocksweep.physics.records import read_record

    r = read_record(src)
    return "".join(f"{i * r.dt:.4f} {a:.7e}\n" for i, a in enumerate(r.acc[:1000]))


def setup(d: Path) -> None:
    """The fixture files every case starts from."""
    (d / "r").mkdir()
    for i in (1, 2):
        shutil.copy(SUITE_DIR / f"SYN0{i}.AT2", d / "r" / f"SYN0{i}.AT2")
    shutil.copy(SUITE_DIR / "SYN03.AT2", d / "rec.AT2")
    (d / "rec.csv").write_text(two_column(SUITE_DIR / "SYN04.AT2"))
    (d / "csvr").mkdir()
    (d / "csvr" / "a.csv").write_text(two_column(SUITE_DIR / "SYN05.AT2"))
    (d / "csvr" / "b.csv").write_text(two_column(SUITE_DIR / "SYN06.AT2"))
    (d / "recpng.png").write_text(two_column(SUITE_DIR / "SYN07.AT2"))
    (d / "suite.txt").write_text("r/SYN01.AT2\nr/SYN02.AT2\n")
    (d / "suite.yaml").write_text(suite_scene("r/*.AT2"))
    (d / "suitelist.yaml").write_text(suite_scene("suite.txt"))
    (d / "csvsuite.yaml").write_text(suite_scene("csvr/*.csv"))
    (d / "one.yaml").write_text(record_scene("rec.AT2"))
    (d / "csv.yaml").write_text(record_scene("rec.csv"))
    (d / "png.yaml").write_text(record_scene("recpng.png"))
    (d / "pulse.yaml").write_text(PULSE)


def snapshot(d: Path) -> dict[str, str]:
    out = {}
    for p in d.rglob("*"):
        if p.is_file() and not p.is_symlink():
            out[str(p.relative_to(d))] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def cli(d: Path, args: list[str], env: dict | None = None) -> subprocess.CompletedProcess:
    freeze(d)
    e = {**os.environ, "PYTHONPATH": str(ROOT), **(env or {})}
    return subprocess.run([sys.executable, "-m", "rocksweep", *args], cwd=d, env=e,
                          capture_output=True, text=True, timeout=TIMEOUT)


def py(d: Path, code: str) -> subprocess.CompletedProcess:
    """Python code run in ``d``; it prints 'OK' when it worked, or the error's class and
    message (one line) when the library refused."""
    prog = ("import sys, rocksweep\n"
            "try:\n" + textwrap.indent(textwrap.dedent(code), "    ") +
            "\nexcept rocksweep.RocksweepError as err:\n"
            "    print('REFUSED', type(err).__name__, str(err).replace(chr(10), ' '))\n"
            "    sys.exit(1)\n")
    freeze(d)
    e = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-c", prog], cwd=d, env=e, capture_output=True,
                          text=True, timeout=TIMEOUT)


CASES: list[tuple[str, str, object]] = []  # (name, expected 'ok'|'clean', function)
FROZEN: dict[str, str] = {}  # the inputs of the running case (``freeze``)


def freeze(d: Path) -> None:
    """The case's inputs are now what is in ``d`` (every command a case runs calls this:
    the last command's inputs are the ones checked)."""
    FROZEN.clear()
    FROZEN.update(snapshot(d))


def case(name: str, expect: str = "clean"):
    def deco(fn):
        CASES.append((name, expect, fn))
        return fn
    return deco


# --- data loss: an output that is an input ------------------------------------------------

@case("dataloss: sweep suite -o one of its records")
def _(d):
    return cli(d, ["sweep", "suite.yaml", "-o", "r/SYN01.AT2", "--overwrite", "-q"])


@case("dataloss: sweep suite -o its listing")
def _(d):
    return cli(d, ["sweep", "suitelist.yaml", "-o", "suite.txt", "--overwrite", "-q"])


@case("dataloss: sweep record scene -o its record")
def _(d):
    return cli(d, ["sweep", "one.yaml", "-o", "rec.AT2", "--overwrite", "-q"])


@case("dataloss: sweep -o the record through '..'")
def _(d):
    return cli(d, ["sweep", "one.yaml", "-o", "r/../rec.AT2", "--overwrite", "-q"])


@case("dataloss: sweep -o a symbolic link to the record")
def _(d):
    os.symlink("rec.AT2", d / "link.AT2")
    return cli(d, ["sweep", "one.yaml", "-o", "link.AT2", "--overwrite", "-q"])


@case("dataloss: sweep -o a hard link to a suite record")
def _(d):
    os.link(d / "r" / "SYN02.AT2", d / "hard.h5")
    return cli(d, ["sweep", "suite.yaml", "-o", "hard.h5", "--overwrite", "-q"])


@case("dataloss: sweep --resume -o the record")
def _(d):
    return cli(d, ["sweep", "one.yaml", "-o", "rec.AT2", "--resume", "-q"])


@case("dataloss: simulate --csv its two-column record")
def _(d):
    return cli(d, ["simulate", "csv.yaml", "--set", "ground.A_ratio=2", "--set",
                   "ground.p=2", "--csv", "rec.csv", "--overwrite"])


@case("dataloss: simulate --plot its record (named .png)")
def _(d):
    return cli(d, ["simulate", "png.yaml", "--set", "ground.A_ratio=2", "--set",
                   "ground.p=2", "--plot", "recpng.png", "--overwrite"])


@case("dataloss: restitution --plot the scene's record")
def _(d):
    return cli(d, ["restitution", "png.yaml", "--plot", "recpng.png", "--overwrite"])


@case("dataloss: accuracy -o the scene's record")
def _(d):
    return cli(d, ["accuracy", "csv.yaml", "--points", "2", "--ladder", "short", "-o",
                   "rec.csv", "--overwrite"])


@case("dataloss: boundaries -o the result's record")
def _(d):
    r = cli(d, ["sweep", "csv.yaml", "-o", "c.h5", "-q"])
    if r.returncode:
        return r
    return cli(d, ["boundaries", "c.h5", "-o", "rec.csv", "--overwrite"])


@case("dataloss: fragility -o one of the suite's records")
def _(d):
    r = cli(d, ["sweep", "csvsuite.yaml", "-o", "cs.h5", "-q"])
    if r.returncode:
        return r
    return cli(d, ["fragility", "cs.h5", "-o", "csvr/a.csv", "--overwrite"])


@case("dataloss: run(output=its record, overwrite=True)")
def _(d):
    return py(d, "rocksweep.run('one.yaml', output='rec.AT2', overwrite=True)")


@case("dataloss: run(dict scene, output=its record, overwrite=True)")
def _(d):
    return py(d, """
        import yaml
        sc = yaml.safe_load(open('one.yaml'))
        sc['ground']['record'] = str(__import__('pathlib').Path('rec.AT2').resolve())
        rocksweep.run(sc, output='rec.AT2', overwrite=True)""")


@case("dataloss: run(suite, output=its listing, overwrite=True)")
def _(d):
    return py(d, "rocksweep.run('suitelist.yaml', output='suite.txt', overwrite=True)")


# --- a good file called damaged -----------------------------------------------------------

@case("lock: open() while xarray holds the file open", "any")
def _(d):
    r = cli(d, ["sweep", "pulse.yaml", "-o", "p.h5", "-q"])
    if r.returncode:
        return r
    r = py(d, """
        import xarray as xr
        ds = xr.open_dataset('p.h5', engine='h5netcdf')
        rocksweep.open('p.h5')""")
    if ("damaged" in r.stdout.replace("not damaged", "") or "overwrite" in r.stdout
            or (r.returncode and "lock" not in r.stdout.lower())):
        r.stdout = "WRONG WORDS " + r.stdout
        r.returncode = 99
    return r


@case("lock: run(resume=True) while xarray holds the file open")
def _(d):
    r = cli(d, ["sweep", "pulse.yaml", "-o", "p.h5", "-q"])
    if r.returncode:
        return r
    r = py(d, """
        import xarray as xr
        ds = xr.open_dataset('p.h5', engine='h5netcdf')
        rocksweep.run('pulse.yaml', output='p.h5', resume=True)""")
    if "damaged" in r.stdout.replace("not damaged", "") or "overwrite" in r.stdout:
        r.stdout = "WRONG WORDS " + r.stdout
        r.returncode = 99
    return r


@case("lock: a truncated file with results: no overwrite as the first remedy")
def _(d):
    r = cli(d, ["sweep", "pulse.yaml", "-o", "p.h5", "-q"])
    if r.returncode:
        return r
    data = (d / "p.h5").read_bytes()
    (d / "p.h5").write_bytes(data[: len(data) // 2])
    r = cli(d, ["info", "p.h5"])
    line = r.stderr.strip()
    if "--overwrite" in line.split("(")[0] or (line and "resume" not in line
                                               and "overwrite" in line):
        r.stderr = "WRONG ADVICE " + r.stderr
        r.returncode = 99
    return r


# --- tracebacks and unclear messages ------------------------------------------------------

@case("symlink loop as a record")
def _(d):
    os.symlink("loop.AT2", d / "loop.AT2")
    (d / "s.yaml").write_text(suite_scene("[loop.AT2, r/SYN01.AT2]"))
    return cli(d, ["sweep", "s.yaml", "-q"])


@case("symlink loop as a single record")
def _(d):
    os.symlink("loop.AT2", d / "loop.AT2")
    (d / "s.yaml").write_text(record_scene("loop.AT2"))
    return cli(d, ["sweep", "s.yaml", "-q"])


@case("symlink loop as a listing")
def _(d):
    os.symlink("loop.txt", d / "loop.txt")
    (d / "s.yaml").write_text(suite_scene("loop.txt"))
    return cli(d, ["sweep", "s.yaml", "-q"])


@case("symlink loop as the output")
def _(d):
    os.symlink("loop.h5", d / "loop.h5")
    return cli(d, ["sweep", "pulse.yaml", "-o", "loop.h5", "-q", "--overwrite"])


@case("symlink loop as a figure output")
def _(d):
    os.symlink("loop.png", d / "loop.png")
    return cli(d, ["simulate", "pulse.yaml", "--set", "pulse.w_over_p=1", "--set",
                   "pulse.A_ratio=2", "--plot", "loop.png", "--overwrite"])


@case("listing in UTF-16")
def _(d):
    (d / "suite.txt").write_bytes("r/SYN01.AT2\nr/SYN02.AT2\n".encode("utf-16"))
    return cli(d, ["sweep", "suitelist.yaml", "-q"])


@case("listing of random bytes (embedded NUL)")
def _(d):
    import random

    rng = random.Random(7)
    (d / "suite.txt").write_bytes(bytes(rng.randrange(256) for _ in range(300)) + b"\0a\n")
    return cli(d, ["sweep", "suitelist.yaml", "-q"])


@case("listing with a UTF-8 BOM", "ok")
def _(d):
    (d / "suite.txt").write_bytes(b"\xef\xbb\xbfr/SYN01.AT2\r\nr/SYN02.AT2\r\n")
    return cli(d, ["sweep", "suitelist.yaml", "-q"])


@case("listed record named r[1].AT2", "ok")
def _(d):
    shutil.copy(d / "r" / "SYN01.AT2", d / "r" / "r[1].AT2")
    (d / "s.yaml").write_text(suite_scene("['r/r[1].AT2', r/SYN02.AT2]"))
    return cli(d, ["sweep", "s.yaml", "-q"])


@case("listing entry r[1].AT2", "ok")
def _(d):
    shutil.copy(d / "r" / "SYN01.AT2", d / "r" / "r[1].AT2")
    (d / "suite.txt").write_text("r/r[1].AT2\nr/SYN02.AT2\n")
    return cli(d, ["sweep", "suitelist.yaml", "-q"])


@case("glob found r[1].AT2: fragility --rtol rebuilds the scene", "ok")
def _(d):
    shutil.copy(d / "r" / "SYN01.AT2", d / "r" / "r[1].AT2")
    r = cli(d, ["sweep", "suite.yaml", "-o", "s.h5", "-q"])
    if r.returncode:
        return r
    return cli(d, ["fragility", "s.h5", "--rtol", "0.1"])


@case("suite result after the record folder moved: spectra and IDA", "ok")
def _(d):
    r = cli(d, ["sweep", "suite.yaml", "-o", "s.h5", "-q"])
    if r.returncode:
        return r
    shutil.move(d / "r", d / "moved")
    return py(d, """
        ds = rocksweep.open('s.h5')
        rocksweep.ida(ds, rtol=0.1)
        print('OK')""")


@case("single-record result after the record moved: spectra", "ok")
def _(d):
    r = cli(d, ["sweep", "one.yaml", "-o", "o.h5", "-q"])
    if r.returncode:
        return r
    shutil.move(d / "rec.AT2", d / "gone.AT2")
    return cli(d, ["spectrum", "o.h5", "--rtol", "0.1"])


@case("in-memory result of a scene named README.md: spectra() opens no file", "ok")
def _(d):
    (d / "README.md").write_text("# not a result\n")
    return py(d, """
        import yaml
        sc = yaml.safe_load(open('one.yaml'))
        sc['name'] = 'README.md'
        ds = rocksweep.run(sc)
        rocksweep.spectra(ds, rtol=0.1)
        print('OK')""")


@case("listing that lists itself")
def _(d):
    (d / "suite.txt").write_text("suite.txt\nr/SYN01.AT2\n")
    r = cli(d, ["sweep", "suitelist.yaml", "-q"])
    if r.returncode and "suite.txt" not in r.stderr:
        r.stderr = "LISTING NOT NAMED " + r.stderr
    return r


@case("listing that lists another listing")
def _(d):
    (d / "other.txt").write_text("r/SYN01.AT2\n")
    (d / "suite.txt").write_text("other.txt\nr/SYN02.AT2\n")
    r = cli(d, ["sweep", "suitelist.yaml", "-q"])
    if r.returncode and "listing" not in r.stderr:
        r.stderr = "LISTING NOT NAMED " + r.stderr
    return r


@case("listing whose entry is a file named 123")
def _(d):
    (d / "123").write_text("hello\n")
    (d / "suite.txt").write_text("123\nr/SYN02.AT2\n")
    r = cli(d, ["sweep", "suitelist.yaml", "-q"])
    if r.returncode and "suite.txt" not in r.stderr:
        r.stderr = "LISTING NOT NAMED " + r.stderr
    return r


@case("ground.scale.im: [PGA]")
def _(d):
    (d / "s.yaml").write_text(suite_scene("r/*.AT2").replace("im: PGA", "im: [PGA]"))
    return cli(d, ["sweep", "s.yaml", "-q"])


@case("ground.scale.im: {a: 1}")
def _(d):
    (d / "s.yaml").write_text(suite_scene("r/*.AT2").replace("im: PGA", "im: {a: 1}"))
    return cli(d, ["sweep", "s.yaml", "-q"])


def _flipped(d: Path, seed: int) -> subprocess.CompletedProcess:
    import random

    r = cli(d, ["sweep", "suite.yaml", "-o", "s.h5", "-q"])
    if r.returncode:
        return r
    data = bytearray((d / "s.h5").read_bytes())
    rng = random.Random(seed)
    for _ in range(40):
        i = rng.randrange(len(data) // 3)  # metadata lives near the start
        data[i] ^= 1 << rng.randrange(8)
    (d / "s.h5").write_bytes(bytes(data))
    worst = None
    for args in (["info", "s.h5"], ["plot", "s.h5", "-o", "x.png"], ["fragility", "s.h5"]):
        r = cli(d, args)
        if "Traceback" in r.stderr or len(r.stderr.strip().splitlines()) > 1:
            return r
        worst = r
        if (d / "x.png").exists():
            (d / "x.png").unlink()
    return worst


for _seed in range(6):
    case(f"flipped bytes inside an HDF5 result (seed {_seed})", "any")(
        lambda d, s=_seed: _flipped(d, s))


@case("array-valued rocksweep_version")
def _(d):
    r = cli(d, ["sweep", "pulse.yaml", "-o", "p.h5", "-q"])
    if r.returncode:
        return r
    import h5py
    import numpy as np

    with h5py.File(d / "p.h5", "r+") as f:
        f.attrs["rocksweep_version"] = np.array([1.0, 2.0])
    for args in (["info", "p.h5"], ["plot", "p.h5", "-o", "x.png"]):
        r = cli(d, args)
        if r.returncode == 0 or "Traceback" in r.stderr:
            return r
    return r


@case("run(client=<closed Client>)")
def _(d):
    return py(d, """
        from dask.distributed import Client, LocalCluster
        cl = LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                          dashboard_address=None)
        c = Client(cl)
        c.close(); cl.close()
        rocksweep.run('pulse.yaml', client=c)""")


@case("--scheduler 'tcp://[::1'")
def _(d):
    return cli(d, ["sweep", "pulse.yaml", "--backend", "dask", "--scheduler", "tcp://[::1",
                   "-q"])


@case("a result re-saved by xarray's to_netcdf")
def _(d):
    r = cli(d, ["sweep", "pulse.yaml", "-o", "p.h5", "-q"])
    if r.returncode:
        return r
    r = py(d, """
        import xarray as xr
        ds = rocksweep.open('p.h5')
        ds.to_netcdf('x.h5', engine='h5netcdf')
        ds.close()""")
    (d / "p.h5").unlink()
    worst = None
    for args in (["info", "x.h5"], ["plot", "x.h5", "-o", "x.png"], ["sweep", "pulse.yaml",
                                                                    "-o", "x.h5", "--resume",
                                                                    "-q"]):
        r = cli(d, args)
        if "rocksweep" not in r.stderr or "Traceback" in r.stderr:
            r.stderr = "NOT SAID " + r.stderr
            return r
        worst = r
    return worst


@case("a CLI message names --resume, not resume=True")
def _(d):
    r = cli(d, ["sweep", "pulse.yaml", "-o", "p.h5", "-q", "--adaptive"])
    if r.returncode:
        return r
    r = cli(d, ["sweep", "pulse.yaml", "-o", "p.h5", "-q", "--resume"])
    if "=True" in r.stderr:
        r.stderr = "PYTHON WORDS " + r.stderr
        r.returncode = 99
    return r


def _interrupt(d: Path, delay: float, after_header: bool) -> subprocess.CompletedProcess:
    """Ctrl-C ``delay`` seconds after a sweep starts (after_header: after it printed its
    header line, i.e. while the kernel loads and the first chunks run; else after the
    process started): exit 130, no traceback, a file that resumes."""
    e = {**os.environ, "PYTHONPATH": str(ROOT)}
    big = PULSE.replace("[1, 2]", "{start: 0.5, stop: 6, num: 300}").replace(
        "[2, 4]", "{start: 1, stop: 8, num: 300}")
    (d / "big.yaml").write_text(big)
    freeze(d)
    p = subprocess.Popen([sys.executable, "-m", "rocksweep", "sweep", "big.yaml", "-o",
                          "b.h5"], cwd=d, env=e, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    head = ""
    if after_header:
        head = p.stderr.readline()  # "big: 90000 points (...); 0 done, ..."
    time.sleep(delay)
    p.send_signal(signal.SIGINT)
    try:
        out, err = p.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        p.kill()
        raise
    err = head + err
    r = subprocess.CompletedProcess(p.args, p.returncode, out, err)
    if p.returncode != 130 or "Traceback" in err or "Exception ignored" in err:
        r.stderr = f"EXIT {p.returncode}: " + err
        r.returncode = 99 if p.returncode == 0 else p.returncode
        return r
    if (d / "b.h5").exists():
        r2 = cli(d, ["sweep", "big.yaml", "-o", "b.h5", "-q", "--resume"])
        if r2.returncode:
            return r2
    freeze(d)  # the resume wrote b.h5, as it should
    r.stderr = "interrupted: exit 130"
    r.returncode = 0  # an interrupt honoured is this case's "ok"
    return r


# Before ~0.15 s (on a loaded machine) Python itself is still starting (importing site):
# no rocksweep code runs yet, so the start-up cases begin at 0.3 s.
for _delay in (0.3, 0.5):
    case(f"Ctrl-C {_delay:.2f} s after the process started", "ok")(
        lambda d, t=_delay: _interrupt(d, t, False))
for _delay in (0.0, 0.02, 0.05, 0.1, 0.15, 0.3, 0.6):
    case(f"Ctrl-C {_delay:.2f} s after the sweep's header", "ok")(
        lambda d, t=_delay: _interrupt(d, t, True))


def _amplitude(d: Path, value: float) -> subprocess.CompletedProcess:
    rows = "".join(f"{i * 0.01:.2f} {value * (1 if i % 2 else -1):.6e}\n" for i in range(50))
    (d / "tiny.csv").write_text(rows)
    (d / "s.yaml").write_text(record_scene("tiny.csv"))
    return cli(d, ["sweep", "s.yaml", "-q"])


@case("a subnormal-amplitude record")
def _(d):
    return _amplitude(d, 1e-310)


@case("a huge-amplitude record")
def _(d):
    return _amplitude(d, 1e300)


@case("a suite with a subnormal-amplitude record")
def _(d):
    rows = "".join(f"{i * 0.01:.2f} {1e-310 * (1 if i % 2 else -1):.6e}\n" for i in range(50))
    (d / "r" / "tiny.csv").write_text(rows)
    (d / "s.yaml").write_text(suite_scene("[r/tiny.csv, r/SYN01.AT2]"))
    return cli(d, ["sweep", "s.yaml", "-q"])


@case("restitution --law vertical --set impact.e=0.5")
def _(d):
    return cli(d, ["restitution", "pulse.yaml", "--law", "vertical", "--set", "impact.e=0.5"])


# --- the run -------------------------------------------------------------------------------

def classify(r: subprocess.CompletedProcess, before: dict, after: dict,
             expect: str) -> tuple[str, str]:
    lost = [k for k, v in before.items() if after.get(k) != v]
    text = (r.stderr.strip() + " " + r.stdout.strip()).strip()
    if lost:
        return "dataloss", f"changed: {', '.join(lost)} | {text[:200]}"
    # Python's warnings (RuntimeWarning: ...), not the library's own "Warning: ..." verdicts
    if "Traceback" in r.stderr or re.search(r"\b[A-Z]\w*Warning\b", r.stderr):
        return "traceback", r.stderr.strip()[-400:]
    if r.returncode == 0:
        return ("ok" if expect in ("ok", "any") else "traceback",
                text[:200] or "(exit 0)")
    lines = [ln for ln in r.stderr.strip().splitlines() if ln.strip()]
    if r.stdout.startswith("REFUSED"):
        lines = [r.stdout.strip()]
    one = len(lines) == 1 and (lines[0].startswith(("Error: ", "REFUSED")))
    if not one or expect == "ok" or r.returncode == 99:
        return "traceback", text[:400]
    return "clean", lines[0][:200]


def interrupt_trials(n: int) -> int:
    """Ctrl-C at random moments (0-0.3 s after the header: the kernel loads then) n times;
    print how many were honoured."""
    import random

    rng = random.Random(32)
    honoured, bad = 0, []
    for _ in range(n):
        delay = rng.uniform(0.0, 0.3)
        with tempfile.TemporaryDirectory(prefix="probe-") as tmp:
            r = _interrupt(Path(tmp), delay, True)
        if r.returncode == 0:
            honoured += 1
        else:
            bad.append(f"{delay:.3f} s: {r.stderr.strip()[-300:]}")
    for b in bad:
        print("not honoured at", b)
    print(f"{honoured} of {n} interrupts honoured (exit 130, no traceback, resumable)")
    return 0 if honoured == n else 1


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-k", default="", help="run only the cases whose name holds this "
                    "(alternatives separated by |)")
    ap.add_argument("-v", action="store_true", help="print every case's answer")
    ap.add_argument("--interrupts", type=int, default=0, metavar="N",
                    help="instead: N Ctrl-Cs at random moments of the first 0.3 s after "
                         "the sweep's header; count those honoured (exit 130, one line)")
    a = ap.parse_args()
    if a.interrupts:
        return interrupt_trials(a.interrupts)
    counts: Counter[str] = Counter()
    t0 = time.perf_counter()
    for name, expect, fn in CASES:
        if not any(k in name for k in a.k.split("|")):
            continue
        with tempfile.TemporaryDirectory(prefix="probe-") as tmp:
            d = Path(tmp)
            setup(d)
            try:
                r = fn(d)
            except subprocess.TimeoutExpired:
                r = subprocess.CompletedProcess([], 124, "", "Traceback: HANG (timeout)")
            after = snapshot(d)
            kind, why = classify(r, dict(FROZEN), after, expect)
        counts[kind] += 1
        if a.v or kind in ("dataloss", "traceback"):
            print(f"{kind:9s} {name}\n          {why}", flush=True)
    total = sum(counts.values())
    print(f"\n{total} cases in {time.perf_counter() - t0:.0f} s: " +
          ", ".join(f"{k} {counts[k]}" for k in ("clean", "ok", "dataloss", "traceback")))
    return 1 if counts["dataloss"] or counts["traceback"] else 0


if __name__ == "__main__":
    sys.exit(main())
