"""Hostile probe: every hostile-input case (except the fragility/IDA argument
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
- hang: no answer within TIMEOUT;
- wrong: a wrong answer (exit 0 where a refusal is due, a refusal that wrote a file, a
  number off its stated tolerance, a verdict left out).
The counts are printed last; the exit status is 1 if any case is neither ok nor clean.
The analysis cases share fixtures made once per run (a suite sweep, its fragility, a
partial file, a measured history: ``fixtures``).
"""

from __future__ import annotations

import argparse
import hashlib
import math
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
TIMEOUT = 60  # [s] longer is a hang (every case answers within a minute)

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
LOST: list[str] = []  # what a case found lost beyond its inputs (a file made meanwhile)


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
    if (d / "b.h5").exists() and "points saved in" not in err:
        # a file was made: the answer says how many points it holds and how to go on
        return wrong(r, "exit 130 without the 'interrupted: N of M points saved' line")
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


# --- the analyses held to the sweeps' standard ------------------------------------------
# Shared fixtures, made once per probe run (``fixtures``) and copied into a case's folder:
# s.h5 a suite sweep (2 records x 2 PGA stripes), f.h5 its fragility, p.h5 a pulse sweep,
# part.h5 a suite file a sweep stopped writing, one.h5 a one-stripe suite, m.csv a
# free-rocking block's history (simulate --csv), free.yaml its scene, hz.csv a hazard.

FIXTURES: dict[str, Path] = {}
FREE = ("name: free\nbody: {kind: block, alpha: 0.2}\nimpact: {lam: 0.0}\n"
        "initial: {theta_over_alpha: 0.7}\n")
HAZARD = ("PGA [g],annual_rate\n0.05,0.01\n0.1,0.003\n0.3,0.0004\n1.0,0.00002\n"
          "3.0,0.000001\n")
PARTIAL = """
import sys
import rocksweep.compute.sweep as sw
from rocksweep.scene.inputs import load
try:
    from rocksweep.scene.grid import Grid
except ImportError:  # the layout of older versions (a probe of them, for comparison)
    from rocksweep.compute.grid import Grid
from rocksweep.store.writer import SweepFile
sc, _ = load('suite.yaml')
sf = SweepFile.create('part.h5', sc)
sf.write(sw.run_chunk(Grid(sc), 0, 3, sw.level(sc)))
sf.close()
"""


def fixtures() -> Path:
    """The folder of the analysis fixtures (made on first use)."""
    if "dir" in FIXTURES:
        return FIXTURES["dir"]
    d = Path(tempfile.mkdtemp(prefix="probe-fixtures-"))
    setup(d)
    (d / "free.yaml").write_text(FREE)
    (d / "hz.csv").write_text(HAZARD)
    (d / "onestripe.yaml").write_text(suite_scene("r/*.AT2").replace("[0.2, 0.6]", "[0.6]"))
    e = {**os.environ, "PYTHONPATH": str(ROOT)}
    for args in (["sweep", "suite.yaml", "-o", "s.h5", "-q"],
                 ["sweep", "onestripe.yaml", "-o", "one.h5", "-q"],
                 ["sweep", "pulse.yaml", "-o", "p.h5", "-q"],
                 ["fragility", "s.h5", "-o", "f.h5", "--bootstrap", "20"],
                 ["simulate", "free.yaml", "--csv", "m.csv"]):
        made = subprocess.run([sys.executable, "-m", "rocksweep", *args], cwd=d, env=e,
                              capture_output=True, text=True, timeout=600)
        _made(made, " ".join(args))
    _made(subprocess.run([sys.executable, "-c", PARTIAL], cwd=d, env=e, capture_output=True,
                         text=True, timeout=600), "the partial suite file")
    FIXTURES["dir"] = d
    return d


def _made(r: subprocess.CompletedProcess, what: str) -> None:
    """A fixture the probe could not make ends the probe (its cases would read as the
    tool's faults)."""
    if r.returncode != 0:
        raise SystemExit(f"probe fixture {what!r} failed: {(r.stderr or r.stdout)[-400:]}")


def fixture(d: Path, *names: str) -> None:
    for n in names:
        shutil.copy(fixtures() / n, d / n)


def wrong(r: subprocess.CompletedProcess, why: str) -> subprocess.CompletedProcess:
    """Mark a case's answer wrong (classified as such, whatever its exit)."""
    r.stderr = f"WRONG: {why} | " + (r.stderr or "") + (r.stdout or "")
    r.returncode = 98
    return r


def api_call(d: Path, code: str) -> subprocess.CompletedProcess:
    """Python code whose wrong argument types must be a one-line TypeError/ValueError
    (or a RocksweepError): printed as REFUSED, anything else a traceback."""
    prog = ("import sys, rocksweep\n"
            "try:\n" + textwrap.indent(textwrap.dedent(code), "    ") +
            "\nexcept (rocksweep.RocksweepError, TypeError, ValueError) as err:\n"
            "    if '\\n' in str(err) or type(err).__name__ in ('AttributeError',):\n"
            "        raise\n"
            "    print('REFUSED', type(err).__name__, str(err))\n"
            "    sys.exit(1)\n")
    freeze(d)
    e = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-c", prog], cwd=d, env=e, capture_output=True,
                          text=True, timeout=TIMEOUT)


# A file made at the output path while the command computes (by the first temporary file
# the command makes: after it checked the path) is the user's: it must be kept.
APPEARS = """
import sys, tempfile
target, args = sys.argv[1], sys.argv[2:]
real = tempfile.mkstemp
def mkstemp(*a, **k):
    try:
        with open(target, 'x') as f:
            f.write('mine')
    except FileExistsError:
        pass
    return real(*a, **k)
tempfile.mkstemp = mkstemp
from rocksweep.cli import main
sys.argv = ['rocksweep', *args]
main()
"""


