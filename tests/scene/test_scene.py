"""Scene validation: one table of keys, a prompt one-line answer for every input.

Each refused input (absurd values, values that hang, duplicate keys) asserts the exact
message, that it is a SceneError (a RocksweepError) and that the answer comes at
once (< 5 s, generous: the inputs below hung or crashed before).
"""

import math
import re
import time
from pathlib import Path

import pytest
from bodies import FIG3, FIG3_YAML

from rocksweep.cli import main
from rocksweep.errors import BodyError, RocksweepError, SceneError
from rocksweep.numerics import MAX_POINT_STEPS
from rocksweep.physics.bodies import BlockBody, FlexibleBody
from rocksweep.physics.points import body_omega_rock
from rocksweep.scene.parse import MAX_POINTS, load_scene, parse_scene

CONFIGS = Path(__file__).resolve().parents[2] / "configs"

GOOD = """
""" + FIG3_YAML + """impact: {lam: 0.4}
pulse: {shape: sine, w_over_p: 5.3, A_ratio: 5.0}
"""
SRC = "s.yaml"


def sub(old: str, new: str) -> str:
    assert old in GOOD
    return GOOD.replace(old, new, 1)


def refused(text: str, overrides: tuple[str, ...] = ()) -> str:
    """The one-line message (without the source prefix) of a refused scene."""
    t0 = time.perf_counter()
    with pytest.raises(SceneError) as info:
        parse_scene(text, SRC, list(overrides))
    assert time.perf_counter() - t0 < 5.0
    assert isinstance(info.value, RocksweepError)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith(f"{SRC}: ")
    return msg[len(SRC) + 2:]


def accepted(text: str, overrides: tuple[str, ...] = ()):
    t0 = time.perf_counter()
    scene = parse_scene(text, SRC, list(overrides))
    assert time.perf_counter() - t0 < 5.0
    return scene


# -- the table's messages, from scenes and from Python --------------------------------

TABLE_CASES = [
    ("zeta: 0.05", "zeta: 1.0e+300", "body.zeta = 1e+300: must be in [0, 1e+06]"),
    ("wn_over_p: 2.43", "wn_over_p: 1.0e+9",
     "body.wn_over_p = 1000000000.0: must be in [1e-06, 1e+06] (omega_n/p), or .inf for a "
     "rigid body"),
    ("alpha_cg: 0.15", "alpha_cg: 1.6", "body.alpha_cg = 1.6: must be in [1e-06, pi/2) rad"),
    ("mA_over_m: 0.47", "mA_over_m: 0", "body.mA_over_m = 0.0: must be in [1e-06, 1e+06]"),
    ("lam: 0.4", "lam: [0.0, 2.5]", "impact.lam = 2.5: must be in [0, 2]"),
    ("A_ratio: 5.0", "A_ratio: .nan",
     "pulse.A_ratio = nan: must be a finite number (negative: a pulse in the other direction)"),
    ("w_over_p: 5.3", "w_over_p: {start: 0, stop: 6, num: 4}",
     "pulse.w_over_p = 0.0: must be > 0 and finite (the pulse lasts 2 pi/omega)"),
]


@pytest.mark.parametrize("old, new, message", TABLE_CASES)
def test_out_of_range_value(old, new, message):
    assert refused(sub(old, new)) == message


@pytest.mark.parametrize("key, value, message", [
    ("zeta", -1.0, "body.zeta = -1.0: must be in [0, 1e+06]"),
    ("zeta", 1e300, "body.zeta = 1e+300: must be in [0, 1e+06]"),
    ("alpha_cg", 1.6, "body.alpha_cg = 1.6: must be in [1e-06, pi/2) rad"),
    ("mA_over_m", 1e300, "body.mA_over_m = 1e+300: must be in [1e-06, 1e+06]"),
    ("wn_over_p", math.nan,
     "body.wn_over_p = nan: must be in [1e-06, 1e+06] (omega_n/p), or .inf for a rigid body"),
])
def test_a_body_from_python_gets_the_scenes_message(key, value, message):
    with pytest.raises(BodyError) as info:
        FlexibleBody(**{**FIG3, key: value})
    assert str(info.value) == message
    assert refused(sub(f"{key}: {FIG3[key]}", f"{key}: {value!r}".replace("nan", ".nan"))
                   ) == message
    with pytest.raises(BodyError, match=re.escape("body.inertia = 0.5: must be in [1, 1e+06]")):
        BlockBody(alpha=0.2, inertia=0.5)


