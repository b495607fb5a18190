"""The labeller (geardyn.label): lines followed point by point, typed bifurcations, certified labels, and
verdicts that depend only on their own line."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from geardyn.khv import design, point
from geardyn.label import Policy, indicators, label_lines, label_points, vocabulary
from geardyn.label import _cycles as cycles
from geardyn.label.compare import directed_distance, hausdorff
from geardyn.runs import sweep
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.base import Tangent

ROOT = Path(__file__).resolve().parents[1]
# the regime maps' settings: 128 steps per period (Poincare error 1.9e-5), 400 + 50 periods
MAP = SimulationSettings(steps_per_period=128, transient_periods=400, recorded_periods=50)
CS = indicators.ClassifierSettings(error_floor=1.9e-5, tangent_periods=200)
ROUTE_X1 = np.linspace(0.5635, 0.5885, 11)  # li2013_route, b = 2, e = 5: P1 -> P2 between x1 = 0.576 and 0.5785


def _line(name: str, x1s, **fixed) -> list:
    d = design.load(ROOT / "config" / "designs" / f"{name}.yaml")
    return [point.point_coefficients(d, {"x1": float(x), "b": 2.0, "e": 5.0, **fixed}) for x in x1s]


def _returns_after_a_long_run(system, x0, longest: int, recorded: int) -> tuple[list[float], np.ndarray]:
    """The independent check of a cycle: a plain run of 20 000 periods from ``x0``, then ``recorded`` periods;
    the largest return distance after n = 1 .. ``longest`` periods over them, relative to the attractor's
    size, and the recorded Poincare points."""
    p = simulate(
        system, SimulationSettings(steps_per_period=128, transient_periods=20000, recorded_periods=recorded), x0=x0
    ).poincare
    size = float(np.max(p.std(axis=0)))
    return [float(np.max(np.abs(p[n:] - p[:-n]))) / size for n in range(1, longest + 1)], p


@pytest.fixture(scope="module")
def route():
    line = _line("li2013_route", ROUTE_X1)
    return line, label_lines([line], Policy(MAP, CS))[0]


def test_period_doubling_is_typed_and_the_new_orbit_followed(route):
    """The P1 orbit's real multiplier leaves through -1 between x1 = 0.576 (|mu| 0.9985) and 0.5785: the
    verdict at 0.5785 says period_doubling, and the run from the lost orbit returns after two periods, where
    shooting certifies the P2 orbit; the points after it follow that P2 orbit."""
    _, out = route
    labels = [v.label for v in out]
    assert labels == [1] * 6 + [2] * 5
    assert [v.bifurcation for v in out] == ["none"] * 6 + ["period_doubling"] + ["none"] * 4
    # the points before and after the doubling follow the orbit from the previous point (no transient)
    assert all(v.transient_used == 0 for v in out[1:6] + out[7:])
    assert out[5].multiplier == pytest.approx(0.99850, abs=1e-4)
    assert all(v.exponent_method == "floquet" and v.exponent < 0 for v in out)


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
    verdict is the one its line gets alone, bit for bit.  (li2013_calibrated past its Neimark-Sacker point,
    with the Birkhoff averages as the only torus test and records growing 4x: records of 800 and 3200
    periods.)"""
    a, alone_a = route
    b = _line("li2013_calibrated", (0.545, 0.55, 0.555, 0.56, 0.565, 0.57))
    cs = dataclasses.replace(CS, order_min_n=0, torus_extend=3)
    together = label_lines([a, b], Policy(MAP, cs))
    alone_b = label_lines([b], Policy(MAP, cs))[0]
    records = {int(v.reason.split(" recorded periods")[0].rsplit("(", 1)[1]) for v in alone_b if v.stage == "torus"}
    assert {800, 3200} <= records
    for got, want in ((together[0], alone_a), (together[1], alone_b)):
        for g, w in zip(got, want, strict=True):
            assert (g.label, g.stage, g.bifurcation, g.reason) == (w.label, w.stage, w.bifurcation, w.reason)
            assert np.array_equal(g.final_state, w.final_state) and np.array_equal(g.poincare, w.poincare)
            assert g.exponent == w.exponent or (np.isnan(g.exponent) and np.isnan(w.exponent))


