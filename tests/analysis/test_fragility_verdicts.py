"""Fits that say when not to trust them (and analyses of files they should not
trust): one test per class of verdict, the competing-risk and ordinal
fits against independent scipy optimisations, damage-state curves that never cross on
the demo suite, partial and adaptive files, flagged points in IDA, bad arguments."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from bodies import FIG3_YAML
from helpers import one_line_error
from scipy.optimize import minimize
from scipy.stats import norm

import rocksweep
from rocksweep import errors
from rocksweep.analysis import fragility as F
from rocksweep.cli import main
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.scene.inputs import load

ROOT = Path(__file__).resolve().parents[2]
LEVELS = np.geomspace(0.1, 1.6, 12)


def stripes_ds(outcome: np.ndarray, levels=LEVELS, status=None) -> xr.Dataset:
    """A stripes Dataset (record, PGA) from outcome codes (R, S)."""
    outcome = np.asarray(outcome, np.int8)
    st = np.where(outcome > 0, L.STATUS_OVERTURNED, L.STATUS_REST).astype(np.int32)
    if status is not None:
        st = np.asarray(status, np.int32)
    R = outcome.shape[0]
    return xr.Dataset(
        {"outcome": (("record", "PGA"), outcome), "status": (("record", "PGA"), st)},
        coords={"record": [f"R{i:02d}.AT2" for i in range(R)], "PGA": levels},
        attrs={"scale_im": "PGA"})


def capacity_outcomes(n_records: int, median: float, beta: float, seed: int,
                      levels=LEVELS) -> np.ndarray:
    """Each record overturns (mode 1) from its lognormal capacity up: outcome (R, S)."""
    cap = np.random.default_rng(seed).lognormal(math.log(median), beta, n_records)
    return np.where(levels[None, :] >= cap[:, None], 1, 0)


def reasons(fr) -> set[str]:
    return set(str(fr["reason"].values).split(","))


# ---------------------------------------------------------------------------------------
# one class of verdict each; good fits stay "ok"
# ---------------------------------------------------------------------------------------


def test_a_good_fit_stays_ok_and_warns_nothing():
    ds = stripes_ds(capacity_outcomes(40, 0.5, 0.4, seed=1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # any FragilityWarning would fail here
        fr = F.fragility(ds, bootstrap=200, seed=0)
    assert str(fr["reason"].values) == "ok"
    assert 0.1 < float(fr["beta"]) < 1.0 and int(fr["n_boot_undefined"]) < 10
    med, beta = float(fr["im_median"]), float(fr["beta"])
    x = np.array([0.2, 0.5, 1.1])
    np.testing.assert_allclose(F.probability(fr, x).values,
                               norm.cdf(np.log(x / med) / beta), rtol=1e-12)


def test_one_stripe_leaves_beta_undetermined_never_zero():
    fit = F.fit_stripes([0.5], [1], [2])  # one stripe, 1 of 2 records overturn
    assert set(fit.reason.split(",")) == {"one_stripe", "beta_undetermined"}
    assert math.isnan(fit.beta) and math.isnan(fit.im_median)
    ds = stripes_ds([[0], [1]], levels=np.array([0.5]))
    with pytest.warns(errors.FragilityWarning, match="one_stripe"):
        fr = F.fragility(ds, bootstrap=0)
    assert {"one_stripe", "beta_undetermined"} <= reasons(fr) and np.isnan(fr["beta"])


def test_too_few_distinct_fractions_and_separation_leave_beta_undetermined():
    x = np.array([0.1, 0.2, 0.4, 0.8])
    n = np.full(4, 10)
    few = F.fit_stripes(x, [0, 0, 5, 5], n)  # one fraction strictly between 0 and 1
    assert "beta_undetermined" in few.reason and math.isnan(few.beta)
    sep = F.fit_stripes(x, [0, 0, 10, 10], n)
    assert set(sep.reason.split(",")) == {"separated", "beta_undetermined"}
    assert math.isnan(sep.beta) and sep.im_median == pytest.approx(math.sqrt(0.2 * 0.4))
    # two distinct fractions inside: beta is determined
    assert F.fit_stripes(x, [0, 3, 7, 10], n).reason == "ok"
    # a separated cloud: the same words
    cloud = F.fit_cloud([0.1, 0.2, 0.3, 0.4], [0, 0, 1, 1])
    assert cloud.reason == "separated,beta_undetermined" and math.isnan(cloud.beta)


def test_falling_fractions_are_non_monotone_and_resurrection_noise_is_not():
    # a state that rises then falls to nothing (20 records a stripe)
    k = np.array([0, 0, 2, 8, 14, 18, 10, 4, 1, 0, 0, 0])
    fit = F.fit_stripes(LEVELS, k, np.full(12, 20))
    assert "non_monotone" in fit.reason.split(",")
    # three records safe again above their first level (14 of 20, then 12): noise, ok
    out = capacity_outcomes(20, 0.5, 0.4, seed=4)
    out[np.flatnonzero(out[:, 7])[:3], 8] = 0  # overturned at stripe 7, safe at 8
    fr = F.fragility(stripes_ds(out), bootstrap=0)
    assert np.diff(fr["fraction"].values).min() < 0 and str(fr["reason"].values) == "ok"


def test_pool_adjacent_violators_is_the_min_max_isotonic_fit():
    # the isotonic fit's closed form: iso[s] = max_{i<=s} min_{j>=s} mean(i..j), the
    # weighted means of the counts over stripes i..j, by brute force
    from rocksweep.analysis.likelihood import isotonic_fit

    rng = np.random.default_rng(3)
    for S in (1, 2, 5, 13):
        n = rng.integers(1, 7, S).astype(float)
        k = rng.binomial(n.astype(int), 0.5, size=(40, S)).astype(float)
        want = np.empty_like(k)
        for b in range(k.shape[0]):
            for s in range(S):
                want[b, s] = max(min(k[b, i:j + 1].sum() / n[i:j + 1].sum()
                                     for j in range(s, S)) for i in range(s + 1))
        np.testing.assert_allclose(isotonic_fit(k, n), want, rtol=1e-12, atol=0.0)


def test_median_or_16_84_points_outside_the_stripes_are_extrapolated():
    # PGV-like stripes 0.05-0.8 with the capacity median above the top stripe
    lv = np.geomspace(0.05, 0.8, 8)
    ds = stripes_ds(capacity_outcomes(40, 0.93, 0.5, seed=2, levels=lv), levels=lv)
    with pytest.warns(errors.FragilityWarning, match=r"extrapolated \(im_median .* above"):
        fr = F.fragility(ds, bootstrap=0)
    assert float(fr["im_median"]) > lv.max() and "extrapolated" in reasons(fr)
    # median inside, 84% point above the stripes: also extrapolated
    lv2 = np.geomspace(0.1, 0.7, 8)
    fr2 = F.fragility(stripes_ds(capacity_outcomes(60, 0.5, 0.5, seed=3, levels=lv2),
                                 levels=lv2), bootstrap=0, warn=False)
    med, beta = float(fr2["im_median"]), float(fr2["beta"])
    assert med < lv2.max() < med * math.exp(beta)
    assert "extrapolated" in reasons(fr2)


def test_a_large_share_of_undefined_resamples_is_reported():
    # two of 12 records overturn near the top (record 1 safe again at one stripe): the
    # full data have a finite fit; a resample lacking either record has none (59 %)
    out = np.zeros((12, 12), int)
    out[0, -3:] = 1
    out[1, [-3, -1]] = 1
    fr = F.fragility(stripes_ds(out), bootstrap=200, seed=0, warn=False)
    assert np.isfinite(fr["im_median"]) and np.isfinite(fr["beta"])
    assert int(fr["n_boot_undefined"]) > 0.4 * 200
    assert "bootstrap_undefined" in reasons(fr)
    samples = fr["im_median_samples"].values
    assert samples.shape == (200,) and np.isnan(samples).sum() == int(fr["n_boot_undefined"])


def competing_outcomes(n_records=30, seed=0, levels=LEVELS):
    """Mode 2 at moderate IM, taken over by mode 1 at high IM: each record has a mode-1
    and a mode-2 capacity; at a level past either it overturns in the mode whose capacity
    is the smaller (the competing-risk model)."""
    rng = np.random.default_rng(seed)
    c1 = rng.lognormal(math.log(0.55), 0.35, n_records)
    c2 = rng.lognormal(math.log(0.9), 0.6, n_records)
    first = np.minimum(c1, c2)
    mode = np.where(c1 <= c2, 1, 2)
    return np.where(levels[None, :] >= first[:, None], mode[:, None], 0)


def test_a_mode_fitted_alone_is_censored_by_the_other_and_the_joint_fit_is_not():
    ds = stripes_ds(competing_outcomes())
    with pytest.warns(errors.FragilityWarning, match="censored"):
        alone = F.fragility(ds, state="mode2", bootstrap=0)
    assert "censored" in reasons(alone)
    joint = F.fragility(ds, state=["mode1", "mode2"], bootstrap=0, warn=False, joint=True)
    assert list(joint["fit"].values) == ["competing", "competing"]
    assert not any("censored" in r for r in joint["reason"].values)
    # mode 2 rising then vanishing (20 records): no competing-risk curve can fall
    k2 = [0, 0, 2, 8, 14, 16, 10, 4, 1, 0, 0, 0]
    k1 = [0, 0, 0, 0, 2, 4, 10, 16, 19, 20, 20, 20]
    out = np.zeros((20, 12), int)
    for s in range(12):
        out[:k1[s], s] = 1
        out[k1[s]:k1[s] + k2[s], s] = 2
    hump = F.fragility(stripes_ds(out), state=["mode1", "mode2"], bootstrap=0, warn=False,
                       joint=True)
    assert "non_monotone" in str(hump["reason"].sel(state="mode2").values).split(",")
    assert "ok" not in hump["reason"].values


def test_partial_data_are_incomplete_with_the_missing_stripes_named():
    out = capacity_outcomes(20, 0.5, 0.4, seed=5)
    out[:, -3:] = L.OUTCOME_NOT_RUN  # the top stripes not computed
    st = np.where(out > 0, L.STATUS_OVERTURNED, L.STATUS_REST)
    st[out < 0] = 0
    ds = stripes_ds(out, status=st)
    ds.attrs["complete"] = 0
    with pytest.warns(errors.FragilityWarning, match=rf"60 points not computed at PGA "
                      rf"{LEVELS[-3]:.3g}-1.6 g left out \(the file is not complete"):
        fr = F.fragility(ds, bootstrap=0)
    assert "incomplete" in reasons(fr) and int(fr["n_not_run"]) == 60


def test_flagged_points_that_could_move_the_fit_mark_it():
    out = capacity_outcomes(20, 0.5, 0.4, seed=6)
    st = np.where(out > 0, L.STATUS_OVERTURNED, L.STATUS_REST)
    j = 6  # near the median: flag 4 points that overturned there
    rows = np.flatnonzero(out[:, j] > 0)[:4]
    st[rows, j] = L.STATUS_HORIZON
    out[rows, j] = 0
    with pytest.warns(errors.FragilityWarning, match="4 flagged points left out"):
        fr = F.fragility(stripes_ds(out, status=st), bootstrap=0)
    assert "flagged" in reasons(fr) and int(fr["n_excluded"]) == 4
    assert int(fr["n_counted"][j]) == 16


# ---------------------------------------------------------------------------------------
# the joint fits against independent maximisations
# ---------------------------------------------------------------------------------------


def cif_trapezoid(x, m1, b1, m2, b2, n_u=20001):
    """(P(safe), P(mode 1), P(mode 2)) at x (S,) of independent lognormal capacities:
    P(mode k) = integral over ln c < ln x of f_k(c) S_other(c), by the trapezoid rule."""
    u = np.linspace(min(math.log(m1) - 9 * b1, math.log(m2) - 9 * b2),
                    math.log(x.max()), n_u)
    f1 = norm.pdf(u, math.log(m1), b1) * norm.sf(u, math.log(m2), b2)
    f2 = norm.pdf(u, math.log(m2), b2) * norm.sf(u, math.log(m1), b1)
    cum = [np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(u))])
           for f in (f1, f2)]
    p1, p2 = (np.interp(np.log(x), u, c) for c in cum)
    ps = norm.sf(np.log(x), math.log(m1), b1) * norm.sf(np.log(x), math.log(m2), b2)
    return ps, p1, p2


def test_competing_risk_fit_equals_an_independent_multinomial_mle():
    rng = np.random.default_rng(3)
    true = (0.6, 0.4, 0.9, 0.6)
    lv = np.geomspace(0.1, 2.0, 12)
    p = np.stack(cif_trapezoid(lv, *true), -1)
    cnt = np.array([rng.multinomial(40, q / q.sum()) for q in p])  # (S, 3)
    # the same counts as a Dataset: 40 records a stripe
    out = np.zeros((40, lv.size), int)
    for s in range(lv.size):
        out[:, s] = np.repeat([0, 1, 2], cnt[s])
    fr = F.fragility(stripes_ds(out, levels=lv), state=["mode1", "mode2"], bootstrap=0,
                     warn=False, joint=True)

    def nll(t):
        ps, p1, p2 = cif_trapezoid(lv, *np.exp(t))
        return -np.sum(cnt[:, 0] * np.log(ps) + cnt[:, 1] * np.log(p1)
                       + cnt[:, 2] * np.log(p2))

    ref = minimize(nll, np.log(true), method="Nelder-Mead",
                   options={"xatol": 1e-9, "fatol": 1e-12, "maxiter": 20000,
                            "maxfev": 20000})
    m1, b1, m2, b2 = np.exp(ref.x)
    got = fr["im_median"].values, fr["beta"].values
    np.testing.assert_allclose(got[0], [m1, m2], rtol=2e-4)
    np.testing.assert_allclose(got[1], [b1, b2], rtol=2e-4)
    # the curves: P(mode 1) + P(mode 2) + P(safe) = 1, P(safe) = S_1 S_2 at every IM
    grid = fr["im_grid"].values
    c = fr["curve"].values
    safe = (norm.sf(np.log(grid), math.log(got[0][0]), got[1][0])
            * norm.sf(np.log(grid), math.log(got[0][1]), got[1][1]))
    np.testing.assert_allclose(c.sum(0) + safe, 1.0, atol=1e-9)
    assert np.all(np.diff(c, axis=1) >= -1e-12)  # cumulative incidences never fall
    # probability() gives the same model at any IM (what a risk integral must use)
    x = np.array([0.05, 0.7, 3.0])
    ps, p1, p2 = cif_trapezoid(x, got[0][0], got[1][0], got[0][1], got[1][1], n_u=200001)
    np.testing.assert_allclose(F.probability(fr, x).values, [p1, p2], atol=1e-6)


DAMAGE = ["theta:0.1", "theta:0.25", "theta:0.5", "overturn"]


@pytest.fixture(scope="module")
def demo():
    """The demo suite of the README (configs/fragility-demo.yaml: 20 records x 16 PGA
    stripes x 3 lam), swept with the project's own tools."""
    return rocksweep.run(ROOT / "configs" / "fragility-demo.yaml")


