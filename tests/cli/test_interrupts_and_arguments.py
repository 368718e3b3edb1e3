"""Ctrl-C is never lost, and arguments that cannot work are one line.

- An interrupt whose KeyboardInterrupt a library callback swallowed (llvmlite's ctypes
  callbacks while the kernel loads) still stops the sweep at its next checkpoint, with
  the finished points saved and the file resumable; the command line exits 130 with one
  line, also when the interrupt surfaced as another error.
- A closed dask Client, a scheduler address that is not a URL, an impact coefficient the
  chosen law ignores, and the API's words in a CLI message.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from bodies import FIG3_YAML
from helpers import one_line_error

import rocksweep
from rocksweep import interrupts
from rocksweep.cli import main
from rocksweep.cli.main import said
from rocksweep.compute.driver import SweepInterrupted
from rocksweep.errors import Arg, SceneError, SweepError, flag, set_key
from rocksweep.store.reader import read_result

ROOT = Path(__file__).resolve().parents[2]
BODY = FIG3_YAML + "impact: {lam: 0.0}\n"
GRID = ("name: g\n" + BODY + "pulse: {shape: sine, w_over_p: {start: 0.5, stop: 6, num: 40}, "
        "A_ratio: {start: 1, stop: 8, num: 40}}\n")


@pytest.fixture()
def swallowed():
    """An interrupt that arrived and whose exception was lost: only the flag is set, as
    after a KeyboardInterrupt dropped by a ctypes callback (``sys.unraisablehook``)."""
    class Info:
        exc_value = KeyboardInterrupt()

    interrupts._unraisable(Info())
    assert interrupts.pending()
    yield
    interrupts._pending.clear()


def test_a_swallowed_interrupt_stops_the_sweep_and_keeps_the_file(tmp_path, swallowed):
    (tmp_path / "g.yaml").write_text(GRID)
    out = tmp_path / "g.h5"
    with pytest.raises(SweepInterrupted) as e:
        rocksweep.run(str(tmp_path / "g.yaml"), output=out, jobs=1)
    assert e.value.report.points_done < 1600
    interrupts._pending.clear()
    assert not read_result(out).done.all()
    rocksweep.run(str(tmp_path / "g.yaml"), output=out, resume=True)
    assert read_result(out).done.all()


@pytest.mark.parametrize("where", ["rocksweep.compute.sweep.prepare",
                                   "rocksweep.scene.parse.load_scene"])
def test_an_error_after_an_interrupt_is_the_interrupt(cli, tmp_path, swallowed, monkeypatch,
                                                      where):
    """A library half-loaded by the interrupt raises something else (llvmlite's
    AttributeError 'PassBuilder'), while the kernel loads or before the sweep: the command
    line says "interrupted" and exits 130, no traceback."""
    def broken(*_a, **_k):
        raise AttributeError("module 'llvmlite.binding' has no attribute 'PassBuilder'")

    module, name = where.rsplit(".", 1)
    monkeypatch.setattr(__import__(module, fromlist=[name]), name, broken)
    (tmp_path / "g.yaml").write_text(GRID)
    r = cli.invoke(main, ["sweep", str(tmp_path / "g.yaml"), "-o", str(tmp_path / "g.h5")])
    assert r.exit_code == 130, r.output
    assert "Traceback" not in r.output and "interrupted" in r.output, r.output
    assert "PassBuilder" not in r.output
    if (tmp_path / "g.h5").exists():  # the file was made: the resume line names it
        assert "--resume" in r.output


def test_a_ctrl_c_while_the_kernel_loads_exits_130_and_resumes(tmp_path):
    """The real signal, sent right after the sweep's header line (the kernel loads then):
    exit 130, one line, no 'Exception ignored'; the file finishes with --resume."""
    big = GRID.replace("num: 40}", "num: 300}")
    (tmp_path / "g.yaml").write_text(big)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for delay in (0.0, 0.1):
        out = tmp_path / f"g{delay}.h5"
        p = subprocess.Popen([sys.executable, "-m", "rocksweep", "sweep", "g.yaml", "-o",
                              out.name], cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        p.stderr.readline()  # the header: the sweep has started
        threading.Event().wait(delay)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=120)
        assert p.returncode == 130, err
        assert "Traceback" not in err and "Exception ignored" not in err, err
        assert "interrupted" in err
        if out.exists():
            r = subprocess.run([sys.executable, "-m", "rocksweep", "sweep", "g.yaml", "-o",
                                out.name, "--resume", "-q"], cwd=tmp_path, env=env,
                               capture_output=True, text=True, timeout=300)
            assert r.returncode == 0, r.stderr
            assert read_result(out).done.all()


def test_a_closed_client_is_said_closed(tmp_path):
    distributed = pytest.importorskip("distributed")
    (tmp_path / "p.yaml").write_text(GRID)
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    client.close()
    cluster.close()
    with pytest.raises(rocksweep.RocksweepError, match="this dask Client is closed"):
        rocksweep.run(str(tmp_path / "p.yaml"), client=client)
    assert list(tmp_path.iterdir()) == [tmp_path / "p.yaml"]


@pytest.mark.parametrize("address", ["tcp://[::1", "tcp://host:port", "[::1]:99999"])
def test_a_scheduler_address_that_is_no_url(cli, tmp_path, address):
    (tmp_path / "p.yaml").write_text(GRID)
    line = one_line_error(cli.invoke(main, ["sweep", str(tmp_path / "p.yaml"), "--backend",
                                            "dask", "--scheduler", address, "-q"]))
    assert line.startswith(f"Error: scheduler {address!r}: not an address like "), line
    assert list(tmp_path.iterdir()) == [tmp_path / "p.yaml"]


@pytest.mark.parametrize("law", ["vertical", "locked"])
def test_an_e_the_law_ignores_is_refused(cli, tmp_path, law):
    (tmp_path / "p.yaml").write_text(GRID)
    line = one_line_error(cli.invoke(main, ["restitution", str(tmp_path / "p.yaml"), "--law",
                                            law, "--set", "impact.e=0.5"]))
    assert line.startswith("Error: --set impact.e=0.5: e is the constant law's") and \
        f"--law {law}" in line, line
    r = cli.invoke(main, ["restitution", str(tmp_path / "p.yaml"), "--law", "constant",
                          "--set", "impact.e=0.5"])
    assert r.exit_code == 0 and "e = 0.5" in r.output, r.output


def test_cli_messages_name_the_cli_flags():
    """One message, two callers: the API's keywords in ``str()``, the command line's
    options where the CLI says it (no rewriting of text: a value that looks like a keyword
    stays as it is)."""
    err = SweepError("{resume} needs {output}; add {adaptive}; {jobs}: resume=True stays",
                     resume=flag("resume"), output=Arg("output"), adaptive=flag("adaptive"),
                     jobs=Arg("jobs", 0))
    assert str(err) == "resume=True needs output; add adaptive=True; jobs = 0: resume=True stays"
    assert said(err) == "--resume needs -o; add --adaptive; --jobs 0: resume=True stays"
    fix = SceneError("pick one with {fix}", fix=set_key("impact.lam", "set_fix"))
    assert (str(fix), said(fix)) == ("pick one with overrides={'impact.lam': ...}",
                                     "pick one with --set impact.lam=VALUE")


@pytest.mark.parametrize("rtol", ["0.3", "0", "nan"])
def test_fragility_rtol_is_refused_before_any_work(cli, suite_result, tmp_path, monkeypatch,
                                                   rtol):
    """``fragility --rtol`` is the shared option: the library's range (0, MAX_RTOL], refused
    while the options are parsed (exit 2, one line naming --rtol), before the result is
    opened or any curve fitted, nothing written."""

    def no_work(*_args, **_kwargs):
        raise AssertionError("work started before the options were checked")

    for name in ("open", "fragility", "ida"):
        monkeypatch.setattr(rocksweep, name, no_work)
    out, fig = tmp_path / "f.csv", tmp_path / "f.png"
    res = cli.invoke(main, ["fragility", str(suite_result), "--rtol", rtol, "-o", str(out),
                            "--plot", str(fig)])
    line = one_line_error(res, 2)
    assert line.startswith(f"Error: --rtol {float(rtol)!r}: must be a relative tolerance in "
                           f"(0, {rocksweep.errors.MAX_RTOL:g}]"), line
    assert list(tmp_path.iterdir()) == []