def test_chaos_needs_a_positive_exponent_that_the_torus_test_confirms():
    """li2013_route at x1 = 0.805 (b = 2, e = 5): exponent +0.043 per unit tau (tangent vector), the weighted
    Birkhoff averages of the two halves agree to less than log10 sqrt(N) + 1.5 digits."""
    v = label_points(_line("li2013_route", [0.805]), Policy(MAP, CS, start="fixed"))[0]
    assert v.label == vocabulary.LABELS["chaotic"] and v.stage == "exponent" and v.exponent_method == "tangent"
    assert 0.025 < v.exponent < 0.05 and v.exponent > 5 * v.exponent_sigma
    assert v.torus_digits < 0.5 * np.log10(100) + 1.5


def test_slowly_attracting_tori_are_certified_past_their_transient():
    """li2013_calibrated, b = 2, e = 5, just past the Neimark-Sacker point of the P1 orbit (x1 = 0.5420): the
    tori attract at about 2 (|mu| - 1) per period, so a record still carries the slow transverse transient.
    The extrapolated torus test (the geometric tail of the windowed Birkhoff averages removed) certifies every
    point as quasi-periodic; the plain test left x1 = 0.555-0.57 undetermined even at 4000 (digits 2.6-3.9 against
    the threshold log10 sqrt(2000) + 2.5 = 4.15), and the averages alone needed 3200.  Where the record still grows
    toward the torus in both its halves (x1 = 0.555, 0.56: the spiral out of the P1 orbit) the growth test sends it
    on until its newest half levels off (4000 and 3200 periods), the others are decided within 400.  That they are
    tori: at x1 = 0.56 a run of 8000 + 4000 periods scores 8.4 digits (tests/test_torus.py)."""
    xs = (0.545, 0.55, 0.555, 0.56, 0.565, 0.57)
    out = label_lines([_line("li2013_calibrated", xs)], Policy(MAP, CS))[0]
    assert [v.label for v in out] == [vocabulary.LABELS["quasi_periodic"]] * len(xs)
    assert all(v.stage == "torus" and abs(v.exponent) < CS.lam_tol + 2 * v.exponent_sigma for v in out)
    records = [int(v.reason.split(" recorded periods")[0].rsplit("(", 1)[1]) for v in out]
    assert [r <= 400 for r in records] == [True, True, False, False, True, True] and max(records) <= 4000
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


def test_coexistence_adds_the_fixed_start_and_leaves_the_followed_labels_bit_for_bit():
    """``coexistence: true`` labels every point from the fixed start as well and changes nothing of the
    followed verdicts (the agreement with earlier builds leaves the flagged points out, docs/classify.md).
    li2013_calibrated at b = 2, e = 1.63 (a row of map_x1_e), x1 0.416-0.4244: the followed line is on a
    torus at x1 = 0.4244, where the fixed start ends on a stable P1 orbit beside it."""

    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    cubes = []
    for coexistence in (False, True):
        entry = {
            "designs": ["li2013_calibrated"],
            "parameter": "x1",
            "start": 0.416,
            "stop": 0.4244,
            "num": 5,
            "fixed": {"b": 2.0, "e": 5.5 * 59 / 199},
            "integration": {"steps_per_period": 128, "transient_periods": 400, "recorded_periods": 50},
            "classifier": {"error_floor": 1.9e-5, "tangent_periods": 200},
            "coexistence": coexistence,
        }
        cubes.append(sweep.run_chunk(d, sweep.SweepSpec.from_config("t", entry, "li2013_calibrated", d.segment), 0))
    plain, both = cubes
    for name in plain.data_vars:
        np.testing.assert_array_equal(plain[name].values, both[name].values, err_msg=name)
    label, fixed, flag = (both[k].values.ravel() for k in ("label", "label_fixed", "coexisting"))
    assert np.all(flag[label != fixed] == 1)
    assert (label[-1], fixed[-1], flag[-1]) == (vocabulary.LABELS["quasi_periodic"], 1, 1)


def test_a_long_cycle_is_labelled_long_period_with_its_period():
    """A periodic orbit longer than max_n gets the label long_period and its least period in ``period`` (the CF
    flags list 1..max_n only): li2013_route, b = 2, e = 5, x1 = 0.586, past the period doubling at x1 = 0.577
    (``ROUTE_X1``), is period 2 under the default max_n and long_period with period 2 when max_n is 1."""
    line = _line("li2013_route", [0.586])
    v = label_points(line, Policy(MAP, CS))[0]
    assert v.label == 2 and v.period == 2
    v = label_points(line, Policy(MAP, dataclasses.replace(CS, max_n=1)))[0]
    assert v.label == vocabulary.LABELS["long_period"] and v.period == 2


