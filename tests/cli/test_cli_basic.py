"""`simulate`, `restitution` and scene errors through the command line (CliRunner)."""

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest
from bodies import FIG3_YAML
from click.testing import CliRunner

from rocksweep.cli import main

CONFIGS = Path(__file__).resolve().parents[2] / "configs"

GOOD = """
""" + FIG3_YAML + """impact: {lam: 0.4}
pulse: {shape: sine, w_over_p: 5.3, A_ratio: 5.0}
"""


def test_simulate_json_keys(cli):
    res = cli.invoke(main, ["simulate", str(CONFIGS / "fig5.yaml"), "--set", "impact.lam=0.4",
                            "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    for k in ("outcome", "impacts", "uplifts", "theta_max_over_alpha", "t_overturn", "t_end",
              "status"):
        assert k in d
    assert d["outcome"] == "mode1" and d["t_overturn"] > 0 and d["impacts"] >= 1


def test_simulate_names_the_body_kinds_slenderness(cli):
    """A block's rotation is over its alpha, a flexible body's over alpha_cg."""
    block = cli.invoke(main, ["simulate", str(CONFIGS / "block.yaml"), "--set",
                              "pulse.shape=sine", "--set", "pulse.w_over_p=2", "--set",
                              "pulse.A_ratio=3"])
    assert block.exit_code == 0, block.output
    assert "max|theta|/alpha: " in block.output and "alpha_cg" not in block.output
    flexible = cli.invoke(main, ["simulate", str(CONFIGS / "fig5.yaml"), "--set",
                                 "impact.lam=0.4"])
    assert "max|theta|/alpha_cg: " in flexible.output


def test_simulate_plot_and_csv(cli, tmp_path):
    png, path = tmp_path / "fig5.png", tmp_path / "h.csv"
    res = cli.invoke(main, ["simulate", str(CONFIGS / "fig5.yaml"), "--plot", str(png),
                            "--csv", str(path)])
    assert res.exit_code == 0, res.output
    assert png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0][:4] == ["run", "lam", "p_t", "theta_over_alpha"]
    assert {r[0] for r in rows[1:]} == {"0", "1", "2"}  # three lam runs
    widths = {len(r) for r in rows}
    assert widths == {len(rows[0])}
    for r in rows[1:]:
        for cell in r:
            float(cell)  # plain numbers only (numpy 2 scalars once printed np.float64(...))
    lam = {r[0]: float(r[1]) for r in rows[1:]}
    assert lam == {"0": 0.0, "1": 0.2, "2": 0.4}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig5.png", "h.csv"]  # no temp


def test_outputs_refuse_existing_files_and_inputs(cli, tmp_path):
    """simulate --csv/--plot, restitution --plot and accuracy -o/--plot: an existing file
    is refused before computing unless --overwrite; the scene itself never."""
    scene = tmp_path / "s.yaml"
    scene.write_text(GOOD)
    old = tmp_path / "old.csv"
    old.write_text("keep")
    png = tmp_path / "old.png"
    png.write_bytes(b"keep")
    report = tmp_path / "old.h5"
    report.write_bytes(b"keep")
    cases = [
        (["simulate", str(scene), "--csv", str(old)], old),
        (["simulate", str(scene), "--plot", str(png)], png),
        (["restitution", str(scene), "--plot", str(png)], png),
        (["accuracy", str(scene), "-o", str(report)], report),
        (["accuracy", str(scene), "--plot", str(png)], png),
    ]
    for args, path in cases:
        res = cli.invoke(main, args)
        assert res.exit_code == 2, (args, res.output)
        assert res.output.strip().splitlines() == [
            f"Error: {path}: already exists; use --overwrite to replace it"], args
    for args in (["simulate", str(scene), "--csv", str(scene), "--overwrite"],
                 ["accuracy", str(scene), "-o", str(scene), "--overwrite"]):
        res = cli.invoke(main, args)
        assert res.output.strip().splitlines() == [
            f"Error: {scene}: is this command's input; choose another output path"], args
    assert old.read_text() == "keep" and png.read_bytes() == b"keep"
    assert report.read_bytes() == b"keep" and scene.read_text() == GOOD
    res = cli.invoke(main, ["simulate", str(scene), "--csv", str(old), "--overwrite"])
    assert res.exit_code == 0, res.output
    assert old.read_text().startswith("run,p_t,theta_over_alpha,")
    res = cli.invoke(main, ["restitution", str(scene), "--plot", str(png), "--overwrite"])
    assert res.exit_code == 0 and png.read_bytes()[:4] == b"\x89PNG"


