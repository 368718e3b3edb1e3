"""A body from the laboratory's numbers (body.kind physical): the Pi
groups and p from the paper's definitions (section 3.1, Table 1), written out here."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import rocksweep
from rocksweep.errors import RocksweepError
from rocksweep.physics.bodies import G

LAB = {"b": 0.1, "h": 0.9, "h_A": 0.3, "m": 20.0, "m_A": 9.4, "I_A": 0.25, "k": 4000.0,
       "c": 10.0}


def scene(**body):
    return {"name": "lab", "body": {"kind": "physical", **{**LAB, **body}},
            "impact": {"lam": 0.2}, "pulse": {"shape": "sine", "w_over_p": 4.0,
                                              "A_ratio": 2.0}}


def test_pi_groups_and_p_of_a_lab_specimen():
    from rocksweep.scene.inputs import load

    sc, _ = load(scene())
    d = sc.physical
    b, h, hA, m, mA, IA, k, c = (LAB[x] for x in ("b", "h", "h_A", "m", "m_A", "I_A", "k",
                                                   "c"))
    M = m + mA
    hcg = (m * h + mA * hA) / M
    p = math.sqrt(M * G * math.hypot(b, hcg) / (IA + mA * (b * b + hA * hA)
                                                 + m * (b * b + h * h)))
    assert d["p"] == pytest.approx(p, rel=1e-12)
    assert d["wn_over_p"] == pytest.approx(math.sqrt(k / m) / p, rel=1e-12)
    assert d["zeta"] == pytest.approx(c / (2 * math.sqrt(k * m)), rel=1e-12)
    assert d["alpha_cg"] == pytest.approx(math.atan(b / hcg), rel=1e-12)
    assert d["alpha_A"] == pytest.approx(math.atan(b / hA), rel=1e-12)
    assert d["IA_ratio"] == pytest.approx(IA / (mA * (b * b + hA * hA)), rel=1e-12)
    # the body the kernel runs has the specimen's proportions (h/b, h_A/b)
    body = sc.single_point().body
    assert body.h / body.b == pytest.approx(h / b, rel=1e-12)
    assert body.h_A / body.b == pytest.approx(hA / b, rel=1e-12)
    assert "p = 3.4" in sc.physical_words()


def test_the_same_run_as_its_pi_groups():
    from rocksweep.scene.inputs import load

    sc, _ = load(scene())
    pis = {k: sc.physical[k] for k in ("wn_over_p", "zeta", "alpha_cg", "alpha_A",
                                       "mA_over_m", "IA_ratio")}
    a = rocksweep.simulate(scene()).summary
    b = rocksweep.simulate({**scene(), "body": pis}).summary
    for key in ("outcome", "impacts", "theta_max_over_alpha", "t_overturn"):
        assert a[key] == b[key]


def test_a_physical_bodys_p_is_in_the_summary_json_file_and_info(tmp_path):
    import json

    import yaml
    from click.testing import CliRunner

    from rocksweep.cli import main

    M = LAB["m"] + LAB["m_A"]
    hcg = (LAB["m"] * LAB["h"] + LAB["m_A"] * LAB["h_A"]) / M
    b = LAB["b"]
    p = math.sqrt(M * G * math.hypot(b, hcg) / (LAB["I_A"] + LAB["m_A"] * (b * b + LAB["h_A"]
                  ** 2) + LAB["m"] * (b * b + LAB["h"] ** 2)))
    assert rocksweep.simulate(scene()).summary["p"] == pytest.approx(p, rel=1e-12)
    path = tmp_path / "lab.yaml"
    path.write_text(yaml.safe_dump(scene()))
    run = CliRunner().invoke(main, ["simulate", str(path), "--json"])
    assert run.exit_code == 0, run.output
    assert json.loads(run.output)["p"] == pytest.approx(p, rel=1e-12)
    out = tmp_path / "lab.h5"
    two = {**scene(), "impact": {"lam": [0.1, 0.2]}}
    path.write_text(yaml.safe_dump(two))
    assert CliRunner().invoke(main, ["sweep", str(path), "-o", str(out), "--quiet"]
                              ).exit_code == 0
    assert float(rocksweep.open(out).attrs["p"]) == pytest.approx(p, rel=1e-12)
    info = CliRunner().invoke(main, ["info", str(out), "--json"])
    assert json.loads(info.output)["p"] == pytest.approx(p, rel=1e-12)
    assert f"p = {p:.5g} rad/s" in CliRunner().invoke(main, ["info", str(out)]).output
    # a body of Pi groups has no p of its own
    assert "p" not in rocksweep.simulate({**scene(), "body": {"kind": "block",
                                                               "alpha": 0.2}}).summary


def test_physical_columns_use_the_body_s_p():
    """A measured history in seconds and radians is read with the body's own p."""
    sim = rocksweep.simulate(scene(), {"impact.lam": 0.3, "numerics.steps_per_period": 200})
    h = sim.history
    t, th = h.p_t.values, h.theta_over_alpha.values
    keep = np.r_[t[1:] != t[:-1], True]
    ts = np.arange(0.0, t[keep][-1] + 2.0, 0.02)
    from rocksweep.scene.inputs import load

    d = load(scene())[0].physical
    df = pd.DataFrame({"t": ts / d["p"],
                       "theta": np.interp(ts, t[keep], th[keep]) * d["alpha_cg"]})
    fit = rocksweep.calibrate(scene(), df, ["impact.lam"])
    assert abs(float(fit.estimate[0]) - 0.3) < 0.03


@pytest.mark.parametrize("body, words", [
    ({"b": -0.1}, "body.b = -0.1: must be > 0"),
    ({"k": math.inf, "c": 3.0}, "body.c = 3.0: a welded top mass"),
    ({"m": [1.0, 2.0]}, "body.m = [1.0, 2.0]: must be a number"),
    ({"m_A": 1e8}, "give mA_over_m = 5000000.0: must be in"),
])
def test_inconsistent_geometry_is_one_line(body, words):
    with pytest.raises(RocksweepError) as err:
        rocksweep.simulate(scene(**body))
    assert words in str(err.value)
    assert "\n" not in str(err.value)
