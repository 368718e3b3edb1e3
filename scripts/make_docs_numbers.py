"""Numbers in README.md and docs/ that a command produces, regenerated from that command.

Each number lives in a marked block of a page (``<!-- numbers:NAME -->`` ... ``<!-- end
numbers:NAME -->``); the blocks are written from ``docs/numbers.json``, which holds what
the command computed (and the command). Hand edits inside a block are overwritten, and
``tests/test_docs_numbers.py`` checks that every block is the rendering of the stored
numbers.

    python scripts/make_docs_numbers.py            # recompute every number, rewrite blocks
    python scripts/make_docs_numbers.py --render   # rewrite the blocks from numbers.json
    python scripts/make_docs_numbers.py --check    # recompute; exit 1 if a number moved

Numbers (``COMPUTE``):

- ``impact_laws``: the mode 1 share of the 80 x 80 grid of ``configs/impact-laws.yaml``
  per law and lam (``rocksweep sweep``; ~1 min on 2 cores): the table of
  docs/impact_laws.md and the sentence of README.md.
- ``demo``: the demo suite (``configs/fragility-demo.yaml``, 960 runs): every IM's
  ``beta_scale`` (``rocksweep.im_efficiency``) and the annual rates of theta:0.25 and
  overturning under ``configs/hazard-example.csv`` (``rocksweep.fragility`` of
  theta:0.25, theta:0.5, overturn, each alone; ``rocksweep.risk``, 50 years): the
  sentences of docs/risk.md.
- ``quick`` (seconds: checked by recomputing in ``tests/test_docs_numbers.py``): the
  points of configs/fig3a.yaml's grid, Figure 5's runs (``rocksweep.simulate
  configs/fig5.yaml``: outcome, impacts, p*t at overturning per lam) and Figure 2's
  restitution values (``rocksweep restitution configs/fig2.yaml``: e at lam = 0, u = 0; at
  lam = 1, u/u_cr = -2; Housner's e of the body welded rigid): README.md's quick start and
  single-run paragraphs; the mode 1 points per lam of the four figures' 80 x 80 grids
  (``rocksweep info``; ~3 s) and their cells in mode 1 at one lam and safe at a larger
  one (the plots' dots): docs/diagrams.md.
- ``calibration`` (seconds, recomputed in the test): docs/calibration.md's worked examples:
  ``rocksweep simulate`` + ``calibrate`` of configs/free-rocking.yaml as the page shows
  them (the truth at ``fine``, and at ``default``), the Figure 3(a) body's fit and its
  diagram at the interval (``FLEX_EXAMPLE``, ``FLEX_PLANE``), and the misfit verdict of a
  block under eq. (1) fitted to a block whose e is 0.6.
- ``fragility`` (seconds, recomputed): docs/fragility.md's demo-suite sentences: the
  overturning fractions' dips and the non-monotone verdict, the crossing of theta:0.5 and
  overturning, where ``joint=True``'s common beta is rejected, the IDA's kernel runs.
- ``api_example`` (seconds, recomputed): what README.md's Python example prints (its
  scene is read from the README's code).
- ``accuracy`` (~10-20 s): docs/accuracy.md's cells where ``default`` differs from
  ``fine`` on the four figures, ``block`` and ``fig4a-rigid``, and Figure 3(a) with
  ``--check`` (``rocksweep info``'s tails); the shipped scenes' step caps (``CAP_SCENES``)
  and the most RK4 evaluations a point of the four figures spends at ``fine``.
- ``calibration_bench`` (~1 min): the recovery errors and interval coverage that
  ``scripts/bench_calibrate.py`` prints (its cases, fitted the same way), in
  docs/calibration.md's "Measured" section; the script's times are not stored.

- ``contact`` (~6-10 s at `fine`, ``--check`` reruns it): docs/contact.md's table of the
  shares that slide and lift off per figure and class, and the safe points' median
  demand (``rocksweep.run`` with ``outputs.contact``).

Benchmark timings quoted in the docs are not regenerated here (they vary with the
machine and its load); docs/performance.md and docs/accuracy.md name the script that
measures each. Nor are the measurements of a change (before -> after tables), nor the
benchmarks' own tables (scripts/bench_*.py, scripts/accuracy_tables.py, wide_space.py).
"""

from __future__ import annotations

import json
import re
import sys
import textwrap
from pathlib import Path

import _here  # noqa: F401 (this checkout's package first)

ROOT = Path(__file__).resolve().parents[1]
STORE = ROOT / "docs" / "numbers.json"
LAWS = ("vertical", "locked", "constant")


def compute_impact_laws() -> dict:
    """{law: {lam: mode 1 share in %}} of configs/impact-laws.yaml (one decimal)."""
    import numpy as np

    from rocksweep.compute.driver import sweep_arrays
    from rocksweep.kernel import layout as L  # noqa: N812
    from rocksweep.scene.parse import load_scene

    scene = load_scene(ROOT / "configs" / "impact-laws.yaml")
    out = np.asarray(sweep_arrays(scene, jobs=2)[0]["outcome"])
    names = [a.name for a in scene.swept]
    lam_i, law_i = names.index("lam"), names.index("law")
    lams = scene.axis("lam").values
    laws = scene.axis("law").values
    shares: dict[str, dict[str, float]] = {}
    for j, law in enumerate(laws):
        shares[str(law)] = {}
        for i, lam in enumerate(lams):
            cut = np.take(np.take(out, [i], axis=lam_i), [j], axis=law_i)
            shares[str(law)][f"{lam:g}"] = round(
                100.0 * float(np.mean(cut == L.OUTCOME_MODE1)), 1)
    return {"command": "rocksweep sweep configs/impact-laws.yaml (outcome == mode1 share "
                       "of the 80 x 80 grid)", "shares": shares}


def compute_demo() -> dict:
    """The demo suite's beta_scale per IM and lam, and its rates (module docstring)."""
    import rocksweep

    ds = _demo_suite()
    eff = rocksweep.im_efficiency(ds)
    lams = [f"{v:g}" for v in ds["lam"].values]
    beta = {str(im): [round(float(v), 2) for v in eff["beta_scale"].sel(im=im).values]
            for im in eff["im"].values}
    fr = rocksweep.fragility(ds, state=["theta:0.25", "theta:0.5", "overturn"])
    rk = rocksweep.risk(fr, ROOT / "configs" / "hazard-example.csv", years=50)
    rate = {st: [float(f"{float(v):.2g}") for v in rk["annual_rate"].sel(state=st).values]
            for st in ("theta:0.25", "overturn")}
    prob = [round(100.0 * float(v), 1) for v in rk["probability"].sel(state="overturn")]
    return {"command": "rocksweep.run(configs/fragility-demo.yaml); im_efficiency; "
                       "fragility(theta:0.25, theta:0.5, overturn); risk(hazard-example, "
                       "50 years)", "lam": lams, "beta_scale": beta, "rate": rate,
            "p50_overturn": prob}