def test_a_torus_locked_to_a_long_cycle_is_certified_from_the_order_of_its_points():
    """li2013_calibrated, b = 2, e = 1.9347 (row 70 of the (x1, e) map), x1 = 0.416, from the static
    deflection: the record does not return within rule 3's tolerance after 48 periods, but every point's
    nearest neighbour is a multiple of 48 periods away and the return distance after 48 periods falls along
    the record; shooting for period 48 certifies a stable cycle (|mu|max = 0.6652).  Independent check: a
    plain run of 20 000 periods from the verdict's final state returns after 48 periods to 1e-9 and not after
    1-47 (the least period); the verdict's points are the cycle's, not the record's slow approach."""
    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    e = float(np.linspace(0.0, 5.5, 200)[70])
    c = point.point_coefficients(d, {"x1": 0.416, "b": 2.0, "e": e})
    cs = dataclasses.replace(CS, torus_max_periods=16000)
    v = label_points([c], Policy(MAP, cs, start="fixed"))[0]
    assert v.label == vocabulary.LABELS["long_period"] and v.period == 48 and v.stage == "period_test"
    assert v.reason.startswith("the record gathers about the points of a cycle")
    assert v.multiplier == pytest.approx(0.665156, abs=1e-5)
    ret, p = _returns_after_a_long_run(c, v.final_state, 48, 200)
    assert ret[47] < 1e-9 and min(ret[:47]) > 1e-3
    assert hausdorff(v.poincare[:48], p[-48:]) < 1e-9  # the figure draws the cycle, not the slow approach


def test_a_record_that_returns_after_a_long_period_is_decided_when_the_cycle_shows():
    """li2013_calibrated, b = 2, e = 1.6583 (row 60 of the (x1, e) map), x1 = 0.4286 (column 6), from the static
    deflection: no test decides the 200-period record; the record of the next round (400 periods) returns
    after 48 periods within rule 3's tolerance, and shooting certifies a stable period-48 cycle.  The record
    ends there, not at ``torus_max_periods`` (16 000): capped at 400 periods, the labeller gives the same
    verdict, capped at 200 none.
    Independent check: a plain run of 20 000 periods from the verdict's final state returns after 48 periods
    to 1e-9 and not after 1-47."""
    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    x1, e = float(np.linspace(0.416, 0.835, 200)[6]), float(np.linspace(0.0, 5.5, 200)[60])
    c = point.point_coefficients(d, {"x1": x1, "b": 2.0, "e": e})
    v, capped, first = (
        label_points([c], Policy(MAP, dataclasses.replace(CS, torus_max_periods=cap), start="fixed"))[0]
        for cap in (16000, 400, 200)
    )
    assert v.label == vocabulary.LABELS["long_period"] and v.period == 48 and v.stage == "period_test"
    assert v.reason.startswith("the longer record returns after a long period")
    # decided on the 400-period record: a cap there gives the same verdict, a cap at the first (200) none
    assert (capped.label, capped.period, capped.reason) == (v.label, v.period, v.reason)
    assert np.array_equal(capped.final_state, v.final_state)
    assert first.label == vocabulary.LABELS["undetermined"]
    ret, _ = _returns_after_a_long_run(c, v.final_state, 48, 200)
    assert ret[47] < 1e-9 and min(ret[:47]) > 1e-3


@pytest.mark.parametrize(("row", "column", "period", "multiplier"), [(68, 82, 189, 0.312992), (72, 65, 92, 0.622513)])
def test_a_torus_locked_to_a_long_cycle_is_found_from_its_record(row, column, period, multiplier):
    """li2013_calibrated, b = 2, row ``row`` of the (x1, e) map followed from x1 = 0.416 to column ``column``.
    The torus test calls the record a circle rotation, but it is a slow approach to a stable long cycle (row
    68: the nearest neighbours of the record's newest half are 189, 378, 567 periods away, while over the
    whole record, its start far from the cycle, the least difference is 25).  What the labeller promises:
    the label, the least period, the certified cycle's multiplier, and that the record gathers about it.
    Which candidate periods it tries on the way is its own affair (they follow the record's last bits).
    Independent check: a plain run from the verdict's final state returns after ``period`` periods to 1e-9
    and not after fewer."""
    e = float(np.linspace(0.0, 5.5, 200)[row])
    line = _line("li2013_calibrated", np.linspace(0.416, 0.835, 200)[: column + 1], e=e)
    cs = dataclasses.replace(CS, torus_max_periods=16000)
    v = label_lines([line], Policy(MAP, cs))[0][-1]
    assert v.label == vocabulary.LABELS["long_period"] and v.period == period and v.stage == "period_test"
    assert v.reason.startswith("the record gathers about the points of a cycle")
    assert v.multiplier == pytest.approx(multiplier, abs=1e-5)
    ret, p = _returns_after_a_long_run(line[-1], v.final_state, period, 3 * period)
    assert ret[-1] < 1e-9 and min(ret[:-1]) > 1e-4
    assert directed_distance(v.poincare, p) < 1e-9 * np.max(p.std(axis=0))  # every stored point is on the cycle