def test_overrides_use_the_same_checks():
    assert refused(GOOD, ("body.mA_over_m=[1.0e-300, 1.0e+300]",)) == (
        "body.mA_over_m = 1e-300: must be in [1e-06, 1e+06]")


def test_an_override_to_null_leaves_the_key_out_and_a_null_in_the_file_is_refused():
    with_e = GOOD.replace("impact: {lam: 0.4}", "impact: {law: constant, e: 0.9}")
    s = parse_scene(with_e, SRC, overrides=["impact.law=vertical", "impact.e=null",
                                            "impact.lam=0.3"])
    assert s.axis("law").values == ("vertical",) and "e" not in [a.name for a in s.axes]
    # leaving out a key of a section the scene does not have adds no section
    plain = parse_scene(GOOD, SRC)
    free = parse_scene(GOOD, SRC, overrides=["initial.theta_over_alpha=null"])
    assert [a.name for a in free.axes] == [a.name for a in plain.axes] and free.text == plain.text
    assert refused(GOOD.replace("impact: {lam: 0.4}", "impact: {lam: null}"), ()) == (
        "impact.lam = null: must be in [0, 2], or leave the key out")


# -- structure: sections, unknown and missing keys, types -----------------------------

STRUCTURE_CASES = [
    (GOOD.replace(FIG3_YAML, "body: 3\n"),
     "body = 3: must be a mapping with keys wn_over_p, zeta, alpha_cg, alpha_A, mA_over_m, "
     "IA_ratio (a flexible body), or kind: block, alpha, inertia"),
    (GOOD.replace("pulse: {shape: sine, w_over_p: 5.3, A_ratio: 5.0}", "pulse: [1, 2]"),
     "pulse = [1, 2]: must be a mapping with keys shape, w_over_p, A_ratio, cycles, gamma, nu, "
     "vertical"),
    (sub("wn_over_p: 2.43", "kind: [block], wn_over_p: 2.43"),
     "body.kind = ['block']: must be one of flexible, block, physical"),
    (sub("zeta: 0.05", "zeta: 0.05, zta: 1"),
     "body.zta: unknown key for a flexible body (allowed: kind, wn_over_p, zeta, alpha_cg, "
     "alpha_A, mA_over_m, IA_ratio, mu, mu_static)"),
    (GOOD + "numerics: {tol: 1}\n",
     "numerics.tol: unknown key (allowed: accuracy, steps_per_period, pulse_steps, refine, "
     "event_tol, horizon, rest_rate, max_events, root, rotation_step)"),
    (GOOD + "foo: 1\n",
     "foo: unknown key (allowed: name, body, impact, pulse, numerics, outputs, ground, "
     "refine, initial, floor)"),
    (sub(", A_ratio: 5.0", ""),
     "pulse.A_ratio: missing required key (a number, a list of numbers or a range "
     "{start, stop, num})"),
    (sub("impact: {lam: 0.4}\n", ""), "impact: missing required section (impact: {lam})"),
    (sub("A_ratio: 5.0", "A_ratio: true"),
     "pulse.A_ratio = True: must be a number, a list of numbers or a range {start, stop, num}"),
    (sub("shape: sine", "shape: square"),
     "pulse.shape = 'square': must be sine, cosine, ricker, mp or a list of them"),
    (GOOD + "outputs: {energy: 'yes'}\n",
     "outputs.energy = 'yes': must be true or false (store energy metrics)"),
    (GOOD + "name: 3\n", "name = 3: must be a string (the scene's title)"),
    ("[1, 2]", "a scene is a YAML mapping with sections body, impact, pulse, numerics, "
     "outputs, ground, refine, initial, floor (got [1, 2])"),
]


