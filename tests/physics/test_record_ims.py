"""The record IMs (Arias, CAV, D5-95, PGV/PGA, AvgSa) against independent
computations on the shipped suite (records/suite), and the drift / scale warnings."""

from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from bodies import FIG3
from scipy import integrate, signal

from rocksweep.physics import intensity as I  # noqa: E741
from rocksweep.physics.records import read_record
from rocksweep.physics.suite import MAX_FACTOR, RecordWarning, make_suite

ROOT = Path(__file__).resolve().parents[2]
SUITE = sorted((ROOT / "records" / "suite").glob("*.AT2"))
from rocksweep.physics.bodies import G  # noqa: E402 (the units of acc: g = G m/s^2)

SUB = 8  # the test's own fine resampling of the piecewise-linear record


def fine(rec):
    """The record's samples linearly resampled SUB times finer (t [s], a [m/s^2])."""
    t = np.arange(rec.acc.size) * rec.dt
    tf = np.linspace(0.0, t[-1], (rec.acc.size - 1) * SUB + 1)
    return tf, np.interp(tf, t, rec.acc) * G


@pytest.fixture(scope="module")
def records():
    return [read_record(p) for p in SUITE]


def test_arias_cav_d595_follow_the_sample_sum_on_the_shipped_suite(records):
    # Arias by Parseval (the FFT's energy equals the samples' sum of squares), CAV and
    # D5-95 by a plain loop over the samples, the first sample reaching 5% / 95%
    assert len(records) == 20
    for rec in records:
        a = rec.acc * G
        spectrum = np.fft.rfft(a, n=2 * a.size)  # zero-padded: every bin once or twice
        energy = (2.0 * np.sum(np.abs(spectrum) ** 2) - abs(spectrum[0]) ** 2
                  - abs(spectrum[-1]) ** 2) / (2 * a.size)
        arias = math.pi / (2 * G) * energy * rec.dt
        total, run, k5, k95 = math.fsum(a * a), 0.0, None, None
        for k, x in enumerate(a):
            run += x * x
            if k5 is None and run >= 0.05 * total:
                k5 = k
            if k95 is None and run >= 0.95 * total:
                k95 = k
        assert I.arias(rec.acc, rec.dt) == pytest.approx(arias, rel=1e-9)
        assert I.cav(rec.acc, rec.dt) == pytest.approx(math.fsum(np.abs(a)) * rec.dt,
                                                       rel=1e-12)
        assert I.significant_duration(rec.acc, rec.dt) == pytest.approx(
            (k95 - k5) * rec.dt, abs=1e-9)
        # the realistic range of a 20-40 s far-field record's D5-95
        assert 3.0 < I.significant_duration(rec.acc, rec.dt) < 40.0


def test_pgv_over_pga_and_avgsa_within_1pct_of_lsim(records):
    for rec in records[:3]:
        t, a = fine(rec)
        v = integrate.cumulative_trapezoid(a, t, initial=0.0)
        ratio = np.max(np.abs(v)) / np.max(np.abs(a))
        su = make_suite([rec], [rec.name], None, [], math.nan, 1.0, [1.0],
                        (0.5, 2.0))
        assert su.record_ims()["record_pgv_over_pga"][0] == pytest.approx(ratio, rel=1e-2)
        # AvgSa: the geometric mean over 10 log-spaced periods of lsim's Sa
        sas = []
        for T in np.geomspace(0.5, 2.0, 10):
            w = 2 * np.pi / T
            sys = signal.lti([-1.0], [1.0, 2 * 0.05 * w, w * w])
            tt = np.concatenate([t, t[-1] + np.arange(1, 4 * int(T / 0.01)) * 0.01 / SUB])
            aa = np.concatenate([a, np.zeros(tt.size - t.size)])
            _, u, _ = signal.lsim(sys, aa, tt)
            sas.append(w * w * np.max(np.abs(u)) / G)
        assert su.avgsa[0] == pytest.approx(np.exp(np.mean(np.log(sas))), rel=1e-2)


def test_closed_forms_on_a_sampled_sine():
    # a_i = A sin(2 pi i / N), n whole cycles of N samples: sum a_i^2 = A^2 n N / 2 and
    # sum |a_i| = A n 2 cot(pi / N) (N even); the Husid sum grows by A^2 N / 2 a cycle
    A, N, n = 0.3, 40, 10
    dt = 1.0 / N
    acc = A * np.sin(2 * np.pi * np.arange(n * N) / N)
    assert I.arias(acc, dt) == pytest.approx(math.pi / (2 * G) * (A * G) ** 2 * n / 2,
                                             rel=1e-12)
    assert I.cav(acc, dt) == pytest.approx(A * G * n * 2 / math.tan(math.pi / N) * dt,
                                           rel=1e-12)
    assert I.significant_duration(acc, dt) == pytest.approx(0.9 * n, abs=2 * dt)


def test_a_sign_change_counts_both_samples_whole():
    # the sample sum, not the interpolant's triangles: two samples of 1 g over 1 s each
    assert I.cav([1.0, -1.0], 1.0) == pytest.approx(2.0 * G, rel=1e-12)
    assert I.arias([1.0, -1.0], 1.0) == pytest.approx(math.pi / (2 * G) * 2 * G * G,
                                                      rel=1e-12)
    assert I.significant_duration([0.0, 1.0, 1.0, 0.0], 1.0) == pytest.approx(1.0)


