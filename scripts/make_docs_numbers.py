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
  (``rocksweep info``; ~3 s): docs/diagrams.md.

Benchmark timings quoted in the docs are not regenerated here (they vary with the
machine and its load); docs/performance.md lists each with the script that measures it.
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
    import warnings

    import rocksweep

    warnings.simplefilter("ignore")  # the demo's record warnings: said in the docs
    ds = rocksweep.run(ROOT / "configs" / "fragility-demo.yaml", jobs=2)
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


def _mode1_counts(name: str) -> dict:
    """{lam: mode 1 points} of configs/NAME.yaml and the points per lam."""
    import numpy as np

    from rocksweep.compute.driver import sweep_arrays
    from rocksweep.kernel import layout as L  # noqa: N812
    from rocksweep.scene.parse import load_scene

    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    out = np.asarray(sweep_arrays(scene, jobs=2)[0]["outcome"])
    i = [a.name for a in scene.swept].index("lam")
    lams = scene.axis("lam").values
    return {"mode1": {f"{lam:g}": int((np.take(out, [k], axis=i) == L.OUTCOME_MODE1).sum())
                      for k, lam in enumerate(lams)},
            "points_per_lam": int(out.size // out.shape[i])}


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


COMPUTE = {"impact_laws": compute_impact_laws, "demo": compute_demo, "quick": compute_quick}
#: the computations of seconds, rerun by tests/test_docs_numbers.py (the others take minutes)
CHEAP = ("quick",)


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
    return {"README.md": {"quick_start": textwrap.fill(start, 90),
                          "single_runs": textwrap.fill(shows, 90)},
            "docs/diagrams.md": {"mode1_points": textwrap.fill(
                mode1, 90, subsequent_indent="  ")}}


RENDER = {"impact_laws": render_impact_laws, "demo": render_demo, "quick": render_quick}


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