def test_joint_damage_states_never_cross_on_the_demo_suite(demo):
    fr = rocksweep.fragility(demo, state=DAMAGE, bootstrap=50, joint=True)
    assert list(fr["fit"].values) == ["ordinal"] * 4
    # the one beta may be rejected by its likelihood-ratio test, nothing else is said
    assert set(fr["reason"].values.ravel()) <= {"ok", "parallel_rejected"}
    rejected = fr["parallel_rejected"].values
    np.testing.assert_array_equal(rejected, fr["parallel_p"].values < F.PARALLEL_P)
    for j, bad in enumerate(rejected):
        assert np.all((fr["reason"].values[:, j] == "parallel_rejected") == bad)
    c = fr["curve"].transpose("lam", "state", "im_grid").values
    assert np.all(np.diff(c, axis=1) <= 1e-12)  # each state at most the one before
    med = fr["im_median"].transpose("lam", "state").values
    assert np.all(np.diff(med, axis=1) > 0)
    beta = fr["beta"].values
    assert np.allclose(beta, beta[:1])  # one dispersion per lam
    # every resample ordered too
    s = fr["im_median_samples"].transpose("lam", "sample", "state").values
    ok = np.all(np.isfinite(s), -1)
    assert np.all(np.diff(s[ok], axis=-1) >= 0)


