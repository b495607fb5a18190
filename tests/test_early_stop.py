"""Early stop of the transient: when it fires, what it records, and that a map or sweep chunk does not
depend on the chunking with it (transient_used stored per point)."""

from pathlib import Path

import numpy as np
import xarray as xr

from benchmarks.work_precision import cases
from geardyn import io
from geardyn.io import quarantine
from geardyn.khv import design
from geardyn.runs import cube, maps, sweep
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.base import EarlyStop, Lane
from geardyn.solve.run import simulate_batch

ROOT = Path(__file__).resolve().parents[1]


def test_stop_when_converged_and_not_before_minimum():
    c = cases()["periodic"]
    s = SimulationSettings(steps_per_period=32, transient_periods=900, recorded_periods=20)
    es = EarlyStop(min_periods=50, confirm=10, floor=4e-4)
    r = simulate_batch([Lane(c)], s, early_stop=es)[0]
    # period 1 (the decaying shaft mode turns by about half a turn per period, so d_2 falls below the
    # tolerance first; the stop waits for distinct cycle points, as rule 3 does)
    assert r.stop_period == 1 and 50 <= r.transient_used < 900
    # the run continued from the stop: the recorded points are those of a run with that transient
    ref = simulate(c, SimulationSettings(steps_per_period=32, transient_periods=r.transient_used, recorded_periods=20))
    assert np.array_equal(ref.poincare, r.poincare)
    # converged: the record returns after one period within the stop tolerance
    assert np.max(np.abs(np.diff(r.poincare, axis=0))) <= 4e-4
    late = simulate_batch([Lane(c)], s, early_stop=EarlyStop(min_periods=700, confirm=10, floor=4e-4))[0]
    assert late.transient_used == 700


def test_chaotic_point_runs_the_full_transient():
    c = cases()["chaotic"]
    s = SimulationSettings(steps_per_period=32, transient_periods=300, recorded_periods=20)
    r = simulate_batch([Lane(c)], s, early_stop=EarlyStop(min_periods=10, confirm=5, floor=1e-3))[0]
    assert r.stop_period == 0 and r.transient_used == 300


def _spec(chunks):
    return maps.MapSpec.from_config(
        "t",
        {
            "designs": ["li2013_w07"],
            "x": {"parameter": "x1", "start": 0.5, "stop": 0.8, "num": 3},
            "y": {"parameter": "b", "start": 0.5, "stop": 2.0, "num": 4},
            "fixed": {"e": 5.0},
            "chunks": chunks,
            "integration": {
                "steps_per_period": 32,
                "transient_periods": 300,
                "recorded_periods": 20,
                "early_stop_min_periods": 20,
            },
            "classifier": {"error_floor": 4e-3, "tangent_periods": 30},
        },
        "li2013_w07",
        (0.416, 0.835),
    )


def test_map_with_early_stop_independent_of_chunking(tmp_path):
    model = design.load(ROOT / "tests" / "data" / "li2013_w07.yaml")
    merged = []
    for chunks in (1, 5):
        spec = _spec(chunks)
        paths = [
            io.write_netcdf(maps.run_chunk(model, spec, k), tmp_path / f"{chunks}_{k}.nc") for k in range(spec.n_chunks)
        ]
        out = cube.merge_chunks(quarantine.read_chunks(paths))
        out.attrs.pop("chunk_wall_time_s", None)
        merged.append(out)
    xr.testing.assert_equal(merged[0], merged[1])
    used = merged[0]["transient_used"]
    assert used.attrs["units"] == "1" and "transient" in used.attrs["long_name"]
    # a row's first point starts from the static deflection (the early stop ends its transient); the others
    # follow their left neighbour: no transient for a followed orbit, at most follow_transient_periods else
    first = used.values[:, 0]
    assert np.all((first >= 20) & (first < 300))
    assert np.all(used.values[:, 1:] <= 100)
    assert merged[0].attrs["early_stop"] == 1


def test_sweep_cube_records_transient_used():
    model = design.load(ROOT / "tests" / "data" / "li2013_w07.yaml")
    spec = sweep.SweepSpec.from_config(
        "t",
        {
            "designs": ["li2013_w07"],
            "parameter": "b",
            "start": 0.5,
            "stop": 2.0,
            "num": 5,
            "fixed": {"e": 5.0, "x1": 0.6},
            "chunks": 1,
            "integration": {
                "steps_per_period": 32,
                "transient_periods": 300,
                "recorded_periods": 20,
                "early_stop_min_periods": 20,
            },
            "classifier": {"error_floor": 4e-3, "tangent_periods": 30},
        },
        "li2013_w07",
        (0.416, 0.835),
    )
    cb = sweep.run_chunk(model, spec, 0)
    used = cb["transient_used"].values[0, 0]
    # the first point stops its transient early; the others follow its orbit (no transient at all)
    assert 20 <= used[0] < 300 and np.all(used[1:] == 0)
    # every point is periodic, certified by shooting, with a Floquet exponent (sigma 0)
    assert np.all(cb["label"].values >= 1)
    assert np.all(cb["lyapunov_sigma"].values == 0.0)
    assert cb["stage"].values[0, 0, 0] == 2 and np.all(cb["stage"].values[0, 0, 1:] == 1)  # period_test, follow
