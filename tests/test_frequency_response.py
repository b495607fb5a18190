"""The frequency response (geardyn.runs.response) in the rigid-shaft limit: the single-DOF clearance oscillator,
checked against an independent DOP853 integration of that oscillator; jump detection."""

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from geardyn import config
from geardyn.config import validate
from geardyn.khv.model import Coefficients
from geardyn.label import Policy
from geardyn.runs.response import find_jumps, frequency_response, jump_frequencies
from geardyn.solve import SimulationSettings

ROOT = Path(__file__).resolve().parents[1]
K_SHAFT = 2000.0  # shaft stiffness / k_mean: shaft modes at 44.7 w_n, the limit is reached to ~(0.7/44.7)^2
MU = 2.0  # every mass / M_VH
W = np.linspace(0.4, 0.9, 26)  # sweep step 0.02


def _rigid() -> Coefficients:
    """Very stiff, well damped shafts, constant mesh stiffness, half backlash 1, light mesh damping (zeta
    ~ 0.05 of the oscillator), preload 0.2 and TE 0.05: the softening clearance oscillator of Kahraman & Singh
    (1990)."""
    c_shaft = 2.0 * 0.1 * math.sqrt(K_SHAFT * MU / 2.0)
    return Coefficients(
        mu_D=MU, mu_H=MU, mu_V=MU, mu_L=MU, k_DH=K_SHAFT, k_VL=K_SHAFT, c_DH=c_shaft, c_VL=c_shaft, c_m=0.14,
        P_D=0.2, P_L=0.2, b=1.0, e=0.05, phi=0.0, omega=0.7, eps=1.5, stiffness_mode="mean",
        omega_n=1.0, k_mean=1.0,
    )  # fmt: skip


def _sdof_rhs(c: Coefficients):
    """The single-DOF limit, derived by hand from the 4-DOF form (X_D = X_H, X_V = X_L): the drive + carrier
    (m1 = mu_D + mu_H) and the planet + load (m2 = mu_V + mu_L) bodies, x = X_V - X_H - e:
    x'' = -(P_L + F) / m2 - (P_D + F) / m1 + e w^2 sin(w t + phi),  F = f(x) + c_m x'."""
    m1, m2 = c.mu_D + c.mu_H, c.mu_V + c.mu_L

    def rhs(t, y):
        x, v = y
        f = x - min(max(x, -c.b), c.b) + c.c_m * v
        return [v, -(c.P_L + f) / m2 - (c.P_D + f) / m1 + c.e * c.omega**2 * math.sin(c.omega * t + c.phi)]

    return rhs


def _dop853_rms(c: Coefficients, x0: float, v0: float, transient: int = 60, record: int = 4) -> float:
    """RMS of x over ``record`` periods after ``transient`` periods, from (x0, v0) at phase 0 (DOP853)."""
    T = c.period
    sol = solve_ivp(
        _sdof_rhs(c), (0.0, (transient + record) * T), [x0, v0], method="DOP853", rtol=1e-10, atol=1e-12,
        dense_output=True,
    )  # fmt: skip
    t = transient * T + np.arange(record * 256) * T / 256
    return float(np.std(sol.sol(t)[0]))


@pytest.fixture(scope="module")
def sweep():
    policy = Policy(SimulationSettings(steps_per_period=256, transient_periods=300, recorded_periods=20))
    return frequency_response(_rigid(), W, policy, 0.25, 0.05)


def test_rigid_limit_shows_a_softening_jump_with_hysteresis(sweep):
    """The up sweep stays on the small-amplitude branch past the linear resonance and jumps up later than
    the down sweep falls off the large-amplitude branch: a softening jump, with the curves split between."""
    w_lin = sweep.natural_frequency.values[0]
    assert w_lin == pytest.approx(math.sqrt(1.0 / (2 * MU)) * math.sqrt(2.0), rel=1e-3)  # sqrt(1/m1 + 1/m2)
    up = [float(v) for v in sweep.attrs["jumps_up"].split(",")]
    down = [float(v) for v in sweep.attrs["jumps_down"].split(",")]
    assert len(up) == 1 and len(down) == 1
    assert down[0] < up[0] < w_lin  # softening: both jumps below the linear natural frequency
    split = W[sweep.hysteresis.values.astype(bool)]
    assert split.min() > down[0] and split.max() < up[0]
    assert set(sweep.impact_class.values[1][sweep.hysteresis.values.astype(bool)]) == {1}  # upper branch separates


def _state(sweep, d: int, j: int) -> tuple[float, float]:
    """(x2, v2) of the labeller's attractor on line d at W[j] (phase 0)."""
    y = sweep.final_state.values[d, j]
    return float(y[1]), float(y[4])


