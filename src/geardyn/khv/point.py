"""From a KHV design file to the dimensionless model at one operating point: the design plus overrides of control
parameters (:data:`CONTROLS`: x1, b and e in um, w, speed in rpm) or of any :class:`~geardyn.khv.model.KHVParameters`
field in SI units (e.g. ``K_DH``); x2, eps and k_C follow x1."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping
from typing import Any

from geardyn.jsontypes import Json
from geardyn.khv import design as design_mod
from geardyn.khv.model import B_C, Coefficients, KHVParameters, Options, dimensionless
from geardyn.solve import SimulationSettings

#: Control parameters with their units and long names (for cube coordinates).
CONTROLS: dict[str, tuple[str, str]] = {
    "x1": ("1", "planet profile-shift coefficient x1"),
    "b": ("1", "half backlash b / b_c (b_c = 1 um)"),
    "e": ("1", "transmission-error amplitude e / b_c (b_c = 1 um)"),
    "w": ("1", "dimensionless mesh frequency w_m / w_n"),
    "speed": ("rpm", "input speed"),
}

#: The control parameters that are one field of the dimensionless coefficients each (the coefficients are linear
#: in them; w where the design's mesh frequency is dimensionless).
COEFFICIENT_FIELDS = {"b": "b", "e": "e", "w": "omega"}

#: UDUNITS units of the model parameters (fields of :class:`KHVParameters`) when used as overrides.
PARAMETER_UNITS: dict[str, str] = {
    f.name: f.metadata["units"] for f in dataclasses.fields(KHVParameters) if "units" in f.metadata
}


def units_of(name: str, default: str | None = None) -> str:
    """UDUNITS units of an override: a control parameter (``CONTROLS``) or a model parameter; ``default`` for
    any other name (else a KeyError)."""
    if name in CONTROLS:
        return CONTROLS[name][0]
    return PARAMETER_UNITS[name] if default is None else PARAMETER_UNITS.get(name, default)


def override_text(overrides: Iterable[tuple[str, float]] | Mapping[str, float], empty: str = "none") -> str:
    """The overrides as ``k=v,k=v`` (values ``:g``), ``empty`` without any."""
    pairs = overrides.items() if isinstance(overrides, Mapping) else overrides
    return ",".join(f"{k}={v:g}" for k, v in pairs) or empty


_PARAM_FIELDS = {f.name for f in dataclasses.fields(KHVParameters)} - {"eps", "k_c", "pressure_angle_deg"}
_OPTION_FIELDS = {f.name for f in dataclasses.fields(Options)}
_SETTING_FIELDS = {f.name for f in dataclasses.fields(SimulationSettings)}
#: The control parameters but x1 as (field of :class:`KHVParameters`, its SI value per unit of the control).
_CONTROL_FIELDS = {
    "b": ("backlash", B_C),
    "e": ("te_amplitude", B_C),
    "w": ("omega_bar", 1.0),
    "speed": ("input_speed_rpm", 1.0),
}


def _split(dynamics: Mapping[str, Json]) -> tuple[dict[str, Json], dict[str, Json], dict[str, Json]]:
    """The model parameters, options and integrator settings of a design's validated ``dynamics`` mapping."""
    params = {k: v for k, v in dynamics.get("parameters", {}).items() if k in _PARAM_FIELDS}
    options = {k: v for k, v in dynamics.get("options", {}).items() if k in _OPTION_FIELDS}
    settings = {k: v for k, v in dynamics.get("integration", {}).items() if k in _SETTING_FIELDS}
    return params, options, settings


def point_model(
    design: design_mod.KHVDesign, overrides: Mapping[str, float] | None = None
) -> tuple[KHVParameters, Options, design_mod.MeshProperties]:
    """Physical parameters and options of ``design`` at the point given by ``overrides``."""
    overrides = dict(overrides or {})
    params, options, _ = _split(design.dynamics)
    options["stiffness_form"] = design.stiffness.form  # one source: the design's stiffness section
    x1 = float(overrides.pop("x1", design.base.x1))
    mesh = design_mod.mesh_properties(design, x1)
    pair = design.base
    alpha = math.radians(pair.pressure_angle_deg)
    # radii and the mesh-frequency tooth count follow the pair unless the design states them
    follow = {
        "r_bV": pair.module * 1e-3 * pair.z1 * math.cos(alpha) / 2.0,
        "r_bH": pair.module * 1e-3 * (pair.z2 - pair.z1) / 2.0 * math.cos(alpha),
        "z_annulus": pair.z2,
    }
    params |= {k: v for k, v in follow.items() if params.get(k) is None}
    params["pressure_angle_deg"] = pair.pressure_angle_deg
    for key, value in overrides.items():
        if key not in _CONTROL_FIELDS and key not in _PARAM_FIELDS:
            allowed = ", ".join(sorted(set(CONTROLS) | _PARAM_FIELDS))
            raise ValueError(f"unknown control parameter {key!r}; allowed: {allowed}")
        field, scale = _CONTROL_FIELDS.get(key, (key, 1.0))
        params[field] = float(value) * scale
    params = {k: v for k, v in params.items() if v is not None}
    return KHVParameters(eps=mesh.contact_ratio, k_c=mesh.k_c, **params), Options(**options), mesh


def nominal(design: design_mod.KHVDesign, name: str, overrides: Mapping[str, float] | None = None) -> float:
    """The value of the override ``name`` at the point of ``overrides`` (the design's own where they do not set
    it), in the override's units (:data:`CONTROLS`: um for b and e; SI for a model parameter)."""
    overrides = dict(overrides or {})
    if name in overrides or name == "x1":
        return float(overrides.get(name, design.base.x1))
    field, scale = _CONTROL_FIELDS.get(name, (name, 1.0))
    return float(getattr(point_model(design, overrides)[0], field)) / scale


def point_coefficients(design: design_mod.KHVDesign, overrides: Mapping[str, float] | None = None) -> Coefficients:
    """The dimensionless coefficients (paper 1 Eq. 13, corrected) at one point."""
    phys, opts, _ = point_model(design, overrides)
    return dimensionless(phys, opts)


# Any: changes to SimulationSettings' fields (of several types), checked by dataclasses.replace.
def integration_settings(design: design_mod.KHVDesign, **changes: Any) -> SimulationSettings:
    """Integrator settings from the design's ``dynamics.integration`` with ``changes`` applied."""
    _, _, settings = _split(design.dynamics)
    settings.update({k: v for k, v in changes.items() if v is not None})
    return SimulationSettings(**settings)
