"""Regime probabilities under uncertain inputs (geardyn.runs.probabilities, probability_stats), against numbers
from outside the code.

* ISO 1328-1:2013: f_pT = (0.001 d + 0.4 m_n + 5) (sqrt 2)^(A - 5), rounded (5.2.3), worked by hand below.
* Closed form: li2013 with the mean mesh stiffness is linear while the teeth stay in contact, so with e uniform on
  [e1, e2] and all else fixed, P(contact loss at w) = clip((e2 - e_g(w)) / (e2 - e1), 0, 1), e_g(w) =
  (|x_s| - b) / |H(w)| the grazing amplitude of docs/orbits.md (the curves' test derives it the same way). 1024
  samples in 8 scramblings, 20 frequencies: within 3 QMC standard errors (the scramblings' spread) and 0.005
  (measured: at most 0.0022, 2.1 of them); the threshold shifted 2 % fails.
* Wilson intervals cover a known p at 93-97 % of 2000 seeded Bernoulli repetitions; they equal scipy's.
* A dummy input (the input speed, which enters no equation at a dimensionless mesh frequency) stays below its
  permutation null; e, which alone decides contact loss and K_v there, a first-order index >= 0.9.
* The same bits whatever the chunking and the thread count.
"""

import copy
import dataclasses
from pathlib import Path

import numba
import numpy as np
import pytest
import xarray as xr
from scipy.stats import binomtest

import _workflow as wf
from geardyn import io
from geardyn.config import ConfigError
from geardyn.config.validate import read_config_file, validate_workflow
from geardyn.gears import tolerances
from geardyn.khv import design, model, point
from geardyn.plots import probabilities as plots
from geardyn.plots import save_figure
from geardyn.runs import cube, probabilities, probability_stats

ROOT = Path(__file__).resolve().parents[1]
E1, E2, N, R, W = 0.8, 2.4, 1024, 8, (1.2, 1.6, 20)


def test_single_pitch_tolerance_of_iso_1328():
    # d = 105 mm (z = 30, m = 3.5): 0.105 + 1.4 + 5 = 6.505 um at class 5; x sqrt(2) = 9.1995 -> 9.0 (nearest 0.5);
    # x 8 at class 11 = 52.04 -> 52 (nearest 1); / 4 at class 1 = 1.626 -> 1.6 (nearest 0.1)
    assert tolerances.single_pitch_tolerance(5, 105.0, 3.5) == 6.5
    assert tolerances.single_pitch_tolerance(6, 105.0, 3.5) == 9.0
    assert tolerances.single_pitch_tolerance(11, 105.0, 3.5) == 52.0
    assert tolerances.single_pitch_tolerance(1, 105.0, 3.5) == 1.6
    # the annulus (d = 115.5 mm): 6.5155 x 2 = 13.031 at class 7 -> 13, as the planet (6.505 x 2 = 13.01)
    assert tolerances.te_amplitude_bound(7, 30, 33, 3.5, "single_pitch", "sum") == 13.0  # half of 13 + 13
    assert [tolerances.rounded(v) for v in (10.5, 7.3, 7.2, 4.25, 4.24)] == [11.0, 7.5, 7.0, 4.3, 4.2]
    for bad in ((0, 100.0, 2.0), (12, 100.0, 2.0), (6, 100.0, 0.3), (6, 2.0, 2.0)):
        with pytest.raises(ValueError):
            tolerances.single_pitch_tolerance(*bad)


def test_wilson_intervals_cover_and_are_scipys():
    rng = np.random.default_rng(7)
    for p, n in ((0.3, 128), (0.05, 256), (0.5, 64)):
        k = rng.binomial(n, p, size=2000)
        lo, hi = probability_stats.wilson(k, n)
        cover = float(np.mean((lo <= p) & (p <= hi)))
        assert 0.93 <= cover <= 0.97, (p, n, cover)  # measured 0.943, 0.953, 0.937
    for k, n in ((0, 20), (3, 20), (20, 20), (57, 128)):
        ci = binomtest(k, n).proportion_ci(0.95, method="wilson")
        assert probability_stats.wilson(k, n) == pytest.approx((ci.low, ci.high), abs=1e-12)


