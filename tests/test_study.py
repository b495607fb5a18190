"""The one study runner (geardyn.runs.study): the specs share their fields and policy, the variables follow
the layout, and a run stores every verdict at its point's index."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from geardyn import io
from geardyn.khv import design, point
from geardyn.label import Policy, label_lines
from geardyn.runs import maps, response, study, sweep
from geardyn.runs.cube import COMMON, VARIABLES, empty

ROOT = Path(__file__).resolve().parents[1]
SEGMENT = (0.416, 0.835)
SHARED = {
    "fixed": {"e": 5.0, "b": 2.0},
    "integration": {"steps_per_period": 64, "transient_periods": 40, "recorded_periods": 12},
    "classifier": {"tangent_periods": 30},
}


@pytest.fixture(scope="module")
def li2013():
    return design.load(ROOT / "config" / "designs" / "li2013.yaml")


@pytest.fixture(scope="module")
def route():
    return design.load(ROOT / "config" / "designs" / "li2013_route.yaml")


def test_the_specs_share_their_fields_and_their_policy(li2013):
    entry = {**SHARED, "chunks": 3, "start_from": "fixed", "coexistence": True}
    a = sweep.SweepSpec.from_config(
        "s", {**entry, "parameter": "x1", "start": "0%", "stop": "100%", "num": 5}, "d", SEGMENT
    )
    axis = {"parameter": "x1", "start": 0.5, "stop": 0.8, "num": 3}
    b = maps.MapSpec.from_config("m", {**entry, "x": axis, "y": {**axis, "parameter": "w"}}, "d", SEGMENT)
    r = response.ResponseSpec.from_config("r", {**SHARED, "start": 0.5, "stop": 1.5, "num": 5}, "d", SEGMENT)
    for spec in (a, b, r):
        assert spec.fixed == (("b", 2.0), ("e", 5.0)) and spec.fixed_overrides == "b=2,e=5"
        assert dict(spec.integration) == SHARED["integration"] and dict(spec.classifier) == SHARED["classifier"]
    assert (a.start, a.stop) == SEGMENT  # percentages of x1 resolved on the segment
    assert (a.chunks, a.start_from, a.coexistence) == (b.chunks, b.start_from, b.coexistence) == (3, "fixed", True)
    assert (r.chunks, r.start_from, r.coexistence) == (1, "follow", False)
    policy = a.policy(li2013)
    assert policy == b.policy(li2013) and policy.start == "fixed" and policy.coexistence
    assert r.policy(li2013) == dataclasses.replace(policy, start="follow", coexistence=False)
    assert policy.integration == point.integration_settings(li2013, **SHARED["integration"])


def test_the_variables_follow_the_layout_and_the_policy(li2013):
    """A study keeps the verdict's and the response's variables, the fixed start's label and the coexistence flag
    with the policy's coexistence, the transient and computed flag where the layout keeps them,
    and the layout's own as given; each on the layout's grid as the table declares it (CF attributes, dtype),
    filled with its fill value (NaN, or the code of "not computed")."""
    policy = Policy(point.integration_settings(li2013), coexistence=True)
    own = {"mine": (("p",), np.zeros(3), {})}
    full = study.variables(study.Layout(("p",), (3,), [], computed=True, own=own), policy)
    assert set(full) == {*COMMON, "label_fixed", "coexisting", "mine", "transient_used", "computed"}
    assert full.pop("mine") is own["mine"]
    assert io.missing_cf_attributes(xr.Dataset(full)) == []
    for name, (dims, values, attrs) in full.items():
        var = VARIABLES[name]
        want = xr.Variable(("p",), np.full(3, var.fill, var.dtype), var.attributes())
        assert values.dtype == want.dtype and xr.Variable(dims, values, attrs).identical(want), name
        if var.flags is not None:
            assert set(np.unique(values)) <= set(var.flags.values()), name
    bare = study.variables(
        study.Layout(("p",), (3,), [], transient=False), dataclasses.replace(policy, coexistence=False)
    )
    assert set(bare) == set(COMMON)


def test_a_run_stores_each_verdict_at_its_index(li2013):
    """Two lines given in any order of indices: each verdict lands where its point says, as label_lines
    gives it; the fixed start's labels and the computed flags where the layout keeps them."""
    spec = sweep.SweepSpec.from_config(
        "s", {**SHARED, "parameter": "x1", "start": 0.5, "stop": 0.8, "num": 3}, "d", SEGMENT
    )
    policy = dataclasses.replace(spec.policy(li2013), coexistence=True)
    systems = [point.point_coefficients(li2013, sweep.point_overrides(spec, 0, x)) for x in spec.values]
    lines = [[((1, 2), systems[2]), ((1, 1), systems[1])], [((0, 0), systems[0])]]
    result = study.run(study.Layout(("a", "b"), (2, 3), lines, computed=True), policy)
    data = {name: var[1] for name, var in result.data.items()}
    verdicts = label_lines([systems[2:0:-1], systems[:1]], policy)
    fixed = label_lines([systems[2:0:-1], systems[:1]], policy.with_start("fixed"))
    assert [[v.label for v in line] for line in result.verdicts] == [[v.label for v in line] for line in verdicts]
    for (i, j), v, f in zip(
        [(1, 2), (1, 1), (0, 0)], [*verdicts[0], *verdicts[1]], [*fixed[0], *fixed[1]], strict=True
    ):
        assert data["label"][i, j] == v.label and data["period"][i, j] == v.period
        assert data["label_fixed"][i, j] == f.label and data["transient_used"][i, j] == v.transient_used
    assert data["computed"].tolist() == [[1, 0, 0], [0, 1, 1]]
    assert data["label_fixed"][0, 1] == data["label"][0, 1] == empty(["label"], ("a",), (1,))["label"][1][0]


@settings(max_examples=5, deadline=None)
@given(recorded=st.integers(1, 24), max_n=st.integers(1, 12))
def test_no_verdict_overflows_its_axis(route, recorded, max_n):
    """Any recorded periods and largest period: every verdict fits the cube.  li2013_route's x1 line holds
    period-2 and period-4 orbits and chaos; without damping at w = 1 its runs diverge and keep their whole
    records.  Each point's label is a flag value of the cube, its section axis holds the verdict's newest points."""
    entry = {
        **SHARED,
        "integration": {"steps_per_period": 32, "transient_periods": 20, "recorded_periods": recorded},
        "classifier": {"max_n": max_n, "tangent_periods": 30},
        "cases": [{}, {"zeta": 0.0, "eta": 0.0, "w": 1.0}],
        **{"parameter": "x1", "start": 0.6, "stop": 0.8, "num": 3},
    }
    spec = sweep.SweepSpec.from_config("s", entry, route.name, SEGMENT)
    policy = spec.policy(route)
    result = study.run(sweep.layout(route, spec, 0, policy), policy)
    data = {name: var[1] for name, var in result.data.items()}
    flags = set(result.data["label"][2]["flag_values"].tolist())
    assert data["x_vh"].shape[-1] == recorded
    for (case, _, order), line in zip(sweep.chunk_work(spec, 0), result.verdicts, strict=True):
        for j, v in zip(order, line, strict=True):
            assert data["label"][case, 0, j] == v.label in flags
            newest = v.poincare[-recorded:, 1]
            np.testing.assert_array_equal(data["x_vh"][case, 0, j, : newest.size], newest)
            assert np.isnan(data["x_vh"][case, 0, j, newest.size :]).all()
