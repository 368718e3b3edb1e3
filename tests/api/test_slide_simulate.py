"""``rocksweep.simulate`` of a point that gives body.mu: the sliding base's summary keys
(slide_max, slide_final, friction_loss_over_Eref beside the other energy terms, phases in
order), its history columns (x_over_b, contact_phase) in the Dataset, the CSV and the
figure; and none of them without mu. (Figure 5's flexible history variant of the slide
loop, shared with tests/kernel/test_slide_loop.py.)"""

from pathlib import Path

import numpy as np

import rocksweep
from rocksweep.compute.history import write_history_csv
from rocksweep.vocab.outcomes import STATUS_BIT
from rocksweep.vocab.phases import PHASE_WORDS, PHASES

FIG5 = Path(__file__).resolve().parents[2] / "configs" / "fig5.yaml"
FIG3A = FIG5.with_name("fig3a.yaml")
SLIDE_KEYS = {"slide_max", "slide_final", "friction_loss_over_Eref", "phases", "regime"}


def test_simulate_with_mu_reports_the_slide(tmp_path):
    sim = rocksweep.simulate(FIG5, impact__lam=0.4, body__mu=0.3)
    s = sim.summary
    assert SLIDE_KEYS <= set(s)
    assert s["phases"][0] == PHASES[0] and set(s["phases"]) <= set(PHASES)
    assert all(a != b for a, b in zip(s["phases"], s["phases"][1:], strict=False))
    assert "slid" in s["status"] and s["slide_max"] > 0
    closure = (s["work_in_over_Eref"] - s["damper_loss_over_Eref"] - s["impact_loss_over_Eref"]
               - s["friction_loss_over_Eref"] - s["energy_end_over_Eref"])
    assert abs(closure) < 1e-3 and s["friction_loss_over_Eref"] > 0
    h = sim.history
    x = h["x_over_b"].values
    assert np.nanmax(np.abs(x)) == np.float64(s["slide_max"])
    words = [PHASE_WORDS[int(c)] for c in h["contact_phase"].values]
    assert [w for i, w in enumerate(words) if i == 0 or w != words[i - 1]] == s["phases"]
    csv = tmp_path / "h.csv"
    write_history_csv([sim.run], [], csv)
    assert {"x_over_b", "contact_phase"} <= set(csv.read_text().splitlines()[0].split(","))
    assert len(sim.figure().axes) == 5  # theta's panel has the x/b axis on its right
    # the stick breaks and slip stops (rows at one time, the corner kept) are no impacts
    assert len(s["impact_losses_over_Eref"]) == s["impacts"]


def test_simulate_without_mu_has_none():
    s = rocksweep.simulate(FIG5, impact__lam=0.4).summary
    assert not SLIDE_KEYS & set(s)
    assert "x_over_b" not in rocksweep.simulate(FIG5, impact__lam=0.4).history


def test_a_lift_off_is_in_a_history_run_s_status_as_in_a_sweep_s():
    """On a base that may slide, `lifts_off` is the model's own word (the rocking corner's
    normal force fell to zero and the loop held the corner), which a sweep reports without
    contact outputs: a single run with its history reports it too. Figure 3(a)'s body at
    mu 0.3 under a sine at w/p 1.152, A 0.82, lifts off on its way over. Without mu the
    word is a contact output, reported only when asked (``outputs.contact``)."""
    sets = {"impact__lam": 0.0, "pulse__w_over_p": 1.1522727272727271,
            "pulse__A_ratio": 0.82}
    sim = rocksweep.simulate(FIG3A, body__mu=0.3, **sets)
    swept = rocksweep.run(FIG3A, overrides={"body.mu": 0.3, **{
        k.replace("__", "."): v for k, v in sets.items()}})
    assert "lifts_off" in sim.summary["status"]
    assert int(swept["status"].values.ravel()[0]) & STATUS_BIT["lifts_off"]
    assert "lifts_off" not in rocksweep.simulate(FIG3A, **sets).summary["status"]
