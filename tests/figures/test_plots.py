"""Figures: `rocksweep plot` over any swept axes, 1-D line plots, the output policy of
figures, Figure-returning functions, and no matplotlib backend switch."""

import os
import re
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from bodies import body_yaml, table3
from helpers import one_line_error
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure

from rocksweep.cli import main
from rocksweep.errors import RocksweepError
from rocksweep.scene.grid import ChunkResult
from rocksweep.store.reader import read_result
from rocksweep.store.writer import SweepFile

ROOT = Path(__file__).resolve().parents[2]
BODY3 = body_yaml(table3(alpha_cg="{start: 0.1, stop: 0.2, num: 3}"))


def visible_axes(fig: Figure) -> list:
    return [ax for ax in fig.axes if ax.get_visible()]


@pytest.fixture(scope="module")
def acg_result(tmp_path_factory):
    """Configs/ci-small.yaml's body swept over body.alpha_cg x pulse.A_ratio (3 x 4 x 2 lam
    = 24 points, w/p fixed): a diagram that is not omega/p x A."""
    from click.testing import CliRunner

    d = tmp_path_factory.mktemp("acg")
    scene = d / "acg.yaml"
    scene.write_text("name: alpha_cg against A\n" + BODY3 + "impact: {lam: [0.0, 0.4]}\n"
                     "pulse: {shape: sine, w_over_p: 3.0, A_ratio: [1.0, 2.5, 4.0, 6.0]}\n")
    out = d / "acg.h5"
    res = CliRunner().invoke(main, ["sweep", str(scene), "-o", str(out), "-q", "-j", "1"])
    assert res.exit_code == 0, res.output
    return out


@pytest.fixture(scope="module")
def line_result(tmp_path_factory):
    """A 1-D sweep: 6 values of omega/p at two lam (12 points)."""
    from click.testing import CliRunner

    d = tmp_path_factory.mktemp("line")
    scene = d / "line.yaml"
    scene.write_text(BODY3.replace("{start: 0.1, stop: 0.2, num: 3}", "0.15")
                     + "impact: {lam: [0.0, 0.4]}\n"
                     "pulse: {shape: sine, w_over_p: [6.0, 1.0, 2.0, 3.0, 4.0, 5.0], "
                     "A_ratio: 3.0}\n")
    out = d / "line.h5"
    res = CliRunner().invoke(main, ["sweep", str(scene), "-o", str(out), "-q", "-j", "1"])
    assert res.exit_code == 0, res.output
    return out


def synthetic_result(tmp_path: Path) -> Path:
    """A block scene (2 shapes x 2 alpha x 5 A x 6 w, no lam) with made-up outcomes: no
    kernel runs."""
    from rocksweep.scene.parse import parse_scene

    sc = parse_scene("name: synthetic block\nbody: {kind: block, alpha: [0.15, 0.25]}\n"
                     "pulse: {shape: [sine, cosine], w_over_p: {start: 0.5, stop: 6, num: 6},"
                     " A_ratio: {start: 0.5, stop: 6, num: 5}}\n")
    out = tmp_path / "block.h5"
    sf = SweepFile.create(out, sc)
    n = sf.grid.size
    arrays = {k: np.full(n, 0, dtype) for k, (dtype, _, _) in sc.variables().items()}
    arrays["outcome"][:] = np.arange(n) % 3
    sf.write(ChunkResult(0, n, arrays, 0.0))
    sf.close()
    return out


# ---------------------------------------------------------------------------------------
# rocksweep plot
# ---------------------------------------------------------------------------------------

def test_plot_of_alpha_cg_against_A(cli, acg_result, tmp_path):
    fig = tmp_path / "acg.png"
    res = cli.invoke(main, ["plot", str(acg_result), "-o", str(fig)])
    assert res.exit_code == 0, res.output
    assert res.output.strip() == f"wrote {fig}"
    data = fig.read_bytes()
    assert data.startswith(b"\x89PNG") and len(data) > 10_000
    assert [p.name for p in tmp_path.iterdir()] == [fig.name]  # no temporary left
    from rocksweep.figures.diagrams import sweep_figure
    from rocksweep.figures.panels import choose_axes

    result = read_result(acg_result)
    assert choose_axes(result) == ("alpha_cg", "A_ratio")
    f = sweep_figure(result)
    (ax,) = visible_axes(f)  # one panel: lam is layered in the colours
    assert "alpha_{cg}" in ax.get_xlabel() and "[rad]" in ax.get_xlabel()
    assert "A/" in ax.get_ylabel()
    # the transposed diagram and a scene key work too
    f2 = sweep_figure(result, "pulse.A_ratio", "body.alpha_cg")
    assert "A/" in visible_axes(f2)[0].get_xlabel()