def test_one_state_fits_equal_the_single_fit_and_the_ordinal_mle_is_the_mle(demo):
    for st in DAMAGE:  # a one-state fit is the binomial MLE of that state
        one = rocksweep.fragility(demo, state=st, bootstrap=0).isel(lam=0)
        k = one["n_failed"].values
        n = one["n_counted"].values
        direct = F.fit_stripes(demo["PGA"].values, k, n)
        assert float(one["im_median"]) == pytest.approx(direct.im_median, rel=1e-9)
    # the ordinal fit of lam = 0 against Nelder-Mead on the multinomial likelihood
    fr = rocksweep.fragility(demo, state=DAMAGE, bootstrap=0, joint=True).isel(lam=0)
    lv = demo["PGA"].values
    reach = fr["n_failed"].values.astype(float)  # (state, S), nested
    n = fr["n_counted"].values.astype(float)
    cats = np.vstack([n - reach[0], reach[:-1] - reach[1:], reach[-1:]])  # (5, S)

    def nll(t):
        med = np.exp(np.cumsum(np.concatenate([[t[0]], np.exp(t[1:4])])))
        beta = math.exp(t[4])
        q = norm.cdf(np.log(lv[None, :] / med[:, None]) / beta)  # P(DS >= j)
        q = np.vstack([np.ones(lv.size), q, np.zeros(lv.size)])
        prob = np.maximum(q[:-1] - q[1:], 1e-300)
        return -np.sum(cats * np.log(prob))

    med0 = fr["im_median"].values
    t0 = np.concatenate([[math.log(med0[0])], np.log(np.diff(np.log(med0))),
                         [math.log(float(fr["beta"][0]))]])
    ref = minimize(nll, t0 + 0.05, method="Nelder-Mead",
                   options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 40000,
                            "maxfev": 40000})
    ref_med = np.exp(np.cumsum(np.concatenate([[ref.x[0]], np.exp(ref.x[1:4])])))
    np.testing.assert_allclose(med0, ref_med, rtol=1e-5)
    assert float(fr["beta"][0]) == pytest.approx(math.exp(ref.x[4]), rel=1e-5)


