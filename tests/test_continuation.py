"""Pseudo-arclength continuation of KHV orbits: folds, Neimark-Sacker, grazing, agreement with simulation.

Numbers measured with the defaults (512 steps per period, rk4_event) on the calibrated design
(w = 0.7, b = 2, e = 5) along x1: folds at 0.72731 and 0.75271, Neimark-Sacker at 0.727405 with
rotation number 0.28805; on li2013 (w = 0.9, x1 = 0.5, b = 2) along e: grazing at e = 0.30608,
folds at 0.37593 and 0.12952.
"""

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import _orbits
from _oracle import rules_label
from geardyn import io
from geardyn.io import provenance
from geardyn.khv import design, point
from geardyn.label import indicators, vocabulary
from geardyn.papers import li2013 as paper
from geardyn.plots import save_figure
from geardyn.plots.orbits import plot_branches
from geardyn.runs import continuation as C
from geardyn.runs.continuation.family import back_margin
from geardyn.runs.cube import STATES
from geardyn.solve import SimulationSettings, simulate

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def calibrated_branch():
    return _orbits.calibrated_branch()


def test_interpolated_coefficients_match_direct(calibrated_branch):
    _, fam, _ = calibrated_branch
    assert fam.interpolation_error < 1e-8


def test_branch_passes_two_folds_and_types_them(calibrated_branch):
    _, _, br = calibrated_branch
    assert br.end_status == {"down": "range", "up": "range"}
    folds = sorted(b.p for b in br.bifurcations if b.kind == "fold")
    assert len(folds) == 2
    assert folds[0] == pytest.approx(0.72731, abs=2e-4)
    assert folds[1] == pytest.approx(0.75271, abs=2e-4)
    for b in br.bifurcations:
        if b.kind == "fold":
            assert b.located and abs(b.critical - 1.0) < 1e-3
    # the branch goes up, back and up again: p is not monotonic along it
    assert np.any(np.diff(br.p) < 0) and np.any(np.diff(br.p) > 0)


def test_neimark_sacker_rotation_number_matches_torus_spectrum(calibrated_branch):
    _, fam, br = calibrated_branch
    ns = [b for b in br.bifurcations if b.kind == "neimark_sacker"]
    assert len(ns) == 1
    ns = ns[0]
    assert ns.located and abs(abs(ns.critical) - 1.0) < 1e-8
    assert ns.p == pytest.approx(0.727405, abs=1e-4)
    # just past the bifurcation, a run started next to the (now unstable) orbit settles on a small
    # torus; the stroboscopic X_VH then oscillates at the rotation number (cycles per mesh period)
    after = br.p > ns.p
    j = np.flatnonzero(after & (br.p > ns.p + 1e-4) & (np.arange(len(br)) > ns.index))[0]
    c = fam.coefficients(float(br.p[j]))
    r = simulate(c, SimulationSettings(transient_periods=3000, recorded_periods=4096), br.states[j] + 1e-3)
    x = r.poincare[:, 1]
    amp = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(x.size)))
    f = np.fft.rfftfreq(x.size)
    k = int(np.argmax(amp[1:])) + 1
    a, b, c2 = np.log(amp[k - 1 : k + 2])
    peak = f[k] + 0.5 * (a - c2) / (a - 2 * b + c2) * (f[1] - f[0])
    assert np.ptp(x) > 1e-3  # a torus, not the fixed point
    assert abs(peak - ns.rotation_number) < 1e-3  # measured 6e-5


def test_branch_agrees_with_simulated_labels_where_stable(calibrated_branch):
    d, _, br = calibrated_branch
    settings = point.integration_settings(d)
    cls = indicators.ClassifierSettings()
    scale = np.max(np.abs(br.states))
    checked = 0
    for x1 in np.linspace(0.70, 0.78, 9):
        coeffs = point.point_coefficients(d, {"x1": x1, "b": 2.0, "e": 5.0})
        res, lab = rules_label(coeffs, settings, cls)
        # branch points at this x1 (one per crossing of the branch), stable or not
        hits = []
        for i in range(len(br) - 1):
            lo, hi = sorted((br.p[i], br.p[i + 1]))
            if lo <= x1 <= hi:
                w = 0.0 if hi == lo else (x1 - br.p[i]) / (br.p[i + 1] - br.p[i])
                hits.append(
                    (br.states[i] + w * (br.states[i + 1] - br.states[i]), bool(br.stable[i] and br.stable[i + 1]))
                )
        if lab.label == 1:
            # a simulated P1 point lies on a stable part of the branch
            d_min = min(np.max(np.abs(res.poincare[-1] - x)) for x, st in hits if st)
            assert d_min < 1e-4 * scale
            checked += 1
        else:
            # not P1: no stable branch point is the attractor reached (it is elsewhere: torus)
            assert lab.label in (vocabulary.LABELS["quasi_periodic"], vocabulary.LABELS["chaotic"]) or lab.label > 1
    assert checked >= 4