def test_plot_dpi_sets_the_pixel_size(cli, acg_result, tmp_path):
    small, big = tmp_path / "a.png", tmp_path / "b.png"
    for path, dpi in ((small, "50"), (big, "100")):
        res = cli.invoke(main, ["plot", str(acg_result), "-o", str(path), "--dpi", dpi])
        assert res.exit_code == 0, res.output

    def width(p: Path) -> int:  # PNG IHDR: width at bytes 16..20
        return int.from_bytes(p.read_bytes()[16:20], "big")

    assert width(big) == pytest.approx(2 * width(small), abs=2)


def test_plot_of_a_1d_sweep_is_a_line_plot_of_theta_max(cli, line_result, tmp_path):
    fig = tmp_path / "line.png"
    res = cli.invoke(main, ["plot", str(line_result), "-o", str(fig)])
    assert res.exit_code == 0, res.output
    assert fig.read_bytes().startswith(b"\x89PNG") and fig.stat().st_size > 10_000
    from rocksweep.figures.diagrams import sweep_figure

    result = read_result(line_result)
    f = sweep_figure(result)
    (ax,) = visible_axes(f)
    lines = [ln for ln in ax.get_lines() if ln.get_label().startswith("$\\lambda$")]
    assert len(lines) == 2  # one per lam
    # the line is max|theta|/alpha_cg of the file against omega/p, sorted by omega/p
    order = np.argsort(result.coords["w_over_p"])
    lam_axis = result.dims.index("lam")
    for k, ln in enumerate(lines):
        want = np.take(result.arrays["theta_max_over_alpha"], k, axis=lam_axis)[order]
        np.testing.assert_array_equal(ln.get_xdata(), np.sort(result.coords["w_over_p"]))
        np.testing.assert_array_equal(ln.get_ydata(), want)


def test_plot_unknown_axis_is_one_line_listing_the_swept_axes(cli, acg_result, tmp_path):
    fig = tmp_path / "f.png"
    msg = one_line_error(cli.invoke(main, ["plot", str(acg_result), "-o", str(fig),
                                           "--x", "zeta"]))
    assert msg == f"Error: {acg_result}: --x zeta: not swept; swept axes: alpha_cg, lam, A_ratio"
    msg = one_line_error(cli.invoke(main, ["plot", str(acg_result), "-o", str(fig),
                                           "--x", "bogus"]))
    assert msg == (f"Error: {acg_result}: --x bogus: no such axis; "
                   "swept axes: alpha_cg, lam, A_ratio")
    msg = one_line_error(cli.invoke(main, ["plot", str(acg_result), "-o", str(fig),
                                           "--y", "w_over_p"]))
    assert msg == (f"Error: {acg_result}: --y w_over_p: not swept; "
                   "swept axes: alpha_cg, lam, A_ratio")
    assert not fig.exists()


def test_plot_refuses_an_existing_output_and_leaves_it_untouched(cli, acg_result, tmp_path,
                                                                  device_node):
    fig = tmp_path / "f.png"
    fig.write_bytes(b"precious")
    msg = one_line_error(cli.invoke(main, ["plot", str(acg_result), "-o", str(fig)]))
    assert msg == f"Error: {fig}: already exists; use --overwrite to replace it"
    assert fig.read_bytes() == b"precious"
    res = cli.invoke(main, ["plot", str(acg_result), "-o", str(fig), "--overwrite"])
    assert res.exit_code == 0, res.output
    assert fig.read_bytes().startswith(b"\x89PNG")
    # a device is refused even with --overwrite
    dev = device_node("null.png")
    msg = one_line_error(cli.invoke(main, ["plot", str(acg_result), "-o", str(dev),
                                           "--overwrite"]))
    assert msg == (f"Error: {dev}: not a regular file (a device, FIFO or socket); outputs "
                   "are written to regular files only")
    assert stat.S_ISCHR(os.stat(dev).st_mode)
    msg = one_line_error(cli.invoke(main, ["plot", str(acg_result), "-o",
                                           str(tmp_path / "no" / "f.png")]))
    assert msg == f"Error: {tmp_path / 'no' / 'f.png'}: directory {tmp_path / 'no'} does not exist"