# ---------------------------------------------------------------------------------------
# files fragility and IDA should not trust as they are
# ---------------------------------------------------------------------------------------

SUITE = """
name: trust test
""" + FIG3_YAML + """impact: {lam: 0.0}
ground:
  records: [ROOT/records/suite/SYN01.AT2, ROOT/records/suite/SYN05.AT2,
            ROOT/records/suite/SYN12.AT2, ROOT/records/suite/SYN17.AT2]
  scale: {im: PGA, values: [0.2, 0.4, 0.6, 0.8, 1.2, 1.6]}
  p: 2.0
"""


@pytest.fixture(scope="module")
def suite_scene(tmp_path_factory):
    d = tmp_path_factory.mktemp("trust")
    scene = d / "s.yaml"
    scene.write_text(SUITE.replace("ROOT", str(ROOT)))
    return d, scene


def test_a_partial_file_is_fitted_as_incomplete_naming_the_missing_points(suite_scene, cli):
    """A file a sweep stopped writing (as after a kill, or while it still runs): the CLI
    warns with the missing points and marks the fit; nothing is silently dropped."""
    import rocksweep.compute.sweep as sw
    from rocksweep.scene.grid import Grid
    from rocksweep.store.writer import SweepFile

    d, scene = suite_scene
    part = d / "part.h5"
    sc, _ = load(scene)
    sf = SweepFile.create(part, sc)
    g = Grid(sc)
    sf.write(sw.run_chunk(g, 0, 18, sw.level(sc)))  # 18 of 24 points
    sf.close()
    res = cli.invoke(main, ["fragility", str(part), "--bootstrap", "0"])
    assert res.exit_code == 0, res.output
    assert "incomplete (6 points not computed at PGA 0.2-1.6 g, record SYN17.AT2 left " \
           "out" in res.stderr and res.stderr.startswith("Warning: fragility, state overturn")
    assert "the file is not complete" in res.stderr
    row = [ln for ln in res.stdout.splitlines() if ln.startswith("overturn")][0]
    assert "incomplete" in row and " 6 " in row  # the "not run" column


def test_an_adaptive_suite_refuses_states_its_fill_cannot_know(tmp_path, cli):
    ds = stripes_ds(capacity_outcomes(10, 0.5, 0.4, seed=7))
    ds["uplifts"] = ds["outcome"].astype(np.int32)
    ds["computed"] = xr.zeros_like(ds["outcome"]) + 1
    ds["computed"][::2, ::3] = 0  # 5 x 4 points filled from the class around them
    with pytest.raises(errors.FragilityError, match=r"state 'uplift': 20 points of this adaptive "
                       "sweep were filled"):
        F.fragility(ds, state="uplift", bootstrap=0)
    with pytest.raises(errors.FragilityError, match="theta:0.5"):
        F.fragility(ds, state=["overturn", "theta:0.5"], bootstrap=0)
    # the class is known at a filled point: overturn and the modes are fitted
    assert str(F.fragility(ds, bootstrap=0)["reason"].values) == "ok"


