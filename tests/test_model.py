"""Model layer: dimensionless coefficients, 4-DOF -> 3-DOF reduction, storage, schema."""

from __future__ import annotations

import dataclasses
import json
import math
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

import _model_oracle as oracle
from _examples import EXAMPLE_SCALE
from _paper import li2013_parameters
from geardyn.khv import design, model, point
from geardyn.khv.model import Options, dimensionless
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.base import LAYOUT

# Paper design at M and N: eps and the ISO k_C rounded (docs/paper1.md, "M and N lie on G_s = 0" and
# "Mesh stiffness"); not computed here
P416 = li2013_parameters(eps=1.30, k_c=3.1e8)
P835 = li2013_parameters(eps=1.17, k_c=3.1e8)


def test_masses_and_scaling_by_hand():
    # Hand values: r_bH = 5.25 mm cos 20 deg, r_bV = 52.5 mm cos 20 deg (Table 1, Table 2)
    ms = model.physical_masses(P416)
    r_bH, r_bV = 5.25e-3 * math.cos(math.radians(20)), 52.5e-3 * math.cos(math.radians(20))
    assert ms["M_D"] == pytest.approx(0.03 / r_bH**2, rel=1e-12)
    assert ms["M_V"] == pytest.approx(0.2175 / r_bV**2, rel=1e-12)
    c = dimensionless(P416)
    # corrected mean stiffness 8/9 eps k_C (docs/paper1.md, "Exact mean"), w_n = sqrt(k_mean / M_VH) (Eq. 13)
    assert c.k_mean == pytest.approx(8 / 9 * 1.30 * 3.1e8, rel=1e-12)
    assert c.omega_n == pytest.approx(math.sqrt(c.k_mean / ms["M_VH"]), rel=1e-12)
    assert c.c_m == pytest.approx(2 * 0.1, rel=1e-12)  # c_m / (M_VH w_n) = 2 zeta exactly
    assert c.b == 2.0 and c.e == pytest.approx(5.0, rel=1e-12)  # b_c = 1 um
    # P_D / (k_mean b_c) with P_D = T_D / r_bH
    assert c.P_D == pytest.approx(50 / r_bH / (c.k_mean * 1e-6), rel=1e-12)


def test_kappa_has_unit_mean_and_matches_stiffness_module():
    for form in ("corrected", "printed"):
        c = dimensionless(P416, Options(stiffness_form=form))
        s = (np.arange(200000) + 0.5) / 200000
        # midpoint rule on piecewise quadratics: error ~ 1e-10 (jump cells dominate)
        assert np.mean(c.kappa(s)) == pytest.approx(1.0, abs=1e-8)
        ps = P416.stiffness(form)
        np.testing.assert_allclose(c.kappa(s[::997]) * ps.mean(), ps(s[::997]), rtol=1e-13)


def test_options_switches():
    c = dimensionless(P416, Options(backlash=False, transmission_error=False, stiffness_mode="mean"))
    assert not c.backlash_on and c.b == 0.0 and c.e == 0.0
    assert np.all(c.kappa(np.linspace(0, 1, 11)) == 1.0)
    with pytest.raises(ValueError):
        Options(stiffness_form="misprinted")  # type: ignore[arg-type]


def test_frequency_modes():
    # physical: w_m = z_K 2 pi n / 60 held, so omega = w_m / w_n grows as k_mean falls with x1
    o = Options(frequency_mode="physical")
    c1, c2 = dimensionless(P416, o), dimensionless(P835, o)
    assert c1.omega * c1.omega_n == pytest.approx(33 * 2 * math.pi * 525 / 60, rel=1e-12)
    assert c2.omega / c1.omega == pytest.approx(math.sqrt(1.30 / 1.17), rel=1e-12)
    d = Options(frequency_mode="dimensionless")
    assert dimensionless(P416, d).omega == dimensionless(P835, d).omega == P416.omega_bar


def test_coefficients_roundtrip_dict_and_netcdf(tmp_path):
    xr = pytest.importorskip("xarray")
    c = dimensionless(P416, Options(stiffness_form="printed"))
    assert model.Coefficients.from_dict(c.as_dict()) == c
    ds = xr.Dataset(attrs=c.as_dict())
    path = tmp_path / "c.nc"
    ds.to_netcdf(path)
    back = xr.open_dataset(path)
    xr.testing.assert_identical(back, ds)
    assert model.Coefficients.from_dict(dict(back.attrs)) == c
    back.close()


def test_static_deflection_is_equilibrium():
    for p in (P416, P835):
        c = dimensionless(p, Options(stiffness_mode="mean", transmission_error=False))
        y = model.static_deflection(c)
        # residual of the full RHS at rest: round-off only (values O(100))
        assert np.abs(oracle.rhs3(c, 0.0, y)).max() < 1e-12
        assert abs(y[1]) > c.b  # teeth in contact under the Table 2 load