def test_restitution_json(cli):
    res = cli.invoke(main, ["restitution", str(CONFIGS / "fig2.yaml"), "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    assert d["lam"][0] == 0 and d["lam"][-1] == 1
    assert d["u_over_ucr"][0] == -2 and d["u_over_ucr"][-1] == 2
    up = d["e"]["upper"]
    assert len(up) == len(d["lam"]) and len(up[0]) == len(d["u_over_ucr"])
    # mirror: lower(lam, u) = upper(lam, -u)
    assert d["e"]["lower"][10][0] == pytest.approx(up[10][-1], rel=1e-12)


def test_restitution_plot(cli, tmp_path):
    png = tmp_path / "fig2.png"
    res = cli.invoke(main, ["restitution", str(CONFIGS / "fig2.yaml"), "--plot", str(png)])
    assert res.exit_code == 0 and png.read_bytes()[:4] == b"\x89PNG"


BAD = [
    ("zeta: 0.05", "zeta: -0.1", "body.zeta = -0.1: must be in [0, 1e+06]"),
    ("zeta: 0.05", "zeta: 0.05, zta: 1", "body.zta: unknown key"),
    ("lam: 0.4", "lam: 2.5", "impact.lam = 2.5: must be in [0, 2]"),
    ("w_over_p: 5.3", "w_over_p: 0", "pulse.w_over_p = 0.0: must be > 0"),
    ("A_ratio: 5.0", "A_ratio: .nan", "pulse.A_ratio = nan"),
    ("A_ratio: 5.0", "A_ratio: .inf", "pulse.A_ratio = inf"),
    ("shape: sine", "shape: square", "pulse.shape = 'square'"),
    ("mA_over_m: 0.47", "mA_over_m: -1", "body.mA_over_m = -1.0: must be in [1e-06, 1e+06]"),
    ("alpha_cg: 0.15", "alpha_cg: 1.6", "body.alpha_cg = 1.6: must be in [1e-06, pi/2) rad"),
    ("alpha_cg: 0.15, alpha_A: 0.28", "alpha_cg: 0.6, alpha_A: 0.1",
     "the top mass cannot sit below the base"),
    ("wn_over_p: 2.43", "wn_over_p: 0",
     "body.wn_over_p = 0.0: must be in [1e-06, 1e+06] (omega_n/p), or .inf"),
    ("impact: {lam: 0.4}", "impact: {lam: 0.4}\nfoo: 1", "foo: unknown key"),
    ("{shape: sine,", "{shape: sine", "YAML syntax error"),
]


@pytest.mark.parametrize("old, new, message", BAD)
def test_bad_scene_one_line_error(cli, tmp_path, old, new, message):
    scene = tmp_path / "bad.yaml"
    assert old in GOOD
    scene.write_text(GOOD.replace(old, new, 1))
    out = tmp_path / "out.png"
    res = cli.invoke(main, ["simulate", str(scene), "--plot", str(out)])
    assert res.exit_code != 0
    assert message in res.output, res.output
    assert len(res.output.strip().splitlines()) == 1
    assert "Traceback" not in res.output
    assert not out.exists()


def test_simulate_rejects_grid_and_missing_file(cli, tmp_path):
    res = cli.invoke(main, ["simulate", str(CONFIGS / "fig3a.yaml")])
    assert res.exit_code != 0 and "--set" in res.output
    res = cli.invoke(main, ["simulate", str(tmp_path / "nope.yaml")])
    assert res.exit_code != 0 and "no such scene file" in res.output


def test_console_script_error_has_no_traceback(tmp_path):
    scene = tmp_path / "bad.yaml"
    scene.write_text(GOOD.replace("zeta: 0.05", "zeta: -1"))
    proc = subprocess.run([sys.executable, "-m", "rocksweep", "simulate", str(scene)],
                          capture_output=True, text=True)
    assert proc.returncode != 0
    assert "Traceback" not in proc.stderr
    want = f"Error: {scene}: body.zeta = -1.0: must be in [0, 1e+06]"
    assert proc.stderr.strip().splitlines() == [want]


def test_kernel_import_pulls_no_io_libraries():
    """The layers point one way: the kernel knows nothing of files, CLI or plots.
    (yaml is not checked: numba itself imports it to read its config file.)"""
    code = ("import sys, rocksweep.kernel, rocksweep.physics.bodies, rocksweep.physics.points;"
            "bad = [m for m in ('h5py', 'click', 'matplotlib', 'pydantic') if m in sys.modules];"
            "print(','.join(bad))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stdout.strip() == ""


def test_a_quiet_one_point_sweep_pays_for_no_pool_or_bar(tmp_path):
    """Demand 3 at start-up: a quiet sweep of one chunk runs it in this thread (no joblib
    pool: ~60 ms) and shows no bar (no tqdm: ~10 ms); the file records the version
    (``rocksweep._version``, not a search of the installed distributions)."""
    out = tmp_path / "one.h5"
    code = ("import sys\nfrom rocksweep.cli import main\ntry:\n"
            f"    main(['sweep', {str(CONFIGS / 'fig3a.yaml')!r}, '--set', 'pulse.w_over_p=2',"
            " '--set', 'pulse.A_ratio=3', '--set', 'impact.lam=0.2', '-q', '-j', '2', "
            f"'-o', {str(out)!r}])\n"
            "except SystemExit as e:\n    assert not e.code, e.code\n"
            "print('LOADED:' + ','.join(m for m in ('joblib', 'tqdm') if m in sys.modules))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split("LOADED:")[-1].strip() == ""
    import h5py

    import rocksweep

    with h5py.File(out) as f:
        assert f.attrs["rocksweep_version"] == rocksweep.__version__


@pytest.mark.parametrize("args, needle", [
    (["sweep"], "Missing argument 'SCENE.yaml'"),
    (["sweep", "x.yaml", "--adaptive", "--margin", "1e12"], "Invalid value for '--margin'"),
    (["plot", "x.h5", "--dpi", "5"], "Invalid value for '--dpi'"),
    (["sweep", "x.yaml", "--bogus"], "No such option '--bogus'"),
    (["bogus"], "No such command 'bogus'"),
])
def test_bad_usage_is_one_line(args, needle):
    """Click's usage errors (a bad option value, a missing argument, an unknown option or
    command) are one line too, exit code 2, like every other error."""
    from helpers import one_line_error

    res = CliRunner().invoke(main, args)
    line = one_line_error(res, code=2)
    assert line.startswith("Error: ") and needle in line


def test_importing_the_command_line_changes_no_environment():
    """Importing any ``rocksweep.cli`` module sets no environment variable (the console
    entry alone sets OPENBLAS_NUM_THREADS, for its own process)."""
    import os

    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    code = ("import os, pkgutil, importlib, rocksweep.cli\n"
            "before = dict(os.environ)\n"
            "for m in pkgutil.iter_modules(rocksweep.cli.__path__):\n"
            "    importlib.import_module('rocksweep.cli.' + m.name)\n"
            "print(dict(os.environ) == before, 'OPENBLAS_NUM_THREADS' in os.environ)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=120)
    assert res.returncode == 0 and res.stdout.split() == ["True", "False"], res.stderr
    entry = ("import os, sys\nfrom rocksweep.cli import entry\n"
             "sys.argv = ['rocksweep', '--version']\n"
             "import atexit\natexit.register(lambda: print('atexit'))\n"
             "print(os.environ.get('OPENBLAS_NUM_THREADS'))\nentry()")
    res = subprocess.run([sys.executable, "-c", entry], capture_output=True, text=True,
                         env=env, timeout=120)
    assert res.returncode == 0 and res.stdout.split()[0] == "None", res.stderr
    assert "atexit" not in res.stdout  # the console entry exits without teardown


def test_os_exit_is_called_only_by_the_console_entry():
    """``os._exit`` (no teardown: no atexit handlers, no coverage) is the console command's
    trade alone: it appears in ``rocksweep.cli.entry`` and nowhere else in the package."""
    import ast
    from pathlib import Path

    import rocksweep

    pkg = Path(rocksweep.__file__).parent
    found = []
    for path in sorted(pkg.rglob("*.py")):
        tree = ast.parse(path.read_text())
        for fn in [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)] + [tree]:
            body = fn.body if fn is not tree else [s for s in tree.body
                                                   if not isinstance(s, ast.FunctionDef)]
            for node in (n for s in body for n in ast.walk(s)):
                if isinstance(node, ast.Attribute) and node.attr == "_exit":
                    found.append((str(path.relative_to(pkg)), getattr(fn, "name", "")))
    assert set(found) == {("cli/__init__.py", "entry")}, found
