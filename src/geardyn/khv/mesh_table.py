"""Tables of mesh quantities along the admissible segment M-N (paper 1 Fig. 5)."""

from __future__ import annotations

import numpy as np
import xarray as xr

from geardyn import io
from geardyn.gears.stiffness import ParabolicStiffness
from geardyn.io import Var
from geardyn.khv.design import KHVDesign, mesh_properties

#: The variables of the table; the first eight are attributes of :class:`geardyn.khv.design.MeshProperties` at
#: each x1 (:data:`FIELDS`).
VARIABLES = (
    Var("x2", "x1", "1", "annulus profile-shift coefficient on line 4 (Chinese sign convention)"),
    Var("working_pressure_angle", "x1", "degree", "working pressure angle alpha'"),
    Var("contact_ratio", "x1", "1", "transverse contact ratio eps"),
    Var("q", "x1", "mm um N-1", "minimum single-tooth flexibility q' (ISO 6336-1 method B)"),
    Var("k_c", "x1", "N m-1", "single-pair mesh stiffness at the pitch point k_C"),
    Var("k_prime", "x1", "N m-1", "single-pair mesh stiffness at entry and exit k' = k_C / 1.5"),
    Var("k_mean", "x1", "N m-1", "mean mesh stiffness over a mesh period"),
    Var("k_min", "x1", "N m-1", "smallest mesh stiffness over a mesh period"),
    Var("k_t", ("x1", "phase"), "N m-1", "time-varying mesh stiffness k(t)"),
    Var(
        "k_mean_closed_form_ratio",
        "x1",
        "1",
        "k_mean / (eps k_C): 8/9 for the corrected form; the paper prints 0.866268",
    ),
    Var("x1", "x1", "1", "planet profile-shift coefficient x1"),
    Var("phase", "phase", "1", "time in mesh periods t"),
)
#: The attribute of :class:`geardyn.khv.design.MeshProperties` behind each of the first variables.
FIELDS = {"working_pressure_angle": "working_pressure_angle_deg"}


def stiffness_table(design: KHVDesign, x1: np.ndarray, phase_points: int = 400) -> xr.Dataset:
    """Mesh quantities at each ``x1`` and k(t) over one mesh period on the phase grid t = j / ``phase_points``
    (k(t) right-continuous at its jumps t = 0 and t = eps - 1)."""
    x1 = np.asarray(x1, dtype=float)
    props = [mesh_properties(design, float(v)) for v in x1]
    phase = np.arange(phase_points) / phase_points
    values = {v.name: np.array([getattr(p, FIELDS.get(v.name, v.name)) for p in props]) for v in VARIABLES[:8]}
    k_t = [ParabolicStiffness(p.contact_ratio, p.k_prime, design.stiffness.form) for p in props]
    values["k_t"] = np.stack([k(phase) for k in k_t])
    values["k_mean_closed_form_ratio"] = np.array([p.k_mean / (p.contact_ratio * p.k_c) for p in props])
    return io.dataset(VARIABLES, values | {"x1": x1, "phase": phase}, stiffness_options=design.stiffness.label)