def test_kept_kernel_array_and_static_state_are_copies_of_their_instance():
    """The coefficients keep their kernel array and static deflection once computed: each call returns the
    value of that instance (a changed copy changes neither the next call nor another instance's value)."""
    c = dimensionless(P416)
    y, k = c.static_state(), c.kernel_array()
    assert np.array_equal(y, model.static_deflection(c)) and k.shape == (len(k),)
    y[:], k[:] = 99.0, 99.0
    assert np.array_equal(c.static_state(), model.static_deflection(c)) and np.all(c.kernel_array() != 99.0)
    wider = c.replace(b=2.0 * c.b)
    assert wider.static_state()[1] == pytest.approx(c.static_state()[1] + math.copysign(c.b, c.static_state()[1]))
    assert wider.kernel_array().tolist() != c.kernel_array().tolist() and wider == dataclasses.replace(c, b=2.0 * c.b)


def test_copies_share_the_static_balance_only_where_it_cannot_change():
    """A copy that changes b, e, w or the stiffness shares its parent's static force balance and has the
    static deflection of a fresh instance, bit for bit; a copy with another load, mass or shaft stiffness
    solves its own."""
    c = dimensionless(P416)
    for changes in ({"b": 1.5}, {"e": 0.0, "omega": 0.7}, {"eps": 1.3, "stiffness_mode": "mean"}):
        copy = c.replace(**changes)
        fresh = dataclasses.replace(c, **changes)
        assert copy.__dict__["_static_balance"] is c.__dict__["_static_balance"]
        assert copy.static_state().tobytes() == model.static_deflection(fresh).tobytes()
    for changes in ({"P_L": 2.0 * c.P_L}, {"mu_V": 1.1 * c.mu_V}, {"k_VL": 0.5 * c.k_VL}):
        copy = c.replace(**changes)
        assert "_static_balance" not in copy.__dict__
        assert copy.static_state().tobytes() == model.static_deflection(dataclasses.replace(c, **changes)).tobytes()
        assert not np.array_equal(copy.static_state(), c.static_state())


def test_fresh_instances_met_in_turn_each_get_the_equilibrium_of_their_own_loads_and_masses():
    """Static deflections of fresh instances (no shared balance) that alternate between two loads and two
    planet masses: each is the rest point of its own equations (residual of the 3-DOF right-hand side at rest,
    mean stiffness, no TE: round-off only, values O(100)), whichever instance came before."""
    c = dimensionless(P416, Options(stiffness_mode="mean", transmission_error=False))
    changes = [{"P_L": c.P_L}, {"P_L": 1.5 * c.P_L}, {"mu_V": 1.2 * c.mu_V}, {"P_L": c.P_L, "e": 0.0}]
    for k in range(12):
        fresh = dataclasses.replace(c, **changes[k % len(changes)])
        assert np.abs(oracle.rhs3(fresh, 0.0, fresh.static_state())).max() < 1e-12


@pytest.mark.parametrize("backlash", [True, False])
def test_the_kernel_array_holds_the_equations_terms_at_their_layout_places(backlash):
    """The accelerations written from the kernel array read by the names of LAYOUT (K21 the x1 term of row 2,
    G3 the mesh force's in row 3, ...) are those of the model's equations (oracle right-hand side, from the
    coefficients' matrices) at random states: round-off only (values O(100))."""
    c = dimensionless(P835, Options(backlash=backlash))
    k = dict(zip(LAYOUT, c.kernel_array(), strict=True))
    assert (k["B"], k["BACKLASH_ON"], k["EPS"], k["T"]) == (c.b, float(backlash), c.eps, c.period)
    rng = np.random.default_rng(3)
    for _ in range(20):
        tau, y = float(rng.uniform(0.0, 10.0)), rng.normal(0.0, 3.0, 6)
        (x1, x2, x3), (v1, v2, v3) = y[:3], y[3:]
        b = k["B"] if backlash else 0.0
        fm = float(c.kappa(tau / k["T"])) * (x2 - min(max(x2, -b), b)) + k["CM"] * v2
        te = k["TE"] * math.sin(2.0 * math.pi * tau / k["T"] + k["PHI"])
        a = [
            k["P1"] - k["K11"] * x1 - k["C11"] * v1 - k["G1"] * fm,
            -k["K21"] * x1 - k["C21"] * v1 - k["K23"] * x3 - k["C23"] * v3 - fm + te,
            k["P3"] - k["K33"] * x3 - k["C33"] * v3 - k["G3"] * fm,
        ]
        assert a == pytest.approx(oracle.rhs3(c, tau, y)[3:], rel=1e-12, abs=1e-10)