def test_grazing_located_on_li2013_e_sweep():
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    fam = C.KHVFamily(d, "e", {"x1": 0.5, "b": 2.0}, 0.0, 1.0, nodes=5)
    c = fam.coefficients(0.05)
    r = simulate(c, SimulationSettings(transient_periods=2000, recorded_periods=1))
    br = C.continue_branch(fam, 0.05, r.final_state, 1, 0.0, 1.0, C.ContinuationSettings(ds=0.02, ds_max=0.02))
    kinds = [b.kind for b in br.bifurcations]
    graz = [b for b in br.bifurcations if b.kind == "grazing"]
    assert len(graz) == 1 and graz[0].located
    assert graz[0].p == pytest.approx(0.30608, abs=1e-4)
    assert abs(fam.grazing(graz[0].p, graz[0].state, 1)) < 1e-6
    assert kinds.count("fold") == 2
    # along the branch (from e = 0): contact is kept up to the grazing point, lost right after it
    i = graz[0].index
    assert br.p[0] == pytest.approx(0.0)
    assert np.all(br.grazing[: i + 1] > 0) and br.grazing[i + 1] < 0


def test_dataset_is_cf_and_table_names_paper_transitions(calibrated_branch, tmp_path):
    _, fam, br = calibrated_branch
    ds = C.branch_dataset([(0, br)], {0: fam}, "x1", ["base"])
    assert io.missing_cf_attributes(ds) == []
    io.write_netcdf(ds, tmp_path / "b.nc", provenance.attributes(title="test"))
    rows = C.bifurcation_rows([(0, br)], "x1", ["base"], paper.TRANSITIONS)
    assert {r["type"] for r in rows} >= {"fold", "neimark_sacker"}
    ns = next(r for r in rows if r["type"] == "neimark_sacker")
    assert ns["paper_transition"] == "0.761" or float(ns["paper_transition"]) in paper.TRANSITIONS
    assert C.rows_to_csv(rows).splitlines()[0].startswith("case,branch,period,type")


def test_overlay_figure_draws_stable_unstable_and_typed_points(calibrated_branch, tmp_path):

    _, fam, br = calibrated_branch
    ds = C.branch_dataset([(0, br)], {0: fam}, "x1", ["base"])
    fig = plot_branches(None, ds, "calibrated, b = 2, e = 5")
    ax = fig.axes[0]
    styles = {line.get_linestyle() for line in ax.get_lines()}
    assert "-" in styles and "--" in styles
    labels = ax.get_legend_handles_labels()[1]
    assert any("fold" in t for t in labels) and any("Neimark-Sacker" in t for t in labels)
    save_figure(fig, tmp_path / "o.png", "caption")
    assert (tmp_path / "o.png").stat().st_size > 1000


def test_orbit_spec_from_config_checks_keys():
    spec = C.OrbitSpec.from_config({"designs": ["li2013"], "max_period": 4, "continuation": {"ds_max": 2e-3}})
    assert spec.max_period == 4 and spec.continuation.ds_max == 2e-3
    with pytest.raises(ValueError):
        C.OrbitSpec.from_config({"max_perod": 4})
    with pytest.raises(ValueError):
        C.OrbitSpec.from_config({"continuation": {"dsmax": 1e-3}})


