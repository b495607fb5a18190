"""Verdicts that never guess (geardyn.label.growth, docs/classify.md): a growing record is no torus and no chaos,
a system without damping is said to be one (and refused by the probabilities study), a quasi-periodic verdict
stores the long-cycle search's reach."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from scipy import stats

from geardyn.config import validate
from geardyn.khv import design, point
from geardyn.label import Policy, indicators, label_points, vocabulary
from geardyn.label._cycles import period_searched
from geardyn.label.growth import envelope, growing, growth_test
from geardyn.label.policy import GrowthSettings
from geardyn.plots import captions
from geardyn.runs import probabilities, response, study, sweep
from geardyn.solve import SimulationSettings, simulate_batch
from geardyn.solve.base import Lane

ROOT = Path(__file__).resolve().parents[1]
QP = vocabulary.LABELS["quasi_periodic"]
RNG = np.random.default_rng(5)


def _rotation(n: int, rate: float = 0.0, corner: float = 0.0) -> np.ndarray:
    """n points of the golden rotation on a circle about the origin (with ``corner``: a curve with a corner),
    its radius growing by exp(rate) per point."""
    k = np.arange(n)
    th = np.pi * (math.sqrt(5.0) - 1.0) * k + RNG.uniform(0.0, 2.0 * np.pi)
    r = np.exp(rate * k)
    return np.column_stack([r * (np.cos(th) + corner * np.abs(np.sin(th))), r * np.sin(th), 0.3 * r * np.cos(th)])


def _henon(n: int) -> np.ndarray:
    x, y, out = RNG.uniform(-0.1, 0.1), 0.0, np.empty((n + 500, 2))
    for i in range(n + 500):
        x, y = 1.0 - 1.4 * x * x + y, 0.3 * x
        out[i] = x, y
    return out[500:]


@pytest.mark.parametrize("n", [400, 1600, 6400])
def test_bounded_records_do_not_grow_and_growing_ones_do(n):
    """Bounded: a golden rotation on a curve with a corner and the Henon attractor, 20 records each, no alarm
    (docs/classify.md: none in 1440 such records). Growing: a circle whose radius rises by 30 % over the record is
    found, with its rise (the Theil-Sen estimate over the 15 block steps of 16: 15/16 of the log-rise), one rising
    by 2 % (below ``min_rise``, 5 %) is not."""
    assert not any(growth_test(_rotation(n, corner=0.4)).growing for _ in range(20))
    assert not any(growth_test(_henon(n)).growing for _ in range(20))
    for rise, found in ((0.3, True), (0.02, False)):
        g = growth_test(_rotation(n, math.log1p(rise) / n))
        assert g.growing is found
        assert g.rise == pytest.approx((1.0 + rise) ** (15 / 16) - 1.0, rel=0.1)
        assert not found or g.newest_rise > 0.1  # one exponential: its newest half rises at the same rate


def test_the_labellers_growth_check_is_the_growth_test_and_its_rise_scipys_theil_sen():
    """``growing`` (the labeller's check) gives ``growth_test``'s verdict and numbers on bounded, borderline and
    growing records (rises of 0 to 30 %, with noise), and the rise is that of ``scipy.stats.theilslopes`` bit for
    bit."""
    settings = GrowthSettings()
    verdicts = []
    for n in (128, 400, 1600):
        for rise in (0.0, 0.03, 0.05, 0.08, 0.3):
            for noise in (0.0, 0.05):
                r = _rotation(n, math.log1p(rise) / n) * (1.0 + noise * RNG.standard_normal((n, 1)))
                g = growth_test(r, settings)
                assert growing(r, settings) == (g if g.growing else None)
                verdicts.append(g.growing)
                env = envelope(r, settings.blocks)
                slope = stats.theilslopes(np.log(np.maximum(env, indicators.LOG_FLOOR)), np.arange(16.0)).slope
                assert g.rise == math.expm1(float(slope) * 15)
    assert 0 < sum(verdicts) < len(verdicts)  # both verdicts met


def test_growth_settings_refuse_bad_values_in_one_line():
    for kw, key in (({"blocks": 3}, "blocks"), ({"alpha": 0.0}, "alpha"), ({"min_rise": -1.0}, "min_rise")):
        with pytest.raises(ValueError, match=key) as err:
            GrowthSettings(**kw)
        assert "\n" not in str(err.value)


def _growing_oscillator(c: float):
    """li2013's linear model (b = 0: no backlash, mean stiffness) with damping ``c`` (negative: energy fed in)
    in every mode."""
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    base = point.point_coefficients(d, {"x1": 0.5, "e": 5.0})
    return base.replace(b=0.0, backlash_on=False, stiffness_mode="mean", c_m=c, c_DH=c, c_VL=c)


def test_a_growing_oscillation_is_never_quasi_periodic_or_periodic():
    """Negative damping on a linear oscillator: the forced response's free part grows like exp(-c t / 2), so the
    record spirals out. Measured: without the growth test the labeller calls it quasi-periodic (the record is a
    smooth spiral whose Birkhoff averages extrapolate); with it, it runs on to the cap and is transient (or
    diverges on the way)."""
    settings = SimulationSettings(steps_per_period=64, transient_periods=50, recorded_periods=50)
    cs = indicators.ClassifierSettings(error_floor=3e-4, tangent_periods=400, torus_max_periods=1600)
    system = _growing_oscillator(-2e-4)
    with_test = label_points([system], Policy(settings, cs))[0]
    assert with_test.label in (vocabulary.LABELS["transient"], vocabulary.LABELS["diverged"]), with_test.reason
    assert not with_test.periodic
    without = label_points([system], Policy(settings, cs, growth=GrowthSettings(blocks=0)))[0]
    assert without.label not in (vocabulary.LABELS["transient"],)  # the new label only comes from the test


def test_period_searched_is_the_long_cycle_searchs_reach():
    """Rule 3 up to long_max_n (240) with three cycles in the record: 133 on a record of 400 periods, 240 from 720."""
    policy = Policy(SimulationSettings())
    assert [period_searched(n, policy) for n in (30, 400, 720, 16000)] == [12, 133, 240, 240]
    assert (
        period_searched(400, dataclasses.replace(policy, classifier=indicators.ClassifierSettings(long_max_n=0))) == 12
    )


def _response_spec(name: str):
    cfg = validate.fill_config(validate.read_config_file(ROOT / "config" / "config.yaml"))
    d = design.load(ROOT / "config" / "designs" / f"{name}.yaml")
    spec = response.ResponseSpec.from_config(
        "frequency_response", cfg["responses"]["frequency_response"], d.name, d.segment
    )
    return point.point_coefficients(d, dict(spec.fixed)), spec.policy(d), spec


@pytest.fixture(scope="module")
def printed():
    """li2013_printed's shipped frequency response on its grid points 160 ... 189 (w = 1.336 ... 1.532), where
    its quasi-periodic points lie, swept up and down."""
    base, policy, spec = _response_spec("li2013_printed")
    ds = response.frequency_response(base, spec.values[160:190], policy, spec.jump_threshold, spec.jump_floor)
    return base, policy, ds


def test_quasi_periodic_response_points_stay_bounded_when_run_on(printed):
    """Each quasi-periodic point rerun 2000 periods from its stored final state by the plain integrator keeps a
    bounded record: no growth over the last 1000 periods by the same statistic; each stores its search's reach
    and the caption gives it."""
    base, policy, ds = printed
    idx = np.argwhere(ds.label.values == QP)
    assert len(idx) >= 10  # measured: the torus band of both sweeps
    systems = [base.replace(omega=float(ds.w.values[j])) for _, j in idx]
    settings = dataclasses.replace(policy.integration, transient_periods=0, recorded_periods=2000, early_stop=False)
    runs = simulate_batch(
        [Lane(s, ds.final_state.values[i, j]) for s, (i, j) in zip(systems, idx, strict=True)], settings
    )
    grown = [
        (float(ds.w.values[j]), r.diverged or growth_test(r.poincare[-1000:]).growing)
        for (_, j), r in zip(idx, runs, strict=True)
    ]
    assert not any(g for _, g in grown), [w for w, g in grown if g]
    searched = ds.period_searched.values[ds.label.values == QP]
    assert (searched > 0).all() and (ds.period_searched.values[ds.label.values != QP] == 0).all()
    reach = f"{searched.min()}" if searched.min() == searched.max() else f"{searched.min()}-{searched.max()}"
    assert f"a torus or cycle longer than {reach} mesh periods" in captions.frequency_response("r", ds)


def test_growing_response_points_are_transient_not_quasi_periodic(printed):
    """The tori that grow toward divergence (w = 1.47-1.53, docs/response.md) are labelled transient or diverged,
    and the caption counts them."""
    _, _, ds = printed
    grow = ds.label.values == vocabulary.LABELS["transient"]
    assert grow.sum() >= 1
    assert f"Transient ({int(grow.sum())} points)" in captions.frequency_response("r", ds)


def test_a_system_without_damping_is_said_to_be_one_and_refused_by_probabilities():
    """li2013_route at w = 2 with zeta = eta = 0 (x1 = 0.5, b = 2, e = 5): a frequency response about it (short
    settings) has the file attribute and the caption line; a probabilities study of it refuses in one line."""
    d = design.load(ROOT / "config" / "designs" / "li2013_route.yaml")
    fixed = {"x1": 0.5, "b": 2.0, "e": 5.0, "w": 2.0, "zeta": 0.0, "eta": 0.0}
    system = point.point_coefficients(d, fixed)
    assert study.undamped(system)
    assert not study.undamped(point.point_coefficients(d, {**fixed, "zeta": 0.01}))
    settings = SimulationSettings(steps_per_period=64, transient_periods=50, recorded_periods=20)
    cs = indicators.ClassifierSettings(error_floor=3e-4, tangent_periods=200, torus_max_periods=400)
    w, policy = np.array([1.98, 2.0, 2.02]), Policy(settings, cs)
    ds = response.frequency_response(system, w, policy, 0.25, 0.05, 0)
    assert ds.attrs["undamped"] == 1
    caption = captions.frequency_response("undamped", ds)
    assert "No damping: no damping in any mode (zeta = eta = 0)" in caption
    assert "single orbit" in caption and "not the only motion" in caption
    damped = response.frequency_response(point.point_coefficients(d, {**fixed, "zeta": 0.03}), w, policy, 0.25, 0.05, 0)
    assert damped.attrs["undamped"] == 0 and "No damping" not in captions.frequency_response("damped", damped)
    entry = {
        "axis": {"parameter": "x1", "start": 0.5, "stop": 0.6, "num": 3},
        "fixed": {k: v for k, v in fixed.items() if k != "x1"},
        "inputs": {"e": {"low": 4.0, "high": 5.0}},
        "samples": 2,
        "integration": {"steps_per_period": 64, "transient_periods": 40, "recorded_periods": 12},
    }
    spec = probabilities.ProbabilitySpec.from_config("undamped", entry, d.name, d.segment)
    with pytest.raises(ValueError, match="c_m = c_DH = c_VL = 0") as err:
        probabilities.run_chunk(d, spec, 0)
    assert "\n" not in str(err.value)


#: The final state stored for li2013_route's Fig. 9 sweep at index (1, 0, 431) (x1 = 0.761, b = 1.9002, e = 5),
#: labelled quasi-periodic; from it the plain integrator ends on a stable P192 within 20 000 periods (return
#: distance after 192 periods 8e-12 of the attractor's size over the last 720, docs/classify.md).
FIG9_431 = [18.0910715, -6.8185857, 1469.57989, 0.0203575361, 3.54978765, 5.08389908]


def test_a_torus_that_may_be_a_longer_cycle_says_so():
    """That point relabelled from its stored state with the sweep's policy: quasi-periodic on its 400-period
    record, whose long-cycle search reaches 133 < 192 periods; the file stores it and the caption says "torus or
    cycle longer than 133"."""
    cfg = validate.fill_config(validate.read_config_file(ROOT / "config" / "config.yaml"))
    d = design.load(ROOT / "config" / "designs" / "li2013_route.yaml")
    spec = sweep.SweepSpec.from_config("fig09_bifurcation_b", cfg["sweeps"]["fig09_bifurcation_b"], d.name, d.segment)
    system = point.point_coefficients(d, sweep.point_overrides(spec, 1, spec.values[431]))
    layout = study.Layout(("b",), (1,), [[((0,), system)]], starts=[np.array(FIG9_431)])
    ds = xr.Dataset(study.run(layout, spec.policy(d)).data)
    assert int(ds.label[0]) == QP
    assert 0 < int(ds.period_searched[0]) < 192
    assert f"a torus or cycle longer than {int(ds.period_searched[0])} mesh periods" in " ".join(
        captions.verdict_notes(ds)
    )