@pytest.mark.parametrize("text, message", STRUCTURE_CASES)
def test_structure(text, message):
    assert refused(text) == message


# -- YAML: numbers, duplicate keys, depth ---------------------------------------------

def test_scientific_notation_without_a_dot_is_a_number():
    scene = accepted(sub("A_ratio: 5.0", "A_ratio: [1e-6, 1E+3, -2e5, 5e0]"))
    assert scene.axis("A_ratio").values == (1e-6, 1e3, -2e5, 5.0)
    scene = accepted(GOOD, ("pulse.A_ratio=1e-6", "impact.lam=2E-1"))
    assert scene.axis("A_ratio").values == (1e-6,) and scene.axis("lam").values == (0.2,)


def test_duplicate_keys_are_refused_with_their_line():
    assert refused(GOOD + "impact: {lam: 0.3}\n") == (
        "YAML error at line 5: key 'impact' given twice in one mapping")
    assert refused(sub("zeta: 0.05", "zeta: 0.05, zeta: 0.1")) == (
        "YAML error at line 2: key 'zeta' given twice in one mapping")


def test_deep_nesting_is_one_line():
    deep = "[" * 3000 + "]" * 3000
    assert refused(GOOD + f"name: {deep}\n") == (
        "YAML error at line 5: nested more than 20 levels deep")
    assert refused(GOOD, (f"name={deep}",)).startswith("overrides['name']: value '[[[[")
    assert refused(GOOD, (f"name={deep}",)).endswith(
        "is not valid YAML (error at line 1: nested more than 20 levels deep)")


def test_yaml_syntax_error():
    assert refused(sub("{shape: sine,", "{shape: sine")) == (
        "YAML syntax error at line 4, column 29: expected ',' or '}', but got ':'")


# -- ranges and duplicate values ------------------------------------------------------

@pytest.mark.parametrize("spec, message", [
    ("{start: 1, stop: 2, num: 2.5}", "pulse.A_ratio.num = 2.5: must be an integer >= 1"),
    ("{start: 1, stop: 2, num: '10'}", "pulse.A_ratio.num = '10': must be an integer >= 1"),
    ("{start: 1, stop: 2, num: 1e10}",
     "pulse.A_ratio.num = 10000000000.0: must be an integer >= 1"),
    ("{start: 1, stop: 2, num: 10000000000}",
     "pulse.A_ratio.num = 10000000000: at most 1,000,000 values per axis"),
    ("{start: 1, num: 3}", "pulse.A_ratio.stop: missing (a range is {start, stop, num}, num "
     "values from start to stop inclusive)"),
    ("{start: 1, stop: 2, num: 3, step: 1}",
     "pulse.A_ratio.step: unknown key in a range (allowed: start, stop, num)"),
    ("{start: 1, stop: .inf, num: 3}", "pulse.A_ratio.stop = inf: must be a finite number"),
    ("{start: 1, stop: 1, num: 3}",
     "pulse.A_ratio = {start: 1.0, stop: 1.0, num: 3}: start = stop, so the value 1.0 "
     "repeats; the values of an axis must differ (they label the result's coordinates)"),
])
def test_bad_range(spec, message):
    assert refused(sub("A_ratio: 5.0", f"A_ratio: {spec}")) == message


def test_duplicate_axis_values():
    assert refused(sub("lam: 0.4", "lam: [0.2, 0.2]")) == (
        "impact.lam: the value 0.2 is given twice; the values of an axis must differ (they "
        "label the result's coordinates)")
    assert refused(sub("shape: sine", "shape: [sine, sine]")) == (
        "pulse.shape = ['sine', 'sine']: a shape is given twice; the values of an axis must "
        "differ")