def test_quantile_intervals_cover():
    rng = np.random.default_rng(3)
    for q in (0.05, 0.5, 0.95):
        hits = [
            lo <= q <= hi
            for lo, hi in (probability_stats.quantile_interval(rng.random(256), q)[1:] for _ in range(400))
        ]
        assert 0.92 <= np.mean(hits) <= 1.0, q  # distribution-free: at least 95 % but for the discreteness


def _linear_design():
    """li2013 with the mean mesh stiffness and damped shafts (eta = 0.05, so every sample is P1): linear while the
    teeth stay in contact."""
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    return dataclasses.replace(
        d, dynamics={**d.dynamics, "options": {**d.dynamics["options"], "stiffness_mode": "mean"}}
    )


FIXED = {"x1": 0.5, "b": 2.0, "eta": 0.05}


def _grazing(d, w):
    """e_g(w) = (|x_s| - b) / |H(w)|, H the response of x_VH to a TE of unit amplitude (docs/orbits.md)."""
    c = point.point_coefficients(d, {**FIXED, "w": w, "e": 1.0})
    m = c.matrices()
    mesh = np.outer(m["g"], [0.0, 1.0, 0.0])
    X = np.linalg.solve(-(w**2) * np.eye(3) + 1j * w * (m["C"] + c.c_m * mesh) + m["K"] + mesh, [0.0, w**2, 0.0])
    return (abs(model.static_deflection(c)[1]) - c.b) / abs(X[1])


@pytest.fixture(scope="module")
def closed_form():
    d = _linear_design()
    entry = {
        "axis": {"parameter": "w", "start": W[0], "stop": W[1], "num": W[2]},
        "fixed": FIXED,
        "inputs": {"e": {"low": E1, "high": E2}, "speed": {"low": 100.0, "high": 1000.0}},
        "samples": N,
        "seed": 1,
        "scramblings": R,
        "integration": {"steps_per_period": 64, "transient_periods": 100, "recorded_periods": 16},
        "classifier": {"error_floor": 3e-4, "tangent_periods": 40},
        "sensitivity": {"indicators": ["no_impact", "dynamic_factor"], "points": W[2]},
    }
    spec = probabilities.ProbabilitySpec.from_config("cf", entry, d.name, d.segment)
    merged = cube.merge_chunks([probabilities.run_chunk(d, spec, 0)])
    return d, probability_stats.summarize(merged, spec, probabilities.samples(d, spec))


def _contact_loss_agrees(ds, grazing):
    """Whether P(contact loss) agrees with clip((e2 - e_g) / (e2 - e1)) at every frequency within 3 QMC standard
    errors and 0.005; the largest error, its ratio to the standard error and the closed form.  The standard error
    is the spread of the R scramblings pooled along the line (the RMS of the points'): at one point an indicator's
    spread is quantized (a scrambling of 128 points stratifies e, so its count is k or k + 1) and all R fall on the
    same count at about 1 point in 20."""
    p = np.clip((E2 - grazing) / (E2 - E1), 0.0, 1.0)
    got = 1.0 - ds.impact_probability.sel(impact="no_impact").values
    se = float(np.sqrt(np.mean(ds.impact_probability_qmc_se.sel(impact="no_impact").values ** 2)))
    err = np.abs(got - p)
    return bool(np.all(err <= 3 * se) and np.all(err <= 0.005)), float(err.max()), float(err.max() / se), p


def test_contact_loss_probability_is_the_closed_form(closed_form):
    d, ds = closed_form
    rows = ds.sample_block.values >= 0
    assert (ds.label.values[rows] == 1).all()  # every sample period-1: the grazing test's regime
    grazing = np.array([_grazing(d, w) for w in ds.w.values])
    ok, worst, ratio, p = _contact_loss_agrees(ds, grazing)
    assert 0.25 < p.min() and p.max() < 0.85  # a range of probabilities, none 0 or 1
    assert ok, (worst, ratio)  # measured: at most 0.0022, 2.1 QMC standard errors (0.0010)
    low, high = (ds[f"impact_probability_{e}"].sel(impact="no_impact").values for e in ("low", "high"))
    assert np.all((low <= 1 - p) & (1 - p <= high))  # the Wilson interval (n = 1024) holds it too
    se = ds.impact_probability_qmc_se.sel(impact="no_impact").values
    assert np.all(se < 0.2 * np.sqrt(p * (1 - p) / N))  # the QMC error: below a fifth of the Monte Carlo one
    # a grazing threshold 2 % off fails the same check
    assert not _contact_loss_agrees(ds, 1.02 * grazing)[0] and not _contact_loss_agrees(ds, 0.98 * grazing)[0]