def test_scaled_ims_follow_their_exponents(records):
    rec = records[0]
    base = make_suite([rec], ["a"], None, [], math.nan, 1.0, [1.0], (0.5, 2.0))
    acc2 = 2.0 * rec.acc
    assert I.arias(acc2, rec.dt) == pytest.approx(4.0 * base.arias[0], rel=1e-12)
    assert I.cav(acc2, rec.dt) == pytest.approx(2.0 * base.cav[0], rel=1e-12)
    assert I.significant_duration(acc2, rec.dt) == pytest.approx(base.d5_95[0], rel=1e-12)
    assert I.avg_sa(acc2, rec.dt, 0.5, 2.0) == pytest.approx(2.0 * base.avgsa[0], rel=1e-9)


@pytest.mark.parametrize(("im", "level", "of"), [
    ("AvgSa", 0.4, lambda a, dt: I.avg_sa(a, dt, 0.5, 2.0)),
    ("CAV", 3.0, I.cav),
    ("Arias", 0.8, I.arias)])
def test_avgsa_cav_and_arias_stripes_scale_each_record_to_the_level(records, im, level, of):
    # the record times its factor has the stripe's IM, computed afresh from the samples
    # (Arias grows as the factor squared: its factor is the square root of the ratio)
    su = make_suite(records[:3], ["a", "b", "c"], im, [level], math.nan, math.nan, [1.0],
                    (0.5, 2.0))
    f = su.factors(np.arange(3), np.zeros(3, np.int64), np.full(3, 0.15), np.full(3, 2.0))
    for rec, fi in zip(records[:3], f, strict=True):
        assert of(fi * rec.acc, rec.dt) == pytest.approx(level, rel=1e-9)


def caught(suite):
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        suite.warn([0.15], [2.0])
    return got


def test_drift_and_large_factors_warn_in_one_line(records):
    rec = records[0]
    ok = make_suite([rec], ["ok.AT2"], "PGA", [rec.pga * 2.0], math.nan, math.nan, [1.0])
    assert caught(ok) == []  # a baseline-corrected record scaled 2x: nothing to say
    big = make_suite([rec], ["big.AT2"], "PGA", [rec.pga * (MAX_FACTOR + 1.0)], math.nan,
                     math.nan, [1.0])
    got = caught(big)
    assert len(got) == 1 and issubclass(got[0].category, RecordWarning)
    text = str(got[0].message)
    assert "\n" not in text and "big.AT2" in text and f"{MAX_FACTOR + 1:.3g}x" in text
    # a constant 0.01 g over the first 5 s: the velocity ends 0.01 g 5 s = 0.49 m/s off
    acc = rec.acc.copy()
    acc[: int(5.0 / rec.dt)] += 0.01
    v_end = I.final_velocity(acc, rec.dt)
    assert v_end == pytest.approx(I.final_velocity(rec.acc, rec.dt) + 0.01 * G * 5.0,
                                  abs=0.01 * G * rec.dt)
    drifting = dataclasses.replace(rec, acc=acc, pga=float(np.max(np.abs(acc))))
    got = caught(make_suite([drifting], ["drift.AT2"], "PGA", [drifting.pga], math.nan,
                            math.nan, [1.0]))
    assert len(got) == 1 and "drift.AT2" in str(got[0].message)
    assert f"{v_end:+.3g} m/s" in str(got[0].message)


def test_cli_says_the_warning_in_one_line():
    from click.testing import CliRunner

    from rocksweep.cli import main

    res = CliRunner().invoke(main, ["sweep", str(ROOT / "configs" / "fragility-demo.yaml"),
                                    "--dry-run"])
    assert res.exit_code == 0, res.output
    warned = [ln for ln in res.output.splitlines() if ln.startswith("Warning:")]
    assert len(warned) == 1 and "scaled by more than 5x" in warned[0]
    assert "RecordWarning" not in res.output and "warnings.warn" not in res.output


def suite_scene(**ground):
    return {"body": dict(FIG3),
            "impact": {"lam": 0.0},
            "ground": {"records": [str(SUITE[0]), str(SUITE[1])], "p": 2.0, **ground}}


def test_avgsa_range_from_the_scene():
    from rocksweep.scene.inputs import load

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordWarning)
        sc, _ = load(suite_scene())  # default: 0.2-3 x 2 pi / p
        assert sc.suite.avgsa_range == pytest.approx((0.2 * math.pi, 3.0 * math.pi))
        assert "2 pi / p" in sc.suite.avgsa_rule
        sc, _ = load(suite_scene(scale={"im": "Sa", "period": 0.5, "values": [0.3, 0.6]}))
        assert sc.suite.avgsa_range == pytest.approx((0.1, 1.5))  # 0.2-3 x scale.period
        sc, _ = load(suite_scene(avgsa=[0.3, 2.0]))
    assert sc.suite.avgsa_range == (0.3, 2.0)
    rec = read_record(SUITE[0])
    assert sc.suite.avgsa[0] == pytest.approx(
        np.exp(np.mean(np.log(I.sa(rec.acc, rec.dt, np.geomspace(0.3, 2.0, 10))))))


@pytest.mark.parametrize("bad", [[2.0, 1.0], [0.0, 1.0], [1.0], "x", [1.0, 200.0]])
def test_bad_avgsa_range_is_one_line(bad):
    from rocksweep.errors import RocksweepError
    from rocksweep.scene.inputs import load

    with pytest.raises(RocksweepError) as err:
        load(suite_scene(avgsa=bad))
    assert "ground.avgsa = " in str(err.value) and "\n" not in str(err.value)