# -- size ----------------------------------------------------------------------------

def test_grids_beyond_the_point_limit_are_refused_with_their_size():
    big = "{start: 1, stop: 2, num: 100000}"
    assert refused(sub("A_ratio: 5.0", f"A_ratio: {big}").replace(
        "w_over_p: 5.3", f"w_over_p: {big}")) == (
        "the grid has 10,000,000,000 points (100,000 pulse.A_ratio x 100,000 "
        "pulse.w_over_p): at most 200,000,000 points per scene (a sweep file stores 45 "
        "bytes a point); split it into several scenes or use fewer values")
    # two body keys with 1e5 values each: refused before any body is built
    assert refused(sub("zeta: 0.05", "zeta: {start: 0, stop: 0.1, num: 100000}").replace(
        "alpha_cg: 0.15", "alpha_cg: {start: 0.1, stop: 0.2, num: 100000}")).startswith(
        "the grid has 10,000,000,000 points (100,000 body.zeta x 100,000 body.alpha_cg)")
    mega = "{start: 1, stop: 2, num: 1000000}"
    assert refused(sub("A_ratio: 5.0", f"A_ratio: {mega}").replace(
        "w_over_p: 5.3", f"w_over_p: {mega}")).startswith(
        "the grid has 1,000,000,000,000 points")
    assert MAX_POINTS == 200_000_000


def test_a_large_body_grid_is_checked_at_once():
    """1e8 bodies (1e4 x 1e4): checked at the keys' extremes, not body by body."""
    text = sub("zeta: 0.05", "zeta: {start: 0, stop: 0.1, num: 10000}").replace(
        "alpha_cg: 0.15", "alpha_cg: {start: 0.1, stop: 0.2, num: 10000}")
    assert accepted(text).size == 10**8
    # one unphysical corner (alpha_cg = 0.9 puts the top mass below the base) is found
    bad = text.replace("stop: 0.2, num: 10000", "stop: 0.9, num: 10000")
    assert refused(bad) == (
        "body: alpha_cg = 0.9, alpha_A = 0.28, mA_over_m = 0.47 put the top mass at h/b = "
        "-0.468 (must be > 0: the top mass cannot sit below the base); lower alpha_cg, raise "
        "alpha_A or lower mA_over_m")
    h_over_b = 1.47 / math.tan(0.9) - 0.47 / math.tan(0.28)  # the message's h/b
    assert f"{h_over_b:.4g}" == "-0.468"


def test_scene_size_and_sweep_bytes():
    scene = accepted(sub("lam: 0.4", "lam: [0.0, 0.2, 0.4]").replace(
        "A_ratio: 5.0", "A_ratio: {start: 1, stop: 5, num: 10}"))
    assert scene.size == 30
    # int8 outcome; int32 impacts, uplifts, status; float64 theta_max, t_overturn;
    # int64 steps, event_steps: 45 bytes a point; coordinates 8 bytes a value
    from rocksweep.store.format import file_bytes

    # coordinates: 16 bytes a value of every axis (the stored axis and its bounds)
    coords = sum(16 * len(a.values) for a in scene.axes)
    assert file_bytes(scene) == 30 * 45 + coords
    energy = accepted(GOOD + "outputs: {energy: true}\n")
    # + three float64 energy metrics
    assert file_bytes(energy) == 45 + 3 * 8 + sum(16 * len(a.values) for a in energy.axes)


# -- cost: every accepted point runs in bounded time ----------------------------------

