"""Hard cases of the sliding base (``kernel.slide_loop``, docs/sliding.md): friction at
Shenton's boundary mu = tan(alpha) exactly, a nearly frictionless base, stick-slip
reversals all through a record, slipping impacts followed by slide-rock. Each stays finite,
ends (no step or event cap, no horizon) and closes its energy balance (friction included)
to 1e-4 E_ref.

Cost: the slide loop's history variants (rigid on pulses and on records, flexible on
pulses; the first two shared with tests/kernel/test_slide_loop.py), a few points."""

import math
from dataclasses import replace
from pathlib import Path

import pytest

from rocksweep.compute.single import run_point
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody
from rocksweep.physics.points import Point
from rocksweep.scene.parse import load_scene
from rocksweep.vocab.outcomes import SLID
from rocksweep.vocab.phases import PHASE_CODE, SLIDE, SLIDE_ROCK

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
FINE = Numerics.preset("fine")


def _closure(s: dict) -> float:
    """W_in - D_damp - E_impact - D_fric - E_end, over E_ref (the summary's energies)."""
    return (s["work_in_over_Eref"] - s["damper_loss_over_Eref"] - s["impact_loss_over_Eref"]
            - s["friction_loss_over_Eref"] - s["energy_end_over_Eref"])


def _ended_well(s: dict) -> None:
    assert not {"nonfinite", "step_cap", "event_cap", "horizon"} & set(s["status"])
    assert math.isfinite(s["slide_max"]) and math.isfinite(s["theta_max_over_alpha"])
    assert abs(_closure(s)) < 1e-4


@pytest.mark.parametrize("mu,shape,A", [(math.tan(0.3), "sine", 1.5),
                                        (math.tan(0.3), "cosine", 3.0), (1e-3, "sine", 1.5)])
def test_hard_friction_values_end(mu, shape, A):
    """mu = tan(alpha) exactly (a sliding block's uplift moment is M g b for good: it
    slides, never tips) and mu = 1e-3: finite, no stall, energy closes."""
    s = run_point(Point(BlockBody(alpha=0.3), 0.0, shape, 2.0, A, mu=mu), FINE).summary()
    _ended_well(s)
    assert s["uplifts"] == 0 and SLID in s["status"]


def test_stick_slip_under_the_record_ends():
    """The shipped near-fault record on a block at mu 0.25 < tan(alpha): stick-slip
    reversals all through the record (slide, rest, slide, ...), every one a located event;
    the run ends at rest, finite, its energy closed."""
    sc = load_scene(CONFIGS / "record-demo.yaml",
                    ["impact.lam=0.0", "ground.A_ratio=1.5", "ground.p=2.0", "body.mu=0.25"])
    pt = replace(sc.single_point(), body=BlockBody(alpha=0.3))
    r = run_point(pt, FINE)
    s = r.summary()
    _ended_well(s)
    assert s["phases"].count(SLIDE) >= 3 and "rest" in s["status"]


def test_slipping_impacts_then_slide_rock_end():
    """Figure 5's point at mu 0.2: the base slides, tips while sliding and slide-rocks
    through impacts: an impact met slipping (slide-rock at theta = 0) that goes on in
    slide-rock on the other corner; the run settles: finite, bounded, energy closed."""
    sc = load_scene(CONFIGS / "fig5.yaml", ["impact.lam=0.4", "body.mu=0.2"])
    r = run_point(sc.single_point(), FINE)
    s = r.summary()
    _ended_well(s)
    h = r.history
    code = PHASE_CODE[SLIDE_ROCK]
    slipping_impacts = [
        i for i in range(len(h["t"]) - 1)
        if h["t"][i] == h["t"][i + 1] and h["contact_phase"][i] == code
        and h["contact_phase"][i + 1] == code and h["phase"][i + 1] == -h["phase"][i] != 0]
    assert slipping_impacts
    assert s["theta_max_over_alpha"] < 1.0