def test_part_of_a_cycle_lies_on_it_at_distance_zero():
    """A verdict stores the newest ``recorded_periods`` points of its cycle: 50 of the 143 points of a long
    cycle lie on the cycle (directed distance 0), while the symmetric Hausdorff distance measures the 93
    points not stored (1.42 in the max norm on the unit circle's points 2 pi k / 143, k = 50 .. 142)."""
    th = 2.0 * np.pi * np.arange(143) / 143
    cycle = np.c_[np.cos(th), np.sin(th)]
    assert directed_distance(cycle[:50], cycle) == 0.0
    assert hausdorff(cycle[:50], cycle) == pytest.approx(directed_distance(cycle, cycle[:50]))
    assert hausdorff(cycle[:50], cycle) == pytest.approx(1.4219, abs=1e-4)
    assert directed_distance(cycle[:50] + 1e-3, cycle) == pytest.approx(1e-3, rel=1e-3)


def test_a_record_circling_an_orbit_at_the_unit_circle_is_undetermined():
    """li2013_calibrated, e = 5, row 115 of the (x1, b) map (b = 1.2714), its points built as the map builds
    them, followed from x1 = 0.416 to column 40 (x1 = 0.50022), one pixel past the P1 orbit's Neimark-Sacker
    curve.  The record circles the P1 orbit within 1 %, and the orbit's largest |mu| is within the stability
    margin (1.9e-5) of 1: no run of the labeller's length tells a slow approach from a torus born there, so
    the point is undetermined and says why.  Without the check (``circle_max_n = 0``) the same record passes
    the torus test and is called quasi-periodic; the pixel before it is a certified P1."""
    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    b = float(np.linspace(0.0, 2.2, 200)[115])
    line = [
        point.point_coefficients(d, {"e": 5.0, "x1": float(x)}).replace(b=b)
        for x in np.linspace(0.416, 0.835, 200)[:41]
    ]
    policy = Policy(MAP, CS)
    v = label_lines([line], policy)[0]
    assert v[-2].label == 1 and v[-2].multiplier < 1.0
    assert v[-1].label == vocabulary.LABELS["undetermined"]
    assert "circles a period-1 orbit" in v[-1].reason and "within the stability margin" in v[-1].reason
    off = dataclasses.replace(policy, locked=dataclasses.replace(policy.locked, circle_max_n=0))
    assert label_lines([line], off)[0][-1].label == vocabulary.LABELS["quasi_periodic"]


# paper 1's sweeps' settings (preset "sweep"): 512 steps per period, records of up to 16 000 periods
SWEEP = Policy(
    SimulationSettings(steps_per_period=512, transient_periods=500, recorded_periods=100),
    indicators.ClassifierSettings(tangent_periods=400, torus_max_periods=16000),
)


