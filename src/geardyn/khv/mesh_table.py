"""Tables of mesh quantities along the admissible segment M-N (paper 1 Fig. 5)."""

from __future__ import annotations

import numpy as np
import xarray as xr

from geardyn.io import cf
from geardyn.khv.design import KHVDesign, mesh_properties

_FIELDS = {
    # name: (attribute of MeshProperties, units, long_name)
    "x2": ("x2", "1", "annulus profile-shift coefficient on line 4 (Chinese sign convention)"),
    "working_pressure_angle": ("working_pressure_angle_deg", "degree", "working pressure angle alpha'"),
    "contact_ratio": ("contact_ratio", "1", "transverse contact ratio eps"),
    "q": ("q", "mm um N-1", "minimum single-tooth flexibility q' (ISO 6336-1 method B)"),
    "k_c": ("k_c", "N m-1", "single-pair mesh stiffness at the pitch point k_C"),
    "k_prime": ("k_prime", "N m-1", "single-pair mesh stiffness at entry and exit k' = k_C / 1.5"),
    "k_mean": ("k_mean", "N m-1", "mean mesh stiffness over a mesh period"),
    "k_min": ("k_min", "N m-1", "smallest mesh stiffness over a mesh period"),
}


def stiffness_table(design: KHVDesign, x1: np.ndarray, phase_points: int = 400) -> xr.Dataset:
    """Mesh quantities at each ``x1`` and k(t) over one mesh period on the phase grid t = j / ``phase_points``
    (k(t) right-continuous at its jumps t = 0 and t = eps - 1)."""
    x1 = np.asarray(x1, dtype=float)
    props = [mesh_properties(design, float(v)) for v in x1]
    phase = np.arange(phase_points) / phase_points
    data = {}
    for name, (attr, units, long_name) in _FIELDS.items():
        data[name] = cf("x1", np.array([getattr(p, attr) for p in props]), units, long_name)
    k_t = np.stack([p.k_of_t(design.stiffness.form)(phase) for p in props])
    data["k_t"] = cf(("x1", "phase"), k_t, "N m-1", "time-varying mesh stiffness k(t)")
    data["k_mean_closed_form_ratio"] = cf(
        "x1",
        np.array([p.k_mean / (p.contact_ratio * p.k_c) for p in props]),
        "1",
        "k_mean / (eps k_C): 8/9 for the corrected form; the paper prints 0.866268",
    )
    return xr.Dataset(
        data,
        coords={
            "x1": cf("x1", x1, "1", "planet profile-shift coefficient x1"),
            "phase": cf("phase", phase, "1", "time in mesh periods t"),
        },
        attrs={"stiffness_options": design.stiffness.label},
    )
