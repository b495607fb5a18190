"""A small, non-chaotic study whose every number must be the same on every CPU (tests/test_cpu_features.py).

Run as a script (``python tests/_cpu_study.py OUT.npz``) it writes the arrays to ``OUT.npz``; geardyn is
imported first, as in the pipeline, so its OpenBLAS setting holds.
"""

import sys
from pathlib import Path

import numpy as np

import geardyn  # noqa: F401 - first, as in every pipeline job
from _oracle import shoot
from geardyn import libm
from geardyn.khv import design, mesh_table, point
from geardyn.label import torus
from geardyn.runs import sweep
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.base import Tangent

ROOT = Path(__file__).resolve().parents[1]
#: The sweep: x1 from 0.45 to 0.8 at the paper's b = 2, e = 5 (period-1 motion; one point, x1 = 0.8,
#: may be labelled otherwise, and is then compared by its label only).
SWEEP = dict(
    designs=["li2013"],
    parameter="x1",
    start=0.45,
    stop=0.80,
    num=4,
    fixed={"b": 2.0, "e": 5.0},
    cases=[{}],
    chunks=1,
    integration={"transient_periods": 200, "recorded_periods": 30, "steps_per_period": 128},
)
#: A point of ``li2013_calibrated``'s map over (x1, e) whose run converges to a stable orbit (exponent
#: -0.013 per unit time, no chaos to amplify anything).  Its states differ by up to 3e-13 within 300
#: periods when glibc's sin is its FMA build (a few of its TE forcing values round the other way;
#: docs/reproducibility.md): with it the study sees which build of the C library ran.
LIBM_SENSITIVE = {"x1": 0.5739145728643216, "b": 2.0, "e": 0.5527638190954774}


def study() -> dict[str, np.ndarray]:
    """Stiffness table, geometry and coefficients along x1, a sweep with labels and exponents, a Newton
    shooting orbit with its Floquet multipliers."""
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    out: dict[str, np.ndarray] = {}
    for k, v in mesh_table.stiffness_table(d, np.linspace(0.45, 0.8, 5), 400).data_vars.items():
        out[f"stiffness/{k}"] = v.values
    spec = sweep.SweepSpec.from_config("t", SWEEP, "li2013", (0.416, 0.835))
    for k, v in sweep.run_chunk(d, spec, 0).data_vars.items():
        out[f"sweep/{k}"] = v.values
    c = point.point_coefficients(d, {"x1": 0.5, "b": 2.0, "e": 5.0, "w": 0.9})
    out["static_state"] = c.static_state()
    r = simulate(c, SimulationSettings(transient_periods=600, recorded_periods=1))
    orbit = shoot(c, r.final_state)
    out["orbit/state"] = orbit.state
    out["orbit/multipliers"] = np.asarray(orbit.multipliers)
    out["orbit/converged"] = np.asarray(orbit.converged)
    t = point.point_coefficients(design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml"), LIBM_SENSITIVE)
    settings = SimulationSettings(steps_per_period=128, transient_periods=0, recorded_periods=300)
    r = simulate(t, settings, variational=Tangent(300))
    out["libm_sensitive/poincare"] = r.poincare
    out["libm_sensitive/growth"] = r.growth
    out["libm_sensitive/order_gaps"] = np.asarray(torus.order_test(r.poincare, 0).gaps)  # cKDTree's neighbours
    # the torus test's compiled sums (label._birkhoff): coordinates and both measures
    out["torus/coordinates"] = torus.coordinates(r.poincare)
    out["torus/digits"] = np.asarray(torus.torus_digits(r.poincare, torus.coordinates))
    # the moduli and products of complex numbers (multipliers, spectra, the plus set's forced response) and
    # the torus test's weights: numpy's own np.abs (complex), complex multiply and np.exp differ from their
    # baseline paths with AVX-512
    rng = np.random.default_rng(7)
    z = rng.normal(size=(4, 4000))
    out["libm/cabs"] = libm.cabs(z[0] + 1j * z[1])
    out["libm/cmul"] = libm.cmul(z[0] + 1j * z[1], z[2] + 1j * z[3])  # numpy's complex multiply: 43 % differ
    out["torus/bump_weights"] = np.asarray(torus.bump_weights(4000))
    return out


if __name__ == "__main__":
    np.savez(sys.argv[1], **study())
