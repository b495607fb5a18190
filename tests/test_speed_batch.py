"""Batch integration (simulate_batch): the same numbers as the point-by-point path,
whatever the batch, its order, its chunking and the number of threads."""

import numba
import numpy as np
import pytest

from _oracle import rules_label
from benchmarks.work_precision import cases
from geardyn.label import Policy, indicators, label_points
from geardyn.solve import SimulationSettings, _batch, _period, simulate
from geardyn.solve.base import EarlyStop, Lane, Monodromy, Tangent
from geardyn.solve.run import simulate_batch, step_tables


@pytest.fixture(scope="module")
def systems():
    cs = list(cases().values())
    # contact loss (b > 0), b = 0, backlash off, both cases
    return [c.replace(b=b) for c in cs for b in (0.0, 0.7, 2.0, 3.0)] + [cs[0].replace(backlash_on=False)]


SHORT = dict(steps_per_period=32, transient_periods=30, recorded_periods=12)


@pytest.mark.parametrize("integrator", ["rk4", "rk4_event"])
@pytest.mark.parametrize("var", [None, Tangent(20), Monodromy(3)])
def test_batch_is_bit_identical_to_simulate(systems, integrator, var):
    """Nine points: eight on a lockstep block and one on the scalar loop (all of them with the monodromy)."""
    s = SimulationSettings(integrator=integrator, **SHORT)
    batch = simulate_batch([Lane(c, variational=var) for c in systems], s)
    for c, r in zip(systems, batch, strict=True):
        r0 = simulate(c, s, variational=var)
        assert np.array_equal(r0.poincare, r.poincare)
        assert np.array_equal(r0.final_state, r.final_state)
        assert r0.n_events == r.n_events and r0.diverged == r.diverged
        if isinstance(var, Tangent):
            assert np.array_equal(r0.growth, r.growth) and np.array_equal(r0.strobe, r.strobe)
        if isinstance(var, Monodromy):
            assert np.array_equal(r0.monodromy, r.monodromy)


def test_tangent_and_monodromy_lanes_in_one_call_are_each_their_point_alone(systems):
    """Lanes with a tangent vector, with the monodromy and with neither, mixed in one call (two batches): each
    lane's record, growth and monodromy are those of :func:`simulate` of its point, bit for bit."""
    s = SimulationSettings(integrator="rk4_event", **SHORT)
    kinds = (Tangent(20), Monodromy(3), None)
    lanes = [Lane(c, variational=kinds[k % 3]) for k, c in enumerate(systems)]
    for q, r in zip(lanes, simulate_batch(lanes, s), strict=True):
        r0 = simulate(q.system, s, variational=q.variational)
        assert np.array_equal(r0.poincare, r.poincare) and np.array_equal(r0.final_state, r.final_state)
        assert np.array_equal(r0.growth, r.growth) and np.array_equal(r0.strobe, r.strobe)
        assert (r.growth.size > 0) == isinstance(q.variational, Tangent)
        if isinstance(q.variational, Monodromy):
            assert np.array_equal(r0.monodromy, r.monodromy)
        else:
            assert r.monodromy is None


def test_a_run_in_pieces_is_one_run(systems):
    """A run of 40 periods with the tangent vector equals, bit for bit, a run of 15 and one of 25 that starts
    from its final state and tangent (the pieces the labeller's growing records are made of), on the
    lockstep block (eight points) and on the scalar loop (the ninth); without the carried tangent the second
    piece's exponents differ."""
    s = SimulationSettings(integrator="rk4_event", **SHORT)
    x0 = [r.final_state for r in simulate_batch([Lane(c) for c in systems], s)]
    rec = [
        SimulationSettings(integrator="rk4_event", steps_per_period=32, transient_periods=0, recorded_periods=n)
        for n in (40, 15, 25)
    ]
    one = simulate_batch([Lane(c, x, variational=Tangent(40)) for c, x in zip(systems, x0, strict=True)], rec[0])
    a = simulate_batch([Lane(c, x, variational=Tangent(15)) for c, x in zip(systems, x0, strict=True)], rec[1])
    b = simulate_batch(
        [Lane(c, r.final_state, variational=Tangent(25, r.tangent)) for c, r in zip(systems, a, strict=True)], rec[2]
    )
    fresh = simulate_batch(
        [Lane(c, r.final_state, variational=Tangent(25)) for c, r in zip(systems, a, strict=True)], rec[2]
    )
    for o, u, v, f in zip(one, a, b, fresh, strict=True):
        assert np.array_equal(o.poincare, np.vstack([u.poincare, v.poincare]))
        assert np.array_equal(o.growth, np.concatenate([u.growth, v.growth]))
        assert np.array_equal(o.strobe, np.concatenate([u.strobe, v.strobe]))
        assert np.array_equal(o.final_state, v.final_state) and np.array_equal(o.tangent, v.tangent)
        assert o.n_events == u.n_events + v.n_events
        assert np.array_equal(f.poincare, v.poincare) and not np.array_equal(f.growth, v.growth)


def run(systems, s, es):
    """The batch run of ``systems`` with a tangent over 15 periods and the early stop ``es``."""
    return simulate_batch([Lane(c, variational=Tangent(15)) for c in systems], s, early_stop=es)


def test_independent_of_threads_order_and_chunking(systems):
    s = SimulationSettings(steps_per_period=32, transient_periods=400, recorded_periods=12)
    es = EarlyStop(min_periods=50, confirm=5, floor=4e-3)
    ref = run(systems, s, es)
    n0 = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = run(systems, s, es)
    finally:
        numba.set_num_threads(n0)
    rev = run(systems[::-1], s, es)[::-1]
    parts = run(systems[:3], s, es) + run(systems[3:], s, es)
    # each point alone: a batch of one runs on the scalar loop
    lanes = [r for c in systems for r in run([c], s, es)]
    assert any(r.stop_period for r in ref) and not all(r.stop_period for r in ref)
    for other in (one, rev, parts, lanes):
        for a, b in zip(ref, other, strict=True):
            assert np.array_equal(a.poincare, b.poincare) and np.array_equal(a.growth, b.growth)
            assert a.transient_used == b.transient_used and a.stop_period == b.stop_period