FIGURES = ("fig3a", "fig3b", "fig4a", "fig4b")
#: the friction coefficients docs/contact.md's table is read at
CONTACT_MU = (0.4, 0.6, 0.8)


def _mode1_counts(name: str) -> dict:
    """{lam: mode 1 points} of configs/NAME.yaml and the points per lam."""
    import numpy as np

    from rocksweep.compute.driver import sweep_arrays
    from rocksweep.kernel import layout as L  # noqa: N812
    from rocksweep.scene.parse import load_scene

    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    arrays = sweep_arrays(scene, jobs=2)[0]
    out = np.asarray(arrays["outcome"])
    names = [a.name for a in scene.swept]
    i = names.index("lam")
    lams = scene.axis("lam").values
    # cells in mode 1 at one lam and safe at a larger one (the plot's dots)
    by_lam = np.moveaxis(out, i, 0)
    back = np.zeros(by_lam.shape[1:], bool)
    for k in range(len(lams) - 1):
        back |= (by_lam[k] == L.OUTCOME_MODE1) & (by_lam[k + 1:] == L.OUTCOME_SAFE).any(0)
    rest = [a for a in scene.swept if a.name != "lam"]
    cells = [{a.name: float(a.values[j]) for a, j in zip(rest, idx, strict=True)}
             for idx in zip(*np.nonzero(back), strict=True)]
    from rocksweep.vocab.outcomes import FLAGGED_WORDS, status_words

    status = np.asarray(arrays["status"]).astype(np.int64)
    flagged = (status & L.STATUS_FLAGGED) != 0
    # what flagged them (uncertified, horizon, the caps, ...)
    words = sorted({w for v in np.unique(status[flagged]) for w in status_words(int(v))
                    if w in FLAGGED_WORDS})
    return {"mode1": {f"{lam:g}": int((np.take(out, [k], axis=i) == L.OUTCOME_MODE1).sum())
                      for k, lam in enumerate(lams)},
            "points_per_lam": int(out.size // out.shape[i]), "safe_again": cells,
            "flagged": int(flagged.sum()), "flag_words": words}


def compute_quick() -> dict:
    """The numbers of the shipped scenes that take seconds (module docstring)."""
    import math

    import rocksweep
    from rocksweep.analysis.restitution import restitution_table
    from rocksweep.scene.parse import load_scene

    fig3a = load_scene(ROOT / "configs" / "fig3a.yaml")
    sims = rocksweep.simulate(ROOT / "configs" / "fig5.yaml")
    fig5 = [{"lam": f"{s.run.point.lam:g}", "outcome": s.summary["outcome"],
             "impacts": int(s.summary["impacts"]),
             "t_overturn": None if s.summary["t_overturn"] is None
             else round(float(s.summary["t_overturn"]), 2)} for s in sims]
    t = restitution_table(load_scene(ROOT / "configs" / "fig2.yaml"))
    lam1, u_m2 = int(abs(t.lam - 1.0).argmin()), int(abs(t.u_over_ucr + 2.0).argmin())
    return {"command": "rocksweep.scene.parse.load_scene(configs/fig3a.yaml) grid points; "
                       "rocksweep.simulate(configs/fig5.yaml); rocksweep restitution "
                       "configs/fig2.yaml",
            "fig3a_points": math.prod(len(a.values) for a in fig3a.swept),
            "fig5": fig5,
            "mode1_points": {name[3:]: _mode1_counts(name) for name in FIGURES},
            "fig2": {"e_at_rest": round(t.e_at_rest, 3),
                     "e_lam1_u_minus2": round(float(t.e_upper[lam1, u_m2]), 2),
                     "e_housner_rigid": round(t.e_housner, 3)}}


def _cli(*args: str) -> str:
    """What ``rocksweep ARGS`` prints (stdout), run in this process; exit 0 checked."""
    from click.testing import CliRunner

    from rocksweep.cli import main as cli

    res = CliRunner().invoke(cli, list(args))
    if res.exit_code != 0:
        raise SystemExit(f"rocksweep {' '.join(args)}: exit {res.exit_code}: {res.output}")
    return res.stdout


def _sampled(history, every: float, noise: float, seed: int):
    """DataFrame (p_t, theta_over_alpha) of a simulated history sampled every ``every``
    p*t (linear between its rows, one row per time) with Gaussian noise of ``noise`` x
    max|theta|: a synthetic measurement (as scripts/bench_calibrate.py makes them)."""
    import numpy as np
    import pandas as pd

    t, th = history.p_t.values, history.theta_over_alpha.values
    keep = np.r_[t[1:] != t[:-1], True]
    t, th = t[keep], th[keep]
    ts = np.arange(0.0, t[-1] + 4.0, every)
    y = np.interp(ts, t, th)
    y += noise * np.abs(th).max() * np.random.default_rng(seed).standard_normal(ts.size)
    return pd.DataFrame({"p_t": ts, "theta_over_alpha": y})


#: docs/calibration.md's flexible-body example: the Figure 3(a) body under a sine pulse
FLEX_EXAMPLE = {"name": "Figure 3(a) body, sine pulse",
                "body": {"wn_over_p": 2.43, "zeta": 0.05, "alpha_cg": 0.15, "alpha_A": 0.28,
                         "mA_over_m": 0.47, "IA_ratio": 0.56},
                "impact": {"lam": 0.0}, "pulse": {"shape": "sine", "w_over_p": 4.0,
                                                 "A_ratio": 2.0}}
#: ... and the (omega/p, A) plane it is swept over at the fitted interval
FLEX_PLANE = {"w_over_p": {"start": 0.5, "stop": 6.0, "num": 23},
              "A_ratio": {"start": 0.5, "stop": 8.0, "num": 31}}


def _interval(fit) -> dict:
    s = fit.isel(parameter=0)
    return {"estimate": round(float(s["estimate"]), 4), "lo": round(float(s["lo"]), 4),
            "hi": round(float(s["hi"]), 4)}


def compute_calibration() -> dict:
    """docs/calibration.md's worked examples (seconds): the command lines of the free
    block (truth at ``fine``; and at ``default``: the generator's own error), the flexible
    body fitted and swept at its interval, and a model that cannot reproduce a
    measurement (a block under eq. (1) fitted to a block whose e is 0.6)."""
    import tempfile
    import warnings

    import numpy as np
    import pandas as pd

    import rocksweep

    free = str(ROOT / "configs" / "free-rocking.yaml")
    lines: dict[str, list[str]] = {}
    with tempfile.TemporaryDirectory() as d:
        for acc in ("fine", "default"):
            truth, meas = Path(d, f"truth-{acc}.csv"), Path(d, f"measured-{acc}.csv")
            _cli("simulate", free, "--set", "impact.lam=0.3", "--set",
                 f"numerics.accuracy={acc}", "--csv", str(truth))
            t = pd.read_csv(truth)  # the page's noise, line for line
            t["theta_over_alpha"] += 0.01 * t.theta_over_alpha.abs().max() * \
                np.random.default_rng(1).standard_normal(len(t))
            t[["p_t", "theta_over_alpha"]].to_csv(meas, index=False)
            out = _cli("calibrate", free, str(meas), "--fit", "impact.lam")
            # the fit's time is the machine's (scripts/bench_calibrate.py measures it)
            lines[acc] = [re.sub(r"runs in [0-9.]+ s", "runs in T s", ln)
                          for ln in out.strip().splitlines()]
    default_impacts = int(rocksweep.simulate(free, {"impact.lam": 0.3})
                          .summary["impacts"])
    sim = rocksweep.simulate(FLEX_EXAMPLE, {"impact.lam": 0.25,
                                            "numerics.accuracy": "fine"})
    fit = rocksweep.calibrate(FLEX_EXAMPLE, _sampled(sim.history, 0.02, 0.01, 1),
                              ["impact.lam"])
    plane = {**FLEX_EXAMPLE, "pulse": {"shape": "sine", **FLEX_PLANE}}
    ds = rocksweep.run(plane, jobs=2, overrides=rocksweep.calibrated_overrides(fit))
    mode1 = (ds.outcome == 1).sum(["w_over_p", "A_ratio"]).values.tolist()
    block = {"name": "free block", "body": {"kind": "block", "alpha": 0.2},
             "initial": {"theta_over_alpha": 0.7}}
    measured = rocksweep.simulate({**block, "impact": {"lam": 0.0, "law": "constant", "e": 0.6}},
                                  {"numerics.accuracy": "fine"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the misfit's warning: its numbers are the point
        bad = rocksweep.calibrate({**block, "impact": {"lam": 0.0}},
                                  _sampled(measured.history, 0.02, 0.01, 0), ["impact.lam"])
    n, dof = bad.attrs["n_peaks"], int(bad["dof"])
    ratio = float(bad["misfit"]) * (n / dof) ** 0.5 / float(bad["noise"])
    return {"command": "rocksweep simulate/calibrate configs/free-rocking.yaml as "
                       "docs/calibration.md's worked example (truth at fine and at default); "
                       "rocksweep.calibrate of FLEX_EXAMPLE (truth lam 0.25 at fine, every "
                       "0.02 p*t, 1% noise, seed 1) and rocksweep.run of FLEX_PLANE at "
                       "calibrated_overrides; a block (law constant, e 0.6) fitted under "
                       "eq. (1)",
            "free_fine": lines["fine"], "free_default": lines["default"],
            "free_default_impacts": default_impacts,
            "flex": {"impacts": int(sim.summary["impacts"]), **_interval(fit),
                     "runs": int(fit.attrs["runs"]), "reason": fit["reason"].item(),
                     "mode1": mode1, "points": int(ds.outcome.size // len(mode1))},
            "misfit": {"reason": bad["reason"].item(), "ratio": round(ratio),
                       "dof": dof}}


_DEMO: list = []


def _demo_suite():
    """The demo suite's Dataset (configs/fragility-demo.yaml), run once per process."""
    import warnings

    import rocksweep

    if not _DEMO:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the demo's record warnings: said in the docs
            _DEMO.append(rocksweep.run(ROOT / "configs" / "fragility-demo.yaml", jobs=2))
    return _DEMO[0]


def compute_fragility() -> dict:
    """docs/fragility.md's numbers of the demo suite (seconds): the overturning fractions'
    dips and the non-monotone verdict, how far theta:0.5's and overturning's separate
    curves cross, where the joint fit's common beta is rejected, and the IDA's runs."""
    import warnings

    import numpy as np

    import rocksweep

    ds = _demo_suite()
    lams = [f"{v:g}" for v in ds["lam"].values]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the verdicts are read from `reason`
        fr = rocksweep.fragility(ds)
        two = rocksweep.fragility(ds, state=["theta:0.5", "overturn"])
        joint = rocksweep.fragility(ds, state=["theta:0.1", "theta:0.25", "theta:0.5",
                                               "overturn"], joint=True, bootstrap=0)
        ida = rocksweep.ida(ds, rtol=1e-2)
    drops = -np.diff(fr["n_failed"].transpose("lam", ...).values, axis=-1)
    dips = drops[drops > 0]
    stripes = ds[ds.attrs["scale_im"]].values  # the crossing verdict's range: the stripes'
    grid = two["im_grid"].values
    inside = (grid >= stripes.min()) & (grid <= stripes.max())
    gap = (two["curve"].sel(state="overturn") - two["curve"].sel(state="theta:0.5")
           ).transpose("lam", "im_grid").values[:, inside].max(axis=1)
    k = int(np.argmax(gap))
    return {"command": "rocksweep.run(configs/fragility-demo.yaml); fragility (overturn; "
                       "theta:0.5 and overturn; theta:0.1/0.25/0.5/overturn joint, no "
                       "bootstrap); ida(rtol=1e-2)",
            "lam": lams, "n_records": int(ds.sizes["record"]), "runs": int(ds.outcome.size),
            "dip_min": int(dips.min()) if dips.size else 0,
            "dip_max": int(dips.max()) if dips.size else 0,
            "overturn_reason": [str(r) for r in fr["reason"].values],
            "crossing_gap": float(f"{gap[k]:.1g}"), "crossing_lam": lams[k],
            "crossing_said": bool(any("crossing" in str(r) for r in
                                      np.ravel(two["reason"].values))),
            "parallel_rejected": [lam for lam, r in zip(
                lams, joint["parallel_rejected"].values, strict=True) if bool(r)],
            "ida_runs": int(ida["runs"].sum())}


def compute_api_example() -> dict:
    """What README.md's Python API example prints (seconds): its scene (read from the
    README's code, so that the numbers are of the scene shown), its points, mode 1 points
    per lam and the two runs at Figure 5's pulse."""
    import ast

    import rocksweep

    code = re.search(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)[1]
    scene = ast.literal_eval(re.search(r"^scene = (\{.*?^\})", code, re.S | re.M)[1])
    est = rocksweep.estimate(scene, jobs=2)
    ds = rocksweep.run(scene, jobs=2)
    mode1 = (ds.outcome == 1).sum(["A_ratio", "w_over_p"])
    sims = rocksweep.simulate(scene, {"pulse.w_over_p": 5.3, "pulse.A_ratio": 5.0})
    return {"command": "README.md's Python API example (its scene, estimate, run, simulate)",
            "points": int(est.points),
            "mode1": repr(dict(zip(ds.lam.values.tolist(), mode1.values.tolist(),
                                   strict=True))),
            "runs": repr([(s.title, s.summary["outcome"], s.summary["impacts"])
                          for s in sims])}


#: the shipped scenes whose `default` classes docs/accuracy.md compares with `fine`
ACCURACY_SCENES = ("fig3a", "fig3b", "fig4a", "fig4b", "block", "fig4a-rigid")


#: the shipped scenes (configs/) whose step caps docs/accuracy.md states: every sweep
#: scene but fig3a-fine (Figure 3(a)'s plane at 1000 x 1000: fig3a's bodies and ranges)
CAP_SCENES = ("fig3a", "fig3b", "fig4a", "fig4b", "block", "fig4a-rigid", "ricker",
              "impact-laws", "record-demo", "fragility-demo", "floor-spectrum", "ci-small",
              "wide-space")


def _step_caps(name: str, accuracy: str | None = None) -> float:
    """The largest step cap (the kernel's PAR_MAXSTEPS, ``numerics.step_budget``) of a
    point of configs/NAME.yaml at its numerics (or at ``accuracy``) and at the finest
    rerun its certification may make (``Numerics.refined``): what the scene's cost
    admission holds to ``numerics.MAX_POINT_STEPS``."""
    from dataclasses import replace

    import numpy as np

    from rocksweep.kernel import layout as L  # noqa: N812
    from rocksweep.numerics import Numerics
    from rocksweep.scene.grid import Grid
    from rocksweep.scene.parse import load_scene

    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    n = scene.numerics if accuracy is None else Numerics.preset(accuracy)
    worst = 0.0
    for run in (n, n.refined(n.refine)):
        grid = Grid(replace(scene, numerics=run))
        for start in range(0, grid.size, 50_000):
            rows = grid.rows(start, min(start + 50_000, grid.size)).rows
            worst = max(worst, float(np.max(rows[:, L.PAR_MAXSTEPS])))
    return worst


def compute_accuracy() -> dict:
    """docs/accuracy.md's counts of the shipped scenes (~10-20 s): cells whose class at
    `default` differs from `fine`'s and the points the certification refined; Figure
    3(a) with ``--check`` (``rocksweep sweep --check``; ``rocksweep info``'s tails); the
    step caps of the shipped scenes (``_step_caps``) and the most RK4 evaluations a point
    of the four figures spends at `fine` (its steps and event re-integrations, the
    certification's reruns included)."""
    import json as _json
    import tempfile
    import warnings

    import rocksweep

    differ, points, spent = {}, {}, {}
    for name in ACCURACY_SCENES:
        path = ROOT / "configs" / f"{name}.yaml"
        d = rocksweep.run(path, jobs=2, overrides={"numerics.accuracy": "default"})
        f = rocksweep.run(path, jobs=2, overrides={"numerics.accuracy": "fine"})
        differ[name] = int((d.outcome != f.outcome).sum())
        points[name] = int(d.outcome.size)
        if name in FIGURES:
            spent[name] = int((f.steps + f.event_steps).max())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the demo suites' scaled records: said elsewhere
        caps = {name: float(f"{_step_caps(name):.3g}") for name in CAP_SCENES}
        caps_fine = {name: float(f"{_step_caps(name, 'fine'):.3g}") for name in FIGURES}
    with tempfile.TemporaryDirectory() as tmp:
        out = str(Path(tmp, "f.h5"))
        _cli("sweep", str(ROOT / "configs" / "fig3a.yaml"), "--check", "-o", out,
             "--quiet", "--jobs", "2")
        chk = _json.loads(_cli("info", out, "--json"))["check"]
        ds = rocksweep.open(out)
        changed = (ds.check_outcome != ds.outcome).sum(["w_over_p", "A_ratio"])
        by_lam = {f"{v:g}": int(n) for v, n in zip(ds.lam.values, changed.values,
                                                   strict=True)}
        ds.close()
    return {"command": "rocksweep.run(configs/NAME.yaml) at numerics.accuracy default and "
                       "fine; rocksweep sweep configs/fig3a.yaml --check; rocksweep info "
                       "--json",
            "differ": differ, "points": points,
            "step_cap": caps, "step_cap_fine": caps_fine, "spent_fine_max": spent,
            "check": {"points": chk["points"], "changes": chk["outcome_changes"],
                      "changes_by_lam": by_lam,
                      "t_p95": float(f"{chk['t_overturn_diff']['p95']:.2g}"),
                      "theta_p95": round(100 * chk["theta_max_rel_diff"]["p95"], 1)}}


def compute_contact() -> dict:
    """docs/contact.md's table (~10 s at `fine`): per figure and class (safe, mode 1, mode
    2), its points, the share whose friction demand exceeds each of ``CONTACT_MU``
    (``mu_required`` > mu) and the share that lifts off (``normal_min_over_Mg`` < 0), and
    the median demand of the safe points (``rocksweep.run`` with ``outputs.contact``,
    which runs `fine`)."""
    import numpy as np

    import rocksweep

    out = {}
    for name in FIGURES:
        ds = rocksweep.run(ROOT / "configs" / f"{name}.yaml", jobs=2,
                           overrides={"outputs.contact": True})
        oc, mu = ds.outcome.values, ds.mu_required.values
        lift = ds.normal_min_over_Mg.values < 0.0
        fig = {}
        for word, code in (("safe", 0), ("mode1", 1), ("mode2", 2)):
            sel = oc == code
            n = int(sel.sum())
            fig[word] = {"points": n,
                         "slides": [round(100 * float((mu[sel] > m).mean()), 1) if n else None
                                    for m in CONTACT_MU],
                         "lifts_off": round(100 * float(lift[sel].mean()), 1) if n else None}
        fig["safe_median_mu"] = round(float(np.median(mu[oc == 0])), 2)
        out[name] = fig
    return {"command": "rocksweep.run(configs/NAME.yaml, overrides={'outputs.contact': True})",
            "mu": list(CONTACT_MU), "figures": out}


def compute_calibration_bench() -> dict:
    """scripts/bench_calibrate.py's recovery numbers (~1 min): its cases (``CASES``) fitted
    back from 1% and 0.3% noise as the script fits them; the truths' impacts, the largest
    errors, the intervals that cover the truth and those narrower at 0.3% noise. Its
    times are the script's to print, not stored here."""
    import importlib.util
    import warnings

    spec = importlib.util.spec_from_file_location(
        "bench_calibrate", ROOT / "scripts" / "bench_calibrate.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    impacts: dict[str, list[int]] = {"pulse": [], "free": []}
    worst = {"impact.lam": 0.0, "impact.e": 0.0}
    covered = narrower = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a verdict's warning: the numbers are read here
        for label, scene, key, truth, start, _tol in bench.CASES:
            df, n_imp = bench.measurement(scene, key, truth, 0.01, 1,
                                          uneven="cos" in label, steps=200)
            f, _ = bench.fit_case(scene, key, start, df)
            df3, _ = bench.measurement(scene, key, truth, 0.003, 2, steps=200)
            f3, _ = bench.fit_case(scene, key, start, df3)
            impacts["free" if "free" in label else "pulse"].append(int(n_imp))
            if key in worst:
                worst[key] = max(worst[key], abs(float(f.estimate) - truth))
            covered += float(f.lo) <= truth <= float(f.hi)
            narrower += float(f3.hi - f3.lo) < float(f.hi - f.lo)
    return {"command": "python scripts/bench_calibrate.py (its CASES, truths at 200 steps "
                       "per period; times not stored)",
            "cases": len(bench.CASES),
            "impacts": {k: [min(v), max(v)] for k, v in impacts.items()},
            "worst": {k: round(v, 4) for k, v in worst.items()},
            "covered": covered, "narrower": narrower}


COMPUTE = {"impact_laws": compute_impact_laws, "demo": compute_demo, "quick": compute_quick,
           "calibration": compute_calibration, "fragility": compute_fragility,
           "api_example": compute_api_example, "accuracy": compute_accuracy,
           "calibration_bench": compute_calibration_bench, "contact": compute_contact}
#: the computations of seconds, rerun by tests/test_docs_numbers.py (the others take
#: more: ``--check`` reruns them)
CHEAP = ("quick", "calibration", "fragility", "api_example")


def _pct(v: float) -> str:
    return f"{v:.1f}%"


def render_impact_laws(d: dict) -> dict[str, str]:
    """page -> the text of its ``impact_laws`` block."""
    s = d["shares"]
    lams = list(s["vertical"])
    rows = ["| lam | vertical | locked | constant (e = 0.77) |", "|---|---|---|---|"]
    rows += [f"| {lam} | " + " | ".join(_pct(s[law][lam]) for law in LAWS) + " |"
             for lam in lams]
    lo, hi = lams[0], lams[-1]
    const = {_pct(s["constant"][lam]) for lam in lams}
    const_text = (f"{const.pop()} at both" if len(const) == 1 else
                  " / ".join(_pct(s["constant"][lam]) for lam in lams))
    sentence = (f"On the Figure 3(a) body, the locked law (less energy lost at impact) "
                f"overturns {_pct(s['locked'][lo])} /\n{_pct(s['locked'][hi])} of the grid "
                f"in mode 1 at lam {lo} / {hi} against eq. (1)'s {_pct(s['vertical'][lo])} /"
                f" {_pct(s['vertical'][hi])}, mostly at\nhigh frequencies and amplitudes. A "
                f"constant e ignores lam ({const_text}), so the growth of\nmode 1 with lam "
                "belongs to the impulse-position laws.")
    return {"docs/impact_laws.md": "\n".join(rows), "README.md": sentence}


#: how docs/risk.md names the efficiency's IMs
IM_LABEL = {"PGV_over_PGA": "PGV/PGA", "D5_95": "D5-95", "Sa(1)": "Sa(1 s)",
            "Sa(0.2)": "Sa(0.2 s)", "PGA_ratio": "PGA/(g tan alpha)",
            "PGV_ratio": "PGV p/(g tan alpha)"}


def _rate(x: float) -> str:
    """7.1e-4 (two digits, the exponent without padding)."""
    m, e = f"{x:.1e}".split("e")
    return f"{m}e{int(e)}"


def _span(v: list[float], fmt=_rate) -> str:
    lo, hi = (fmt(x) for x in (min(v), max(v)))
    return lo if lo == hi else f"{lo}-{hi}"


def _two(x: float) -> str:
    return f"{x:.2f}"


def _one(x: float) -> str:
    return f"{x:.1f}"


def render_demo(d: dict) -> dict[str, str]:
    """docs/risk.md's two sentences: the IMs best first (beta_scale per lam, or its span
    over lam), and the rates."""
    lams = " / ".join(d["lam"])
    best = sorted(((im, v) for im, v in d["beta_scale"].items()
                   if im not in ("PGA_ratio", "PGV_ratio")),  # PGA's and PGV's own beta
                  key=lambda kv: sum(kv[1]))
    parts = [f"{IM_LABEL.get(im, im)} {' / '.join(f'{x:.2f}' for x in v)}" if k < 2 else
             f"{IM_LABEL.get(im, im)} {_span(v, _two)}" for k, (im, v) in enumerate(best)]
    eff = (f"On the demo suite (Figure 3(a) body, 20 records, PGA stripes), beta_scale per "
           f"lam {lams}: " + ", ".join(parts) + ".")
    r, p = d["rate"], d["p50_overturn"]
    risk = (f"with the illustrative `configs/hazard-example.csv` (each state fitted alone): "
            f"overturning {_span(r['overturn'])} /yr (lam {d['lam'][0]} to "
            f"{d['lam'][-1]}), P(50 yr) {_span(p, _one)}%; theta:0.25 "
            f"{_span(r['theta:0.25'])} /yr.")
    return {"docs/risk.md": {"demo_efficiency": textwrap.fill(eff, 90),
                             "demo_risk": textwrap.fill(risk, 90)}}


def _thousands(n: int) -> str:
    """19 200 (a thin space's stand-in: a space, as the README writes it)."""
    return f"{n:,}".replace(",", " ")


def render_quick(d: dict) -> dict[str, str]:
    """README.md's quick-start sentence and its paragraph on Figures 5 and 2."""
    start = ("On a fresh machine (Python >= 3.10). Install and run a real sweep (Figure 3(a), "
             f"{_thousands(d['fig3a_points'])} points) and draw it:")
    runs = d["fig5"]
    safe = [r["lam"] for r in runs if r["outcome"] == "safe"]
    over = [r for r in runs if r["outcome"] != "safe"]
    said = []
    if safe:
        said.append(f"lam = {' and '.join(safe)} survive" if len(safe) > 1 else
                    f"lam = {safe[0]} survives")
    said += [f"lam = {r['lam']} overturns{'' if r['outcome'] == 'mode1' else ' in ' + r['outcome']}"
             f" after {r['impacts']} impacts at p*t = {r['t_overturn']:.2f}" for r in over]
    e = d["fig2"]
    shows = ("What they show against the paper: for the Figure 5 scene (sine pulse, omega/p "
             "= 5.3, A/(g tan alpha_cg) = 5) " + " while ".join(said) + ", and at every time "
             "less energy has been dissipated for larger lam (tested). For the Table 2 body, "
             "e grows with lam for every u (eq. 5), e > 1 at lam = 1, u/u_cr = -2 "
             f"({e['e_lam1_u_minus2']:.2f}), and e at lam = 0, u = 0 is {e['e_at_rest']:.3f}, "
             f"far below Housner's {e['e_housner_rigid']:.3f} for the same body welded rigid; "
             "e is not monotonic in u/u_cr (Figure 2(b)).")
    counts = d["mode1_points"]
    lams = list(next(iter(counts.values()))["mode1"])
    each = {c["points_per_lam"] for c in counts.values()}
    per = (f"of {each.pop()} each" if len(each) == 1 else
           "of " + " / ".join(str(c["points_per_lam"]) for c in counts.values()))
    mode1 = ("- Raising lam expands the mode 1 area in all four figures; safe points turn into "
             f"mode 1 points. Mode 1 points at lam = {' / '.join(lams)} (`rocksweep info`): "
             + ", ".join(f"{fig} " + " / ".join(str(v) for v in c["mode1"].values())
                         for fig, c in zip(("3(a)", "3(b)", "4(a)", "4(b)"), counts.values(),
                                           strict=True)) + f" ({per}).")
    again = [(fig, cell) for fig, c in zip(("3(a)", "3(b)", "4(a)", "4(b)"), counts.values(),
                                           strict=True) for cell in c["safe_again"]]
    mode1 += (" No cell is in mode 1 at one lam and safe at a larger one." if not again else
              f" {len(again)} cell{'s' * (len(again) > 1)} in mode 1 at one lam and safe "
              "at a larger one (the figures' black dots): " + "; ".join(
                  f"{fig} at " + ", ".join(f"{k} = {v:g}" for k, v in cell.items())
                  for fig, cell in again) + ".")
    flags = [c["flagged"] for c in counts.values()]
    why = sorted({w for c in counts.values() for w in c["flag_words"]})
    mode1 += (" No point is flagged in the four diagrams." if not any(flags) else
              " Points flagged (drawn x; status " + ", ".join(f"`{w}`" for w in why)
              + "): " + " / ".join(str(n) for n in flags) + ".")
    return {"README.md": {"quick_start": textwrap.fill(start, 90),
                          "single_runs": textwrap.fill(shows, 90)},
            "docs/diagrams.md": {"mode1_points": textwrap.fill(
                mode1, 90, subsequent_indent="  ")}}


def render_calibration(d: dict) -> dict[str, dict[str, str]]:
    """docs/calibration.md: the worked example's output, the default-preset generator's
    fit, the flexible body's fit and diagram, the misfit example."""
    iv = {k: re.search(r"\[([0-9.]+), ([0-9.]+)\]", d[k][0]).groups()
          for k in ("free_fine", "free_default")}
    est = {k: re.search(r"= ([0-9.]+)", d[k][0])[1] for k in iv}
    step = re.search(r"to ([0-9.]+) p\*t", d["free_default"][-1])
    lam3 = lambda x: f"{float(x):.3f}"  # noqa: E731
    generator = (
        "A \"measurement\" made with `simulate` and 1% noise, fitted back (the block of "
        "`configs/free-rocking.yaml` released from 0.7 alpha, truth lam = 0.3; the CSV rows "
        "are the kernel's own steps at `fine`, unevenly spaced, with the event rows). The "
        "truth is made at `fine`: at the `default` preset (5 steps per period, rows up to "
        f"{step[1] if step else '?'} p*t apart) the simulated \"measurement\" of "
        f"{d['free_default_impacts']} impacts carries that preset's own integration error, "
        "and the fit, which runs at least at `fine`, recovers lam = "
        f"{lam3(est['free_default'])} [{lam3(iv['free_default'][0])}, "
        f"{lam3(iv['free_default'][1])}] from it: the error of the generator, not of the "
        "fit.")
    out = ("```\n" + "\n".join(d["free_fine"]) + "\n```\n\n(T: the fit's compute time, "
           "~1 s on the 2-core machine; `python scripts/bench_calibrate.py` measures it.)")
    f = d["flex"]
    m1 = ", ".join(str(v) for v in f["mode1"])
    moved = max(f["mode1"]) - min(f["mode1"])
    flex = (
        "```python\n"
        "fit = rocksweep.calibrate(scene, measured, fit=[\"impact.lam\"])\n"
        f"# impact.lam = {f['estimate']:.4f} [{f['lo']:.4f}, {f['hi']:.4f}], {f['runs']} "
        f"runs, fit {f['reason']}\n"
        "ds = rocksweep.run(diagram, overrides=rocksweep.calibrated_overrides(fit))\n"
        "(ds.outcome == 1).sum([\"w_over_p\", \"A_ratio\"])   # mode 1 points: "
        f"{m1} of {f['points']}\n```\n\n"
        + textwrap.fill(
            f"Here the calibrated interval moves the diagram by {moved} "
            f"point{'' if moved == 1 else 's'} of {f['points']}: the fitted lam is known "
            "well enough for the stability question. A wider interval (more noise, fewer "
            "impacts) shows directly how much of the diagram is uncertain.", 90))
    flex_intro = textwrap.fill(
        "The paper's question for a flexible body: the Figure 3(a) body under a sine pulse "
        f"(omega/p = 4, A/(g tan alpha_cg) = 2, {f['impacts']} impacts), truth lam = 0.25 "
        "(simulated at `fine`), sampled every 0.02 p*t with 1% noise, fitted back and then "
        "swept over the (omega/p, A) plane (`FLEX_PLANE` of scripts/make_docs_numbers.py, "
        f"{f['points']} points) at the interval's ends and the estimate:", 90)
    m = d["misfit"]
    misfit = textwrap.fill(
        "A model that cannot reproduce the measurement: a block under the vertical law "
        "fitted to a block whose e is 0.6 (both released from 0.7 alpha, the measurement "
        f"sampled every 0.02 p*t with 1% noise) says `{m['reason']}`, its peaks' RMS error "
        f"{m['ratio']} times the noise on {m['dof']} dof.", 90)
    return {"docs/calibration.md": {
        "calibration_generator": textwrap.fill(generator, 90),
        "calibration_output": out, "calibration_flex_intro": flex_intro,
        "calibration_flex": flex, "calibration_misfit": misfit}}


def render_fragility(d: dict) -> dict[str, dict[str, str]]:
    """docs/fragility.md's sentences on the demo suite."""
    lams = d["lam"]
    dips = (f"{d['dip_min']}" if d["dip_min"] == d["dip_max"] else
            f"{d['dip_min']}-{d['dip_max']}")
    fires = [lam for lam, r in zip(lams, d["overturn_reason"], strict=True)
             if "non_monotone" in r]
    monotone = (f"On the demo suite, whose overturning fractions dip by {dips} of "
                f"{d['n_records']} records, it " + (
                    "does not fire." if not fires else
                    f"fires at lam = {' and '.join(fires)}."))
    crossing = (f"On the demo suite, theta:0.5 and overturning of its slender body, nearly "
                f"one state, cross by {d['crossing_gap']:g} at lam = {d['crossing_lam']}: "
                + ("said." if d["crossing_said"] else "not said."))
    rej = d["parallel_rejected"]
    parallel = ("On the demo suite (theta:0.1/0.25/0.5/overturn, `--joint`) the common "
                "beta is " + (f"rejected at lam = {' and '.join(rej)}" if rej else
                              "not rejected at any lam") +
                f" (of {', '.join(lams)}).")
    ida = (f"On the demo suite ({d['n_records']} records x {len(lams)} lam) the IDA "
           f"(`--rtol 1e-2`) takes {d['ida_runs']} kernel runs.")
    commands = ("```sh\n"
                f"rocksweep sweep configs/fragility-demo.yaml -o frag.h5     # {d['runs']} runs, "
                "seconds\n"
                "rocksweep fragility frag.h5 --plot frag.png                 # lognormal MLE, "
                "bootstrap bands\n```")
    return {"README.md": {"fragility_commands": commands},
            "docs/fragility.md": {
        "fragility_monotone": textwrap.fill(monotone, 90),
        "fragility_crossing": textwrap.fill(crossing, 90),
        "fragility_parallel": textwrap.fill(parallel, 90),
        "fragility_ida": textwrap.fill(ida, 90)}}


def render_api_example(d: dict) -> dict[str, dict[str, str]]:
    """README.md: what the Python API example prints."""
    text = ("What it prints, besides the estimate's RK4 evaluations and seconds (this "
            f"machine's): {d['points']} points; mode 1 points per lam `{d['mode1']}`; "
            f"the two runs `{d['runs']}`.")
    return {"README.md": {"api_example": textwrap.fill(text, 90)}}


def render_calibration_bench(d: dict) -> dict[str, dict[str, str]]:
    """docs/calibration.md's "Measured" paragraph (the recovery, not the times)."""
    span = {k: f"{lo}-{hi}" if lo != hi else f"{lo}" for k, (lo, hi) in d["impacts"].items()}
    n = d["cases"]
    text = (
        "Synthetic truths at 200 steps per period (10x the fit's), 1% noise of max|theta|, "
        "fitted back from another start value: flexible and stiff bodies under sine and "
        f"cosine pulses (safe, {span['pulse']} impacts; the cosine cases unevenly sampled "
        f"with a NaN gap), rigid blocks rocking freely ({span['free']} impacts). Largest "
        f"error: lam {d['worst']['impact.lam']:.4f} (target 0.03), e "
        f"{d['worst']['impact.e']:.4f} (target 0.02); {d['covered']}/{n} intervals cover "
        "the truth and " + ("all are" if d["narrower"] == n else f"{d['narrower']}/{n} are")
        + " narrower at 0.3% noise than at 1%.")
    return {"docs/calibration.md": {"calibration_bench": textwrap.fill(text, 90)}}


#: how docs/accuracy.md names the shipped scenes
SCENE_LABEL = {"fig3a": "3(a)", "fig3b": "3(b)", "fig4a": "4(a)", "fig4b": "4(b)"}


def render_accuracy(d: dict) -> dict[str, dict[str, str]]:
    """docs/accuracy.md: `default` against `fine` on the shipped scenes; Figure 3(a)'s
    half-step check."""
    figs = [k for k in d["differ"] if k in SCENE_LABEL]
    others = [k for k in d["differ"] if k not in SCENE_LABEL]
    each = {d["points"][k] for k in figs}
    per = (f"of their {_thousands(each.pop())} cells each" if len(each) == 1 else
           "of " + "/".join(_thousands(d["points"][k]) for k in figs) + " cells")
    vs = ("With the rules as they stand, `default` classifies the four figures like "
          "`fine` on all but "
          + "/".join(str(d["differ"][k]) for k in figs) + f" {per} (Figures "
          + ", ".join(SCENE_LABEL[k] for k in figs) + "), and differs from `fine` on "
          + ", ".join(f"{d['differ'][k]} of {_thousands(d['points'][k])} cells of "
                      f"`configs/{k}.yaml`" for k in others)
          + " (`scripts/make_docs_numbers.py`, group `accuracy`).")
    c = d["check"]
    lams = " / ".join(c["changes_by_lam"])
    counts = " / ".join(str(n) for n in c["changes_by_lam"].values())
    check = ((f"{c['changes']} of {_thousands(c['points'])} points change (at lam = {lams}: "
              f"{counts}), knife-edge runs" if c["changes"] else
              f"No point of {_thousands(c['points'])} changes")
             + "; the overturning time's estimate is below "
             f"{c['t_p95']:g} p t at the 95th percentile, max|theta|'s below "
             f"{c['theta_p95']:g}%.")
    cap = d["step_cap"]
    top = max(cap, key=cap.get)
    rest = max((k for k in cap if k != top), key=cap.get)
    fine = d["step_cap_fine"]
    top_fine = max(fine, key=fine.get)
    spent = d["spent_fine_max"]
    top_spent = max(spent, key=spent.get)
    from rocksweep.numerics import EVENT_STEP_ALLOWANCE, Numerics

    def sci(x: float) -> str:
        return f"{x:.3g}".replace("e+0", "e").replace("e+", "e")

    events = Numerics().max_events
    caps = (f"The shipped scenes' largest step cap of a point (PAR_MAXSTEPS at their own "
            "numerics and at the finest rerun of a close call, what the cost admission "
            f"holds to the cap) is {sci(cap[top])} (`configs/{top}.yaml`), next "
            f"{sci(cap[rest])} (`configs/{rest}.yaml`); the four figures' at `fine` reach "
            f"{sci(fine[top_fine])} (Figure {SCENE_LABEL[top_fine]}). Most of a cap is the "
            f"allowance for max_events events ({sci(EVENT_STEP_ALLOWANCE * events)} at the "
            f"default {events}): the runs spend far "
            f"less, at most {_thousands(spent[top_spent])} RK4 evaluations a point on the "
            f"four figures at `fine` (Figure {SCENE_LABEL[top_spent]}; `scripts/"
            "make_docs_numbers.py`, group `accuracy`).")
    return {"docs/accuracy.md": {"accuracy_fine": textwrap.fill(vs, 90),
                                 "accuracy_check": textwrap.fill(check, 90),
                                 "accuracy_step_cap": textwrap.fill(caps, 90)}}


def render_contact(d: dict) -> dict[str, dict[str, str]]:
    """docs/contact.md: the shares that slide and lift off per figure and class, and the
    safe points' median demand."""
    def share(v: list) -> str:
        if all(x == 100.0 for x in v):
            return "100%"
        return " / ".join(f"{x:.1f}" for x in v) + "%"

    mus = " / ".join(f"{m:g}" for m in d["mu"])
    rows = ["| figure | safe (points) | mode 1 | mode 2 | lifts off (safe / mode 1 / mode 2) |",
            "|---|---|---|---|---|"]
    for name, f in d["figures"].items():
        cells = [f"{share(f['safe']['slides'])} ({f['safe']['points']})"]
        cells += [share(f[w]["slides"]) if f[w]["points"] else "no points"
                  for w in ("mode1", "mode2")]
        lifts = " / ".join("-" if f[w]["lifts_off"] is None else
                           f"{f[w]['lifts_off']:g}" if f[w]["lifts_off"] in (0.0, 100.0) else
                           f"{f[w]['lifts_off']:.1f}" for w in ("safe", "mode1", "mode2"))
        rows.append(f"| {SCENE_LABEL[name]} | " + " | ".join(cells) + f" | {lifts}% |")
    med = [f["safe_median_mu"] for f in d["figures"].values()]
    # the least mu at which under 1% of every figure's safe points would slide
    holds = next((m for k, m in enumerate(d["mu"]) if all(
        f["safe"]["slides"][k] < 1.0 for f in d["figures"].values())), None)
    head = (f"Share of each class that slides at mu = {mus}, and that lifts off (shipped 80 x "
            "80 x 3 grids with `--set outputs.contact=true`, which sweeps at `fine`; "
            "`scripts/make_docs_numbers.py`, group `contact`):")
    median = ((f"So the safe part of every diagram holds for mu >= {holds:g} (under 1% of its "
               "points would slide; " if holds is not None else
               "So the safe part of some diagram slides at every mu of the table (")
              + f"the median demand of safe points is {min(med):.2f}-{max(med):.2f});")
    return {"docs/contact.md": {"contact_table": textwrap.fill(head, 90) + "\n\n"
                                + "\n".join(rows),
                                "contact_median": textwrap.fill(median, 90)}}


RENDER = {"impact_laws": render_impact_laws, "demo": render_demo, "quick": render_quick,
          "calibration": render_calibration, "fragility": render_fragility,
          "api_example": render_api_example, "accuracy": render_accuracy,
          "calibration_bench": render_calibration_bench, "contact": render_contact}


def _markers(name: str) -> tuple[str, str]:
    return f"<!-- numbers:{name} -->", f"<!-- end numbers:{name} -->"


def blocks(text: str) -> dict[str, str]:
    """name -> the text inside each marked block of a page."""
    return {m.group(1): m.group(2).strip("\n") for m in re.finditer(
        r"<!-- numbers:(\w+) -->\n(.*?)\n<!-- end numbers:\1 -->", text, flags=re.S)}


def with_block(text: str, name: str, body: str) -> str:
    begin, end = _markers(name)
    if begin not in text or end not in text:
        raise SystemExit(f"no block {begin} ... {end}")
    head, rest = text.split(begin, 1)
    return head + f"{begin}\n{body}\n{end}" + rest.split(end, 1)[1]


def pages(numbers: dict) -> dict[Path, str]:
    """Every page with its blocks written from ``numbers``."""
    out: dict[Path, str] = {}
    for name, render in RENDER.items():
        for page, body in render(numbers[name]).items():
            path = ROOT / page
            # a page may hold several blocks of one computation: {block name: text}
            for block, text in (body.items() if isinstance(body, dict) else [(name, body)]):
                out[path] = with_block(out.get(path, path.read_text()), block, text)
    return out


def main(argv: list[str]) -> int:
    stored = json.loads(STORE.read_text()) if STORE.exists() else {}
    if "--render" not in argv:
        fresh = {name: fn() for name, fn in COMPUTE.items()}
        if "--check" in argv:
            moved = [n for n in fresh if fresh[n] != stored.get(n)]
            for n in moved:
                print(f"{n}: computed {json.dumps(fresh[n])}, stored "
                      f"{json.dumps(stored.get(n))}")
            print("up to date" if not moved else "out of date: run "
                  "python scripts/make_docs_numbers.py")
            return 1 if moved else 0
        stored.update(fresh)
        STORE.write_text(json.dumps(stored, indent=2) + "\n")
    for path, text in pages(stored).items():
        path.write_text(text)
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