@pytest.mark.parametrize("d", [0, 1])
def test_branch_amplitudes_agree_with_dop853(sweep, d):
    """On each branch, at three frequencies where the branches coexist, the RMS DTE agrees within 1 % with
    DOP853 (rtol 1e-10) on the single-DOF oscillator started from the same branch (the limit's own error is
    ~(w / 44.7)^2 ~ 3e-4)."""
    c0 = _rigid()
    split = np.flatnonzero(sweep.hysteresis.values)
    for j in (split[0], split[len(split) // 2], split[-1]):
        ref = _dop853_rms(c0.replace(omega=float(W[j])), *_state(sweep, d, j))
        assert sweep.dte_rms.values[d, j] == pytest.approx(ref, rel=0.01)


@pytest.mark.parametrize("d", [0, 1])
def test_jump_frequencies_agree_with_a_dop853_sweep(sweep, d):
    """A DOP853 sweep of the single-DOF oscillator, continued point to point in the same direction from two
    steps before the jump, jumps within one sweep step of where the labelled sweep jumps."""
    c0 = _rigid()
    j_jump = int(np.flatnonzero(sweep.jump.values[d])[0])  # higher-frequency point of the jump pair
    order = list(range(j_jump - 3, j_jump + 3)) if d == 0 else list(range(j_jump + 2, j_jump - 4, -1))
    x, v = _state(sweep, d, order[0])
    rms = []
    for j in order:
        c = c0.replace(omega=float(W[j]))
        sol = solve_ivp(_sdof_rhs(c), (0.0, 80 * c.period), [x, v], method="DOP853", rtol=1e-10, atol=1e-12)
        x, v = sol.y[:, -1]
        rms.append(_dop853_rms(c, x, v, transient=0))
    steps = np.abs(np.diff(rms)) > 0.25 * np.maximum(rms[1:], rms[:-1])
    k = int(np.flatnonzero(steps)[0])  # the DOP853 jump lies between order[k] and order[k + 1]
    pair = sorted((order[k], order[k + 1]))
    assert abs(pair[1] - j_jump) <= 1


def test_find_jumps_needs_both_a_step_and_a_split():
    up = np.array([1.0, 1.1, 1.2, 3.0, 2.9, 1.0])
    down = np.array([1.0, 1.1, 3.2, 3.1, 2.9, 1.0])
    jump, split = find_jumps(np.stack([up, down]), 0.25, 0.05)
    assert split.tolist() == [False, False, True, False, False, False]
    assert np.flatnonzero(jump[0]).tolist() == [3] and np.flatnonzero(jump[1]).tolist() == [2]
    w = np.arange(6.0)
    assert jump_frequencies(w, jump[0], "up").tolist() == [2.5]
    # a single curve's steep step without a split (a coarse grid across a resonance) is no jump
    jump, _ = find_jumps(np.stack([up, up]), 0.25, 0.05)
    assert not jump.any()
    with pytest.raises(ValueError, match="rms must be"):
        find_jumps(up, 0.25, 0.05)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            {"fixed": {"w": 0.5}},
            "responses.fr.fixed name 'w' is not allowed: a parameter other than w and speed: the frequency "
            "response sweeps the mesh frequency",
        ),
        ({"start": 1.0, "stop": 0.5}, "stop = 0.5 must be above start = 1.0"),
        ({"num": 2}, "num = 2 is not allowed"),
        ({"start": 0.0}, "start = 0.0 is not allowed"),
        ({"fixed": {"b": -1.0}}, "responses.fr.fixed: b = -1.0 is not allowed"),
    ],
)
def test_bad_frequency_response_config_is_one_line(change, message):
    spec = {"designs": ["li2013"], "start": 0.3, "stop": 1.5, "num": 11, **change}
    cfg = {"designs": {"li2013": "config/designs/li2013.yaml"}, "responses": {"fr": spec}}
    with pytest.raises(config.ConfigError) as info:
        validate.validate_workflow(cfg, ROOT)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_shipped_config_sweeps_every_khv_design_over_primary_and_superharmonic_resonances():
    """The shipped study runs for every KHV design with at least 200 frequencies, from below the third
    super-harmonic (1/4 of the mesh mode near w = 1) to above the primary resonance."""
    root = ROOT
    cfg = validate.fill_config(validate.read_config_file(root / "config" / "config.yaml"))
    spec = cfg["responses"]["frequency_response"]
    assert spec["designs"] == "all" and spec["num"] >= 200
    assert spec["start"] <= 0.25 and spec["stop"] >= 1.5
    assert spec["classifier"]["error_floor"] == pytest.approx(1.9e-5)  # preset map: 128 steps per period