def test_ida_takes_no_flagged_stripe_as_safe_and_stops_at_a_flagged_run(suite_scene,
                                                                         monkeypatch):
    d, scene = suite_scene
    ds = rocksweep.run(scene)
    over = np.isin(ds["outcome"].transpose("record", "PGA").values, (1, 2))
    # a record overturning from stripe j >= 1 on, and at j + 1
    r = next(i for i in range(4) if over[i].argmax() >= 1 and over[i, over[i].argmax() + 1])
    j = int(over[r].argmax())
    status = ds["status"].transpose("record", "PGA").values.copy()
    status[r, j] = L.STATUS_HORIZON  # its first overturning stripe: undecided
    flagged = ds.assign(status=(("record", "PGA"), status))
    name = str(ds["record"].values[r])
    got = rocksweep.ida(flagged, rtol=0.05).sel(record=name)
    levels = ds["PGA"].values
    assert int(got["n_flagged"]) == 1 and int(got["unresolved"]) == 0
    # the flagged stripe is not taken as safe: the bracket starts below it (at j - 1), and
    # the bisection finds the crossing below levels[j] (where the record does overturn)
    assert levels[j - 1] <= float(got["ida_lo"]) < float(got["ida_hi"]) <= levels[j]
    # a bisection run that comes back flagged stops the record's bisection
    import rocksweep.analysis.ida as ida_mod

    real = ida_mod.run_point

    def flagged_run(pt, numerics, history=False):
        run = real(pt, numerics, history=history)
        run.out[L.OUT_STATUS] = int(run.out[L.OUT_STATUS]) | L.STATUS_EVENT_CAP
        return run

    monkeypatch.setattr(ida_mod, "run_point", flagged_run)
    stopped = rocksweep.ida(ds, rtol=1e-3).sel(record=name)
    assert int(stopped["unresolved"]) == 1 and int(stopped["runs"]) == 1
    assert float(stopped["ida_lo"]) == levels[j - 1] and float(stopped["ida_hi"]) == levels[j]


@pytest.mark.parametrize("kw, word", [
    ({"period": "x"}, "period = 'x'"), ({"ci": "x"}, "ci = 'x'"), ({"ci": None}, "ci = None"),
    ({"ci": [0.9]}, "ci = [0.9]"), ({"state": None}, "state = None"),
    ({"state": 5}, "state = 5"), ({"state": {"a": 1}}, "state = {'a': 1}"),
    ({"state": b"overturn"}, "state = b'overturn'"),
    ({"state": "theta:1.5"}, "0 < X <= 1"), ({"bootstrap": 10**8}, "at most 100000"),
    ({"bootstrap": -1}, "bootstrap = -1"), ({"seed": -2}, "seed = -2")])
def test_bad_arguments_are_one_line_errors(kw, word):
    ds = stripes_ds(capacity_outcomes(10, 0.5, 0.4, seed=8))
    with pytest.raises(rocksweep.RocksweepError) as err:
        rocksweep.fragility(ds, **{"bootstrap": 0, **kw})
    assert word in str(err.value) and "\n" not in str(err.value)


def test_cli_bad_arguments_write_nothing(suite_scene, cli, tmp_path):
    d, scene = suite_scene
    out = tmp_path / "s.h5"
    rocksweep.run(scene, output=out)
    for args in (["--state", "theta:2"], ["--state", "topple"], ["--ci", "1.5"],
                 ["--bootstrap", "100000000"], ["--period", "1.0"]):
        res = cli.invoke(main, ["fragility", str(out), "-o", str(tmp_path / "c.csv"),
                                *args])
        line = one_line_error(res)
        assert line.startswith("Error:"), line
        assert not (tmp_path / "c.csv").exists()


def test_a_mode2_curve_that_falls_again_at_high_pga_is_not_ok():
    """An eight-record measurement: mode 2 counts 0 0 0 0 0 0 0 1 1 2 3 1 3 1 0 0 of 8 over PGA
    0.1-1.6 g, mode 1 taking over at high PGA, was fitted "ok" with its median above every
    stripe."""
    lv = np.linspace(0.1, 1.6, 16)
    k2 = [0, 0, 0, 0, 0, 0, 0, 1, 1, 2, 3, 1, 3, 1, 0, 0]
    k1 = [0, 0, 0, 0, 0, 1, 2, 2, 3, 3, 3, 6, 4, 7, 8, 8]
    out = np.zeros((8, 16), int)
    for s in range(16):
        out[:k1[s], s] = 1
        out[k1[s]:k1[s] + k2[s], s] = 2
    with pytest.warns(errors.FragilityWarning):
        fr = F.fragility(stripes_ds(out, levels=lv), state="mode2", bootstrap=200)
    assert {"censored", "extrapolated"} <= reasons(fr)
    assert float(fr["im_median"]) > lv.max()


