"""The labeller (geardyn.label): lines followed point by point, typed bifurcations, certified labels, and
verdicts that depend only on their own line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from geardyn import classify
from geardyn.khv import design, point
from geardyn.label import Policy, label_lines, label_points
from geardyn.label import _stages as st
from geardyn.label.compare import hausdorff
from geardyn.runs import sweep
from geardyn.solve import SimulationSettings, simulate

ROOT = Path(__file__).resolve().parents[1]
# the regime maps' settings: 128 steps per period (Poincare error 1.9e-5), 400 + 50 periods
MAP = SimulationSettings(steps_per_period=128, transient_periods=400, recorded_periods=50)
CS = classify.ClassifierSettings(error_floor=1.9e-5, tangent_periods=200)
ROUTE_X1 = np.linspace(0.575, 0.60, 11)  # li2013_route, b = 2, e = 5: P1 -> P2 at x1 = 0.59


def _line(name: str, x1s, **fixed) -> list:
    d = design.load(ROOT / "config" / "designs" / f"{name}.yaml")
    return [point.point_coefficients(d, {"x1": float(x), "b": 2.0, "e": 5.0, **fixed}) for x in x1s]


@pytest.fixture(scope="module")
def route():
    line = _line("li2013_route", ROUTE_X1)
    return line, label_lines([line], Policy(MAP, CS))[0]


def test_period_doubling_is_typed_and_the_new_orbit_followed(route):
    """The P1 orbit's real multiplier leaves through -1 between x1 = 0.5875 (|mu| 0.998) and 0.59: the
    verdict at 0.59 says period_doubling and finds the P2 orbit by shooting (the unstable P1 orbit, also a
    fixed point of the 2-period map, deflated); the points after it follow that P2 orbit."""
    _, out = route
    labels = [v.label for v in out]
    assert labels == [1] * 6 + [2] * 5
    assert [v.bifurcation for v in out] == ["none"] * 6 + ["period_doubling"] + ["none"] * 4
    assert [v.stage for v in out[1:6]] == ["follow"] * 5 and [v.stage for v in out[7:]] == ["follow"] * 4
    assert out[5].multiplier == pytest.approx(0.99816, abs=1e-4)
    assert all(v.exponent_method == "floquet" and v.exponent < 0 for v in out)
    assert all(v.transient_used == 0 for v in out[7:])


def test_a_long_run_from_the_follow_start_ends_on_the_labelled_orbit(route):
    """Independent check: 6000 periods of a plain run from the state the labeller started the point from
    (the previous point's orbit) end on the orbit the verdict certified, within 1e-6."""
    line, out = route
    for k in (3, 8):
        r = simulate(
            line[k],
            SimulationSettings(steps_per_period=128, transient_periods=6000, recorded_periods=out[k].period),
            x0=out[k - 1].final_state,
        )
        cycle = out[k].poincare[: out[k].period]
        assert hausdorff(r.poincare, cycle) < 1e-6


def test_a_batch_of_lines_is_each_line_alone(route):
    """Lines advance on their own, the tori's records growing in pieces while the other line goes on; each
    verdict is the one its line gets alone, bit for bit.  (li2013_calibrated past its Neimark-Sacker point:
    records of 800 and 3200 periods.)"""
    a, alone_a = route
    b = _line("li2013_calibrated", (0.545, 0.55, 0.555, 0.56, 0.565, 0.57))
    together = label_lines([a, b], Policy(MAP, CS))
    alone_b = label_lines([b], Policy(MAP, CS))[0]
    records = {int(v.reason.split(" recorded periods")[0].rsplit("(", 1)[1]) for v in alone_b if v.stage == "torus"}
    assert {800, 3200} <= records
    for got, want in ((together[0], alone_a), (together[1], alone_b)):
        for g, w in zip(got, want, strict=True):
            assert (g.label, g.stage, g.bifurcation, g.reason) == (w.label, w.stage, w.bifurcation, w.reason)
            assert np.array_equal(g.final_state, w.final_state) and np.array_equal(g.poincare, w.poincare)
            assert g.exponent == w.exponent or (np.isnan(g.exponent) and np.isnan(w.exponent))


def test_chaos_needs_a_positive_exponent_that_the_torus_test_confirms():
    """li2013_route at x1 = 0.80 (b = 2, e = 5): exponent +0.037 per unit tau (tangent vector), the weighted
    Birkhoff averages of the two halves agree to less than log10 sqrt(N) + 1.5 digits."""
    v = label_points(_line("li2013_route", [0.80]), Policy(MAP, CS, start="fixed"))[0]
    assert v.label == classify.LABELS["chaotic"] and v.stage == "exponent" and v.exponent_method == "tangent"
    assert 0.025 < v.exponent < 0.05 and v.exponent > 5 * v.exponent_sigma
    assert v.torus_digits < 0.5 * np.log10(100) + 1.5


def test_slowly_attracting_tori_are_certified_past_their_transient():
    """li2013_calibrated, b = 2, e = 5, just past the Neimark-Sacker point of the P1 orbit (x1 = 0.5420): the
    tori attract at about 2 (|mu| - 1) per period, so a record still carries the slow transverse transient.
    The extrapolated torus test (the geometric tail of the windowed Birkhoff averages removed) certifies
    every point as quasi-periodic within 3200 recorded periods; the plain test left x1 = 0.555-0.57
    undetermined even at 4000 (digits 2.6-3.9 against the threshold log10 sqrt(2000) + 2.5 = 4.15).  That they
    are tori: at x1 = 0.56 a run of 8000 + 4000 periods scores 8.4 digits (tests/test_torus.py)."""
    xs = (0.545, 0.55, 0.555, 0.56, 0.565, 0.57)
    out = label_lines([_line("li2013_calibrated", xs)], Policy(MAP, CS))[0]
    assert [v.label for v in out] == [classify.LABELS["quasi_periodic"]] * len(xs)
    assert all(v.stage == "torus" and abs(v.exponent) < CS.lam_tol for v in out)
    records = [int(v.reason.split(" recorded periods")[0].rsplit("(", 1)[1]) for v in out]
    assert max(records) <= 3200
    assert all(v.torus_digits >= 0.5 * np.log10(r // 2) + 2.5 for v, r in zip(out, records, strict=True))


def test_follow_and_fixed_agree_where_one_attractor_exists():
    """li2013 (P1 everywhere at b = 2, e = 5): both starts give P1 and the same orbit within 1e-8; the
    followed points need no transient, the fixed ones hundreds of periods."""
    line = _line("li2013", np.linspace(0.45, 0.55, 4))
    fol = label_lines([line], Policy(MAP, CS))[0]
    fix = label_lines([line], Policy(MAP, CS, start="fixed"))[0]
    assert [v.label for v in fol] == [v.label for v in fix] == [1] * 4
    for a, b in zip(fol, fix, strict=True):
        assert np.max(np.abs(a.final_state - b.final_state)) < 1e-8 * max(1.0, np.max(np.abs(b.final_state)))
    assert all(v.transient_used == 0 for v in fol[1:]) and all(v.transient_used > 50 for v in fix)


def test_coexistence_stores_both_starts_and_flags_where_they_differ():
    """With ``coexistence`` every point is also labelled from the fixed start: ``label_fixed`` and the
    ``coexisting`` flag are stored, and the flag is 1 exactly where the two verdicts differ in label (here,
    li2013 at b = 2, e = 5, both starts find the one P1 orbit: never)."""

    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    spec = sweep.SweepSpec.from_config(
        "t",
        {
            "designs": ["li2013"],
            "parameter": "x1",
            "start": 0.45,
            "stop": 0.55,
            "num": 4,
            "fixed": {"b": 2.0, "e": 5.0},
            "integration": {"steps_per_period": 128, "transient_periods": 400, "recorded_periods": 20},
            "classifier": {"error_floor": 1.9e-5, "tangent_periods": 100},
            "coexistence": True,
        },
        "li2013",
        d.segment,
    )
    cube = sweep.run_chunk(d, spec, 0)
    assert cube.attrs["coexistence"] == 1
    assert np.array_equal(cube["label_fixed"].values, cube["label"].values)
    assert np.all(cube["coexisting"].values == 0)
    assert cube["coexisting"].attrs["flag_meanings"] == "not_checked same coexisting"


def test_a_long_cycle_is_labelled_long_period_with_its_period():
    """A periodic orbit longer than max_n (a torus locked to a long cycle) gets the label long_period and its
    least period in ``period``; a followed one keeps that label (the CF flags list 1..max_n only)."""

    line = _line("li2013_route", [0.80])
    point_ = st.Point(line[0], None, None)
    cycle_state = np.zeros(6)
    shot = st.ShootingResult(cycle_state, 1, True, "converged", 0, 0.0, np.eye(6) * 0.5, np.full(6, 0.5 + 0j))
    small = Policy(MAP, classify.ClassifierSettings(error_floor=1.9e-5, max_n=0))
    v = st.periodic_verdicts([point_], [shot], small, "follow", "test")[0]
    assert v.label == classify.LABELS["long_period"] and v.period == 1
    v = st.periodic_verdicts([point_], [shot], Policy(MAP, CS), "follow", "test")[0]
    assert v.label == 1 and v.period == 1