def appears(d: Path, target: str, args: list[str]) -> subprocess.CompletedProcess:
    freeze(d)
    e = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-c", APPEARS, target, *args], cwd=d, env=e,
                       capture_output=True, text=True, timeout=TIMEOUT)
    if not (d / target).exists() or (d / target).read_text(errors="replace") != "mine":
        LOST.append(f"{target} (made meanwhile) replaced")
    freeze(d)  # the user's file is an input now: the check above said if it was lost
    errors = [ln for ln in r.stderr.splitlines() if ln.startswith("Error: ")]
    if r.returncode and len(errors) == 1 and "Traceback" not in r.stderr:
        # the command did its work and said so; its refusal to publish is the answer
        r = subprocess.CompletedProcess(r.args, r.returncode, "", errors[0])
    return r


for _name, _files, _target, _args in (
        ("table -o", ("s.h5",), "t.csv", ["table", "s.h5", "-o", "t.csv"]),
        ("risk -o", ("f.h5", "hz.csv"), "r.csv", ["risk", "f.h5", "--hazard", "hz.csv",
                                                  "-o", "r.csv"]),
        ("efficiency -o", ("s.h5",), "e.csv", ["efficiency", "s.h5", "-o", "e.csv"]),
        ("fragility -o", ("s.h5",), "fr.h5", ["fragility", "s.h5", "--bootstrap", "0", "-o",
                                              "fr.h5"]),
        ("fragility --plot", ("s.h5",), "fr.png", ["fragility", "s.h5", "--bootstrap", "0",
                                                   "--plot", "fr.png"]),
        ("calibrate -o", ("free.yaml", "m.csv"), "fit.h5",
         ["calibrate", "free.yaml", "m.csv", "--fit", "impact.lam", "-o", "fit.h5"]),
        ("simulate --csv", (), "h.csv", ["simulate", "pulse.yaml", "--set",
                                         "pulse.w_over_p=1", "--set", "pulse.A_ratio=2",
                                         "--csv", "h.csv"])):
    case(f"dataloss: a file made at {_name}'s path meanwhile is kept")(
        lambda d, f=_files, t=_target, a=_args: (fixture(d, *f), appears(d, t, a))[1])