def test_the_figure_draws_a_competing_mode_by_its_own_model_not_a_lognormal():
    from rocksweep.figures.fragility import fragility_figure

    lv = np.geomspace(0.1, 2.0, 12)
    fr = F.fragility(stripes_ds(competing_outcomes(40, seed=1, levels=lv), levels=lv),
                     state=["mode1", "mode2"], bootstrap=0, warn=False, joint=True)
    med, beta = fr["im_median"].values, fr["beta"].values
    lines = [ln for ln in fragility_figure(fr).axes[0].get_lines() if len(ln.get_xdata())]
    assert len(lines) == 2
    x = np.asarray(lines[1].get_xdata())
    # mode 2's cumulative incidence, integrated independently (cif_trapezoid): P(C2 <= x,
    # C2 < C1), well below the lognormal CDF of its own median and beta at high IM
    _, _, p2 = cif_trapezoid(x, med[0], beta[0], med[1], beta[1], n_u=20001)
    np.testing.assert_allclose(lines[1].get_ydata(), p2, atol=1e-4)
    assert np.max(np.abs(norm.cdf(np.log(x / med[1]) / beta[1]) - p2)) > 0.05


# ---------------------------------------------------------------------------------------
# one question, one answer: separate fits by default, the joint fit tested
# ---------------------------------------------------------------------------------------


def nested_ds(n_records: int, med_mild: float, beta_mild: float, med_severe: float,
              beta_severe: float, seed: int, levels=LEVELS) -> xr.Dataset:
    """Two nested states: theta:0.5 from one lognormal capacity, overturning (mode 1)
    from a second capacity, never below the first (a record overturns only once past
    theta:0.5)."""
    rng = np.random.default_rng(seed)
    c1 = rng.lognormal(math.log(med_mild), beta_mild, n_records)
    c2 = np.maximum(c1, rng.lognormal(math.log(med_severe), beta_severe, n_records))
    x = levels[None, :]
    ds = stripes_ds(np.where(x >= c2[:, None], 1, 0), levels)
    ds["theta_max_over_alpha"] = (("record", "PGA"), np.where(x >= c1[:, None], 0.8, 0.1))
    return ds


def test_a_states_numbers_do_not_depend_on_the_other_states(demo):
    alone = rocksweep.fragility(demo, state="overturn", bootstrap=40)
    many = rocksweep.fragility(demo, state=DAMAGE, bootstrap=40).sel(state="overturn")
    for v in ("im_median", "beta", "im_median_samples", "beta_samples", "curve"):
        np.testing.assert_array_equal(alone[v].values, many[v].values)
    hz = ROOT / "configs" / "hazard-example.csv"
    a = rocksweep.risk(alone, hz)["annual_rate"].values
    b = rocksweep.risk(many.expand_dims(state=["overturn"]), hz)["annual_rate"].values[0]
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=0.0)


def test_separate_curves_that_cross_in_the_data_say_crossing():
    # theta:0.5 spread wide, overturning steep just above its median: the separate
    # overturning curve passes above theta:0.5's at the top stripes
    ds = nested_ds(60, 0.5, 0.8, 0.55, 0.05, seed=3)
    fr = F.fragility(ds, state=["theta:0.5", "overturn"], bootstrap=0, warn=False)
    c = fr["curve"].values
    grid = fr["im_grid"].values
    inside = (grid >= LEVELS[0]) & (grid <= LEVELS[-1])
    assert np.max(c[1, inside] - c[0, inside]) > F.CROSSING_TOL  # they do cross
    assert all("crossing" in str(r).split(",") for r in fr["reason"].values)
    # one shared capacity: the same curve twice, nothing crosses
    same = nested_ds(60, 0.5, 0.4, 0.01, 0.1, seed=3)
    fr2 = F.fragility(same, state=["theta:0.5", "overturn"], bootstrap=0, warn=False)
    assert not any("crossing" in str(r) for r in fr2["reason"].values)


def test_the_joint_fits_parallel_test_is_a_likelihood_ratio_and_rejects_unequal_betas():
    from scipy.stats import chi2

    ds = nested_ds(80, 0.4, 0.8, 0.7, 0.15, seed=5)
    fr = F.fragility(ds, state=["theta:0.5", "overturn"], bootstrap=0, warn=False,
                     joint=True)
    # the free (beta per state) multinomial likelihood by Nelder-Mead, against the common
    k = fr["n_failed"].values.astype(float)  # (2, S) reaching each state
    n = fr["n_counted"].values.astype(float)
    cats = np.vstack([n - k[0], k[0] - k[1], k[1]])

    def nll(t):
        q = norm.cdf(np.log(LEVELS[None, :] / np.exp(t[:2, None])) / np.exp(t[2:, None]))
        q = np.vstack([np.ones(LEVELS.size), q, np.zeros(LEVELS.size)])
        return -np.sum(cats * np.log(np.maximum(q[:-1] - q[1:], 1e-300)))

    med, beta = fr["im_median"].values, float(fr["beta"].values[0])
    common = nll(np.log([med[0], med[1], beta, beta]))
    free = minimize(nll, np.log([med[0], med[1], beta, beta]), method="Nelder-Mead",
                    options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 20000}).fun
    assert float(fr["parallel_lr"]) == pytest.approx(2 * (common - free), rel=1e-4)
    assert int(fr["parallel_dof"]) == 1
    assert float(fr["parallel_p"]) == pytest.approx(chi2.sf(2 * (common - free), 1), rel=1e-3)
    assert bool(fr["parallel_rejected"]) and float(fr["parallel_p"]) < 1e-3
    assert all("parallel_rejected" in str(r) for r in fr["reason"].values)
    # the states drawn with one beta: not rejected
    ok = F.fragility(nested_ds(80, 0.4, 0.4, 0.7, 0.4, seed=5), state=["theta:0.5",
                     "overturn"], bootstrap=0, warn=False, joint=True)
    assert not bool(ok["parallel_rejected"])


