"""The long-run reading of ``python -m benchmarks.bench growth`` (benchmarks/long_run.py): what a record of
20 000 periods shows, and which verdicts agree with it, on records whose answer is known by construction."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from benchmarks.long_run import _consistent, _finding, settled_at
from geardyn.label import indicators, vocabulary
from geardyn.label.policy import GrowthSettings

N = 4000  # periods of each constructed record; the reading uses its two halves of 2000
CAP = 1000  # the labeller's record cap the reading compares with
L = vocabulary.LABELS
#: the reading's part of the labeller's policy: the growth test and rule 3's numbers, as the default build's
POLICY = SimpleNamespace(growth=GrowthSettings(), classifier=indicators.ClassifierSettings())


def _record(radius: np.ndarray, rotation: float) -> SimpleNamespace:
    """A run whose Poincare points turn by ``rotation`` of a turn per period on a circle of the given radii (six
    states: the circle, its copy at a third of the size and zeros)."""
    th = 2.0 * np.pi * rotation * np.arange(radius.size) + 0.3
    c = np.column_stack([radius * np.cos(th), radius * np.sin(th)])
    return SimpleNamespace(
        diverged=False, poincare=np.column_stack([c, c / 3.0, np.zeros((radius.size, 2))]), growth=None
    )


GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
CASES = {
    # radius growing by 20 % over each half: the newest half still grows
    "growing": (np.exp(np.log(1.2) / (N / 2) * np.arange(N)), GOLDEN, "still growing", 0),
    # a torus: constant radius, irrational rotation
    "torus": (np.ones(N), GOLDEN, "bounded", 0),
    # growing by 40 % over the oldest half, constant over the newest: it settles after the cap (1000)
    "late": (np.minimum(np.exp(np.log(1.4) / (N / 2) * np.arange(N)), 1.4), GOLDEN, "bounded late", 0),
    # growing by 40 % over the first 500 periods: it settles before the cap
    "early": (np.minimum(np.exp(np.log(1.4) / 500 * np.arange(N)), 1.4), GOLDEN, "bounded", 0),
    # a cycle of period 7 (rotation 2/7)
    "cycle": (np.ones(N), 2.0 / 7.0, "bounded", 7),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_long_run_reading(case):
    radius, rotation, want, period = CASES[case]
    word, n, end, _ = _finding(_record(radius, rotation), SimpleNamespace(period=1.0), POLICY, N, CAP)
    assert (word, n, end) == (want, period, "")


def test_a_diverged_run_and_the_verdicts_it_agrees_with():
    word, n, end, detail = _finding(SimpleNamespace(diverged=True, diverged_period=7299), None, POLICY, N, CAP)
    assert (word, detail) == ("diverged", "diverges in period 7299")
    assert _consistent(L["diverged"], 0, word, n, end) and _consistent(L["transient"], 0, word, n, end)
    assert not _consistent(L["quasi_periodic"], 0, word, n, end)


def test_which_verdicts_agree_with_a_bounded_run():
    # transient: wrong on a run bounded with no trend from its start, right on one bounded only late
    assert not _consistent(L["transient"], 0, "bounded", 0, "")
    assert _consistent(L["transient"], 0, "bounded late", 0, "")
    assert _consistent(L["undetermined"], 0, "bounded", 0, "")
    assert not _consistent(L["diverged"], 0, "bounded", 0, "")
    # a cycle: the long run's least period; QP and chaos: what the tangent vector reads (None without one)
    assert _consistent(6, 6, "bounded", 6, "") and not _consistent(4, 4, "bounded", 8, "")
    assert not _consistent(L["quasi_periodic"], 0, "bounded", 192, "long cycle")
    assert _consistent(L["quasi_periodic"], 0, "bounded", 0, "torus")
    assert _consistent(L["quasi_periodic"], 0, "bounded", 0, "") is None
    assert not _consistent(L["chaotic"], 0, "still growing", 0, "")


def test_the_period_a_growing_run_settles_at():
    # radius 1.4^(k/2000) up to 1.4: within 10 % of 1.4 (above 0.9 x 1.4) from k = 2000 ln 1.26 / ln 1.4 = 1374,
    # read to a block of 50 periods
    radius = CASES["late"][0]
    want = 2000.0 * math.log(0.9 * 1.4) / math.log(1.4)
    got = settled_at(_record(radius, GOLDEN).poincare)
    assert abs(got - want) <= N / 80