@settings(max_examples=60 * EXAMPLE_SCALE, deadline=None)
@given(
    z=st.lists(st.floats(-30, 30), min_size=8, max_size=8),
    tau=st.floats(0, 50),
    form=st.sampled_from(["corrected", "printed"]),
)
def test_relative_form_is_exact_reduction_of_4dof(z, tau, form):
    """d/dtau of the relative coordinates of the 4-DOF state = the 3-DOF right-hand side.

    This is the corrected Eq. (4): it fails with the printed extra -e' in lines 1 and 3.
    """
    c = dimensionless(P416, Options(stiffness_form=form))
    z = np.array(z)
    dz = oracle.rhs4(c, tau, z)
    y = oracle.to_relative(c, tau, z)
    w = c.omega
    e2 = -c.e * w**2 * math.sin(w * tau + c.phi)  # e''
    dy_from_4 = np.array(
        [
            dz[0] - dz[1],
            dz[2] - dz[1] - c.e * w * math.cos(w * tau + c.phi),
            dz[2] - dz[3],
            dz[4] - dz[5],
            dz[6] - dz[5] - e2,
            dz[6] - dz[7],
        ]
    )
    # relative tolerance: round-off on O(1e3) terms
    np.testing.assert_allclose(oracle.rhs3(c, tau, y), dy_from_4, rtol=1e-11, atol=1e-9)


def test_4dof_and_3dof_trajectories_agree():
    """Integrate Eq. (2) (4-DOF, DOP853) and the 3-DOF relative form (event RK4) on one case."""
    c = dimensionless(li2013_parameters(eps=1.24, k_c=3.1e8, omega_bar=0.9))
    y0 = model.static_deflection(c)
    n = 10
    s = SimulationSettings(steps_per_period=1024, transient_periods=0, recorded_periods=n)
    r3 = simulate(c, s, y0)
    z0 = oracle.from_relative(c, 0.0, y0)
    t_eval = np.arange(1, n + 1) * c.period
    sol = solve_ivp(
        lambda t, z: oracle.rhs4(c, t, z), (0, t_eval[-1]), z0, method="DOP853", rtol=1e-11, atol=1e-9, t_eval=t_eval
    )
    y4 = oracle.to_relative(c, sol.t, sol.y.T)
    assert r3.n_events > 0  # the case has contact loss
    # tolerance: DOP853 stepping over the kinks without events (~1e-7 here) and the growing
    # absolute 4-DOF coordinates (rigid-body drift with T_D != T_L r_bH / r_bV): 1e-5 of ~30
    np.testing.assert_allclose(r3.poincare, y4, atol=1e-5 * np.abs(y4).max())


def test_schema_defaults_match_dataclasses():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(resources.files("geardyn.config").joinpath("schemas/dynamics.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate({}, schema)
    sections = {
        "parameters": li2013_parameters(eps=1.3, k_c=3e8),
        "options": Options(),
        "integration": SimulationSettings(),
    }
    # set from the design, not from the dynamics section: the mesh inputs and the pressure angle come
    # from the pair, the stiffness form from the design's stiffness section (one source each)
    derived = {"eps", "k_c", "pressure_angle_deg", "stiffness_form"}
    for name, obj in sections.items():
        props = schema["properties"][name]["properties"]
        fields_ = {f.name for f in dataclasses.fields(obj)} - derived
        assert set(props) == fields_, name
        for key, spec in props.items():
            assert spec["description"]
            if spec["default"] is None:  # null: taken from the pair (test_pair_derived_parameters)
                continue
            want = getattr(obj, key)
            if isinstance(want, float):
                assert spec["default"] == pytest.approx(want, rel=1e-9), key
            else:
                assert spec["default"] == want, key
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"parameters": {"zeta": -1}}, schema)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"parameters": {"unknown": 1}}, schema)


def test_pair_derived_parameters_equal_the_paper_constants():

    spec = design.load(Path(__file__).resolve().parents[1] / "config" / "designs" / "li2013.yaml")
    phys, opts, _ = point.point_model(spec, {"x1": 0.5})
    assert phys.r_bV == pytest.approx(
        3.5e-3 * 30 / 2 * math.cos(math.radians(20)), rel=1e-12
    )  # m z1 cos(a) / 2 = 49.33 mm
    assert phys.r_bH == pytest.approx(3.5e-3 * 3 / 2 * math.cos(math.radians(20)), rel=1e-12)  # a cos(a) = 4.933 mm
    assert phys.z_annulus == 33 and phys.pressure_angle_deg == 20.0
    assert opts.stiffness_form == spec.stiffness.form