def test_label_agreement_counts_points_on_stable_branch(calibrated_branch):

    _, _, br = calibrated_branch
    # a two-point "cube": one P1 point on the stable lower branch, one P1 point off it
    j = int(np.argmin(np.abs(br.p - 0.71)))
    on, off = br.states[j], br.states[j] + 1.0
    data = {
        v: (("case", "direction", "x1", "section"), np.array([on[k], off[k]]).reshape(1, 1, 2, 1))
        for k, v in enumerate(STATES)
    }
    data["label"] = (("case", "direction", "x1"), np.array([[[1, 1]]]))
    cube = xr.Dataset(data, coords={"x1": [br.p[j], br.p[j]]}, attrs={"control_parameter": "x1"})
    checked, agree, bad = C.label_agreement(cube, 0, [br], 6)
    assert (checked, agree) == (2, 1) and len(bad) == 1


def test_period_doubling_bubble_of_the_khv_model_under_light_load():
    """li2013 with T_D = T_L = 2 N m, w = 0.55, b = 2, e = 5 along x1: period doubling at x1 = 0.801349
    and back at 0.808879 (multiplier -1); the period-2 branch between them is stable and ends where it
    merges into the period-1 orbit; a simulation at 0.805 is P2 on that branch."""
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    fixed = {"b": 2.0, "e": 5.0, "T_D": 2.0, "T_L": 2.0, "w": 0.55}
    fam = C.KHVFamily(d, "x1", fixed, 0.79, 0.82, nodes=7)
    c = fam.coefficients(0.79)
    r = simulate(c, SimulationSettings(transient_periods=3000, recorded_periods=1))
    cs = C.ContinuationSettings(ds=0.01, ds_max=0.01, grazing=False)
    br = C.continue_branch(fam, 0.79, r.final_state, 1, 0.79, 0.82, cs)
    pds = sorted((b for b in br.bifurcations if b.kind == "period_doubling"), key=lambda b: b.p)
    assert [round(b.p, 4) for b in pds] == [0.8013, 0.8089]
    assert all(b.located and abs(b.critical + 1.0) < 1e-6 for b in pds)
    p2 = C.switch_at_period_doubling(fam, pds[0], 0.79, 0.82, cs)
    assert p2 is not None and p2.n == 2 and p2.stable.all()
    assert p2.end_status["up"] == "merged_into_period_1"
    assert p2.p.max() == pytest.approx(pds[1].p, abs=1e-3)
    res, lab = rules_label(fam.coefficients(0.805), point.integration_settings(d), indicators.ClassifierSettings())
    assert lab.label == 2
    checked, agree, _ = C.label_agreement(_one_point_cube(0.805, res.poincare[-1], 2), 0, [p2], 6)
    assert (checked, agree) == (1, 1)


def _one_point_cube(p, x, label):

    data = {v: (("case", "direction", "x1", "section"), np.array([[[[x[k]], [x[k]]]]])) for k, v in enumerate(STATES)}
    data["label"] = (("case", "direction", "x1"), np.array([[[label, 0]]]))
    return xr.Dataset(data, coords={"x1": [p, p + 1.0]}, attrs={"control_parameter": "x1"})


def test_branch_interpolated_at_a_parameter_value_on_every_step_that_holds_it():
    # a branch that folds: p goes 0 -> 2 -> 1, so p = 1.5 lies on two steps
    br = C.Branch(
        n=1,
        p=np.array([0.0, 2.0, 1.0]),
        states=np.array([[0.0, 0.0], [4.0, 2.0], [6.0, 8.0]]),
        multipliers=np.full((3, 2), 0.5 + 0j),
        arclength=np.zeros(3),
        grazing=np.zeros(3),
        iterations=np.zeros(3, np.int32),
    )
    hits = list(br.states_at(1.5))
    assert [i for i, _ in hits] == [0, 1]
    np.testing.assert_allclose(hits[0][1], [3.0, 1.5])
    np.testing.assert_allclose(hits[1][1], [5.0, 5.0])
    assert list(br.states_at(2.0 + 1e-9)) == [] and [i for i, _ in br.states_at(2.0 + 1e-9, 1e-8)] == [0, 1]
    assert C.on_branch(br, 1.5, np.array([[9.0, 9.0], [5.0, 5.0 + 1e-4]]), 1e-3)
    assert not C.on_branch(br, 1.5, np.array([[5.0, 5.1]]), 1e-3)


