"""The response measures come from the labeller's own runs: a periodic verdict's are those of one cycle from
its final state, bit for bit; a non-periodic verdict's, summed over the last recorded periods of its record,
agree with those of the next recorded periods within their standard errors; the study runner integrates no
point a second time."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import geardyn.solve.response as response
from geardyn.khv import design, point
from geardyn.label import Policy, indicators, label_lines
from geardyn.runs import study
from geardyn.solve import SimulationSettings, simulate_batch
from geardyn.solve.base import Lane, Sums
from geardyn.solve.response import (
    ResponseMeasures,
    measures_of_sums,
    response_measures_many,
    rms_errors_many,
)

ROOT = Path(__file__).resolve().parent.parent
SETTINGS = SimulationSettings(steps_per_period=128, transient_periods=400, recorded_periods=50)


def _line(name: str, x1: np.ndarray, e: float) -> list:
    d = design.load(ROOT / "config" / "designs" / f"{name}.yaml")
    return [point.point_coefficients(d, {"x1": float(x), "b": 2.0, "e": e}) for x in x1]


def _same(a: ResponseMeasures, b: ResponseMeasures) -> bool:
    """Field by field, NaN equal to NaN, floats bit for bit."""
    return all(
        (isinstance(x, float) and math.isnan(x) and math.isnan(y)) or x == y
        for x, y in zip(dataclasses.astuple(a), dataclasses.astuple(b), strict=True)
    )


@pytest.fixture(scope="module")
def labelled():
    """A periodic line (``li2013``, P1) and a few points of a torus row of ``li2013_calibrated`` (the map
    x1-e at e = 5.5 * 72 / 199), labelled with the maps' integration and short growing records."""
    cs = dataclasses.replace(
        indicators.ClassifierSettings(error_floor=1.9e-5, tangent_periods=200), torus_max_periods=800
    )
    lines = [
        _line("li2013", np.linspace(0.45, 0.8, 4), 5.0),
        _line("li2013_calibrated", np.linspace(0.416, 0.835, 200)[3:7], 5.5 * 72 / 199),
    ]
    return lines, label_lines(lines, Policy(SETTINGS, cs))


def test_a_periodic_verdict_carries_the_measures_of_one_cycle_from_its_final_state(labelled):
    lines, verdicts = labelled
    pairs = [(s, v) for line, vs in zip(lines, verdicts, strict=True) for s, v in zip(line, vs, strict=True)]
    periodic = [(s, v) for s, v in pairs if v.periodic]
    assert len(periodic) >= 4
    again = response_measures_many([s for s, _ in periodic], [v.final_state for _, v in periodic], SETTINGS,
                                   [v.period for _, v in periodic])  # fmt: skip
    for (_, v), r in zip(periodic, again, strict=True):
        assert _same(v.response, r)
        assert v.response.periods == v.period and not v.response.diverged


def test_a_non_periodic_verdict_measures_its_record_within_the_standard_errors(labelled):
    """Over the last recorded periods of the record instead of the next ones: the RMS values differ by less
    than 4 standard errors of the difference of the two records (each record's error from its own blocks),
    the means by less than 1 %."""
    lines, verdicts = labelled
    pairs = [(s, v) for line, vs in zip(lines, verdicts, strict=True) for s, v in zip(line, vs, strict=True)]
    other = [(s, v) for s, v in pairs if not v.periodic and not v.diverged]
    assert other, "the torus row has non-periodic points"
    systems, n = [s for s, _ in other], SETTINGS.recorded_periods
    own = rms_errors_many(systems, [v.poincare for _, v in other], [v.response for _, v in other], SETTINGS)
    runs = simulate_batch([Lane(s, v.final_state, 0, sums=Sums(n)) for s, v in other], SETTINGS)
    nxt = [measures_of_sums(r.sums, s, n) for r, s in zip(runs, systems, strict=True)]
    errors = rms_errors_many(systems, [r.poincare for r in runs], nxt, SETTINGS)
    for (_, v), e1, r, e2 in zip(other, own, nxt, errors, strict=True):
        got = v.response
        assert got.periods == n and not got.diverged and e1.blocks == 10
        assert abs(got.dte_rms - r.dte_rms) <= 4.0 * math.hypot(e1.dte_rms_error, e2.dte_rms_error) + 1e-12
        assert abs(got.force_rms - r.force_rms) <= 4.0 * math.hypot(e1.force_rms_error, e2.force_rms_error) + 1e-12
        assert got.force_mean == pytest.approx(r.force_mean, rel=1e-2)
        assert got.dte_mean == pytest.approx(r.dte_mean, rel=1e-2, abs=1e-3)


def test_the_error_bars_blocks_are_pieces_of_the_verdicts_own_record(labelled):
    """A non-periodic verdict keeps its record's Poincare points: a block integrated from the point where it
    begins ends on the point where the next begins, bit for bit, so the error bar's blocks are the very record
    the RMS was summed over (the first block: the record less the others)."""
    lines, verdicts = labelled
    other = [(s, v) for line, vs in zip(lines, verdicts, strict=True) for s, v in zip(line, vs, strict=True)
             if not v.periodic and not v.diverged]  # fmt: skip
    n = SETTINGS.recorded_periods
    runs = simulate_batch([Lane(s, v.poincare[-n], 0, n - 1) for s, v in other], SETTINGS)
    for (_, v), r in zip(other, runs, strict=True):
        assert v.poincare.shape[0] >= n and np.array_equal(r.poincare, v.poincare[-(n - 1) :])


def test_the_study_runner_does_not_integrate_the_points_again(monkeypatch):
    """The stored measures are the verdicts': the second integration of the points is never entered."""

    def refuse(*args, **kwargs):
        raise AssertionError("a second integration of the labelled points")

    monkeypatch.setattr(response, "response_measures_many", refuse)
    monkeypatch.setattr(study, "response_measures_many", refuse, raising=False)
    systems = _line("li2013", np.linspace(0.45, 0.8, 3), 5.0)
    layout = study.Layout(("x",), (3,), [[((k,), s) for k, s in enumerate(systems)]])
    res = study.run(layout, Policy(SETTINGS))
    for k, v in enumerate(res.verdicts[0]):
        assert res.data["dte_rms"][1][k] == v.response.dte_rms
        assert np.isfinite(res.data["force_rms"][1][k])