def test_one_panel_per_shape_and_swept_body_key(tmp_path):
    out = synthetic_result(tmp_path)
    from rocksweep.figures.diagrams import stability_diagram

    result = read_result(out)
    fig = stability_diagram(result)
    assert len(visible_axes(fig)) == 4  # 2 shapes x 2 alpha
    titles = [ax.get_title() for ax in visible_axes(fig)]
    assert titles[0] == r"sine pulse, $\alpha$ = 0.15"
    assert fig.get_suptitle() == "synthetic block"


def test_title_says_the_pulse_shape_once(tmp_path):
    from rocksweep.figures.diagrams import stability_diagram
    from rocksweep.scene.parse import parse_scene

    sc = parse_scene("name: 'Figure X: flexible body, sine pulse'\n"
                     + BODY3.replace("{start: 0.1, stop: 0.2, num: 3}", "0.15")
                     + "impact: {lam: [0.0, 0.2]}\n"
                     "pulse: {shape: sine, w_over_p: [1.0, 2.0, 3.0], A_ratio: [1.0, 2.0]}\n")
    out = tmp_path / "x.h5"
    sf = SweepFile.create(out, sc)
    arrays = {k: np.full(sf.grid.size, 0, dtype) for k, (dtype, _, _) in sc.variables().items()}
    sf.write(ChunkResult(0, sf.grid.size, arrays, 0.0))
    sf.close()
    fig = stability_diagram(read_result(out))
    texts = [fig.get_suptitle(), *(ax.get_title() for ax in fig.axes)]
    assert sum(t.count("sine pulse") for t in texts) == 1


# ---------------------------------------------------------------------------------------
# Figure functions
# ---------------------------------------------------------------------------------------

def test_stability_diagram_draws_into_given_axes(acg_result):
    from rocksweep.errors import DiagramError
    from rocksweep.figures.diagrams import stability_diagram

    result = read_result(acg_result)
    mine = Figure()
    ax = mine.add_subplot()
    assert stability_diagram(result, axes=ax) is mine
    assert len(ax.collections) >= 1  # the mesh
    with pytest.raises(DiagramError, match="x = 'w_over_p': not swept"):
        stability_diagram(result, "w_over_p")
    with pytest.raises(RocksweepError, match="are both alpha_cg"):
        stability_diagram(result, "alpha_cg", "alpha_cg")


@pytest.fixture(scope="module")
def fig5_runs():
    from rocksweep.compute.single import run_point
    from rocksweep.scene.parse import load_scene

    scene = load_scene(ROOT / "configs" / "fig5.yaml")
    fixed = {a.name: a.values[0] for a in scene.axes}
    lam = next(a for a in scene.axes if a.name == "lam")
    return [run_point(scene.point({**fixed, "lam": v}), scene.single_numerics)
            for v in lam.values]


def test_time_history_has_the_input_pulse_and_guide_legend(fig5_runs):
    from rocksweep.figures.history import time_history

    fig = time_history(fig5_runs, ["lam"], "Figure 5")
    assert isinstance(fig, Figure) and len(fig.axes) == 4
    ax_in, ax_th = fig.axes[0], fig.axes[1]
    (pulse,) = [ln for ln in ax_in.get_lines() if ln.get_label().startswith("sine")]
    t, y = pulse.get_xdata(), pulse.get_ydata()
    # eq. (2): xg''/A = sin(w t) for one period 2 pi/(w/p), then 0
    w = fig5_runs[0].point.w_over_p
    inside = t < 2 * np.pi / w - 1e-9
    np.testing.assert_allclose(y[inside], np.sin(w * t[inside]), atol=1e-9)
    assert np.all(y[t > 2 * np.pi / w + 1e-9] == 0.0)
    labels = ax_th.get_legend().get_texts()
    words = [tx.get_text() for tx in labels]
    assert len(words) == 3 + 2  # three runs, the |theta| = alpha_cg line, overturning
    assert any("alpha_{cg}" in s and "corner" in s for s in words)
    assert any("overturning" in s for s in words)