def test_seeds_are_the_middles_of_the_longest_periodic_runs():

    labels = np.array([1, 1, 1, -3, 2, 2, 2, 2, 2, 7, 1, 1, 1, 1])
    values = np.linspace(0.0, 1.3, labels.size)
    data = {
        v: (("case", "direction", "x1", "section"), np.full((1, 1, labels.size, 1), float(k)))
        for k, v in enumerate(STATES)
    }
    data["label"] = (("case", "direction", "x1"), labels.reshape(1, 1, -1))
    cube = xr.Dataset(data, coords={"x1": values}, attrs={"control_parameter": "x1"})
    seeds = C.seeds_from_cube(cube, 0, 6, 2)
    # runs: P2 of 5 points (4..8), P1 of 4 (10..13), P1 of 3 (0..2); P7 is above max_period
    assert [(round(p, 6), n) for p, _, n in seeds] == [(0.6, 2), (1.2, 1)]
    np.testing.assert_array_equal(seeds[0][1], np.arange(6.0))
    assert [n for _, _, n in C.seeds_from_cube(cube, 0, 7, 10)] == [2, 1, 1, 7]


def test_both_margins_take_the_callers_divergence_threshold():
    """The grazing and back-flank margins integrate the cycle with the caller's settings: a run whose states pass
    the caller's divergence threshold (here 0.5 of the static state's size, below the P1 orbit's excursion) is
    diverged, and both margins are NaN; with the default threshold both are finite (li2013, x1 = 0.5, b = 2,
    e = 5: x_VH passes through the backlash, g = -b; the back flank is struck, h < 0)."""
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    c = point.point_coefficients(d, {"x1": 0.5, "b": 2.0, "e": 5.0})
    x = simulate(c, SimulationSettings(transient_periods=2000, recorded_periods=1)).final_state
    ok = SimulationSettings()
    assert C.grazing_margin(c, x, 1, ok) == -2.0 and back_margin(c, x, 1, ok) < 0
    low = SimulationSettings(divergence_threshold=0.5)
    assert np.isnan(C.grazing_margin(c, x, 1, low))
    assert np.isnan(back_margin(c, x, 1, low))


def _two_pair_map(p: float, n: int):
    """The map x -> M(p) x on R^4 with M = diag(r R(2 pi 0.2), B): a pair r e^(+-i 2 pi 0.2), r = 0.95 + 0.1 p,
    leaves the unit circle at p = 0.5 (Neimark-Sacker, rotation number 0.2), and B = [[0.5, 1], [0.49 - p, 0.5]]
    has the multipliers 0.5 +- sqrt(0.49 - p): a real pair that turns complex at p = 0.49, inside the circle
    (modulus sqrt(0.25 + p - 0.49))."""
    c, s = np.cos(2 * np.pi * 0.2), np.sin(2 * np.pi * 0.2)
    M = np.zeros((4, 4))
    M[:2, :2] = (0.95 + 0.1 * p) * np.array([[c, -s], [s, c]])
    M[2:, 2:] = [[0.5, 1.0], [0.49 - p, 0.5]]
    Mn = np.linalg.matrix_power(M, n)
    return lambda x, jacobian=True: (Mn @ x, Mn if jacobian else None)


def test_neimark_sacker_located_when_another_pair_turns_complex_in_the_same_step():
    """On a branch step that holds both the Neimark-Sacker point (p = 0.5) and the point where another real pair
    turns complex inside the circle (p = 0.49), the product of |mu| - 1 over the complex pairs has one sign at
    both ends; the event is located on the modulus of the pair that crosses, at the analytic point."""
    fam = _orbits.CallableFamily(_two_pair_map)
    cs = C.ContinuationSettings(ds=0.04, ds_max=0.04, grazing=False)
    br = C.continue_branch(fam, 0.0, np.zeros(4), 1, 0.0, 1.0, cs)
    (ns,) = [b for b in br.bifurcations if b.kind == "neimark_sacker"]
    i = ns.index
    assert br.p[i] < 0.49 < 0.5 < br.p[i + 1]  # the step holds both changes

    def product(mu):
        c = mu[(np.abs(mu.imag) > 1e-8) & (mu.imag > 0)]
        return np.prod(np.abs(c) - 1.0)

    assert np.sign(product(br.multipliers[i])) == np.sign(product(br.multipliers[i + 1]))
    assert ns.located and ns.p == pytest.approx(0.5, abs=1e-9)
    assert abs(ns.critical) == pytest.approx(1.0, abs=1e-9) and ns.rotation_number == pytest.approx(0.2, abs=1e-12)