def test_the_input_that_decides_leads_and_a_dummy_does_not(closed_form):
    """The index design (a Latin hypercube of 128 lines): e decides contact loss and K_v; the input speed enters no
    equation at a dimensionless mesh frequency, so its index stays below its permutation null."""
    _, ds = closed_form
    s, conf, null = ds.sensitivity_index, ds.sensitivity_index_conf, ds.sensitivity_null
    for indicator in ("no_impact", "dynamic_factor"):
        assert (s.sel(indicator=indicator, input="e") >= 0.9).all()  # measured >= 0.929 (no_impact), 1.0 (K_v)
        at = {"indicator": indicator, "input": "speed"}
        assert (s.sel(at) - conf.sel(at) < null.sel(at)).all()  # measured: at least 0.27 below
        assert (null.sel(at) < 0.2).all()  # the null of 128 lines: measured 0.08-0.12
    assert ds.attrs["leading_input_no_impact"] == ds.attrs["leading_input_dynamic_factor"] == "e"


def _small(chunks):
    d = design.load(ROOT / "tests" / "data" / "li2013_w07.yaml")
    entry = {
        "axis": {"parameter": "x1", "start": 0.5, "stop": 0.8, "num": 4},
        "fixed": {"b": 2.0},
        "tolerances": {"grade": 6},
        "inputs": {"zeta": {"std": 0.01}, "K_DH": {"low": 1e4, "high": 1e5, "scale": "log"}},
        "initial_state": {"box_x": 3.0, "box_v": 3.0},
        "samples": 6,
        "sensitivity": {"samples": 4},
        "chunks": chunks,
        "integration": {"steps_per_period": 64, "transient_periods": 40, "recorded_periods": 12},
        "classifier": {"error_floor": 3e-4, "tangent_periods": 30},
    }
    return d, probabilities.ProbabilitySpec.from_config("s", entry, d.name, d.segment)


def test_the_same_bits_whatever_the_chunking_and_the_threads(tmp_path):
    runs = []
    n0 = numba.get_num_threads()
    try:
        for chunks, threads in ((1, n0), (4, 1)):
            numba.set_num_threads(threads)
            d, spec = _small(chunks)
            parts = [
                io.write_netcdf(probabilities.run_chunk(d, spec, c), tmp_path / f"{chunks}_{c}.nc")
                for c in range(spec.n_chunks)
            ]
            merged = cube.merge_chunks([io.read_dataset(p) for p in parts])
            merged.attrs.pop("chunk_wall_time_s")
            runs.append(probability_stats.summarize(merged, spec, probabilities.samples(d, spec)))
    finally:
        numba.set_num_threads(n0)
    xr.testing.assert_identical(runs[0], runs[1])
    table = probabilities.samples(d, spec)
    assert table.names == ("e", "te_phase", "zeta", "K_DH", *probabilities.START_INPUTS)
    # e_max of class 6: half the rss of F_aT = 13 um on both gears, 9.19 um (tests/test_tolerance_classes.py)
    assert np.all(table.values[:, 0] <= 9.2) and np.all(np.abs(table.values[:, 4:]) <= 3.0)


def test_saltelli_design_and_sobol_indices():
    unit, block = probabilities.saltelli(3, 64, 0)
    assert unit.shape == (64 * (3 + 2), 3) and (block == 0).sum() == 64  # N (D + 2) runs; the base sample A
    s = probability_stats.indices("sobol", unit, unit[:, 0] + 0.1 * unit[:, 2], 50, 0)
    assert s[0, 0] > 0.9 and abs(s[0, 1]) < 0.05 and s[2, 0] >= s[0, 0] - 0.05  # first-order and total


