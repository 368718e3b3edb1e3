"""Every kernel variant with an effect switched off equals the general kernel with that
effect at zero; the welded limit; early exits.

Variants (``rocksweep.kernel``): kinds flexible / flexible_undamped / rigid, each at the
bookkeeping levels outcome-only and energy (sweeps) and with energy + history (single
runs). All are compiled from the same functions with compile-time flags, so the state they
integrate must agree to round-off whenever the physics agrees.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from bodies import FIG3, SHARED

from rocksweep.compute.dispatch import history_capacity
from rocksweep.compute.single import run_point
from rocksweep.kernel import chunk_kernel, point_kernel
from rocksweep.kernel import equations as eq
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.kernel.ridge import ridge_energy, ridge_theta
from rocksweep.numerics import Numerics
from rocksweep.physics.bodies import BlockBody, FlexibleBody, G, restitution, restitution_rigid
from rocksweep.physics.points import Point, kernel_kind, point_row
from rocksweep.physics.reference import reference_run
from rocksweep.vocab.laws import CONSTANT, EQ1, LOCKED

TABLE3 = dict(SHARED)  # Table 3 without omega_n/p
# A short horizon keeps undamped runs (which may never come to rest) cheap.
NUM = Numerics.preset("draft", horizon=20.0)
ENERGY_COLS = [L.OUT_W_IN, L.OUT_D_DAMP, L.OUT_E_IMPACT, L.OUT_E_GAINED, L.OUT_N_GAINING,
               L.OUT_E_END]
CONTACT_COLS = [L.OUT_MU_REQ, L.OUT_N_MIN, L.OUT_IMPULSE_MAX]  # tests/test_contact.py
OUTCOME_COLS = [c for c in range(L.N_OUT)
                if c not in ENERGY_COLS + CONTACT_COLS
                and c not in (L.OUT_HIST_ROWS, L.OUT_STATUS)]  # status: by bit, below
# A small grid that crosses safe, mode 1 and mode 2 (sine and cosine, lam 0 and 0.4).
GRID = [(shape, lam, w, a) for shape in ("sine", "cosine") for lam in (0.0, 0.4)
        for w in (0.8, 3.0, 8.0) for a in (0.8, 2.5, 6.0)]


def rows_for(body) -> np.ndarray:
    """Parameter rows float64[len(GRID), N_PAR] of the test grid for ``body``."""
    return np.array([point_row(Point(body, lam, shape, w, a), NUM) for shape, lam, w, a in GRID])


def run_chunk(kind: int, level: int, rows: np.ndarray) -> np.ndarray:
    outs = np.empty((rows.shape[0], L.N_OUT))
    chunk_kernel(kind, level)(rows, outs)
    return outs


def run_points(kind: int, rows: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """The single-run (energy + history) kernel on every row: results and histories."""
    outs = np.empty((rows.shape[0], L.N_OUT))
    hists = []
    for i, row in enumerate(rows):
        hist = np.empty((history_capacity(row), L.N_HIST))
        point_kernel(kind)(row, outs[i], hist)
        hists.append(hist[: int(outs[i, L.OUT_HIST_ROWS])])
    return outs, hists


# the history variants always track the ground reactions (rocksweep.compute.single clears these
# bits when a run did not ask for contact): compare the other bits
CONTACT_BITS = L.STATUS_SLIDES | L.STATUS_LIFTS_OFF


def assert_same_outcomes(a: np.ndarray, b: np.ndarray, cols=OUTCOME_COLS, ignore: int = 0
                         ) -> None:
    np.testing.assert_array_equal(a[:, L.OUT_OUTCOME], b[:, L.OUT_OUTCOME])
    mask = ~(CONTACT_BITS | ignore)
    np.testing.assert_array_equal(a[:, L.OUT_STATUS].astype(int) & mask,
                                  b[:, L.OUT_STATUS].astype(int) & mask)
    np.testing.assert_allclose(a[:, cols], b[:, cols], rtol=1e-12, atol=1e-14)


def assert_covers_all_outcomes(outs: np.ndarray) -> None:
    """The comparison means something only if the grid rocks, impacts and overturns."""
    codes = set(outs[:, L.OUT_OUTCOME].astype(int))
    assert {L.OUTCOME_SAFE, L.OUTCOME_MODE1, L.OUTCOME_MODE2} <= codes
    assert np.any((outs[:, L.OUT_OUTCOME] == L.OUTCOME_SAFE) & (outs[:, L.OUT_IMPACTS] > 0))


@pytest.fixture(scope="module")
def bodies() -> dict:
    return {
        "flexible": FlexibleBody(**FIG3),
        "undamped": FlexibleBody(**{**FIG3, "zeta": 0.0}),
        "rigid": FlexibleBody(wn_over_p=math.inf, **TABLE3),
        "block": BlockBody(alpha=0.15),
    }


def test_kernel_kind_picks_the_effects_a_body_calls_for(bodies):
    assert kernel_kind(bodies["flexible"]) == L.KIND_FLEXIBLE
    assert kernel_kind(bodies["undamped"]) == L.KIND_FLEXIBLE_UNDAMPED
    assert kernel_kind(bodies["rigid"]) == L.KIND_RIGID
    assert kernel_kind(bodies["block"]) == L.KIND_RIGID


# ---------------------------------------------------------------------------------------
# Damping switched off == damped kernel at zeta = 0
# ---------------------------------------------------------------------------------------


def test_undamped_kernel_equals_damped_kernel_at_zero_zeta(bodies):
    rows = rows_for(bodies["undamped"])
    assert np.all(rows[:, L.PAR_C] == 0.0)
    for level in (L.LEVEL_OUTCOME, L.LEVEL_ENERGY):
        general = run_chunk(L.KIND_FLEXIBLE, level, rows)
        special = run_chunk(L.KIND_FLEXIBLE_UNDAMPED, level, rows)
        cols = OUTCOME_COLS + (ENERGY_COLS if level == L.LEVEL_ENERGY else [])
        assert_same_outcomes(general, special, cols)
    assert_covers_all_outcomes(general)
    # histories too, row by row
    out_g, hist_g = run_points(L.KIND_FLEXIBLE, rows)
    out_s, hist_s = run_points(L.KIND_FLEXIBLE_UNDAMPED, rows)
    assert_same_outcomes(out_g, out_s, OUTCOME_COLS + ENERGY_COLS)
    for hg, hs in zip(hist_g, hist_s, strict=True):
        np.testing.assert_allclose(hg, hs, rtol=1e-12, atol=1e-14)
    np.testing.assert_array_equal(out_s[:, L.OUT_D_DAMP], 0.0)  # no damper, no damper loss


def test_damping_is_not_ignored(bodies):
    """The converse: with zeta > 0 the damped kernel differs from the undamped physics."""
    damped = run_chunk(L.KIND_FLEXIBLE, L.LEVEL_ENERGY, rows_for(bodies["flexible"]))
    undamped = run_chunk(L.KIND_FLEXIBLE, L.LEVEL_ENERGY, rows_for(bodies["undamped"]))
    assert np.all(damped[:, L.OUT_D_DAMP] > 0)
    assert not np.allclose(damped[:, L.OUT_THETA_MAX], undamped[:, L.OUT_THETA_MAX])


# ---------------------------------------------------------------------------------------
# Bookkeeping: outcome-only == energy == history, for every kind
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["flexible", "undamped", "rigid"])
def test_bookkeeping_levels_give_identical_outcomes(bodies, name):
    body = bodies[name]
    kind = kernel_kind(body)
    bounded_rows = rows_for(body)
    # every level to rest: the outcome-only kernel ends a flexible run at its energy's
    # bound (``flexible_bounded``), which the others do not test
    rows = bounded_rows.copy()
    rows[:, L.PAR_TO_REST] = 1.0
    outcome_only = run_chunk(kind, L.LEVEL_OUTCOME, rows)
    energy = run_chunk(kind, L.LEVEL_ENERGY, rows)
    history, hists = run_points(kind, rows)
    assert_covers_all_outcomes(outcome_only)
    # ending there keeps every outcome, and a flexible body's theta_max, to the bit (a rigid
    # body's bound gives the peak to come in closed form, ``rigid_peak``)
    bounded = run_chunk(kind, L.LEVEL_OUTCOME, bounded_rows)
    cols = [L.OUT_OUTCOME, L.OUT_T_OVERTURN] + ([L.OUT_THETA_MAX] if name != "rigid" else [])
    for col in cols:
        np.testing.assert_array_equal(bounded[:, col], outcome_only[:, col])
    ends = (bounded[:, L.OUT_STATUS].astype(int) & L.STATUS_BOUNDED) > 0
    assert ends.any()
    assert np.all(bounded[ends, L.OUT_T_END] < outcome_only[ends, L.OUT_T_END])
    # (the outcome-only kernel flags a flexible run's bound, then 'bounded', not 'horizon',
    # and its OUT_MARGIN takes the energy's margin there: ``loop._decided``)
    flex_bits = 0 if name == "rigid" else L.STATUS_BOUNDED | L.STATUS_HORIZON
    cols = [c for c in OUTCOME_COLS
            if name == "rigid" or c not in (L.OUT_MARGIN, L.OUT_T_CLOSE)]
    assert_same_outcomes(outcome_only, energy, cols, ignore=flex_bits)
    assert_same_outcomes(outcome_only, history, cols, ignore=flex_bits)
    np.testing.assert_allclose(energy[:, ENERGY_COLS], history[:, ENERGY_COLS], rtol=1e-12,
                               atol=1e-14)
    # the outcome-only kernel keeps no energy account and no history ...
    assert np.all(np.isnan(outcome_only[:, ENERGY_COLS]))
    assert np.all(outcome_only[:, L.OUT_HIST_ROWS] == 0)
    assert np.all(energy[:, L.OUT_HIST_ROWS] == 0)
    # ... the history kernel records the run to its end
    for out, hist in zip(history, hists, strict=True):
        assert hist[-1, L.HIST_T] == out[L.OUT_T_END]
        assert hist[-1, L.HIST_E] == pytest.approx(out[L.OUT_E_END], rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("name", ["rigid", "block"])
def test_rigid_energy_balance(bodies, name):
    """Rigid kernel with energy accounting: work of the ground = energy left + lost in
    impacts (no damper), up to the integration error."""
    body = bodies[name]
    pinned = Numerics.preset("default", steps_per_period=20, event_tol=1e-8)  # not the preset
    rows = np.array([point_row(Point(body, lam, shape, w, a), pinned) for shape, lam, w, a in GRID])
    out = run_chunk(L.KIND_RIGID, L.LEVEL_ENERGY, rows)
    assert np.all(out[:, L.OUT_D_DAMP] == 0.0)
    balance = out[:, L.OUT_W_IN] - out[:, L.OUT_E_IMPACT] - out[:, L.OUT_E_END]
    alive = out[:, L.OUT_OUTCOME] == L.OUTCOME_SAFE  # overturned runs gain unbounded energy
    assert np.all(np.abs(balance[alive]) < 1e-4 * body.E_ref)
    assert np.any(out[alive, L.OUT_E_IMPACT] > 0.01 * body.E_ref)


def test_simulate_runs_bookkeeping_only_when_asked(bodies):
    point = Point(bodies["flexible"], 0.2, "sine", 3.0, 2.5)
    lean = run_point(point, NUM, history=False)
    full = run_point(point, NUM, history=True)
    assert lean.history is None and "work_in_over_Eref" not in lean.summary()
    assert full.history is not None and "work_in_over_Eref" in full.summary()
    np.testing.assert_array_equal(lean.out[OUTCOME_COLS], full.out[OUTCOME_COLS])


# ---------------------------------------------------------------------------------------
# Rigid variants among themselves
# ---------------------------------------------------------------------------------------


def test_block_equals_welded_body_of_the_same_geometry(bodies):
    """The rigid kernel sees M, b, h_cg, I_O only: a uniform-block description with the
    same slenderness and I_O/(M R^2) as the welded two-mass body is the same body."""
    welded = bodies["rigid"]
    block = BlockBody(alpha=welded.alpha_cg, inertia=welded.I_O / (welded.M * welded.R_cg**2))
    assert block.p == pytest.approx(1.0) and welded.p == pytest.approx(1.0)
    assert float(restitution_rigid(block, 0.3)) == pytest.approx(
        float(restitution_rigid(welded, 0.3)), rel=1e-12)
    a = run_chunk(L.KIND_RIGID, L.LEVEL_OUTCOME, rows_for(welded))
    b = run_chunk(L.KIND_RIGID, L.LEVEL_OUTCOME, rows_for(block))
    assert_covers_all_outcomes(a)
    np.testing.assert_array_equal(a[:, L.OUT_OUTCOME], b[:, L.OUT_OUTCOME])
    np.testing.assert_array_equal(a[:, L.OUT_IMPACTS], b[:, L.OUT_IMPACTS])
    for col in (L.OUT_THETA_MAX, L.OUT_T_END, L.OUT_T_FIRST_IMPACT, L.OUT_T_OVERTURN):
        np.testing.assert_allclose(a[:, col], b[:, col], rtol=1e-8)


def test_rigid_body_is_not_the_stiff_flexible_body_after_an_impact(bodies):
    """Why the welded limit below stops at the first impact: eq. (1) lets no impulse through
    the spring, so even a stiff flexible body loses more at impact than the welded one
    (paper, section 3: e(lam = 0, u = 0) is much smaller than Housner's)."""
    stiff = FlexibleBody(wn_over_p=1e4, **TABLE3)
    e_flex = float(restitution(stiff, 0.0, 0.0, upper=True))
    e_rigid = float(restitution_rigid(bodies["rigid"], 0.0))
    assert e_flex < e_rigid - 0.1


def test_flexible_body_tends_to_the_welded_body_before_impact(bodies):
    """Uplift time and (impact-free) overturning time converge to the rigid kernel's as
    wn_over_p grows; the spring's transient makes the approach oscillate, so only the
    overall decrease is checked."""
    fine = Numerics.preset("fine", steps_per_period=400, event_tol=1e-12)

    def times(body, numerics):
        out = np.empty(L.N_OUT)
        row = point_row(Point(body, 0.0, "sine", 1.0, 3.0), numerics)
        hist = np.empty((history_capacity(row), L.N_HIST))
        point_kernel(kernel_kind(body))(row, out, hist)
        hist = hist[: int(out[L.OUT_HIST_ROWS])]
        assert out[L.OUT_OUTCOME] == L.OUTCOME_MODE2
        return hist[np.nonzero(hist[:, L.HIST_PHASE] != 0)[0][0], L.HIST_T], out[
            L.OUT_T_OVERTURN]

    t_up_rigid, t_over_rigid = times(bodies["rigid"], fine)
    d_up, d_over = [], []
    for wn in (40.0, 160.0, 640.0):
        t_up, t_over = times(FlexibleBody(wn_over_p=wn, **TABLE3), NUM)
        d_up.append(abs(t_up - t_up_rigid))
        d_over.append(abs(t_over - t_over_rigid))
    assert d_up[-1] < 1e-4 and d_up[-1] < d_up[0] / 100
    assert d_over[-1] < 1e-4 and d_over[-1] < d_over[0] / 10


# ---------------------------------------------------------------------------------------
# Early exits
# ---------------------------------------------------------------------------------------


def _stopped_early(out: np.ndarray, row: np.ndarray) -> None:
    horizon_end = row[L.PAR_TEND]
    assert not int(out[L.OUT_STATUS]) & L.STATUS_FLAGGED
    assert out[L.OUT_T_END] < row[L.PAR_TPULSE] + 0.05 * (horizon_end - row[L.PAR_TPULSE])
    # the loop really stopped: the regular steps cover [0, t_end], not the horizon; the
    # rotation limit (PAR_ROT_STEP) adds about one step per rot of the body's turning (a
    # fall: pi/2), counted twice here
    extra = 2 * (math.pi / 2) / row[L.PAR_ROT_STEP] if row[L.PAR_ROT_STEP] > 0 else 0.0
    assert out[L.OUT_STEPS] <= out[L.OUT_T_END] / row[L.PAR_DT] + 3 + extra


@pytest.mark.parametrize("name", ["flexible", "rigid", "block"])
def test_overturning_stops_the_run(bodies, name):
    body = bodies[name]
    row = point_row(Point(body, 0.0, "sine", 1.0, 6.0), Numerics.preset("default"))
    out = run_chunk(kernel_kind(body), L.LEVEL_OUTCOME, row[None])[0]
    assert out[L.OUT_OUTCOME] == L.OUTCOME_MODE2
    assert out[L.OUT_T_END] == out[L.OUT_T_OVERTURN]
    assert int(out[L.OUT_STATUS]) & L.STATUS_OVERTURNED
    _stopped_early(out, row)


def test_rest_stops_the_flexible_run(bodies):
    """No uplift (A < g tan alpha_cg); the damped spring cannot uplift the body after the
    pulse: rest is proven at the pulse's end."""
    body = bodies["flexible"]
    row = point_row(Point(body, 0.0, "sine", 1.0, 0.3), Numerics.preset("default"))
    out = run_chunk(kernel_kind(body), L.LEVEL_OUTCOME, row[None])[0]
    assert out[L.OUT_UPLIFTS] == 0
    assert int(out[L.OUT_STATUS]) & L.STATUS_REST
    assert out[L.OUT_T_END] == pytest.approx(row[L.PAR_TPULSE])
    _stopped_early(out, row)


@pytest.mark.parametrize("lam, a_ratio", [(0.0, 4.0), (1.0, 2.0)])
def test_rigid_run_below_the_overturning_energy_stops_after_the_pulse(lam, a_ratio):
    """A rigid body rocking after the pulse with energy below M g (R - h_cg) and |e| <= 1
    cannot overturn: the run stops (status 'bounded'). At lam = 1 (e = 1, no loss) it
    would otherwise rock to the horizon. The energy at the stop is below the barrier and
    theta_max is the peak of the excursion then under way (energy conservation)."""
    body = BlockBody(alpha=0.2618)
    row = point_row(Point(body, lam, "sine", 6.0, a_ratio), Numerics.preset("default"))
    out = run_chunk(L.KIND_RIGID, L.LEVEL_ENERGY, row[None])[0]
    assert out[L.OUT_OUTCOME] == L.OUTCOME_SAFE and out[L.OUT_IMPACTS] >= 1
    assert int(out[L.OUT_STATUS]) & L.STATUS_BOUNDED
    _stopped_early(out, row)
    barrier = body.M * G * (body.R - body.h_cg)
    assert 0 < out[L.OUT_E_END] < barrier
    e = float(restitution_rigid(body, lam))
    # the peaks still to come: at E (moving away from theta = 0) or e^2 E (after the impact)
    peaks = [body.alpha - math.acos(math.cos(body.alpha) + x * out[L.OUT_E_END] / (body.M * G
                                                                                 * body.R))
             for x in (1.0, e * e)]
    assert out[L.OUT_THETA_MAX] >= min(peaks) * (1 - 1e-12)
    assert out[L.OUT_THETA_MAX] < body.alpha


def test_flexible_run_below_its_ridge_stops_after_an_impact(bodies):
    """Figure 3's body, safe after a pulse that rocks it: once the ground is still and its
    energy T + V is below the ridge at its theta_max (W, the least V at that tilt over u,
    ``kernel.ridge``), it can neither overturn nor tilt that far again. The run stops
    (status 'bounded') at an impact. Run on to rest (PAR_TO_REST) it keeps its class and
    its theta_max to the bit, makes more impacts, and its energy stays below that W."""
    body = bodies["flexible"]
    row = point_row(Point(body, 0.0, "sine", 3.3, 3.5), NUM)
    out = run_chunk(kernel_kind(body), L.LEVEL_OUTCOME, row[None])[0]
    # it tilted past the ridge's peak and came back (u off the ridge's): the bound holds
    # at W(theta_r), from the first impact after the pulse
    assert out[L.OUT_THETA_MAX] > row[L.PAR_RIDGE]
    assert out[L.OUT_OUTCOME] == L.OUTCOME_SAFE and out[L.OUT_IMPACTS] >= 1
    assert int(out[L.OUT_STATUS]) & L.STATUS_BOUNDED
    assert not int(out[L.OUT_STATUS]) & L.STATUS_FLAGGED
    on = row.copy()
    on[L.PAR_TO_REST] = 1.0
    full, (hist,) = run_points(kernel_kind(body), on[None])
    full = full[0]
    assert full[L.OUT_OUTCOME] == L.OUTCOME_SAFE
    assert full[L.OUT_THETA_MAX] == out[L.OUT_THETA_MAX]
    assert full[L.OUT_IMPACTS] > out[L.OUT_IMPACTS] + 10  # the rocking to rest it spared
    assert full[L.OUT_T_END] > out[L.OUT_T_END] + 5.0
    after = hist[:, L.HIST_T] > out[L.OUT_T_END]  # (the impact's rows share its time)
    w = ridge_energy(min(out[L.OUT_THETA_MAX], row[L.PAR_RIDGE]), body.m, body.m_A, body.h,
                     body.h_A, body.b, body.k, G)
    assert hist[after, L.HIST_E].max() < w
    assert np.abs(hist[after, L.HIST_THETA]).max() < row[L.PAR_RIDGE]


def test_flexible_body_past_its_ridge_still_falls(bodies):
    """A fall without impact after the pulse (mode 2): its energy is below the ridge's
    peak as it falls past it, which proves nothing (the bound needs the body inside the
    ridge's peak, |theta| < theta_r). Figure 3(a)'s point lam 0.2, A 5.7, w/p 2.85."""
    body = bodies["flexible"]
    row = point_row(Point(body, 0.2, "sine", 2.85, 5.7), NUM)
    out = run_chunk(kernel_kind(body), L.LEVEL_OUTCOME, row[None])[0]
    assert out[L.OUT_OUTCOME] == L.OUTCOME_MODE2
    assert not int(out[L.OUT_STATUS]) & L.STATUS_BOUNDED
    assert out[L.OUT_T_OVERTURN] > row[L.PAR_TPULSE]


def test_a_bound_by_a_thin_energy_margin_is_a_close_call(bodies):
    """Figure 3(b)'s point lam 0, A 2.0374, w/p 1.1366 (cosine pulse; from its adaptive
    diagram at 1000 x 1000): at 5 steps a period the energy at the pulse's end is 0.15%
    below the ridge's peak, and the bare run ends there, safe. At 10 steps it is above,
    and the body creeps over the saddle 10 p t later (mode 2, as `fine` and the
    reference). The bare run's margin is its energy's, sqrt((W_r - E) / W_r) ~ 0.04, below
    PAR_CLOSE: a near-miss, which the certification probes, and then refines."""
    body = bodies["flexible"]
    point = Point(body, 0.0, "cosine", 1.1366366366366365, 2.0374374374374375)
    default = Numerics.preset("default")
    row = point_row(point, default)
    bare = run_chunk(kernel_kind(body), L.LEVEL_OUTCOME, row[None])[0]
    assert bare[L.OUT_OUTCOME] == L.OUTCOME_SAFE
    assert int(bare[L.OUT_STATUS]) & L.STATUS_BOUNDED
    assert bare[L.OUT_T_END] == row[L.PAR_TPULSE]  # decided as the pulse ended
    assert 0.0 < bare[L.OUT_MARGIN] < row[L.PAR_CLOSE]
    assert bare[L.OUT_T_CLOSE] == bare[L.OUT_T_END]
    certified = run_point(point, default, history=False)
    assert certified.outcome == "mode2" and "refined" in certified.status
    assert reference_run(point, default)["outcome"] == L.OUTCOME_MODE2


def test_energy_bound_only_where_impacts_lose_energy(bodies):
    """PAR_RIDGE is kept only where every impact below the ridge loses energy
    (``points.impacts_lose``): checked against the kernel's own impact loss (eq. 6,
    ``equations.impact_loss``) at random top-mass positions |u| <= sqrt(2 W(theta_r)/k)."""
    body = bodies["flexible"]
    rng = np.random.default_rng(3)
    seen = set()
    cases = [(EQ1, 0.0, math.nan, 1.0), (EQ1, 1.0, math.nan, 1.0), (EQ1, 0.5, math.nan, 1.3),
             (CONSTANT, 0.0, 0.9, 1.0), (CONSTANT, 0.0, 1.02, 1.0), (LOCKED, 0.0, math.nan, 1.0)]
    for law, lam, e, factor in cases:
        point = Point(body, lam, "sine", 3.0, 2.0, law=law, e=e, e_factor=factor)
        row = point_row(point, NUM)
        kept = bool(row[L.PAR_RIDGE] > 0)
        seen.add(kept)
        if law == LOCKED:
            assert not kept
            continue
        w_r = ridge_energy(ridge_theta(body.m, body.m_A, body.h, body.h_A, body.b, body.k, G),
                           body.m, body.m_A, body.h, body.h_A, body.b, body.k, G)
        u_lim = math.sqrt(2 * w_r / body.k)
        losses = []
        for u in rng.uniform(-u_lim, u_lim, 400):
            for s in (1, -1):
                e_u = float(eq.restitution(s, u, row, True))
                w = -s * 1.0
                w_plus = e_u * w if e_u > 0 else 0.0
                losses.append(eq.impact_loss(s, -s if e_u > 0 else 0, u, 0.0, w, w_plus,
                                             row, True))
        assert kept == (min(losses) >= 0.0), (law, lam, e, factor, min(losses))
    assert seen == {True, False}


def test_rigid_energy_exit_needs_e_at_most_1():
    """lam > 1 gives e > 1 (impacts feed energy in): no early exit then."""
    body = BlockBody(alpha=0.2618)
    assert float(restitution_rigid(body, 1.5)) > 1
    row = point_row(Point(body, 1.5, "sine", 6.0, 2.0), NUM)
    out = run_chunk(L.KIND_RIGID, L.LEVEL_OUTCOME, row[None])[0]
    assert not int(out[L.OUT_STATUS]) & L.STATUS_BOUNDED
