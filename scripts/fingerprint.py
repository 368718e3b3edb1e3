"""Bit-for-bit check of a refactor: every stored result of the shipped scenes, saved or compared.

    python scripts/fingerprint.py save  /tmp/before.npz     # on the old code
    python scripts/fingerprint.py check /tmp/before.npz     # on the new code
    python scripts/fingerprint.py diff  /tmp/before.npz     # how much a deliberate change moved

Runs the four figures, the rigid body and block scenes and the CI grid through
``rocksweep.compute.driver.sweep_arrays`` (outcome kernels), the same grids with energy
accounting on (``outputs.energy``), and Figure 5's single runs with their time histories
(history kernels). Then the ground motions beyond the pulse (``excitation_scenes``, small
grids): the shipped record, a suite, a Ricker pulse, floors (one mode swept, a list of
modes, under a record, a suite and a pulse), a second horizontal component at angles, the
vertical (a record's ``ground.vertical``, a PEER folder's UP files, ``pulse.vertical``),
each swept (outcome and energy kernels) and one point of each run alone with its history;
and A_min searched (``analysis.boundaries.a_min``: the boundary search's own rows) on four
of them. The records these scenes need beyond the shipped ones are written
(deterministically, from the shipped record) into a temporary folder.

``check`` prints the number of point-runs compared and every array that differs in any
bit (NaN equals NaN); it exits 1 if any does. ``diff`` measures a change that is meant to
move results (a numerical method's, argued in its commit): per sweep, the points whose
outcome changed, the largest and 99th-percentile changes of the overturning time and of
max|theta| where both runs agree on the outcome, and the RK4 steps (regular + event)
before and after; per single run, the outcome and the end time.
"""

from __future__ import annotations

import dataclasses
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
    for name, (scene, energy, single, amin) in excitation_scenes().items():
        for e in () if energy is None else (False, True) if energy else (False,):
            sc = dataclasses.replace(scene, energy=True) if e else scene
            for k, v in sweep_arrays(sc, jobs=2)[0].items():
                arrays[f"{name}{'+energy' if e else ''}/{k}"] = v
        if single:  # the grid's first point, run alone with its history
            names = [a.name for a in scene.axes]
            point = scene.point(dict(zip(names, (a.values[0] for a in scene.axes),
                                         strict=True)))
            run = run_point(point, scene.single_numerics)
            arrays[f"{name}[0]/out"] = np.asarray(run.out)
            for k, v in (run.history or {}).items():
                arrays[f"{name}[0]/history/{k}"] = np.asarray(v)
        if amin:
            from rocksweep.analysis.boundaries import a_min

            outcome = arrays[f"{name}/outcome"]
            for i, c in enumerate(a_min(scene, outcome, rtol=0.02, axes=amin)):
                for k in ("a_min", "lo", "hi", "mode", "runs"):
                    arrays[f"{name}/a_min[{i}]/{k}"] = np.asarray(getattr(c, k))
    return arrays


def _records(d: Path) -> dict[str, Path]:
    """The records the excitation scenes need beyond the shipped ones, written into d: a
    second horizontal component and a vertical of the shipped near-fault record, a short
    vertical at another DT, and a PEER folder of three records (H1, H2, UP) cut from it."""
    from rocksweep.physics.records import read_record, write_at2

    rec = read_record(ROOT / "records" / "synthetic_nearfault.AT2")
    out = {"nearfault": ROOT / "records" / "synthetic_nearfault.AT2"}
    out["h2"] = d / "h2.AT2"
    write_at2(out["h2"], 0.8 * np.roll(rec.acc, 300), rec.dt, "second component")
    out["up"] = d / "up.AT2"
    write_at2(out["up"], 0.4 * np.roll(rec.acc, 200), rec.dt, "vertical")
    t = np.arange(int(rec.duration / 0.007)) * 0.007  # another DT: interpolated
    out["up_fine"] = d / "up_fine.txt"
    np.savetxt(out["up_fine"], np.c_[t, 0.3 * np.interp(t, rec.times(), np.roll(rec.acc, 90))])
    peer = d / "peer"
    peer.mkdir()
    for i in range(3):
        a = rec.acc[400 * i:400 * i + 1200]
        for comp, f in (("000", 1.0), ("090", -0.7), ("-UP", 0.45)):
            write_at2(peer / f"RSN{100 + i}_EVENT_STA{comp}.AT2",
                      f * np.roll(a, 37 * i + (50 if comp != "000" else 0)), rec.dt,
                      f"RSN{100 + i}")
    out["peer"] = peer
    return out


