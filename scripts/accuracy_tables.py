"""Tables for the README from ``rocksweep accuracy`` reports: the presets' price, and the
setting the default preset is chosen by.

Run the study on each shipped figure scene first, e.g.

    for f in fig3a fig3b fig4a fig4b; do
        rocksweep accuracy configs/$f.yaml --points 1000 --ladder candidates -o acc_$f.h5
    done
    python scripts/accuracy_tables.py acc_fig3a.h5 acc_fig3b.h5 acc_fig4a.h5 acc_fig4b.h5

(``--ladder roots`` reports give the presets at the default root finder and a table of
every root finder.)

Prints (1) a markdown table of each preset's time per point (weighted mean over the
stratified sample: an estimate for the whole scene, one core) and outcome agreement with
the reference (+- its standard error) per scene, and (2) every setting measured on all
the scenes, cheapest first (time summed over the scenes), marking those whose agreement
is at least 99.5% on every scene, also once two standard errors are taken off (the
sample's own uncertainty): the first setting that passes with that margin is the choice
for `default`. RK4 evaluations per point (deterministic) back up the timings, which
vary by ~10% between identical settings on a shared machine.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import _here  # noqa: F401 (this checkout's rocksweep, not an installed one)
import h5py
import numpy as np

from rocksweep.numerics import PRESETS, Numerics
from rocksweep.vocab.settings import ROOTS

TARGET = 0.995


def _text(v) -> str:
    return v.decode() if isinstance(v, bytes) else str(v)


def read(path: Path) -> dict:
    with h5py.File(path) as f:
        t = f["table"]
        names = [_text(n) for n in t["setting"][:]]
        rows = {n: {k: (t[k][i] if t[k].dtype.kind != "O" else _text(t[k][i]))
                    for k in t} for i, n in enumerate(names)}
        # per preset and root finder: sampled points whose outcome equals bisection's
        same = {}
        for n in names:
            preset, _, root = n.partition("-")
            if root and f"{preset}-bisection" in names:
                same[preset, root] = int(np.sum(f[f"kernel/{n}/outcome"][:]
                                                == f[f"kernel/{preset}-bisection/outcome"][:]))
        return {"scene": _text(f.attrs["scene_name"]), "command": _text(f.attrs["command"]),
                "n": int(f.attrs["points_sampled"]), "size": int(f.attrs["points_in_scene"]),
                "rows": rows, "same": same}


TAILS = (("t_overturn", "t_overturn [p*t]"), ("theta_rel", "max|theta| rel."),
         ("theta_max", "max|theta| [alpha_cg]"), ("t_first_impact", "t_1st_impact [p*t]"),
         ("impacts", "impacts"), ("energy", "energy balance [E_ref]"))


def _tails(reports: list[dict], short: list[str]) -> None:
    """Per preset and scene: 95th percentile (max) of every error on the sampled points."""
    print("Tails: 95th percentile (max) of each error over the sampled points")
    print("| preset | scene | " + " | ".join(lab for _, lab in TAILS) + " |")
    print("|" + "---|" * (2 + len(TAILS)))
    for name in PRESETS:
        for r, sc in zip(reports, short, strict=True):
            d = r["rows"].get(name, r["rows"].get(f"{name}-{Numerics().root}"))
            if d is None or f"p95_err_{TAILS[0][0]}" not in d:
                continue
            cells = [f"{d[f'p95_err_{m}']:.1e} ({d[f'max_err_{m}']:.1e})" for m, _ in TAILS]
            print(f"| {name} | {sc} | " + " | ".join(cells) + " |")
    print()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("reports", nargs="+", type=Path)
    args = ap.parse_args()
    reports = [read(p) for p in args.reports]
    short = [r["scene"].split(":")[0] for r in reports]

    print("Commands:")
    for r in reports:
        print(f"    {r['command']}   # {r['n']} of {r['size']} points")
    print()
    head = ("| preset | steps/period, pulse_steps, event_tol, rotation_step, refine | "
            + " | ".join(
        f"{s}: us/pt, agreement" for s in short) + " |")
    print(head)
    print("|" + "---|" * (2 + len(reports)))
    for name in PRESETS:
        cells = []
        for r in reports:
            # a candidates report names the presets, a roots report "<preset>-<root>"
            d = r["rows"].get(name, r["rows"].get(f"{name}-{Numerics().root}"))
            cells.append("-" if d is None else
                         f"{d['mean_us']:.0f}, {100 * d['agreement']:.2f}% "
                         f"(+-{100 * d['agreement_se']:.2f})")
        d0 = reports[0]["rows"].get(name, reports[0]["rows"].get(f"{name}-{Numerics().root}"))
        if d0 is None:
            continue
        p = PRESETS[name]
        print(f"| {name} | {int(d0['steps_per_period'])}, {p.pulse_steps}, "
              f"{d0['event_tol']:.0e}, {p.rotation_step:g}, {p.refine} | "
              + " | ".join(cells) + " |")
    print()
    _tails(reports, short)

    if all(f"default-{root}" in r["rows"] for r in reports for root in ROOTS):
        print("Event root finders (--ladder roots): us/pt (RK4 evaluations per point), "
              "agreement; the same outcomes as bisection on how many sampled points")
        print("| preset | root | " + " | ".join(short) + " |")
        print("|" + "---|" * (2 + len(reports)))
        for name in PRESETS:
            for root in ROOTS:
                cells = []
                for r in reports:
                    d = r["rows"][f"{name}-{root}"]
                    cells.append(f"{d['mean_us']:.0f} ({d['evals_per_point']:.0f}), "
                                 f"{100 * d['agreement']:.2f}%, "
                                 f"{r['same'][name, root]}/{r['n']}")
                print(f"| {name} | {root} | " + " | ".join(cells) + " |")
        print()

    common = set.intersection(*(set(r["rows"]) for r in reports))
    ranked = []
    for name in common:
        ds = [r["rows"][name] for r in reports]
        cost = float(np.sum([d["mean_us"] for d in ds]))
        evals = float(np.sum([d["evals_per_point"] for d in ds]))
        worst = min(float(d["agreement"]) for d in ds)
        worst_2se = min(float(d["agreement"] - 2 * d["agreement_se"]) for d in ds)
        ranked.append((cost, name, evals, worst, worst_2se, ds))
    ranked.sort()
    print(f"Settings measured on every scene, cheapest first. ok: agreement >= "
          f"{100 * TARGET:.1f}% on every scene; ok-2se: also with two standard errors off")
    print(f"{'setting':>12} {'spp':>4} {'tol':>6} {'sum us/pt':>10} {'sum evals':>10} "
          f"{'worst %':>8} {'-2se %':>7}  " + "  ".join(f"{s:>12}" for s in short))
    choice = None
    for cost, name, evals, worst, worst_2se, ds in ranked:
        ok = "ok-2se" if worst_2se >= TARGET else "ok" if worst >= TARGET else ""
        if ok == "ok-2se" and choice is None:
            choice = name
        per = "  ".join(f"{100 * d['agreement']:>11.2f}%" for d in ds)
        print(f"{name:>12} {int(ds[0]['steps_per_period']):>4} {ds[0]['event_tol']:>6.0e} "
              f"{cost:>10.0f} {evals:>10.0f} {100 * worst:>8.2f} {100 * worst_2se:>7.2f}  "
              f"{per}  {ok}{'  <- default' if name == choice else ''}")


if __name__ == "__main__":
    main()
