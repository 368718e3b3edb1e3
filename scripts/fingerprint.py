"""Bit-for-bit check of a refactor: every stored result of the shipped scenes, saved or compared.

    python scripts/fingerprint.py save  /tmp/before.npz     # on the old code
    python scripts/fingerprint.py check /tmp/before.npz     # on the new code
    python scripts/fingerprint.py diff  /tmp/before.npz     # how much a deliberate change moved

Runs the four figures, the rigid body and block scenes and the CI grid through
``rocksweep.compute.driver.sweep_arrays`` (outcome kernels), the same grids with energy
accounting on (``outputs.energy``), and Figure 5's single runs with their time histories (history
kernels). ``check`` prints the number of point-runs compared and every array that differs
in any bit (NaN equals NaN); it exits 1 if any does. ``diff`` measures a change that is
meant to move results (a numerical method's, argued in its commit): per sweep, the points
whose outcome changed, the largest and 99th-percentile changes of the overturning time and
of max|theta| where both runs agree on the outcome, and the RK4 steps (regular + event)
before and after; per single run, the outcome and the end time.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the tree this script is in, not an installed copy
SWEEPS = ["fig3a", "fig3b", "fig4a", "fig4b", "block", "fig4a-rigid", "ci-small"]
SINGLE = ["fig5", "fig5-rigid"]


def collect() -> dict[str, np.ndarray]:
    from itertools import product

    from rocksweep.compute.driver import sweep_arrays
    from rocksweep.compute.single import run_point
    from rocksweep.scene.parse import load_scene

    arrays: dict[str, np.ndarray] = {}
    for name in SWEEPS:
        for energy in (False, True):
            sets = ["outputs.energy=true"] if energy else []
            scene = load_scene(ROOT / "configs" / f"{name}.yaml", sets)
            for k, v in sweep_arrays(scene, jobs=2)[0].items():
                arrays[f"{name}{'+energy' if energy else ''}/{k}"] = v
    for name in SINGLE:
        scene = load_scene(ROOT / "configs" / f"{name}.yaml")
        names = [a.name for a in scene.axes]
        for i, combo in enumerate(product(*(a.values for a in scene.axes))):
            run = run_point(scene.point(dict(zip(names, combo, strict=True))),
                            scene.single_numerics)
            arrays[f"{name}[{i}]/out"] = np.asarray(run.out)
            for k, v in (run.history or {}).items():
                arrays[f"{name}[{i}]/history/{k}"] = np.asarray(v)
    return arrays


def diff(ref: dict[str, np.ndarray], arrays: dict[str, np.ndarray]) -> None:
    """Print how far a deliberate change moved the results (see the module docstring)."""
    print(f"{'sweep':<20}{'points':>8}{'outcome flips':>15}{'t_over max':>12}{'t_over p99':>12}"
          f"{'theta max':>11}{'theta p99':>11}{'steps before':>14}{'after':>10}")
    for name in [k[:-len("/outcome")] for k in sorted(arrays) if k.endswith("/outcome")]:
        a = {k: np.asarray(ref[f"{name}/{k}"]) for k in ("outcome", "t_overturn",
             "theta_max_over_alpha", "steps", "event_steps")}
        b = {k: np.asarray(arrays[f"{name}/{k}"]) for k in a}
        flips = int(np.sum(a["outcome"] != b["outcome"]))
        same = a["outcome"] == b["outcome"]
        cols = []
        for k in ("t_overturn", "theta_max_over_alpha"):
            d = np.abs(a[k] - b[k])[same]
            d = d[np.isfinite(d)]
            cols += [d.max() if d.size else 0.0, np.percentile(d, 99) if d.size else 0.0]
        steps = [float(x["steps"].sum() + x["event_steps"].sum()) for x in (a, b)]
        print(f"{name:<20}{a['outcome'].size:>8}{flips:>15}{cols[0]:>12.2e}{cols[1]:>12.2e}"
              f"{cols[2]:>11.2e}{cols[3]:>11.2e}{steps[0]:>14.4g}{steps[1]:>10.4g}")
    from rocksweep.kernel import layout as L  # noqa: N812

    for k in sorted(k for k in arrays if k.endswith("/out") and k in ref):
        o0, o1 = np.asarray(ref[k]), np.asarray(arrays[k])
        print(f"{k:<20} outcome {o0[L.OUT_OUTCOME]:.0f} -> {o1[L.OUT_OUTCOME]:.0f}, "
              f"end p*t {o0[L.OUT_T_END]:.9g} -> {o1[L.OUT_T_END]:.9g}, impacts "
              f"{o0[L.OUT_IMPACTS]:.0f} -> {o1[L.OUT_IMPACTS]:.0f}")


def main(argv: list[str]) -> int:
    if len(argv) != 2 or argv[0] not in ("save", "check", "diff"):
        print(__doc__)
        return 2
    mode, path = argv
    arrays = collect()
    if mode == "save":
        np.savez_compressed(path, **arrays)
        print(f"saved {len(arrays)} arrays to {path}")
        return 0
    ref = np.load(path)
    if mode == "diff":
        diff(dict(ref), arrays)
        return 0
    bad: list[str] = []
    grew: list[str] = []
    n_points = 0
    for k in sorted(set(ref.files) | set(arrays)):
        if k not in ref.files or k not in arrays:
            bad.append(f"{k}: only in {'the new run' if k in arrays else path}")
            continue
        a, b = np.asarray(ref[k]), np.asarray(arrays[k])
        if k.endswith("/out") and a.ndim == b.ndim == 1 and a.size < b.size:
            # the result row grew (new slots appended at its end): compare the old slots
            grew.append(f"{k}: {a.size} -> {b.size} slots")
            b = b[:a.size]
        if k.endswith("/outcome"):
            n_points += a.size
        same = a.shape == b.shape and a.dtype == b.dtype and (
            a.tobytes() == b.tobytes()
            or np.array_equal(a, b, equal_nan=a.dtype.kind == "f"))
        if not same:
            bad.append(f"{k}: differs")
    print(f"compared {len(arrays)} arrays ({n_points} sweep point-runs); "
          f"{len(bad)} differ")
    for line in bad:
        print("  " + line)
    if grew:
        print(f"{len(grew)} single-run result rows grew (their old slots compared): "
              + "; ".join(grew[:2]) + ("; ..." if len(grew) > 2 else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