def test_the_orbit_born_at_a_period_doubling_is_found_by_branch_switching():
    """li2013_route, Fig. 7 (b = 2, e = 5): the P1 orbit loses its stability through -1 between x1 = 0.57622
    (|mu| 0.99908) and 0.57664 (1.00018). The P2 born there attracts at |mu| 0.99928 per two periods, and a
    record from the old orbit leaves it at 1.00018 per period: 3200 periods still look like a torus. Shooting
    for period 2 from the old orbit displaced along its eigenvector of the multiplier past -1 certifies the P2;
    an independent 20 000-period run from the old orbit has moved towards that cycle and returns after two
    periods (to 5e-9 of the state's size, against 3e-5 after one). The line goes on from the torus verdict,
    so the points after it are those of the labeller without the check, bit for bit (which now finds the P2 too:
    the growth test runs the growing record on)."""
    line = _line("li2013_route", np.linspace(0.416, 0.835, 1000)[382:387])
    out = label_lines([line], SWEEP)[0]
    old, new = out[:2]
    assert (old.label, new.label, new.period, new.bifurcation) == (1, 2, 2, "period_doubling")
    # the line goes on from the verdict before the check: the points after it are as without the check
    plain = label_lines([line], dataclasses.replace(SWEEP, switch_step=0.0, doubt_periods=0))[0]
    # without the checks of doubt the growth test sends the record leaving the old orbit on, and the longer record
    # finds the P2 itself (docs/classify.md, "Growing records"); before that test it was a torus
    assert (plain[1].label, plain[1].period) == (2, 2)
    for a, b in zip(out[2:], plain[2:], strict=True):
        assert a.label == b.label and np.array_equal(a.final_state, b.final_state) and a.response == b.response
    assert new.multiplier == pytest.approx(0.99928, abs=2e-5)  # 0.999287 from Newton at the long run's end
    long = dataclasses.replace(SWEEP.integration, transient_periods=20000, recorded_periods=4)
    p = simulate(line[1], long, x0=old.final_state).poincare
    scale = float(np.max(np.abs(p)))

    # the cycle's two points: from the certified orbit point (the drawn record may still approach it)
    two = dataclasses.replace(SWEEP.integration, transient_periods=0, recorded_periods=2, early_stop=False)
    cycle = simulate(line[1], two, x0=new.final_state).poincare

    def to_cycle(q: np.ndarray) -> float:
        return float(np.min(np.max(np.abs(cycle - q), axis=1)))

    assert to_cycle(p[-1]) < 0.5 * to_cycle(old.final_state)
    assert float(np.max(np.abs(p[2:] - p[:-2]))) < 1e-7 * scale < float(np.max(np.abs(p[1:] - p[:-1])))


def test_a_torus_after_a_period_doubling_is_run_on_until_its_record_decides():
    """li2013_route, Fig. 9 at x1 = 0.83 (e = 5): past the period doubling of the P8 orbit at b = 1.7856 the
    Birkhoff averages converge on the first 400 periods (a torus) while a 20 000-period run from there has a
    positive exponent, 2.6e-3 per unit time (chaos): the record in doubt runs on, and the verdict is not a torus.
    Where the longer record confirms the torus (Fig. 7, x1 = 0.71127, past the P8's doubling), the verdict is
    the one first reached, and every verdict of the line is that of the labeller without the doubt, bit for bit."""
    d = design.load(ROOT / "config" / "designs" / "li2013_route.yaml")
    bs = np.linspace(0.0, 2.2, 500)[400:406]
    line = [point.point_coefficients(d, {"x1": 0.83, "b": float(b), "e": 5.0}) for b in bs]
    out = label_lines([line], SWEEP)[0]
    assert [v.label for v in out[:5]] == [4, 4, 4, 8, 8] and out[5].bifurcation == "period_doubling"
    assert out[5].label == vocabulary.LABELS["undetermined"]
    long = dataclasses.replace(SWEEP.integration, transient_periods=0, recorded_periods=20000)
    r = simulate(line[5], long, x0=out[5].final_state, variational=Tangent(20000))
    lam, sigma = indicators.lyapunov_estimate(r.growth, r.period)
    assert lam > 2e-3 and lam > SWEEP.classifier.lam_tol + 3 * sigma
    x1s = np.linspace(0.416, 0.835, 1000)[698:707]
    line = _line("li2013_route", x1s)
    held, plain = (label_lines([line], dataclasses.replace(SWEEP, doubt_periods=k))[0] for k in (3200, 0))
    assert held[6].label == vocabulary.LABELS["quasi_periodic"] and "confirmed on 3200" in held[6].reason
    for a, b in zip(held, plain, strict=True):
        assert a.label == b.label and np.array_equal(a.final_state, b.final_state) and a.response == b.response


def test_a_record_gathering_in_pairs_about_a_doubled_cycle_points_to_its_period():
    """A record approaching a period-16 cycle born from a period-8 one (the 16 points in pairs 0.02 of the
    attractor's size apart, the distance to the cycle falling by 0.999 per period): the return distance after
    8 periods stays at the pairs' spacing, after 16 (and 32) it falls below 1 % of the size."""
    k = np.arange(3200)
    base = np.stack([np.cos(np.pi * k / 4), np.sin(np.pi * k / 4), np.zeros_like(k, float)], axis=1)
    base[:, 2] = 0.02 * np.where((k // 8) % 2 == 0, 1.0, -1.0)
    record = np.concatenate([base, np.zeros((k.size, 3))], axis=1)
    record += 0.3 * 0.999 ** k[:, None] * np.random.default_rng(0).normal(size=(16, 6))[k % 16]
    policy = Policy(MAP, CS)
    assert not cycles._gathers_at(record, 8, policy, False)
    assert cycles._gathers_at(record, 16, policy, False) and cycles._gathers_at(record, 32, policy, False)