def test_a_run_without_history_is_refused_in_pythons_words(fig5_runs):
    """A Run made without its history (``run_point(..., history=False)``, as sweeps make
    them) asked for one: the figure and the Run say how Python gets one (not "simulate
    with history=True": rocksweep.simulate has no such keyword). The command line cannot
    make such a Run: its runs (``run_points``, rocksweep simulate's) all record one."""
    import inspect

    import rocksweep
    from rocksweep.compute.history import run_points
    from rocksweep.compute.single import run_point
    from rocksweep.errors import FigureError
    from rocksweep.figures.history import time_history
    from rocksweep.scene.parse import load_scene

    bare = run_point(fig5_runs[0].point, fig5_runs[0].numerics, history=False)
    want = "run_point(..., history=True) records one (rocksweep.simulate always does)"
    with pytest.raises(FigureError) as err:
        time_history([bare])
    assert str(err.value) == f"time history: this run has no history: {want}"
    for ask in (bare.impact_losses, bare.history_columns):
        with pytest.raises(ValueError, match=re.escape(want)):
            ask()
    assert "history" not in inspect.signature(rocksweep.simulate).parameters
    scene = load_scene(ROOT / "configs" / "fig5.yaml", ["impact.lam=0"])
    assert all(r.history is not None for r in run_points(scene))


def test_the_flag_marks_legend_names_the_flags_the_points_carry(tmp_path):
    """The x marks' legend entry says which flags the drawn points carry (a close call
    left uncertified, a step cap), not a fixed list that missed `uncertified`."""
    from rocksweep.figures.diagrams import stability_diagram
    from rocksweep.scene.parse import parse_scene
    from rocksweep.vocab.outcomes import STATUS_BIT

    text = ("name: flags\n" + BODY3.replace("{start: 0.1, stop: 0.2, num: 3}", "0.15")
            + "impact: {lam: 0.0}\n"
            "pulse: {shape: sine, w_over_p: [1.0, 2.0, 3.0], A_ratio: [1.0, 2.0]}\n")
    sc = parse_scene(text)
    out = tmp_path / "f.h5"
    sf = SweepFile.create(out, sc)
    arrays = {k: np.full(sf.grid.size, 0, dtype) for k, (dtype, _, _) in sc.variables().items()}
    arrays["status"][1] = STATUS_BIT["uncertified"] | STATUS_BIT["refined"]
    arrays["status"][4] = STATUS_BIT["step_cap"]
    sf.write(ChunkResult(0, sf.grid.size, arrays, 0.0))
    sf.close()
    fig = stability_diagram(read_result(out))
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "flagged (step_cap, uncertified)" in labels, labels


def test_restitution_map_u0_curve_is_dark(body_fig2):
    from rocksweep.figures.restitution import restitution_map
    from rocksweep.physics.bodies import restitution, restitution_rigid

    lam = np.linspace(0, 1, 11)
    u = np.linspace(-2, 2, 9)
    e = restitution(body_fig2, lam[:, None], u[None, :] * body_fig2.u_cr, upper=True)
    fig = restitution_map(lam, u, e, float(restitution_rigid(body_fig2, 0.0)), "Figure 2")
    assert len(fig.axes) == 2
    (u0,) = [ln for ln in fig.axes[0].get_lines() if ln.get_label() == "$u/u_{cr}$ = 0"]
    r, g, b = to_rgb(u0.get_color())
    assert 0.2126 * r + 0.7152 * g + 0.0722 * b < 0.3  # luminance: visible on white


def test_work_precision_returns_two_axes(tmp_path):
    from rocksweep.analysis.accuracy import accuracy_study, ladder
    from rocksweep.figures.accuracy import work_precision
    from rocksweep.scene.parse import parse_scene

    sc = parse_scene("name: tiny\n" + BODY3.replace("{start: 0.1, stop: 0.2, num: 3}", "0.15")
                     + "impact: {lam: 0.2}\n"
                     "pulse: {shape: sine, w_over_p: [2.0, 5.3], A_ratio: [1.5, 3.0]}\n")
    study = accuracy_study(sc, 3, ladder("short"), repeat=1)
    fig = work_precision(study)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    assert "impacts: mean" in fig.axes[0].get_ylabel()
    assert "root finder: hermite" in fig.get_suptitle()