BAD = [
    (lambda e: e["inputs"].update(zet={"low": 0.1, "high": 0.2}), "inputs: unknown control parameter 'zet'"),
    (lambda e: e["inputs"].update(zeta={"low": 0.2, "high": 0.1}), "inputs.zeta: zeta uniform on [0.2, 0.1] is not"),
    (lambda e: e["inputs"].update(zeta={"std": -0.1}), "inputs.zeta.std = -0.1 is not allowed: number > 0"),
    (lambda e: e.update(samples=0), "samples = 0 is not allowed: integer >= 1 and <= 1000000"),
    (lambda e: e.update(samples=1000001), "samples = 1000001 is not allowed: integer >= 1 and <= 1000000"),
    (lambda e: e.update(tolerances={"grade": 12}), "tolerances.grade = 12 is not allowed: integer >= 1 and <= 11"),
    (lambda e: e["inputs"].update(w={"low": 0.3, "high": 2.0}), "inputs.w: input w is not allowed: an operating"),
    (lambda e: e["inputs"].update(b={"tolerance": 0.5}), "inputs.b: input b is not allowed"),
    (lambda e: e.update(claims="fig09"), "claims = 'fig09' is not allowed for design 'li2013': one of 'fig07'"),
]


def _config():
    cfg = read_config_file(ROOT / "config" / "config.yaml")
    cfg["designs"] = {"li2013": "config/designs/li2013.yaml"}
    for section in ("sweeps", "points", "maps", "curves", "responses", "orbits", "calibration"):
        cfg[section] = {}
    cfg["claims"] = {"designs": []}
    entry = copy.deepcopy(cfg["probabilities"]["fig07_unknowns"])
    cfg["probabilities"] = {"p": {**entry, "designs": ["li2013"], "claims": "fig07"}}
    return cfg


@pytest.mark.parametrize(("change", "message"), BAD)
def test_bad_input_gives_one_line(change, message):
    cfg = _config()
    validate_workflow(copy.deepcopy(cfg), ROOT)  # the study itself is valid
    change(cfg["probabilities"]["p"])
    with pytest.raises(ConfigError) as err:
        validate_workflow(cfg, ROOT)
    assert "\n" not in str(err.value) and f"config: probabilities.p.{message}" in str(err.value), str(err.value)


def test_bad_input_stops_snakemake_before_any_job(tmp_path):
    cfg = _config()
    cfg["probabilities"]["p"]["inputs"]["zeta"] = {"low": 0.2, "high": 0.1}
    work = wf.workflow_copy(tmp_path / "w", cfg)
    run = wf.snakemake(work, "--cores", "1", timeout=120, check=False)
    lines = [line for line in (run.stderr + run.stdout).splitlines() if line.strip()]
    assert run.returncode != 0 and len(lines) == 1, run.stderr + run.stdout
    assert lines[0].startswith("geardyn config error: config: probabilities.p.inputs.zeta: zeta uniform on [0.2, 0.1]")
    assert not (work / "results").exists()


def test_a_study_of_one_point_with_sobol_indices_and_its_figure(tmp_path):
    """No axis: the design's point; the initial state as an input (basin stability); Saltelli's design of 4 base
    points for 2 inputs and the 6 start components: 4 (8 + 2) = 40 runs, the probabilities on the 4 base points."""
    d = design.load(ROOT / "tests" / "data" / "li2013_w07.yaml")
    entry = {
        "fixed": {"x1": 0.5, "b": 2.0, "e": 5.0},
        "inputs": {"zeta": {"relative_tolerance": 0.2}, "m_V": {"tolerance": 0.1}},
        "initial_state": {"box_x": 5.0, "box_v": 5.0},
        "samples": 4,
        "sensitivity": {"method": "sobol", "indicators": ["dynamic_factor", "P1"]},
        "integration": {"steps_per_period": 64, "transient_periods": 40, "recorded_periods": 12},
        "classifier": {"error_floor": 3e-4, "tangent_periods": 30},
    }
    spec = probabilities.ProbabilitySpec.from_config("one", entry, d.name, d.segment)
    table = probabilities.samples(d, spec)
    assert table.values.shape == (40, 8)
    zeta = point.nominal(d, "zeta", entry["fixed"])
    assert np.all(np.abs(table.values[:, 0] - zeta) <= 0.2 * zeta)
    ds = probability_stats.summarize(cube.merge_chunks([probabilities.run_chunk(d, spec, 0)]), spec, table)
    assert ds.sizes == {**ds.sizes, "sample": 40, "point": 1, "sensitivity_at": 1}
    assert np.isclose(ds.family_probability.sum("family"), 1.0).all() and "total_index" in ds
    save_figure(plots.probabilities_figure(ds, "one point"), tmp_path / "one.png", plots.caption("one", ds))
    assert (tmp_path / "one.png").stat().st_size > 10_000