def excitation_scenes() -> dict[str, tuple]:
    """name -> (scene, also with energy (None: not swept), one point run alone, A_min axes
    or None)."""
    import tempfile
    import warnings

    from rocksweep.physics.suite import RecordWarning
    from rocksweep.scene.inputs import load
    from rocksweep.scene.parse import load_scene

    d = Path(tempfile.mkdtemp(prefix="fingerprint-"))
    r = {k: str(v) for k, v in _records(d).items()}
    block = {"kind": "block", "alpha": 0.2, "inertia": 4.0 / 3.0}
    fig3 = {"wn_over_p": 2.43, "zeta": 0.05, "alpha_cg": 0.15, "alpha_A": 0.28,
            "mA_over_m": 0.47, "IA_ratio": 0.56}
    floor1 = {"period": [0.3, 0.6], "damping": 0.05, "participation": 1.3}
    modes2 = {"modes": [{"period": 0.5, "damping": 0.05, "participation": 1.3},
                        {"period": 0.15, "damping": 0.03, "participation": -0.4}]}
    sine = {"shape": "sine", "w_over_p": [1.5, 3.0], "A_ratio": [1.0, 2.0, 3.5]}
    dicts = {
        "x-record-vertical": ({"body": block, "ground": {
            "record": r["nearfault"], "vertical": r["up"], "A_ratio": [1.0, 2.0, 4.0, 8.0],
            "p": [1.5, 3.0]}}, True, True, ("p", "A_ratio")),
        "x-record-vertical-flex": ({"body": fig3, "impact": {"lam": 0.2}, "ground": {
            "record": r["nearfault"], "vertical": r["up_fine"], "A_ratio": [1.0, 3.0, 6.0],
            "p": [2.0, 4.0]}}, True, True, None),
        "x-pulse-vertical": ({"body": block, "pulse": {
            "shape": "sine", "w_over_p": [2.0, 4.0], "A_ratio": [0.5, 1.0, 1.5, 2.5, 4.0],
            "vertical": {"amplitude": [0.3, 1.2], "w_over_p": 9.0, "phase": 30}}},
            True, True, ("w_over_p", "A_ratio")),
        "x-pulse-vertical-flex": ({"body": fig3, "impact": {"lam": [0.0, 0.4]}, "pulse": {
            "shape": "ricker", "w_over_p": [1.0, 3.0], "A_ratio": [1.0, 4.0],
            "vertical": {"amplitude": 0.5, "w_over_p": [6.0, 12.0]}}}, True, True, None),
        "x-floor-record": ({"body": block, "ground": {
            "record": r["nearfault"], "A_ratio": [1.0, 2.0, 4.0], "p": [2.0, 3.0]},
            "floor": floor1}, True, True, ("p", "A_ratio")),
        "x-floor-pulse": ({"body": block, "pulse": sine, "floor": floor1}, True, True,
                          None),
        "x-floor-vertical": ({"body": block, "ground": {
            "record": r["nearfault"], "vertical": r["up"], "A_ratio": [1.0, 2.5],
            "p": [2.0, 3.0]}, "floor": floor1}, True, True, None),
        "x-angle-floor": ({"body": block, "ground": {
            "record": r["nearfault"], "h2": r["h2"], "angle": [0.0, 30.0, 90.0],
            "A_ratio": [1.0, 2.0], "p": [2.0, 3.0]}, "floor": floor1}, True, False, None),
        "x-angle-modes": ({"body": fig3, "impact": {"lam": 0.2}, "ground": {
            "record": r["nearfault"], "h2": r["h2"], "angle": [0.0, 45.0],
            "A_ratio": [1.0, 3.0], "p": 2.0}, "floor": modes2}, False, True, None),
        "x-peer-vertical": ({"body": block, "ground": {
            "records": r["peer"], "p": [2.0, 3.0], "angle": [0.0, 60.0],
            "scale": {"im": "PGA_ratio", "values": [1.0, 2.5]}}}, True, True, None),
        "x-peer-up": ({"body": fig3, "impact": {"lam": 0.2}, "ground": {
            "records": r["peer"], "p": 2.0,
            "scale": {"im": "PGA", "values": [0.2, 0.5]}}}, False, True, None),
        "x-floor-modes-single": ({"body": block, "ground": {
            "record": r["nearfault"], "A_ratio": 2.0, "p": 2.0}, "floor": modes2},
            False, True, None),
    }
    out: dict[str, tuple] = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordWarning)
        for name, (spec, energy, single, amin) in dicts.items():
            scene, _ = load(spec)
            if name == "x-floor-modes-single":  # run alone only: its sweep crashed (#45)
                energy = None
            out[name] = (scene, energy, single, amin)
        cfg = ROOT / "configs"
        out["x-record"] = (load_scene(cfg / "record-demo.yaml", [
            "impact.lam=[0.0, 0.4]", "ground.A_ratio={start: 0.5, stop: 6, num: 7}",
            "ground.p={start: 0.5, stop: 5, num: 6}"]), True, True, ("p", "A_ratio"))
        out["x-suite"] = (load_scene(cfg / "fragility-demo.yaml", [
            "impact.lam=0.2", "ground.scale.values=[0.2, 0.6, 1.2]"]), True, True, None)
        out["x-floor-suite"] = (load_scene(cfg / "floor-spectrum.yaml", [
            "floor.period=[0.1, 0.4, 1.6]"]), True, True, None)
        out["x-ricker"] = (load_scene(cfg / "ricker.yaml", [
            "pulse.w_over_p={start: 0.2, stop: 6, num: 12}",
            "pulse.A_ratio={start: 0.1, stop: 8, num: 12}"]), True, True,
            ("w_over_p", "A_ratio"))
    return out


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