def test_save_figure_policy(tmp_path, device_node):
    from rocksweep.figures.style import save_figure

    fig = Figure()
    fig.add_subplot().plot([0, 1], [0, 1])
    out = save_figure(fig, tmp_path / "a.svg")
    assert out.read_bytes().startswith(b"<?xml")
    with pytest.raises(RocksweepError, match="already exists; use overwrite=True"):
        save_figure(fig, out)
    with pytest.raises(RocksweepError, match=r"unsupported file type '\.gif'"):
        save_figure(fig, tmp_path / "a.gif")
    dev = device_node("null.png")
    with pytest.raises(RocksweepError, match="not a regular file"):
        save_figure(fig, dev, overwrite=True)
    assert stat.S_ISCHR(os.stat(dev).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.svg", "null.png"]


def test_no_backend_switch_and_no_pyplot():
    """Importing and using the figure modules leaves a notebook's backend alone and never
    imports pyplot (no global figure state)."""
    code = """
import sys, tempfile, os
import matplotlib
matplotlib.use("svg")
import rocksweep.figures.style, rocksweep.figures.diagrams
import rocksweep.figures.accuracy, rocksweep.cli.plot
from rocksweep.figures.restitution import restitution_map
from rocksweep.figures.style import save_figure
import numpy as np
fig = restitution_map(np.linspace(0, 1, 3), np.linspace(-2, 2, 5), np.ones((3, 5)), 0.8)
save_figure(fig, os.path.join(tempfile.mkdtemp(), "r.png"))
print(matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules)
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["svg", "False"]
    # without a backend chosen, importing the modules resolves none (no Agg forced)
    code = ("import matplotlib, sys; before = matplotlib.rcParams._get_backend_or_none();"
            "import rocksweep.figures.style, rocksweep.figures.diagrams;"
            "import rocksweep.figures.accuracy;"
            "print(before == matplotlib.rcParams._get_backend_or_none(),"
            " 'matplotlib.pyplot' in sys.modules)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["True", "False"]
    src = "".join(f.read_text() for f in [*(ROOT / "rocksweep" / "figures").glob("*.py"),
                                           ROOT / "rocksweep" / "cli" / "plot.py"])
    assert "matplotlib.use(" not in src
    assert "import matplotlib.pyplot" not in src and "import pyplot" not in src


def test_check_files_ring_the_points_whose_outcome_changes(tmp_path):
    """A sweep with outputs.check: the cells whose check_outcome differs from outcome (at
    any lam) get a ring, at exactly those coordinates, and a legend entry; a checked file
    where nothing changes says so in its legend (it looked like an unchecked one); a file
    without check, neither."""
    from rocksweep.figures.diagrams import stability_diagram
    from rocksweep.scene.parse import parse_scene

    text = ("name: rings\n" + BODY3.replace("{start: 0.1, stop: 0.2, num: 3}", "0.15")
            + "impact: {lam: [0.0, 0.2]}\n"
            "pulse: {shape: sine, w_over_p: [1.0, 2.0, 3.0], A_ratio: [1.0, 2.0]}\n")
    labels = {}
    for check in (False, True, "none"):
        sc = parse_scene(text + f"outputs: {{check: {str(bool(check)).lower()}}}\n")
        out = tmp_path / f"c{check}.h5"
        sf = SweepFile.create(out, sc)
        arrays = {k: np.full(sf.grid.size, 0, dtype)
                  for k, (dtype, _, _) in sc.variables().items()}
        if check is True:  # grid order (lam, A_ratio, w_over_p): flip two points
            arrays["check_outcome"][[1, 6 + 5]] = 1  # lam 0 (A 1, w 2); lam 0.2 (A 2, w 3)
        sf.write(ChunkResult(0, sf.grid.size, arrays, 0.0))
        sf.close()
        fig = stability_diagram(read_result(out, optional=("check_outcome",)))
        ax = fig.axes[0]
        rings = [ln for ln in ax.lines if ln.get_marker() == "o"]
        labels[check] = [t.get_text() for t in fig.legends[0].get_texts()]
        if check is True:
            assert len(rings) == 1
            assert sorted(zip(*rings[0].get_data(), strict=True)) == [(2.0, 1.0), (3.0, 2.0)]
        else:
            assert rings == []
    assert "outcome changes at half the step" in labels[True]
    assert "outcome changes at half the step: none" in labels["none"]
    assert not any("half the step" in t for t in labels[False])
