"""Tolerance classes of ISO 1328-1:2013 worked by hand: the profile tolerances (formulas 7, 8, 9) of two classes and
the two gears of paper 1's pair (z = 30 and 33, m_n = 3.5 mm), their combination into the bound of the mesh-frequency
TE amplitude, and the backlash range from tooth thickness and centre distance allowances (DIN 3967 relations)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

import _workflow as wf
from geardyn import cli
from geardyn.gears import tolerances
from geardyn.khv import design
from geardyn.runs import cube, probabilities, tolerance_classes

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(
    ("grade", "diameter", "slope", "form", "total"),
    [
        # class 6, step (sqrt 2)^1 = 1.414214; planet d = 30 x 3.5 = 105 mm:
        # (7) (0.4 x 3.5 + 0.001 x 105 + 4) = 5.505 x 1.414214 = 7.7852 -> 8.0 (nearest 0.5 between 5 and 10 um)
        # (8) (0.55 x 3.5 + 5) = 6.925 x 1.414214 = 9.7934 -> 10.0
        # (9) sqrt(7.7852^2 + 9.7934^2) = sqrt(60.609 + 95.911) = 12.511 -> 13 (nearest 1 above 10 um)
        (6, 105.0, 8.0, 10.0, 13.0),
        # annulus d = 33 x 3.5 = 115.5 mm: 5.5155 x 1.414214 = 7.8001 -> 8.0; form as above 10.0;
        # sqrt(7.8001^2 + 95.911) = 12.520 -> 13
        (6, 115.5, 8.0, 10.0, 13.0),
        # class 8, step (sqrt 2)^3 = 2.828427; planet: 5.505 x 2.828427 = 15.571 -> 16; 6.925 x 2.828427 = 19.587
        # -> 20; sqrt(15.571^2 + 19.587^2) = sqrt(242.44 + 383.65) = 25.022 -> 25
        (8, 105.0, 16.0, 20.0, 25.0),
        # annulus: 5.5155 x 2.828427 = 15.600 -> 16; sqrt(15.600^2 + 383.65) = sqrt(243.37 + 383.65) = 25.040 -> 25
        (8, 115.5, 16.0, 20.0, 25.0),
    ],
)
def test_profile_tolerances_by_hand(grade, diameter, slope, form, total):
    assert tolerances.profile_slope_tolerance(grade, diameter, 3.5) == slope
    assert tolerances.profile_form_tolerance(grade, diameter, 3.5) == form
    assert tolerances.total_profile_tolerance(grade, diameter, 3.5) == total


def test_the_total_is_of_the_unrounded_parts():
    # class 3 (step 1/2), d = 105 mm: (7) 5.505 / 2 = 2.7525, (8) 6.925 / 2 = 3.4625, (9) sqrt(2.7525^2 + 3.4625^2)
    # = 4.4232 -> 4.4 (nearest 0.1); the rounded parts 2.8 and 3.5 would give sqrt(7.84 + 12.25) = 4.4822 -> 4.5
    assert tolerances.total_profile_tolerance(3, 105.0, 3.5) == 4.4


@pytest.mark.parametrize(
    ("grade", "combine", "bound"),
    [
        (6, "rss", 0.5 * math.hypot(13.0, 13.0)),  # half of sqrt(13^2 + 13^2) = 18.385: 9.1924 um
        (6, "sum", 13.0),  # half of 13 + 13
        (8, "rss", 0.5 * math.hypot(25.0, 25.0)),  # half of 35.355: 17.678 um
        (8, "sum", 25.0),
    ],
)
def test_the_pairs_te_amplitude_by_hand(grade, combine, bound):
    assert tolerances.te_amplitude_bound(grade, 30, 33, 3.5, "profile", combine) == pytest.approx(bound, abs=1e-12)


def test_the_single_pitch_option_keeps_its_name():
    # f_pT (5) at class 6: planet 6.505 x 1.414214 = 9.1995 -> 9.0, annulus 6.5155 x 1.414214 = 9.2143 -> 9.0;
    # half of their root-sum-square: 9 sqrt(2) / 2 = 6.3640 um
    got = tolerances.te_amplitude_bound(6, 30, 33, 3.5, "single_pitch")
    assert got == pytest.approx(4.5 * math.sqrt(2.0), abs=1e-12)
    with pytest.raises(ValueError, match="tolerance = 'pitch', combine = 'rss' is not allowed"):
        tolerances.te_amplitude_bound(6, 30, 33, 3.5, "pitch")


def test_backlash_from_allowances_by_hand():
    # allowances [-40, -80] um on both gears, A_a = +-10 um, a_n = 20 deg, a_w = 30 deg:
    # smallest j_n = 80 cos 20 - 2 x 10 sin 30 = 75.175 - 10 = 65.175 um -> b = 32.588 um
    # largest j_n = 160 cos 20 + 2 x 10 sin 30 = 150.351 + 10 = 160.351 um -> b = 80.175 um
    low, high = tolerances.backlash_range(((-40.0, -80.0), (-40.0, -80.0)), 10.0, 20.0, 30.0)
    assert low == pytest.approx(32.5877, abs=1e-4) and high == pytest.approx(80.1754, abs=1e-4)
    with pytest.raises(ValueError, match="smallest backlash"):
        tolerances.backlash_range(((0.0, -10.0), (0.0, -10.0)), 5.0, 20.0, 30.0)


def test_a_class_gives_e_the_phase_and_b():
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    block = {
        "grade": 6,
        "tooth_thickness_allowances": [[-40.0, -80.0], [-40.0, -80.0]],
        "centre_distance_allowance": 10,
    }
    inputs = {i.name: i for i in probabilities.tolerance_inputs(d, block)}
    assert (inputs["e"].low, inputs["e"].high) == (0.0, pytest.approx(9.1924, abs=1e-4))  # as worked above
    assert (inputs["te_phase"].low, inputs["te_phase"].high) == (0.0, 2.0 * math.pi)
    # li2013's pair at x1 = 0.626 has a_w = 30.46 deg (MODEL_NOTES: 31.0 deg at x1 = 0.416 falling to 29.97 at
    # 0.835): b from 0.5 (80 cos 20 - 20 sin 30.46) = 0.5 (75.175 - 10.140) = 32.518 um
    # to 0.5 (160 cos 20 + 20 sin 30.46) = 0.5 (150.351 + 10.140) = 80.245 um
    assert inputs["b"].low == pytest.approx(32.518, abs=2e-3) and inputs["b"].high == pytest.approx(80.245, abs=2e-3)
    stated = {i.name: i for i in probabilities.tolerance_inputs(d, {**block, "backlash": [1.0, 3.0]})}
    assert (stated["b"].low, stated["b"].high) == (1.0, 3.0)  # the stated range overrides the allowances


def _copied_design():
    """li2013.yaml copied and edited as a user starts: a name of its own, no paper, other teeth and module, and
    (as in the paper's file) no tolerances: block."""
    raw = yaml.safe_load((ROOT / "config" / "designs" / "li2013.yaml").read_text())
    raw.update(name="mine", paper=None)
    raw["pair"].update(z1=40, z2=43, module=2.0)
    assert "tolerances" not in raw
    return raw


def test_a_design_without_a_class_plans_every_other_study(tmp_path, monkeypatch):
    shipped = wf.shipped("config/config.yaml")
    cfg = {k: v for k, v in shipped.items() if k in ("closed_graph", "stiffness_table", "presets")}
    cfg["designs"] = {"mine": "config/designs/mine.yaml"}
    for section in ("sweeps", "maps", "probabilities"):
        cfg[section] = {n: s for n, s in shipped[section].items() if s.get("designs") == "own"}
    cfg["calibration"], cfg["claims"], cfg["benchmarks"] = {}, {"designs": []}, {"work_precision": False}
    studies = ["regimes_w", "classes_w"]  # the standard studies of an own design that read its class
    assert [n for n, s in cfg["probabilities"].items() if s.get("tolerances") == "design"] == studies
    work = wf.workflow_copy(tmp_path / "w", cfg, {"mine": _copied_design()})
    run = wf.snakemake(work, "-n", "--cores", "1", timeout=300)
    out = run.stdout + run.stderr
    why = "it states no tolerances: block (the study takes tolerances: design)"
    skips = [f"geardyn: probabilities.{n} skips design 'mine': {why}" for n in studies]
    assert [out.count(line) for line in skips] == [1, 1], out[-3000:]
    assert "sweep_chunk" in out and "map_chunk" in out  # the other studies are planned
    rest = out
    for line in skips:
        rest = rest.replace(line, "")
    assert "probabilities_chunk" not in rest and not any(n in rest for n in studies)
    monkeypatch.chdir(work)  # check-design reads the config of the working directory
    assert cli._skipped_by(_copied_design()) == [f"probabilities.{n}: {why}" for n in studies]


def test_the_coarsest_class_is_the_closed_forms():
    """Linear closed form (tests/test_probabilities.py): with e uniform on [0, e_max(A)] of class A, the contact-loss
    probability is clip(1 - e_g(w) / e_max(A), 0, 1), so the coarsest class with P <= p* is the largest A with
    e_max(A) <= e_g(w) / (1 - p*). The class study must give that class at every tested frequency."""
    from test_probabilities import FIXED, _grazing, _linear_design  # noqa: PLC0415 - the closed-form setup

    d, classes, p_star = _linear_design(), np.array([1, 2, 3]), 0.3
    entry = {
        "axis": {"parameter": "w", "start": 1.2, "stop": 1.6, "num": 20},
        "fixed": FIXED,
        "tolerances": {"grade": 1},
        "classes": classes.tolist(),
        "limits": {"contact_loss": p_star},
        "samples": 128,
        "scramblings": 1,  # one net of 128 points: the bound below (R scramblings of 128 / R stratify 1/(128 / R))
        "seed": 1,
        "integration": {"steps_per_period": 64, "transient_periods": 100, "recorded_periods": 16},
        "classifier": {"error_floor": 3e-4, "tangent_periods": 40},
    }
    spec = probabilities.ProbabilitySpec.from_config("cls", entry, d.name, d.segment)
    # e_max of classes 1, 2, 3 (F_aT 2.2, 3.1, 4.4 um on both gears; half their root-sum-square): 1.556, 2.192, 3.111
    bounds = {int(c): tolerances.te_amplitude_bound(int(c), 30, 33, 3.5) for c in classes}
    assert [round(bounds[c], 3) for c in (1, 2, 3)] == [1.556, 2.192, 3.111]
    merged = cube.merge_chunks([probabilities.run_chunk(d, spec, 0)])
    ds = tolerance_classes.summarize(merged, spec, d)
    e_g = np.array([_grazing(d, w) for w in ds.w.values])
    p = np.clip(1.0 - e_g[None, :] / np.array([bounds[c] for c in classes])[:, None], 0.0, 1.0)
    # the e coordinate of 128 scrambled Sobol' points has one point in each 1/128: error at most 0.0078
    assert ds.e_max.values == pytest.approx([bounds[c] for c in classes], abs=1e-12)
    assert np.abs(ds.contact_loss.values - p).max() <= 0.01, np.abs(ds.contact_loss.values - p).max()
    expected = tolerance_classes.coarsest(p <= p_star, classes)
    tested = np.abs(p - p_star).min(axis=0) > 0.01  # a frequency whose answer the sampling error cannot flip
    assert tested.sum() >= 12 and len(set(expected[tested])) >= 2, (tested.sum(), expected)
    assert (ds.coarsest_class.values[tested] == expected[tested]).all(), (ds.coarsest_class.values, expected)


def test_an_operating_condition_is_drawn_only_on_purpose_and_then_says_so():
    from geardyn.config import ConfigError  # noqa: PLC0415
    from geardyn.config.validate import validate_workflow  # noqa: PLC0415
    from geardyn.plots import probabilities as plots  # noqa: PLC0415
    from test_probabilities import _config  # noqa: PLC0415 - the li2013 config of one fig07_unknowns study

    cfg = _config()
    entry = cfg["probabilities"]["p"]
    entry.pop("claims")
    entry["inputs"] = {**entry["inputs"], "w": {"low": 0.3, "high": 2.0}}
    with pytest.raises(ConfigError, match="input w is not allowed: an operating condition"):
        validate_workflow(yaml.safe_load(yaml.safe_dump(cfg)), ROOT)
    entry["inputs"]["w"]["operating"] = True
    validate_workflow(yaml.safe_load(yaml.safe_dump(cfg)), ROOT)  # on purpose: allowed
    w = probabilities.distribution("w", entry["inputs"]["w"], 1.0)
    assert w.operating and (w.low, w.high) == (0.3, 2.0) and "a share of the box" in w.text
    box = plots.conditioning(xr.Dataset(attrs={"axis_parameter": "x1", "operating_inputs": "w"}))
    assert "shares of the box" in box and "not probabilities of a drive" in box
    held = plots.conditioning(xr.Dataset(attrs={"axis_parameter": "x1", "operating_inputs": ""}))
    assert "conditional on x1 and the fixed overrides" in held and "box" not in held


def test_a_study_given_values_of_w_holds_each_and_draws_the_rest_alike():
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    entry = {
        "axis": {"parameter": "x1", "start": 0.5, "stop": 0.8, "num": 3},
        "fixed": {"b": 2.0, "e": 5.0},
        "inputs": {"zeta": {"low": 0.03, "high": 0.15}, "K_DH": {"low": 1e3, "high": 1e6, "scale": "log"}},
        "given": {"parameter": "w", "values": [0.6, 1.2, 1.8]},
        "samples": 8,
    }
    spec = probabilities.ProbabilitySpec.from_config("g", entry, d.name, d.segment)
    table = probabilities.study_samples(d, spec)
    assert table.names == ("zeta", "K_DH", "w") and table.values.shape == (24, 3)
    assert (table.values[:, 2] == np.repeat([0.6, 1.2, 1.8], 8)).all()  # held: 8 samples at each value
    # the same unknowns at every value (common random numbers)
    assert (table.values[:8, :2] == table.values[8:16, :2]).all() and (
        table.values[:8, :2] == table.values[16:, :2]
    ).all()
    assert table.inputs[-1].operating  # the summary over all values is a share of the box: its caption says so
    # no index lines (sample_block < 0) in a given or class study; each value, each class, the same scramblings
    assert spec.index_samples == 0 and (table.block == np.tile(np.repeat(np.arange(4), 2), 3)).all()
    entry = {k: v for k, v in entry.items() if k != "given"} | {"tolerances": {"grade": 6}, "classes": [5, 7]}
    spec = probabilities.ProbabilitySpec.from_config("c", entry, d.name, d.segment)
    classes = probabilities.study_samples(d, spec)
    assert spec.index_samples == 0 and (classes.block == np.tile(np.repeat(np.arange(4), 2), 2)).all()
    lines = probabilities.layout(d, spec, 0, table).lines
    assert [line[0][1].omega for line in lines[::8]] == pytest.approx([0.6, 1.2, 1.8])  # each line at its w
