"""Bit-for-bit check of a refactor: every stored result of the shipped scenes, saved or compared.

    python scripts/fingerprint.py save  /tmp/before.npz     # on the old code
    python scripts/fingerprint.py check /tmp/before.npz     # on the new code

Runs the four figures, the rigid body and block scenes and the CI grid through
``rocksweep.compute.sweep.compute`` (outcome kernels), the same grids with energy accounting on
(``outputs.energy``), and Figure 5's single runs with their time histories (history
kernels). ``check`` prints the number of point-runs compared and every array that differs
in any bit (NaN equals NaN); it exits 1 if any does.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SWEEPS = ["fig3a", "fig3b", "fig4a", "fig4b", "block", "fig4a-rigid", "ci-small"]
SINGLE = ["fig5", "fig5-rigid"]


def collect() -> dict[str, np.ndarray]:
    from itertools import product

    from rocksweep.compute.single import simulate
    from rocksweep.compute.sweep import compute
    from rocksweep.scene.parse import load_scene

    arrays: dict[str, np.ndarray] = {}
    for name in SWEEPS:
        for energy in (False, True):
            sets = ["outputs.energy=true"] if energy else []
            scene = load_scene(ROOT / "configs" / f"{name}.yaml", sets)
            for k, v in compute(scene, jobs=2).items():
                arrays[f"{name}{'+energy' if energy else ''}/{k}"] = v
    for name in SINGLE:
        scene = load_scene(ROOT / "configs" / f"{name}.yaml")
        names = [a.name for a in scene.axes]
        for i, combo in enumerate(product(*(a.values for a in scene.axes))):
            run = simulate(scene.point(dict(zip(names, combo, strict=True))),
                           scene.single_numerics)
            arrays[f"{name}[{i}]/out"] = np.asarray(run.out)
            for k, v in (run.history or {}).items():
                arrays[f"{name}[{i}]/history/{k}"] = np.asarray(v)
    return arrays


def main(argv: list[str]) -> int:
    if len(argv) != 2 or argv[0] not in ("save", "check"):
        print(__doc__)
        return 2
    mode, path = argv
    arrays = collect()
    if mode == "save":
        np.savez_compressed(path, **arrays)
        print(f"saved {len(arrays)} arrays to {path}")
        return 0
    ref = np.load(path)
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