def _expected_steps(w: float, A: float, wn: float = FIG3["wn_over_p"],
                    zeta: float = FIG3["zeta"], mu: float = FIG3["mA_over_m"],
                    spp: int = 5 * 8, ps: int = 12 * 8,
                    horizon: float = 200.0, max_events: int = 5000) -> float:
    """PAR_MAXSTEPS as the kernel's docs define it: 20 x (ceil(t_pulse/dt_on) +
    ceil(horizon/dt)) + 200 x max_events, t_pulse = 2 pi/w; dt = the shorter of the spring's
    period over spp x max(1, (27.5/omega_rock)^(2/5)) (or, for a spring that oscillates
    while rocking, zeta' < 1, over the n at which RK4's leading-order damping of it,
    omega_rock (2 pi/n)^5/144, is min(0.1, 0.002 + zeta' omega_rock/38) (5/spp)^5, if more)
    and the rocking's (2 pi) over spp;
    dt_on = dt, the pulse's period over max(ps, spp) and the amplitude's (2 pi/sqrt(|A| tan
    alpha_cg)) over spp, the shortest. Default: `default`'s finest refinement (3 doublings
    of 5 steps per period and 12 per pulse period), the scene's costliest run."""
    body = FlexibleBody(**{**FIG3, "wn_over_p": wn, "zeta": zeta, "mA_over_m": mu})
    omega_rock = body_omega_rock(body)
    n_spring = spp * max(1.0, (27.5 / omega_rock) ** 0.4)
    zeta_rock = body.zeta * omega_rock / body.omega_n  # zeta sqrt(Gamma) if underdamped
    if zeta_rock < 1.0:
        tol = min(0.1, 0.002 + zeta_rock * omega_rock / 38)
        n_damp = 2 * math.pi * (omega_rock / (144 * tol * (5 / spp) ** 5)) ** 0.2
        n_spring = max(n_spring, n_damp)
    dt = min(2 * math.pi / omega_rock / n_spring, 2 * math.pi / spp)
    w_amp = math.sqrt(abs(A) * math.tan(0.15))
    dt_on = min(dt, 2 * math.pi / w / max(ps, spp),
                2 * math.pi / w_amp / spp if w_amp > 0 else math.inf)
    t_pulse = 2 * math.pi / w
    first = t_pulse / dt_on
    first = math.ceil(first) if math.isfinite(first) else math.inf
    return 20 * (first + math.ceil(horizon / dt)) + 200 * max_events


REFINED = " when a close call is refined 3 times (numerics.refine = 3) ("


COST_CASES = [  # (old, new, key, expected steps kwargs, direction of the bound)
    ("w_over_p: 5.3", "w_over_p: 1.0e-9", "pulse.w_over_p", dict(w=1e-9, A=5.0), ">="),
    ("w_over_p: 5.3", "w_over_p: 1.0e-300", "pulse.w_over_p", dict(w=1e-300, A=5.0), ">="),
    ("A_ratio: 5.0", "A_ratio: 1.0e+300", "|pulse.A_ratio|", dict(w=5.3, A=1e300), "<="),
    ("A_ratio: 5.0", "A_ratio: -1.0e+300", "|pulse.A_ratio|", dict(w=5.3, A=-1e300), "<="),
    ("wn_over_p: 2.43", "wn_over_p: 1.0e+5", "body.wn_over_p", dict(w=5.3, A=5.0, wn=1e5),
     "<="),
    ("zeta: 0.05", "zeta: 1.0e+4", "body.zeta", dict(w=5.3, A=5.0, zeta=1e4), "<="),
    ("mA_over_m: 0.47", "mA_over_m: 1.0e-6", "body.mA_over_m",
     dict(w=5.3, A=5.0, mu=1e-6), ">="),
]


@pytest.mark.parametrize("old, new, key, kw, op", COST_CASES)
def test_a_point_beyond_the_step_cap_is_refused_with_the_bound(old, new, key, kw, op):
    msg = refused(sub(old, new))
    steps = _expected_steps(**kw)
    assert steps > MAX_POINT_STEPS
    value = new.split(": ")[1]
    lead = (f"{key.strip('|')} = {float(value)!r}: one point could need {steps:.2g} RK4 steps"
            + REFINED)
    assert msg.startswith(lead), msg
    assert ("more than the cap of 1e+08 a point (~8.5 s of one core); with the scene's other "
            f"values {key} must be {op} ") in msg
    bound = float(msg.rsplit(" ", 1)[1])
    # the bound is where the cap is reached: at it the scene is accepted, 2% beyond refused
    sign = -1.0 if value.startswith("-") else 1.0
    beyond = bound * (1.02 if op == "<=" else 1 / 1.02)
    accepted(sub(old, new.replace(value, repr(sign * bound))))
    assert "one point could need" in refused(sub(old, new.replace(value, repr(sign * beyond))))