def test_each_joint_resample_fit_is_the_ordinal_mle_of_the_records_it_draws():
    # 4 records: 40 resamples draw 20 distinct multisets of records (repeats are fitted
    # once); each resample refitted from scratch as a Dataset of the records it draws
    R, N, seed = 4, 40, 1
    ds = nested_ds(R, 0.4, 0.5, 0.7, 0.5, seed=2, levels=np.geomspace(0.1, 1.6, 24))
    states = ["theta:0.5", "overturn"]
    fr = F.fragility(ds, state=states, joint=True, bootstrap=N, seed=seed, warn=False)
    draws = np.random.default_rng(seed).integers(0, R, size=(N, R))
    assert len({tuple(sorted(d)) for d in draws}) < N
    med_s, beta_s = fr["im_median_samples"].values, fr["beta_samples"].values
    finite = 0
    for i, d in enumerate(draws):
        one = ds.isel(record=d).assign_coords(record=[f"D{j}.AT2" for j in range(R)])
        ref = F.fragility(one, state=states, joint=True, bootstrap=0, warn=False)
        med, beta = ref["im_median"].values, ref["beta"].values
        fin = np.isfinite(med) & np.isfinite(beta)
        np.testing.assert_array_equal(np.isfinite(med_s[:, i]), fin)
        np.testing.assert_allclose(med_s[fin, i], med[fin], rtol=1e-6)
        np.testing.assert_allclose(beta_s[fin, i], beta[fin], rtol=1e-6)
        finite += int(fin.all())
    assert finite > N // 2


def test_the_joint_models_jacobians_equal_central_differences_of_their_probabilities():
    from rocksweep.analysis.likelihood import _cif, _cif_jac, _ordinal_jac, _ordinal_probs

    rng = np.random.default_rng(4)
    z = 1.5 * rng.standard_normal((2, 9))
    theta = 0.5 * rng.standard_normal((2, 4))  # ordinal: K = 3 states; competing: 2 modes

    def ordinal(th):
        return np.exp(_ordinal_probs(z, th))

    def competing(th):
        return np.stack(_cif(z, th[:, [0, 2]], np.exp(th[:, [1, 3]])), 1)

    h = 1e-6
    for prob, jac in ((ordinal, _ordinal_jac(z, theta)),
                      (competing, _cif_jac(z, theta[:, [0, 2]], np.exp(theta[:, [1, 3]])))):
        num = np.stack([(prob(theta + h * e) - prob(theta - h * e)) / (2 * h)
                        for e in np.eye(4)], 1)
        np.testing.assert_allclose(jac, num, atol=1e-8)


def test_a_competing_fit_over_a_wide_im_range_reaches_the_maximum():
    # 100 stripes over three decades: P(mode k) cancels to 0 at the low stripes, where an
    # information J^2 / p taken there stalled the ascent 2-40 % short of the maximum
    # while saying "ok"
    lv = np.geomspace(0.01, 10.0, 100)
    out = competing_outcomes(10, seed=3, levels=lv)
    fr = F.fragility(stripes_ds(out, levels=lv), state=["mode1", "mode2"], bootstrap=0,
                     warn=False, joint=True)
    assert set(fr["reason"].values) == {"ok"}
    cnt = np.stack([(out == c).sum(0) for c in (0, 1, 2)], -1)  # (S, 3)

    def nll(t):
        p = np.stack(cif_trapezoid(lv, *np.exp(t)), -1)
        return -np.sum(np.where(cnt > 0, cnt * np.log(np.maximum(p, 1e-300)), 0.0))

    med, beta = fr["im_median"].values, fr["beta"].values
    t0 = np.log([med[0], beta[0], med[1], beta[1]])
    ref = minimize(nll, t0 + 0.05, method="Nelder-Mead",
                   options={"xatol": 1e-8, "fatol": 1e-10, "maxiter": 4000})
    assert nll(t0) <= ref.fun + 1e-6
    np.testing.assert_allclose(t0, ref.x, atol=1e-4)


def test_a_file_without_records_is_named_with_the_way_out(tmp_path):
    import yaml
    from click.testing import CliRunner

    scene = tmp_path / "one.yaml"
    scene.write_text(yaml.safe_dump({"body": {"kind": "block", "alpha": 0.2},
                                     "impact": {"lam": 0.0},
                                     "pulse": {"shape": "sine", "w_over_p": 4.0,
                                               "A_ratio": [2.0, 3.0]}}))
    out = tmp_path / "one.h5"
    assert CliRunner().invoke(main, ["sweep", str(scene), "-o", str(out), "--quiet"]
                              ).exit_code == 0
    run = CliRunner().invoke(main, ["fragility", str(out)])
    assert run.exit_code != 0
    assert str(out) in run.output and "ground.records" in run.output
    assert run.output.count("\n") == 1


