"""Sweeps: chunks tile the sweep, results do not depend on the chunking, continuation works."""

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from geardyn import io
from geardyn.io import quarantine
from geardyn.khv import design, point
from geardyn.label import label_lines
from geardyn.label.vocabulary import LABELS, NOT_COMPUTED
from geardyn.runs import cube, sweep

ROOT = Path(__file__).resolve().parents[1]
#: The integration of a new user's small sweep (64 steps per period, 40 + 8 periods).
FAST = {"steps_per_period": 64, "transient_periods": 40, "recorded_periods": 8}


@pytest.fixture(scope="module")
def li2013():
    return design.load(ROOT / "config" / "designs" / "li2013.yaml")


def _spec(**changes):
    base = dict(
        designs=["li2013"],
        parameter="x1",
        start=0.45,
        stop=0.80,
        num=7,
        fixed={"b": 2.0, "e": 5.0},
        cases=[{}],
        chunks=1,
        integration={"transient_periods": 30, "recorded_periods": 8, "steps_per_period": 64},
    )
    base.update(changes)
    return sweep.SweepSpec.from_config("t", base, "li2013", (0.416, 0.835))


@pytest.mark.parametrize("chunks", [1, 2, 3, 7])
def test_chunks_tile_each_point_once(chunks):
    spec = _spec(chunks=chunks, cases=[{"b": 1.0}, {"b": 2.0}])
    seen = {}
    for c in range(spec.n_chunks):
        for case, d, idx in sweep.chunk_work(spec, c):
            for j in idx:
                seen[(case, d, j)] = seen.get((case, d, j), 0) + 1
    assert len(seen) == 2 * 7 and set(seen.values()) == {1}


@pytest.mark.parametrize("start_from", ["follow", "fixed"])
def test_result_independent_of_chunking(li2013, tmp_path, start_from):
    """Three lines (cases); a chunk holds whole lines (follow) or any points (fixed): the merged cube is
    the same bit for bit whatever the chunking."""
    merged = []
    for chunks in (1, 3):
        spec = _spec(chunks=chunks, cases=[{"b": 1.0}, {"b": 2.0}, {"b": 3.0}], start_from=start_from)
        assert spec.n_chunks == chunks
        # through netCDF and the merge rules' loader, as in the pipeline
        paths = [
            io.write_netcdf(sweep.run_chunk(li2013, spec, c), tmp_path / f"{start_from}{chunks}_{c}.nc")
            for c in range(spec.n_chunks)
        ]
        parts = quarantine.read_chunks(paths)
        merged.append(cube.merge_chunks(parts))
    xr.testing.assert_equal(merged[0], merged[1])  # bit-identical values, coordinates and dims
    assert int((merged[0]["stage"] == NOT_COMPUTED).sum()) == 0  # every point computed
    assert np.isfinite(merged[0]["x_vh"].values).all()


def test_merge_refuses_missing_or_duplicate_chunks(li2013):
    spec = _spec(chunks=2, num=2, cases=[{"b": 1.0}, {"b": 2.0}])
    a = sweep.run_chunk(li2013, spec, 0)
    with pytest.raises(ValueError, match="2 points missing"):
        cube.merge_chunks([a])
    with pytest.raises(ValueError, match="computed twice"):
        cube.merge_chunks([a, a, sweep.run_chunk(li2013, spec, 1)])


def test_continuation_both_directions_has_direction_coordinate(li2013):
    spec = _spec(continuation="both", num=4, chunks=5)
    assert spec.n_chunks == 2  # one job per (case, direction), whatever 'chunks' says
    merged = cube.merge_chunks([sweep.run_chunk(li2013, spec, c) for c in range(spec.n_chunks)])
    assert list(merged["direction"].values) == ["up", "down"]
    assert np.isfinite(merged["x_vh"].values).all()
    # the first point of the upward sweep starts from the static deflection, like an unchained run
    plain = sweep.run_chunk(li2013, _spec(num=4), 0)
    np.testing.assert_array_equal(
        merged["x_vh"].sel(direction="up").values[:, 0], plain["x_vh"].sel(direction="none").values[:, 0]
    )


def test_an_undamped_sweep_diverges_and_stores_the_newest_points_its_axis_holds(li2013):
    """No damping (zeta = eta = 0): every point grows without bound (parametric instability).  A diverged run
    keeps its whole record, longer than the recorded periods at x1 = 0.625; the cube stores its newest points."""
    spec = _spec(num=3, fixed={"b": 2.0, "e": 5.0, "zeta": 0.0, "eta": 0.0, "w": 2.0}, integration=FAST)
    policy = spec.policy(li2013)
    ds = sweep.run_chunk(li2013, spec, 0)
    assert ds.label.values.ravel().tolist() == [LABELS["diverged"]] * 3 and (ds.diverged_period.values >= 0).all()
    assert ds.sizes["section"] == FAST["recorded_periods"]
    systems = [point.point_coefficients(li2013, sweep.point_overrides(spec, 0, x)) for x in spec.values]
    (verdicts,) = label_lines([systems], policy)
    assert max(v.poincare.shape[0] for v in verdicts) > FAST["recorded_periods"]  # the case that overflowed
    for j, v in enumerate(verdicts):
        newest = v.poincare[-FAST["recorded_periods"] :]
        stored = ds.x_vh.values[0, 0, j]
        np.testing.assert_array_equal(stored[: newest.shape[0]], newest[:, 1])
        assert np.isnan(stored[newest.shape[0] :]).all()