def test_numerics_that_would_hang_are_refused():
    tol = "must be in [1e-12, 1) (p*t; below 1e-12 an event time t ~ 1e2 is at float64's " \
          "resolution)"
    for v in ("1.0e-20", "1.0e-300"):
        assert refused(GOOD + f"numerics: {{event_tol: {v}}}\n") == (
            f"numerics.event_tol = {float(v)!r}: {tol}")
    accepted(GOOD + "numerics: {event_tol: 1.0e-12}\n")
    assert refused(GOOD + "numerics: {steps_per_period: 1e23}\n") == (
        "numerics.steps_per_period = 1e+23: must be an integer in [4, 1e9]")
    msg = refused(GOOD + "numerics: {steps_per_period: 1000000}\n")
    steps = _expected_steps(w=5.3, A=5.0, spp=8_000_000, ps=96)
    assert msg.startswith(f"numerics.steps_per_period = 1000000: one point could need "
                          f"{steps:.2g} RK4 steps" + REFINED)
    msg = refused(GOOD + "numerics: {horizon: 1.0e+300}\n")
    steps = _expected_steps(w=5.3, A=5.0, horizon=1e300)
    assert msg.startswith(f"numerics.horizon = 1e+300: one point could need {steps:.2g} RK4 "
                          "steps" + REFINED)


def test_the_refinement_is_checked_too():
    """The certification of close calls re-runs a point at up to 8x the steps (refine = 3):
    a scene whose finest rerun would pass the step cap is refused, naming numerics.refine;
    without certification it runs."""
    wn = 1000.0
    assert _expected_steps(w=5.3, A=5.0, wn=wn, spp=5, ps=12) < MAX_POINT_STEPS
    assert _expected_steps(w=5.3, A=5.0, wn=wn) > MAX_POINT_STEPS
    msg = refused(sub("wn_over_p: 2.43", f"wn_over_p: {wn}"))
    steps = _expected_steps(w=5.3, A=5.0, wn=wn)
    assert msg.startswith(f"body.wn_over_p = 1000.0: one point could need {steps:.2g} RK4 "
                          "steps" + REFINED), msg
    accepted(sub("wn_over_p: 2.43", f"wn_over_p: {wn}") + "numerics: {refine: 0}\n")
    accepted(sub("wn_over_p: 2.43", "wn_over_p: 300.0"))


def test_shipped_scenes_stay_valid():
    for path in sorted(CONFIGS.glob("*.yaml")):
        t0 = time.perf_counter()
        load_scene(path)
        assert time.perf_counter() - t0 < 5.0


def test_cli_reports_one_line_without_traceback(cli, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(sub("w_over_p: 5.3", "w_over_p: 1.0e-9"))
    res = cli.invoke(main, ["simulate", str(bad)])
    assert res.exit_code == 2
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.output
    assert lines[0].startswith(f"Error: {bad}: pulse.w_over_p = 1e-09: one point could need ")


def test_the_key_reference_in_the_docs_is_the_schema():
    """docs/scenes.md's table of keys is written from rocksweep.schema.KEYS (one
    definition): a key added, removed or reworded without regenerating it fails here."""
    import subprocess
    import sys

    root = CONFIGS.parent
    proc = subprocess.run([sys.executable, str(root / "scripts" / "make_docs_keys.py"),
                           "--check"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    text = (root / "docs" / "scenes.md").read_text()
    from rocksweep.schema import KEYS

    assert all(f"| `{k}` |" in text for k in KEYS)