def test_compiled_tables_equal_step_tables(systems):
    n = 48
    L = len(systems)
    H, S, K, P = np.empty((L, n)), np.empty((L, n)), np.empty((L, n, 3)), np.empty((L, n, 3))
    SEG = np.empty((L, n), np.int64)
    for lane, c in enumerate(systems):
        _batch.fill_tables(
            lane,
            float(c.eps),
            float(c.period),
            float(c.te_forcing),
            float(c.phi),
            c.stiffness_polys(),
            n,
            H,
            S,
            SEG,
            K,
            P,
        )
        _, h, st, sg, tk, tp, _ = step_tables(c, n, True)
        for a, b in ((h, H[lane]), (st, S[lane]), (sg, SEG[lane]), (tk, K[lane]), (tp, P[lane])):
            assert np.array_equal(a, b)


def test_compiled_rule3_equals_strict_period():
    rng = np.random.default_rng(3)
    cs = indicators.ClassifierSettings()
    seqs = []
    for n in (1, 2, 3, 5, 12):
        cyc = rng.normal(size=(n, 6))
        seqs.append(np.tile(cyc, (60 // n + 1, 1))[:60] + 1e-9 * rng.normal(size=(60, 6)))
    k = np.arange(60)[:, None]
    seqs.append(np.hstack([np.cos(0.7 * k), np.sin(0.7 * k), np.zeros((60, 4))]))  # quasi-periodic circle
    seqs.append(rng.normal(size=(60, 6)))
    pts = np.stack(seqs)
    out = np.zeros((len(seqs), 2))
    _period.strict_periods(
        pts, np.full(len(seqs), 60), cs.max_n, cs.atol, cs.rtol, cs.error_margin * cs.error_floor, cs.separation, out
    )
    assert [int(v) for v in out[:, 0]] == [indicators.strict_period(p, cs) for p in seqs] == [1, 2, 3, 5, 12, 0, 0]


def test_floquet_exponent_of_periodic_points():
    """Periodic points (the periodic benchmark case, slow shaft mode), labelled from the static deflection:
    the early stop ends the transient well before its end, the orbit is certified by shooting, and the
    Floquet exponent is the least-damped multiplier's (log 0.9812 per period) inside the error bar of the
    tangent estimate of a plain run of the whole transient (the test oracle)."""

    periodic = [cases()["periodic"].replace(b=b) for b in (0.0, 1.0, 2.5)]
    base = SimulationSettings(steps_per_period=32, transient_periods=900, recorded_periods=50)
    cls = indicators.ClassifierSettings(error_floor=4e-3, tangent_periods=200)
    new = label_points(periodic, Policy(base, cls, start="fixed"))
    for c, v in zip(periodic, new, strict=True):
        _, lo = rules_label(c, base, cls)
        assert lo.label == v.label == 1 and v.stage == "period_test" and v.exponent_method == "floquet"
        assert 250 < v.transient_used < 400
        assert v.exponent_sigma == 0.0
        assert v.exponent == pytest.approx(-0.002717, abs=2e-6)
        assert abs(v.exponent - lo.lyapunov) <= 2 * lo.lyapunov_sigma


def _rule3_by_hand(p: np.ndarray, cs: indicators.ClassifierSettings) -> int:
    """Rule 3 with every return distance summed in full (the statement of docs/classify.md)."""
    size = float(np.max(np.ptp(p, axis=0)))
    tol = max(cs.atol * max(float(np.max(np.abs(p))), 1.0) + cs.rtol * size, cs.error_margin * cs.error_floor)
    d = [float(np.max(np.abs(p[n:] - p[:-n]))) for n in range(1, min(cs.max_n, len(p) - 1) + 1)]
    for n, dn in enumerate(d, start=1):
        if dn <= tol and all(dm > cs.separation * tol for dm in d[: n - 1]):
            return n
    return 0


def test_rule3_cut_short_gives_the_full_sums_answer():
    """The compiled rule 3 stops summing a return distance once it exceeds both thresholds and stops testing
    once no larger period can have distinct cycle points: the same periods as the full sums, on cycles whose
    points are barely distinct, barely not, and returns just inside and outside the tolerance."""
    rng = np.random.default_rng(11)
    cs = indicators.ClassifierSettings()
    seqs, found = [], set()
    for n in (1, 2, 3, 4, 7):
        for spread in (1e-6, 1e-5, 3e-5, 1e-4, 1e-2):  # cycle points apart by about spread (tol is about 1e-5)
            for noise in (0.0, 2e-6, 1e-5, 3e-5):
                cyc = 0.5 + spread * rng.normal(size=(n, 6))
                seqs.append(np.tile(cyc, (40 // n + 1, 1))[:40] + noise * rng.normal(size=(40, 6)))
    # a period-3 cycle (tol about 1e-6) whose first step is short (3 tol) and its others long (20 tol): only
    # the whole sum shows the cycle points distinct (> 10 tol)
    seqs.append(np.tile(0.5 + np.array([[0.0], [3e-6], [23e-6]]) * np.ones(6), (14, 1))[:40])
    for p in seqs:
        want = _rule3_by_hand(p, cs)
        assert indicators.strict_period(p, cs) == want
        found.add(want)
    assert {0, 1, 2, 3, 4, 7} <= found  # the cases reach every branch: periods found and none
