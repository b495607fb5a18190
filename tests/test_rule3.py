"""Rule 3 of the classifier is stated once, compiled (geardyn.solve._period); its users are
indicators.strict_period, simulate.strict_periods and the early stop of both loops.  Checked here against
a plain numpy statement of the rule written in this file."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.label import indicators
from geardyn.solve import _period
from geardyn.solve.run import strict_period, strict_periods


def _rule3_numpy(p: np.ndarray, max_n: int, atol: float, rtol: float, floor_tol: float, sep: float) -> int:
    tol = max(atol * max(float(np.max(np.abs(p))), 1.0) + rtol * float(np.max(np.ptp(p, axis=0))), floor_tol)
    seen: list[float] = []
    for n in range(1, min(max_n, p.shape[0] - 1) + 1):
        dn = float(np.max(np.abs(p[n:] - p[:-n])))
        if dn <= tol and min(seen, default=np.inf) > sep * tol:
            return n
        seen.append(dn)
    return 0


def _records(rng: np.random.Generator) -> list[np.ndarray]:
    out = []
    for n in (1, 2, 3, 4, 7, 12, 13):
        for noise in (0.0, 1e-9, 1e-5):
            cyc = rng.normal(size=(n, 6))
            out.append(np.tile(cyc, (40 // n + 1, 1))[:40] + noise * rng.normal(size=(40, 6)))
    k = np.arange(40)[:, None]
    decay = 0.9**k * np.hstack([np.cos(2.1 * k), np.sin(2.1 * k), np.zeros((40, 4))])  # rotating transient
    out += [decay, decay[20:], rng.normal(size=(40, 6)), np.zeros((40, 6)), rng.normal(size=(2, 6))]
    return out


def test_compiled_rule_equals_the_numpy_statement():
    rng = np.random.default_rng(11)
    cs = indicators.ClassifierSettings()
    args = (cs.max_n, cs.atol, cs.rtol, cs.error_margin * cs.error_floor, cs.separation)
    records = _records(rng)
    expected = [_rule3_numpy(p, *args) for p in records]
    assert [strict_period(np.ascontiguousarray(p), len(p), *args)[0] for p in records] == expected
    assert [indicators.strict_period(p, cs) for p in records] == expected
    assert {1, 2, 3, 4, 7, 12, 0} <= set(expected)  # the cases exercise every outcome
    # the batch version on the same records (fewer than 3 points: rule 2, no period)
    m = max(len(p) for p in records)
    P = np.zeros((len(records), m, 6))
    for k, p in enumerate(records):
        P[k, : len(p)] = p
    out = np.zeros((len(records), 2))
    strict_periods(P, np.array([len(p) for p in records]), *args, out)
    assert [int(v) for v in out[:, 0]] == [e if len(p) >= 3 else 0 for e, p in zip(expected, records, strict=True)]


def test_two_points_of_one_state_are_period_one():
    p = np.array([[0.5], [0.5]])
    assert indicators.strict_period(p) == 1 == _rule3_numpy(p, 12, 1e-6, 1e-4, 7.5e-7, 10.0)


@pytest.mark.parametrize("n", [1, 3, 5])
def test_early_stop_finds_the_cycle_after_confirm_periods(n):
    """The early stop's running record: a period-n cycle is confirmed after n + confirm points, not before;
    a slowly decaying rotation by 1/3 (returns within tol = 1e-5 after 3 periods, but its points are only
    3.5e-5 apart, not distinct by separation * tol) is never confirmed."""
    rng = np.random.default_rng(n)
    cyc = rng.normal(size=(n, 6))
    max_n, confirm = 12, 4
    ring, count, dcur = np.empty((max_n + 1, 6)), np.zeros(max_n + 1, np.int64), np.full(max_n + 1, np.inf)
    seen, found = 0, []
    for k in range(n + confirm + 3):
        seen, stop = _period.early_stop(
            ring, count, dcur, seen, cyc[k % n], (0, confirm, max_n, 1e-5, 1e-7, 10.0), True
        )
        found.append(stop)
    assert found.index(n) == n + confirm - 1 and set(found[: n + confirm - 1]) == {0}
    ring, count, dcur = np.empty((max_n + 1, 6)), np.zeros(max_n + 1, np.int64), np.full(max_n + 1, np.inf)
    seen, stops = 0, set()
    for k in range(60):
        y = np.zeros(6)
        y[:2] = 2e-5 * 0.999**k * np.array([np.cos(2 * np.pi * k / 3), np.sin(2 * np.pi * k / 3)])
        seen, stop = _period.early_stop(ring, count, dcur, seen, y, (0, confirm, max_n, 1e-5, 1e-7, 10.0), True)
        stops.add(stop)
    assert stops == {0} and count[3] > confirm and 1e-5 < dcur[1] < 1e-4