def two_writers(d: Path, target: str, args: list[str]) -> subprocess.CompletedProcess:
    """The same command writing ``target`` twice at once: both check the path, then both
    wait 2 s before writing it (they overlap): one writes, the other refuses."""
    freeze(d)
    e = {**os.environ, "PYTHONPATH": str(ROOT)}
    slow = APPEARS.replace("    try:\n        with open(target, 'x') as f:\n"
                           "            f.write('mine')\n    except FileExistsError:\n"
                           "        pass\n", "    import time; time.sleep(2)\n")
    assert "sleep" in slow
    procs = [subprocess.Popen([sys.executable, "-c", slow, target, *args], cwd=d, env=e,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for _ in range(2)]
    outs = [p.communicate(timeout=TIMEOUT) for p in procs]
    r = subprocess.CompletedProcess([], 0, outs[0][0] + outs[1][0], "")
    wrote = sum("wrote" in o for o, _ in outs)
    if wrote != 1 and not all(p.returncode == 0 for p in procs):
        return wrong(r, f"{wrote} wrote")
    if wrote == 2:  # both published: the second replaced the first's file
        return wrong(r, f"both wrote {target}")
    return r


case("two table -o t.csv at once: one writes, the other refuses", "ok")(
    lambda d: (fixture(d, "s.h5"), two_writers(d, "t.csv", ["table", "s.h5", "-o",
                                                             "t.csv"]))[1])


@case("a killed risk -o's temporary files are removed by the next risk -o", "ok")
def _(d):
    fixture(d, "f.h5", "hz.csv")
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    (d / f".r.h5.{dead}-abcd1234.partial.h5").write_bytes(b"half")
    old = d / ".r.abcd1234.partial.h5"
    old.write_bytes(b"half")
    os.utime(old, (time.time() - 3600, time.time() - 3600))
    r = cli(d, ["risk", "f.h5", "--hazard", "hz.csv", "-o", "r.h5"])
    left = [p.name for p in d.iterdir() if ".partial" in p.name]
    freeze(d)  # the killed writers' files are no inputs: their removal is the point
    return wrong(r, f"left {left}") if left else r


# hangs: every case answers in TIMEOUT

@case("hang: calibrate --fit initial.u_over_ucr of a rigid block")
def _(d):
    fixture(d, "free.yaml", "m.csv")
    return cli(d, ["calibrate", "free.yaml", "m.csv", "--fit", "initial.u_over_ucr"])


@case("hang: risk --hazard a FIFO")
def _(d):
    fixture(d, "f.h5")
    os.mkfifo(d / "hz.csv")
    return cli(d, ["risk", "f.h5", "--hazard", "hz.csv"])


@case("hang: calibrate of a FIFO measured history")
def _(d):
    fixture(d, "free.yaml")
    os.mkfifo(d / "m.csv")
    return cli(d, ["calibrate", "free.yaml", "m.csv", "--fit", "impact.lam"])


def _oq(d: Path, T: str, imt: str, poes: str = "0.5,0.1,0.01") -> subprocess.CompletedProcess:
    fixture(d, "f.h5")
    (d / "oq.csv").write_text(f"#,,,,,\"generated_by='OpenQuake engine 3.16', "
                              f"investigation_time={T}, imt='{imt}'\"\n"
                              "lon,lat,depth,poe-0.1,poe-0.3,poe-1.0\n"
                              f"10.0,45.0,0.0,{poes}\n")
    return cli(d, ["risk", "f.h5", "--hazard", "oq.csv"])


for _T, _imt in (("50.0.1", "PGA"), ("e", "PGA"), ("50.0", "SA(1.0.0)"), ("50.0", "SA(e)")):
    case(f"OpenQuake header investigation_time={_T}, imt='{_imt}'")(
        lambda d, T=_T, i=_imt: _oq(d, T, i))
case("OpenQuake poe = 1.0 at a higher level than a poe below 1 (rising)")(
    lambda d: _oq(d, "50.0", "PGA", "0.5,1.0,1.0"))


def _measured(d: Path, text: str, fit: str = "impact.lam") -> subprocess.CompletedProcess:
    fixture(d, "free.yaml")
    (d / "mm.csv").write_text(text)
    return cli(d, ["calibrate", "free.yaml", "mm.csv", "--fit", fit])


def _history(scale: float = 1.0, t_scale: float = 1.0, head: str = "p_t,theta_over_alpha",
             sep: str = ",", dup: bool = False) -> str:
    import math
    rows = [head]
    for i in range(300):
        t = i * 0.05
        th = scale * 0.7 * math.cos(1.3 * t) * math.exp(-0.05 * t)
        rows.append(sep.join([repr(t * t_scale)] * (2 if dup else 1) + [repr(th)]))
    return "\n".join(rows) + "\n"


case("measured CSV with a duplicated column 'p_t ,p_t'")(
    lambda d: _measured(d, _history(head="p_t ,p_t,theta_over_alpha", dup=True)))
case("measured p_t near 1e300")(lambda d: _measured(d, _history(t_scale=1e298)))
case("measured |theta| up to 10 rad on a block of alpha 0.2")(
    lambda d: _measured(d, _history(scale=10 / 0.2 / 0.7)))
case("measured CSV separated by semicolons")(
    lambda d: _measured(d, _history(sep=";").replace("p_t,theta", "p_t;theta")))
case("calibrate --bounds of a key that is not fitted")(
    lambda d: (fixture(d, "free.yaml", "m.csv"), cli(d, [
        "calibrate", "free.yaml", "m.csv", "--fit", "impact.lam", "--bounds",
        "impact.e_factor=0.5,1"]))[1])
case("calibrate --bounds =0,1")(
    lambda d: (fixture(d, "free.yaml", "m.csv"), cli(d, [
        "calibrate", "free.yaml", "m.csv", "--fit", "impact.lam", "--bounds", "=0,1"]))[1])


def _hazard(d: Path, text: str) -> subprocess.CompletedProcess:
    fixture(d, "f.h5")
    (d / "h.csv").write_text(text)
    r = cli(d, ["risk", "f.h5", "--hazard", "h.csv"])
    if r.returncode and "line" not in r.stderr:
        return wrong(r, "the refusal does not name the line")
    return r


case("risk --site of a one-curve hazard")(
    lambda d: (fixture(d, "f.h5", "hz.csv"), cli(d, ["risk", "f.h5", "--hazard", "hz.csv",
                                                     "--site", "0"]))[1])
case("risk --state of a fitted fragility")(
    lambda d: (fixture(d, "f.h5", "hz.csv"), cli(d, ["risk", "f.h5", "--hazard", "hz.csv",
                                                     "--state", "mode1"]))[1])
case("calibrate --p of a dimensionless history")(
    lambda d: (fixture(d, "free.yaml", "m.csv"), cli(d, [
        "calibrate", "free.yaml", "m.csv", "--fit", "impact.lam", "--p", "3"]))[1])
case("hazard separated by semicolons")(lambda d: _hazard(d, HAZARD.replace(",", ";")))
case("hazard separated by tabs")(lambda d: _hazard(d, HAZARD.replace(",", "\t")))


def _scene(d: Path, extra: str, body: str = BODY) -> subprocess.CompletedProcess:
    (d / "x.yaml").write_text("name: x\n" + body + extra + "\n")
    return cli(d, ["simulate", "x.yaml"])


BLOCK = "body: {kind: block, alpha: 0.2}\nimpact: {lam: 0.0}\n"
case("initial: {u_over_ucr: 1e300} on a flexible body")(
    lambda d: _scene(d, "initial: {u_over_ucr: 1e300}"))
case("initial: {thetadot_over_palpha: 1e300} on a block")(
    lambda d: _scene(d, "initial: {thetadot_over_palpha: 1e300}", BLOCK))
case("initial: {theta_over_alpha: null} is not 0")(
    lambda d: _scene(d, "initial: {theta_over_alpha: null}", BLOCK))
case("pulse: null is refused as pulse: {} is")(lambda d: _scene(d, "pulse: null", BLOCK))
case("efficiency of a one-stripe suite")(
    lambda d: (fixture(d, "one.h5"), cli(d, ["efficiency", "one.h5"]))[1])
case("risk of a pulse sweep names the file")(
    lambda d: (fixture(d, "p.h5", "hz.csv"), _named(cli(d, ["risk", "p.h5", "--hazard",
                                                             "hz.csv"]), "p.h5"))[1])


def _named(r: subprocess.CompletedProcess, name: str) -> subprocess.CompletedProcess:
    return r if r.returncode == 0 or name in r.stderr else wrong(r, f"{name} not named")


@case("risk of a risk file names the file")
def _(d):
    fixture(d, "f.h5", "hz.csv")
    r = cli(d, ["risk", "f.h5", "--hazard", "hz.csv", "-o", "r.h5"])
    if r.returncode:
        return r
    return _named(cli(d, ["risk", "r.h5", "--hazard", "hz.csv"]), "r.h5")


@case("efficiency of a partial file says incomplete", "ok")
def _(d):
    fixture(d, "part.h5")
    r = cli(d, ["efficiency", "part.h5"])
    return r if r.returncode or "incomplete" in r.stderr else wrong(r, "no 'incomplete'")


@case("fragility of a partial file says incomplete", "ok")
def _(d):
    fixture(d, "part.h5")
    r = cli(d, ["fragility", "part.h5", "--bootstrap", "0"])
    return r if r.returncode or "incomplete" in r.stderr else wrong(r, "no 'incomplete'")


@case("fragility --rtol of a partial file: one line, no fit warnings first")
def _(d):
    fixture(d, "part.h5")
    return cli(d, ["fragility", "part.h5", "--bootstrap", "0", "--rtol", "0.01"])


def _frag_beta(d: Path, beta: float) -> subprocess.CompletedProcess:
    return api_call(d, f"""
        import math
        import numpy as np, pandas as pd, xarray as xr
        fr = xr.Dataset({{"im_median": (("lam",), [0.3]), "beta": (("lam",), [{beta!r}])}},
                        coords={{"lam": [0.0]}}, attrs={{"im": "PGA", "im_units": "g"}})
        x = np.geomspace(1e-4, 1e2, 40)
        hz = pd.DataFrame({{"PGA [g]": x, "annual_rate": 1e-4 * x ** -2.0}})
        rk = rocksweep.risk(fr, hz)
        exact = 1e-4 * 0.3 ** -2.0 * math.exp(4.0 * {beta!r} ** 2 / 2)
        err = abs(float(rk.annual_rate[0]) / exact - 1)
        print("OK" if err <= 1e-6 else f"WRONG rate off by {{err:.2e}}")
        sys.exit(0 if err <= 1e-6 else 98)""")


case("risk of a fragility with beta = -0.4")(lambda d: _frag_beta(d, -0.4))
case("risk with beta = 1e-6 meets the closed form to 1e-6", "ok")(
    lambda d: _frag_beta(d, 1e-6))
case("risk with beta = 0 meets the closed form to 1e-6", "ok")(lambda d: _frag_beta(d, 0.0))

for _code in ("rocksweep.plot(None)", "rocksweep.plot(5)", "rocksweep.plot([1, 2])",
              "rocksweep.plot(rocksweep.open('p.h5'), ax=5)",
              "rocksweep.calibrate('free.yaml', 'm.csv', 'impact.lam', bounds=[0, 1])",
              "rocksweep.calibrate('free.yaml', 'm.csv', 'impact.lam', p='3')",
              "rocksweep.risk('f.h5', 'hz.csv', site=1.5)",
              "rocksweep.risk('f.h5', 'hz.csv', site=True)",
              "rocksweep.table(None)", "rocksweep.fragility([1, 2])"):
    case(f"API type: {_code}")(
        lambda d, c=_code: (fixture(d, "p.h5", "f.h5", "hz.csv", "free.yaml", "m.csv"),
                            api_call(d, c))[1])


# --- a refusal is one line after the library warned; suites where a grid is read ----------

@case("risk of a suite sweep (fit warns no_failures), hazard in PGV: one line")
def _(d):
    fixture(d, "s.h5")
    (d / "hzv.csv").write_text(HAZARD.replace("PGA [g]", "PGV [m/s]"))
    return cli(d, ["risk", "s.h5", "--hazard", "hzv.csv"])


@case("sweep of a suite scaled 100x (a record warning) to an existing file: one line")
def _(d):
    (d / "big.yaml").write_text(suite_scene("r/*.AT2").replace("[0.2, 0.6]", "[0.2, 60]"))
    (d / "taken.h5").write_text("x")
    return cli(d, ["sweep", "big.yaml", "-o", "taken.h5"])


@case("boundaries of a suite sweep (no A_ratio axis)")
def _(d):
    fixture(d, "s.h5")
    return cli(d, ["boundaries", "s.h5"])


@case("info of a fragility result (an analysis's file, not a sweep's)")
def _(d):
    fixture(d, "f.h5")
    return cli(d, ["info", "f.h5"])


@case("simulate of a 2-record x 2-stripe suite runs each point", "ok")
def _(d):
    return cli(d, ["simulate", "suite.yaml"])


# --- issue 45: the new axes (vertical, floors, orientation, PEER folders) ------------------
# Fixtures made once (``new_axes``): peer/ a PEER folder (3 records: 000, 090, -UP), h2.csv
# and up.csv two-column components of rec.csv, three.yaml (record + h2 + vertical + angle),
# fl.h5 a floor suite sweep over angle and floor.period, fla.h5 its fragility, flpart.h5
# the same sweep interrupted, pfl.h5 a pulse floor sweep.

BLOCK_BODY = "body: {kind: block, alpha: 0.2}\nimpact: {lam: 0.0}\n"
FLOOR_SUITE = ("name: fl\n" + BLOCK_BODY + "ground:\n  records: peer\n  vertical: false\n"
               "  angle: [0, 90]\n  scale: {im: PGA, values: [0.3, 0.6]}\n  p: 2.0\n"
               "floor: {period: [0.2, 0.5], damping: 0.05, participation: 1.3}\n")
PULSE_FLOOR = ("name: pfl\n" + BLOCK_BODY + "pulse: {shape: sine, w_over_p: 2, A_ratio: "
               "[0.5, 1, 2, 4]}\nfloor: {period: [0.2, 1.0], damping: 0.05, "
               "participation: 1.3}\n")
NEW_AXES: dict[str, Path] = {}
MAKE_PEER = """
import sys
import numpy as np
from pathlib import Path
from rocksweep.physics.records import read_record, write_at2
src, d = Path(sys.argv[1]), Path('peer')
d.mkdir()
for i, name in enumerate(('SYN01', 'SYN02', 'SYN03')):
    r = read_record(src / f'{name}.AT2')
    write_at2(d / f'RSN{i + 1}_EV_ST000.AT2', r.acc, r.dt, name)
    write_at2(d / f'RSN{i + 1}_EV_ST090.AT2', np.roll(r.acc, 50), r.dt, name)
    write_at2(d / f'RSN{i + 1}_EV_ST-UP.AT2', 0.4 * np.roll(r.acc, 20), r.dt, name)
r = read_record(src / 'SYN04.AT2')
for name, a in (('h2.csv', np.roll(r.acc, 40)), ('up.csv', 0.3 * np.roll(r.acc, 10))):
    Path(name).write_text(''.join(f'{k * r.dt:.4f},{v:.7e}\\n' for k, v in
                                  enumerate(a[:1000])))
"""


def new_axes() -> Path:
    """The folder of this section's fixtures (made on first use)."""
    if "dir" in NEW_AXES:
        return NEW_AXES["dir"]
    d = Path(tempfile.mkdtemp(prefix="probe-axes-"))
    setup(d)
    e = {**os.environ, "PYTHONPATH": str(ROOT)}
    _made(subprocess.run([sys.executable, "-c", MAKE_PEER, str(SUITE_DIR)], cwd=d, env=e,
                         capture_output=True, text=True, timeout=600), "the PEER folder")
    (d / "fl.yaml").write_text(FLOOR_SUITE)
    (d / "pfl.yaml").write_text(PULSE_FLOOR)
    (d / "three.yaml").write_text(
        "name: three\n" + BLOCK_BODY + "ground: {record: rec.csv, h2: h2.csv, vertical: "
        "up.csv, angle: [0, 90], A_ratio: [1, 3], p: [1.0, 2.0]}\n")
    for args in (["sweep", "fl.yaml", "-o", "fl.h5", "-q"],
                 ["sweep", "pfl.yaml", "-o", "pfl.h5", "-q"],
                 ["sweep", "three.yaml", "-o", "three.h5", "-q"],
                 ["fragility", "fl.h5", "-o", "fla.h5", "--bootstrap", "20"]):
        _made(subprocess.run([sys.executable, "-m", "rocksweep", *args], cwd=d, env=e,
                             capture_output=True, text=True, timeout=600), " ".join(args))
    _made(subprocess.run([sys.executable, "-c", PARTIAL.replace("suite.yaml", "fl.yaml")
                          .replace("part.h5", "flpart.h5")], cwd=d, env=e,
                         capture_output=True, text=True, timeout=600), "the partial floor file")
    NEW_AXES["dir"] = d
    return d


def axes_fixture(d: Path, *names: str) -> None:
    for n in names:
        src = new_axes() / n
        if src.is_dir():
            shutil.copytree(src, d / n, dirs_exist_ok=True)
        else:
            shutil.copy(src, d / n)


def _with(d: Path, *names: str) -> Path:
    axes_fixture(d, *names)
    return d


# item 0: one guard of every input of a scene
for _name, _args in (
        ("table -o the result's ground.vertical", ["table", "three.h5", "-o", "up.csv"]),
        ("table -o the result's ground.h2", ["table", "three.h5", "-o", "h2.csv"]),
        ("boundaries -o the result's ground.vertical", ["boundaries", "three.h5", "-o",
                                                        "up.csv"]),
        ("sweep -o its ground.vertical", ["sweep", "three.yaml", "-o", "up.csv", "-q"]),
        ("simulate --csv its ground.h2", ["simulate", "three.yaml", "--set",
                                          "ground.angle=0", "--set", "ground.A_ratio=1",
                                          "--csv", "h2.csv"]),
        ("sweep -o a PEER folder's UP file", ["sweep", "fl.yaml", "-o",
                                              "peer/RSN2_EV_ST-UP.AT2", "-q"]),
        ("sweep -o a PEER folder's H2 file", ["sweep", "fl.yaml", "-o",
                                              "peer/RSN1_EV_ST090.AT2", "-q"])):
    for _over in ([], ["--overwrite"]):
        case(f"dataloss: {_name}{' --overwrite' if _over else ''}")(
            lambda d, a=_args, o=_over: _guarded(d, [*a, *o]))


def _guarded(d: Path, args: list[str]) -> subprocess.CompletedProcess:
    """A command that writes over one of the inputs of a scene or result made here (the
    result names the files where its sweep read them: this case's)."""
    axes_fixture(d, "peer", "h2.csv", "up.csv", "three.yaml", "fl.yaml")
    if "three.h5" in args:
        r = cli(d, ["sweep", "three.yaml", "-o", "three.h5", "-q"])
        if r.returncode:
            return r
    return cli(d, args)


# item 1: crashes
@case("risk of a fragility with an orientation dimension", "ok")
def _(d):
    axes_fixture(d, "fla.h5")
    (d / "hz.csv").write_text(HAZARD)
    return cli(d, ["risk", "fla.h5", "--hazard", "hz.csv"])
for _im in ("AvgSa", "CAV", "Arias"):
    case(f"ground.scale.component: RotD50 with {_im} stripes")(
        lambda d, im=_im: (axes_fixture(d, "peer"), (d / "r.yaml").write_text(
            FLOOR_SUITE.replace("im: PGA", f"im: {im}, component: RotD50")
            .replace("[0.3, 0.6]", "[0.1, 0.2]")), cli(d, ["sweep", "r.yaml", "-q"]))[2])


def _floor_value(d: Path, key: str, value: str) -> subprocess.CompletedProcess:
    (d / "f.yaml").write_text("name: f\n" + BLOCK_BODY + "ground: {record: rec.AT2, "
                              "A_ratio: [1, 3], p: 2.0}\nfloor: {period: 0.5, damping: 0.05, "
                              "participation: 1.3}\n")
    return cli(d, ["sweep", "f.yaml", "-q", "--set", f"floor.{key}={value}"])


for _key, _value, _expect in (("period", "1e-300", "ok"), ("damping", "5e-324", "clean"),
                              ("damping", "1e-7", "clean"), ("period", "1e6", "ok"),
                              ("period", "-1", "clean"), ("period", "inf", "clean"),
                              ("damping", "1", "clean"), ("participation", "0", "clean"),
                              ("period", "x", "clean")):
    case(f"floor.{_key}: {_value}", _expect)(
        lambda d, k=_key, v=_value: _floor_value(d, k, v))
case("floor: {modes: [...]} under one record, no angle axis", "ok")(
    lambda d: ((d / "m.yaml").write_text(
        "name: m\n" + BLOCK_BODY + "ground: {record: rec.AT2, A_ratio: [1, 3], p: 2.0}\n"
        "floor: {modes: [{period: 0.5, damping: 0.05, participation: 1.3}]}\n"),
        cli(d, ["sweep", "m.yaml", "-q"]))[1])
case("floor: {modes: [...]} under a pulse, no angle axis", "ok")(
    lambda d: ((d / "m.yaml").write_text(
        "name: m\n" + BLOCK_BODY + "pulse: {shape: sine, w_over_p: 2, A_ratio: [1, 3]}\n"
        "floor: {modes: [{period: 0.5, damping: 0.05, participation: 1.3}, {period: 0.2, "
        "damping: 0.05, participation: -0.4}]}\n"), cli(d, ["sweep", "m.yaml", "-q"]))[1])
case("spectrum of a sweep over pulse.shape", "ok")(
    lambda d: ((d / "s.yaml").write_text(
        "name: s\n" + BLOCK_BODY + "pulse: {shape: [sine, cosine], w_over_p: [1, 2], "
        "A_ratio: [2, 4]}\n"), cli(d, ["sweep", "s.yaml", "-o", "s.h5", "-q"]),
        cli(d, ["spectrum", "s.h5", "--rtol", "0.1"]))[2])
# hostile values of the other new keys
def _ground_value(d: Path, extra: str) -> subprocess.CompletedProcess:
    """One record with ground.h2 and one hostile value of a new ground key."""
    axes_fixture(d, "h2.csv")
    rows = "".join(f"{k * 0.02:.4f},{0.1 * math.sin(k / 7):.6e}\n" for k in range(500))
    (d / "h2dt.csv").write_text(rows)  # DT 0.02 against the record's 0.01
    keys = {"record": "rec.csv", "h2": "h2.csv", "A_ratio": "1", "p": "2.0"}
    k, v = extra.split(": ", 1)
    keys[k] = v
    (d / "g.yaml").write_text("name: g\n" + BLOCK_BODY + "ground: {" + ", ".join(
        f"{a}: {b}" for a, b in keys.items()) + "}\n")
    return cli(d, ["sweep", "g.yaml", "-q"])


for _extra in ("angle: [400]", "angle: x", "angle: .nan", "angle: [-1]",
               "h2: nothere.csv", "h2: h2dt.csv", "h2: rec.csv", "vertical: true",
               "vertical: {a: 1}", "h2: g.yaml"):
    case(f"ground.{_extra}", "ok" if _extra == "h2: rec.csv" else "clean")(
        lambda d, x=_extra: _ground_value(d, x))
for _val in ("rotd50", "[H1]", "maybe"):
    case(f"ground.scale.component: {_val}")(
        lambda d, v=_val: (axes_fixture(d, "peer"), (d / "c.yaml").write_text(
            FLOOR_SUITE.replace("im: PGA", f"im: PGA, component: {v}")),
            cli(d, ["sweep", "c.yaml", "-q"]))[2])
case("ground.missing: maybe")(
    lambda d: (axes_fixture(d, "peer"), (d / "c.yaml").write_text(
        FLOOR_SUITE.replace("vertical: false", "vertical: false\n  missing: maybe")),
        cli(d, ["sweep", "c.yaml", "-q"]))[2])


# item 2: hangs and unbounded memory
case("hang: floor-spectrum of a FIFO")(
    lambda d: (os.mkfifo(d / "ff.h5"), cli(d, ["floor-spectrum", "ff.h5"]))[1])


# item 3: silent wrong answers
def _peer_hostile(d: Path, how: str, skip: bool = False) -> subprocess.CompletedProcess:
    axes_fixture(d, "peer")
    bad = d / "peer" / "RSN3_EV_ST090 (1).AT2"
    if how == "duplicate":
        shutil.copy(d / "peer" / "RSN3_EV_ST000.AT2", bad)
    elif how == "fifo":
        os.mkfifo(d / "peer" / "RSN4_EV_ST000.AT2")
    elif how == "dangling":
        os.symlink("gone.AT2", d / "peer" / "RSN4_EV_ST000.AT2")
    elif how == "loop":
        os.symlink("RSN4_EV_ST000.AT2", d / "peer" / "RSN4_EV_ST000.AT2")
    elif how == "lying H2":  # another DT: refused, not resampled
        text = (d / "peer" / "RSN2_EV_ST090.AT2").read_text().replace("DT=   .0100",
                                                                    "DT=   .0200")
        (d / "peer" / "RSN2_EV_ST090.AT2").write_text(text)
    elif how == "empty UP":
        (d / "peer" / "RSN2_EV_ST-UP.AT2").write_text("")
    (d / "c.yaml").write_text(FLOOR_SUITE.replace("vertical: false", "vertical: false" + (
        "\n  missing: skip" if skip else "")))
    r = cli(d, ["sweep", "c.yaml", "-q", "-o", "c.h5"])
    if skip and r.returncode == 0:
        said = r.stderr
        if "Warning" not in said:
            return wrong(r, "skipped without a warning")
        r.stderr = ""
    return r


for _how in ("duplicate", "fifo", "dangling", "loop", "lying H2", "empty UP"):
    case(f"PEER folder with a {_how} component file")(
        lambda d, h=_how: _peer_hostile(d, h))
for _how in ("duplicate", "fifo"):
    case(f"PEER folder with a {_how} under ground.missing: skip (warned)", "ok")(
        lambda d, h=_how: _peer_hostile(d, h, skip=True))
case("floor-spectrum of an interrupted floor sweep")(
    lambda d: cli(_with(d, "flpart.h5"), ["floor-spectrum", "flpart.h5", "-o", "x.png"]))
case("floor-spectrum --rtol -5 of a suite")(
    lambda d: cli(_with(d, "fl.h5"), ["floor-spectrum", "fl.h5", "--rtol", "-5"]))
case("floor-spectrum --rtol 0.3 of a pulse")(
    lambda d: cli(_with(d, "pfl.h5"), ["floor-spectrum", "pfl.h5", "--rtol", "0.3"]))
case("floor-spectrum of a missing file says so")(
    lambda d: _named(cli(d, ["floor-spectrum", "none.h5"]), "no such file"))
case("floor-spectrum -o CSV and PNG of a suite", "ok")(
    lambda d: cli(_with(d, "fl.h5"), ["floor-spectrum", "fl.h5", "-o", "f.csv", "-o",
                                      "f.png"]))


@case("orientation each: n_records counts records, the bootstrap resamples them", "ok")
def _(d):
    axes_fixture(d, "fl.h5")
    return py(d, """
        import warnings
        warnings.simplefilter('ignore')
        ds = rocksweep.open('fl.h5')
        fr = rocksweep.fragility(ds, bootstrap=0)
        n = int(fr['n_records'].sel(orientation='each').max())
        print('OK' if n == ds.sizes['record'] else f'WRONG n_records {n}')
        sys.exit(0 if n == ds.sizes['record'] else 98)""")


@case("efficiency of a 3-record sweep gives a verdict", "ok")
def _(d):
    axes_fixture(d, "fl.h5")
    r = cli(d, ["efficiency", "fl.h5"])
    if r.returncode == 0 and "few_records" not in r.stdout + r.stderr:
        return wrong(r, "no verdict on 3 records")
    r.stderr = ""  # its verdict is a warning line, as it should be
    return r


@case("table of a result with an airborne run: one rule (kept, said)", "ok")
def _(d):
    rows = "".join(f"{i * 0.01:.2f},{0.3 * math.sin(2 * math.pi * i * 0.01):.6e}\n"
                   for i in range(401))
    down = "".join(f"{i * 0.01:.2f},{-1.5 * math.sin(2 * math.pi * i * 0.01) ** 2 * (i > 50):.6e}\n"
                   for i in range(401))
    (d / "ah.csv").write_text(rows)
    (d / "av.csv").write_text(down)
    (d / "a.yaml").write_text("name: a\n" + BLOCK_BODY + "ground: {record: ah.csv, vertical: "
                              "av.csv, A_ratio: [0.5, 1.0], p: 2.0}\n")
    r = cli(d, ["sweep", "a.yaml", "-o", "a.h5", "-q"])
    if r.returncode:
        return r
    r = cli(d, ["table", "a.h5", "-o", "a.csv"])
    if "left out" in r.stderr:
        return wrong(r, "the table says left out and keeps the rows")
    r.stderr = ""
    return r


@case("calibrate of the exact model at its own noise says ok", "ok")
def _(d):
    return py(d, """
        import warnings
        import numpy as np, pandas as pd
        from rocksweep.analysis.peaks import hermite
        warnings.simplefilter('ignore')
        sc = {'name': 'b', 'body': {'kind': 'block', 'alpha': 0.2}, 'impact': {'lam': 0.0,
              'law': 'constant', 'e': 0.85}, 'initial': {'theta_over_alpha': 0.7}}
        h = rocksweep.simulate(sc, {'numerics.accuracy': 'fine'}).history
        tt, th, dth = (h[v].values for v in ('p_t', 'theta_over_alpha', 'theta_dot_over_alpha'))
        bad = []
        for seed in (3, 13, 21):
            t = np.arange(0.0, tt[-1] + 3.0, 0.02)
            y = np.where(t <= tt[-1], hermite(tt, th, dth, t), th[-1])
            y = y + 0.01 * np.abs(y).max() * np.random.default_rng(seed).standard_normal(t.size)
            fit = rocksweep.calibrate({**sc, 'impact': {**sc['impact'], 'e': 0.8}},
                                      pd.DataFrame({'p_t': t, 'theta_over_alpha': y}), 'impact.e')
            est = float(fit['estimate'][0])
            if str(fit['reason'].item()) != 'ok' or abs(est - 0.85) > 0.01:
                bad.append((seed, str(fit['reason'].item()), est))
        print('OK' if not bad else f'WRONG {bad}')
        sys.exit(0 if not bad else 98)""")


# item 4: API types
for _code in ("rocksweep.floor_spectrum(None)", "rocksweep.floor_spectrum(5)",
              "rocksweep.floor_spectrum([1, 2])", "rocksweep.floor_spectrum({})",
              "rocksweep.floor_spectrum('fl.h5', rtol='x')",
              "rocksweep.floor_spectrum('fl.h5', search='no')",
              "rocksweep.floor_spectrum('nothere.h5')",
              "from rocksweep.analysis.floors import worst_orientation\n"
              "worst_orientation(None)",
              "rocksweep.felt_motion('fl.yaml')"):
    case(f"API type: {_code.splitlines()[-1]}")(
        lambda d, c=_code: (axes_fixture(d, "fl.h5", "fl.yaml", "peer"), api_call(d, c))[1])
case("API: floor_spectrum of a path, as the other analyses take one", "ok")(
    lambda d: (axes_fixture(d, "fl.h5"), py(d, "rocksweep.floor_spectrum('fl.h5')\n"
                                             "print('OK')"))[1])


# kills and resumes of floor sweeps; two writers
@case("kill -9 of a floor sweep, then --resume: every point as one uninterrupted sweep", "ok")
def _(d):
    axes_fixture(d, "peer", "fl.h5")
    big = FLOOR_SUITE.replace("[0.2, 0.5]", "{start: 0.1, stop: 2, num: 24}").replace(
        "[0, 90]", "[0, 45, 90, 135]")
    (d / "k.yaml").write_text(big)
    e = {**os.environ, "PYTHONPATH": str(ROOT)}
    freeze(d)
    p = subprocess.Popen([sys.executable, "-m", "rocksweep", "sweep", "k.yaml", "-o", "k.h5",
                          "-q"], cwd=d, env=e, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    time.sleep(4.0)
    p.kill()
    p.communicate(timeout=TIMEOUT)
    r = cli(d, ["sweep", "k.yaml", "-o", "k.h5", "-q", "--resume"])
    if r.returncode:
        return r
    r2 = cli(d, ["sweep", "k.yaml", "-o", "one.h5", "-q"])
    if r2.returncode:
        return r2
    r3 = py(d, """
        import numpy as np
        a, b = rocksweep.open('k.h5'), rocksweep.open('one.h5')
        same = np.array_equal(a['outcome'].values, b['outcome'].values) and np.allclose(
            a['theta_max_over_alpha'].values, b['theta_max_over_alpha'].values, equal_nan=True)
        print('OK' if same else 'WRONG the resumed file differs')
        sys.exit(0 if same else 98)""")
    freeze(d)  # the sweeps wrote their files, as they should
    return r3


case("two floor-spectrum -o f.csv at once: one writes, the other refuses", "ok")(
    lambda d: (axes_fixture(d, "fl.h5"), two_writers(d, "f.csv", [
        "floor-spectrum", "fl.h5", "-o", "f.csv"]))[1])


# --- the run -------------------------------------------------------------------------------

def classify(r: subprocess.CompletedProcess, before: dict, after: dict,
             expect: str) -> tuple[str, str]:
    lost = [k for k, v in before.items() if after.get(k) != v] + LOST
    text = (r.stderr.strip() + " " + r.stdout.strip()).strip()
    if lost:
        return "dataloss", f"changed: {', '.join(lost)} | {text[:200]}"
    if r.returncode == 124 and "HANG" in r.stderr:
        return "hang", text[:200]
    if r.returncode == 98:
        return "wrong", text[:300]
    # Python's warnings (RuntimeWarning: ...), not the library's own "Warning: ..." verdicts
    if "Traceback" in r.stderr or re.search(r"\b[A-Z]\w*Warning\b", r.stderr):
        return "traceback", r.stderr.strip()[-400:]
    if r.returncode == 0:
        return ("ok" if expect in ("ok", "any") else "wrong",
                text[:200] or "(exit 0)")
    lines = [ln for ln in r.stderr.strip().splitlines() if ln.strip()]
    if r.stdout.startswith("REFUSED"):
        lines = [r.stdout.strip()]
    one = len(lines) == 1 and (lines[0].startswith(("Error: ", "REFUSED")))
    if not one or expect == "ok" or r.returncode == 99:
        return "traceback", text[:400]
    new = sorted(set(after) - set(before))
    if new:  # a refusal writes nothing
        return "wrong", f"refused but wrote {', '.join(new)} | {lines[0][:200]}"
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
            LOST.clear()
            try:
                r = fn(d)
            except subprocess.TimeoutExpired:
                r = subprocess.CompletedProcess([], 124, "", "Traceback: HANG (timeout)")
            except Exception as err:  # noqa: BLE001 (a fixture the version cannot make...)
                r = subprocess.CompletedProcess([], 99, "", f"Traceback: the case failed: "
                                                f"{type(err).__name__}: {err}")
            after = snapshot(d)
            kind, why = classify(r, dict(FROZEN), after, expect)
        counts[kind] += 1
        if a.v or kind in ("dataloss", "traceback", "hang", "wrong"):
            print(f"{kind:9s} {name}\n          {why}", flush=True)
    total = sum(counts.values())
    print(f"\n{total} cases in {time.perf_counter() - t0:.0f} s: " +
          ", ".join(f"{k} {counts[k]}" for k in ("clean", "ok", "dataloss", "traceback",
                                                    "hang", "wrong")))
    for made in (FIXTURES, NEW_AXES):
        if "dir" in made:
            shutil.rmtree(made["dir"], ignore_errors=True)
    return 1 if any(counts[k] for k in ("dataloss", "traceback", "hang", "wrong")) else 0


if __name__ == "__main__":
    sys.exit(main())