def test_a_verdicts_way_out_is_said_in_the_callers_words():
    """The way out a verdict names is an argument: Python reads ``joint=True`` /
    ``joint=False``, the command line's ``Warning:`` line ``--joint`` / ``without --joint``
    (through the one map of options, as an error's)."""
    from rocksweep.cli.main import warning_line

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", errors.FragilityWarning)
        F.fragility(stripes_ds(competing_outcomes()), state="mode2", bootstrap=0)
        F.fragility(nested_ds(80, 0.4, 0.8, 0.7, 0.15, seed=5),
                    state=["theta:0.5", "overturn"], bootstrap=0, joint=True)
    censored = [w.message for w in caught if "censored" in str(w.message)]
    rejected = [w.message for w in caught if "parallel_rejected" in str(w.message)]
    assert censored and rejected
    for m in censored:
        assert str(m).endswith("fit mode1 and mode2 together (joint=True))")
        assert warning_line(m).startswith("Warning: fragility, state mode2: ")
        assert warning_line(m).endswith("fit mode1 and mode2 together (--joint))")
    for m in rejected:
        assert "fit them separately (joint=False)" in str(m) and "--" not in str(m)
        assert "fit them separately (without --joint)" in warning_line(m)
        assert "joint=" not in warning_line(m)


def test_a_period_without_sa_names_the_im_in_the_callers_words():
    from rocksweep.cli.main import said

    ds = stripes_ds(capacity_outcomes(10, 0.5, 0.4, seed=8))
    ds.attrs.pop("scale_im")  # a cloud: the IM per record
    with pytest.raises(errors.FragilityError) as err:
        F.fragility(ds, period=1.0, bootstrap=0)
    assert str(err.value) == "period = 1.0: only with im = 'Sa'"
    assert said(err.value) == "--period 1.0: only with --im Sa"
    with pytest.raises(errors.FragilityError) as err:
        F.fragility(ds, im="Sa", period=-1.0, bootstrap=0)
    assert said(err.value).startswith("--period -1.0: a period in s") \
        and said(err.value).endswith("with --im Sa")


# ---------------------------------------------------------------------------------------
# convergence: an ascent that stops without meeting its test says so
# ---------------------------------------------------------------------------------------


def test_an_ascent_that_cannot_raise_a_quantised_likelihood_is_not_converged():
    # the parameters rounded to 0.01 inside the probabilities: every small step leaves the
    # likelihood flat while its gradient (the smooth model's) is not 0; stopping there is
    # no maximum (the ascent used to call it converged)
    from rocksweep.analysis.likelihood import _maximise

    z = np.linspace(-2.0, 2.0, 9)
    n = np.full(z.size, 20.0)
    k = np.round(n * norm.cdf(0.3 + 1.2 * z))
    m = np.stack([n - k, k])[None]  # (1, 2, P)

    def smooth(th):
        return norm.cdf(th[:, :1] + th[:, 1:] * z)

    def prob(th, rows):
        p = smooth(np.round(th, 2))
        return np.stack([1.0 - p, p], 1)

    def jac(th, rows):
        d = norm.pdf(th[:, :1] + th[:, 1:] * z)
        dp = np.stack([d, d * z], 1)  # (b, 2, P)
        return np.stack([-dp, dp], 2)

    start = np.array([[0.25, 1.1], [0.0, 0.5], [1.0, 3.0]])
    mm = np.repeat(m, 3, 0)
    _, conv = _maximise(prob, mm, start, np.array([60.0, 60.0]), jac=jac)
    assert not conv.any()
    # the same ascent on the smooth probabilities reaches the maximum and says so
    theta, conv = _maximise(lambda th, r: np.stack([1.0 - smooth(th), smooth(th)], 1), mm,
                            start, np.array([60.0, 60.0]), jac=jac)
    assert conv.all()
    ref = minimize(lambda t: -np.sum(k * norm.logcdf(t[0] + t[1] * z)
                                     + (n - k) * norm.logsf(t[0] + t[1] * z)), [0.0, 1.0],
                   method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-12})
    np.testing.assert_allclose(theta, np.repeat(ref.x[None], 3, 0), atol=1e-6)


@pytest.mark.parametrize("joint", [False, True])
def test_a_fit_stopped_by_its_iteration_cap_says_not_converged(monkeypatch, joint):
    from rocksweep.analysis import likelihood as LK

    ds = nested_ds(60, 0.4, 0.5, 0.7, 0.5, seed=5)
    states = ["theta:0.5", "overturn"]
    fr = F.fragility(ds, state=states, bootstrap=0, warn=False, joint=joint)
    assert set(fr["reason"].values) == {"ok"}
    monkeypatch.setattr(LK, "SCORE_ITER", 1)
    monkeypatch.setattr(LK, "MAX_ITER", 1)
    with pytest.warns(errors.FragilityWarning, match="not_converged"):
        capped = F.fragility(ds, state=states, bootstrap=0, joint=joint)
    assert all("not_converged" in str(r).split(",") for r in capped["reason"].values)
    assert np.all(np.isnan(capped["im_median"].values))
    assert "not_converged" in F.fit_stripes(LEVELS, [0, 1, 2, 5, 9, 12, 14, 17, 18, 19, 20,
                                                     20], [20] * 12).reason


def test_the_parallel_tests_jacobian_equals_central_differences_of_its_probabilities():
    from rocksweep.analysis.likelihood import _free_ordinal_jac, _free_ordinal_probs

    rng = np.random.default_rng(7)
    z = 1.5 * rng.standard_normal(9)
    theta = np.array([[-0.8, 0.1, 0.9, 0.2, -0.1, 0.3], [-0.5, 0.4, 1.2, 0.0, 0.2, -0.2]])
    h = 1e-6
    num = np.stack([(_free_ordinal_probs(z, theta + h * e)
                     - _free_ordinal_probs(z, theta - h * e)) / (2 * h) for e in np.eye(6)], 1)
    np.testing.assert_allclose(_free_ordinal_jac(z, theta), num, atol=1e-8)
