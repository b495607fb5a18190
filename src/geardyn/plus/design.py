"""Design of the plus planetary set of paper 2 (Yue et al. 2014, Table 1) as frozen dataclasses in SI units, built
(:func:`design_from_dict`) from a design file in printed units that :func:`load` reads through :mod:`geardyn.config`."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

from geardyn.config import ConfigError, load_design_dict, validated
from geardyn.jsontypes import Json


@dataclass(frozen=True)
class Body:
    """A gear or the carrier. ``base_radius`` in m, ``mass`` in kg, ``inertia`` in kg m^2."""

    teeth: int
    base_radius: float
    mass: float
    inertia: float


@dataclass(frozen=True)
class Springs:
    """Spring (N/m) or damper (N s/m) constants: sun-planet, planet-planet, planet-ring, sun bearing."""

    sun_planet: float
    planet_planet: float
    planet_ring: float
    sun_bearing: float

    def scaled(self, factor: float) -> Springs:
        return Springs(*(factor * v for v in (self.sun_planet, self.planet_planet, self.planet_ring, self.sun_bearing)))


@dataclass(frozen=True)
class TESpec:
    """Transmission-error settings (paper 2 Eq. 9); deviations in m."""

    driver: str
    ef1: float
    ef2: float
    es: float
    pitch_error_sign: int
    shear_coefficient: float
    points_per_period: int


@dataclass(frozen=True)
class ReliefSpec:
    """Tip-relief optimisation settings; bounds in m (amount) and m (length along the path of contact)."""

    apply_to: str
    paper_amount: tuple[float, float]
    paper_length: tuple[float, float]
    physical_amount: tuple[float, float]
    physical_length: tuple[float, float]
    seed: int
    popsize: int
    maxiter: int
    tol: float
    landscape_points: int
    load_study_torques: tuple[float, ...] = (43.0,)


@dataclass(frozen=True)
class ForcedSpec:
    """Forced-response settings (:mod:`geardyn.plus.forced`): modal damping ratio, working condition,
    number of TE harmonics, planet mesh phasing and the input-speed grid."""

    damping_ratio: float = 0.05
    condition: str = "I"
    harmonics: int = 5
    phasing: str = "sequential"
    speed_points: int = 1500
    speed_max_factor: float = 1.2


@dataclass(frozen=True)
class PlusDesign:
    """Plus (double-planet) planetary gear set.  Lengths in m, angles in rad, SI otherwise."""

    name: str
    title: str
    paper: str | None
    module: float
    pressure_angle: float
    addendum: float
    clearance: float
    facewidth: float
    planet_angles: tuple[float, ...]
    outer_planet_side: int
    sun: Body
    planet_p: Body
    planet_d: Body
    carrier: Body
    ring: Body
    stiffness: Springs
    damping: Springs
    youngs_modulus: float
    poisson: float
    torque: float
    torque_member: str
    te: TESpec
    relief: ReliefSpec
    forced: ForcedSpec = field(default_factory=ForcedSpec)
    planet_angles_in_sun_terms: bool = True
    plus_set_sign: bool = True
    raw: Mapping[str, Json] = field(default_factory=dict, compare=False, repr=False)

    @property
    def n_planets(self) -> int:
        return len(self.planet_angles)

    def with_stiffness_scale(self, factor: float) -> PlusDesign:
        """Copy with every spring (meshes and bearing) multiplied by ``factor``."""
        return replace(self, stiffness=self.stiffness.scaled(factor))


def _body(d: Mapping[str, Json]) -> Body:
    return Body(
        teeth=int(d.get("teeth", 0)),
        base_radius=float(d.get("base_radius_mm", 0.0)) * 1e-3,
        mass=float(d.get("mass_kg", 0.0)),
        inertia=float(d["inertia_kgm2"]),
    )


def _springs(d: Mapping[str, Json]) -> Springs:
    return Springs(*(float(d[f.name]) for f in fields(Springs)))


def design_from_dict(d: Mapping[str, Json], where: str = "design") -> PlusDesign:
    """Build a :class:`PlusDesign` (SI units) from a schema-validated dict with defaults filled
    (:func:`geardyn.config.load_design_dict`), with the checks the schema cannot state."""

    te, rl = d["transmission_error"], d["relief"]
    bounds = {}  # the four relief bounds in m
    for name in ("paper_amount", "paper_length", "physical_amount", "physical_length"):
        lo, hi = rl[f"{name}_mm"]
        if not lo < hi:
            raise ConfigError(
                f"{where}: relief.{name}_mm = {[lo, hi]} is not allowed: the lower bound must be below the upper bound"
            )
        bounds[name] = (lo * 1e-3, hi * 1e-3)
    return PlusDesign(
        name=d["name"],
        paper=d.get("paper"),
        title=d["title"],
        module=d["module_mm"] * 1e-3,
        pressure_angle=math.radians(d["pressure_angle_deg"]),
        addendum=d["addendum_coefficient"],
        clearance=d["clearance_coefficient"],
        facewidth=d["facewidth_mm"] * 1e-3,
        planet_angles=tuple(math.radians(a) for a in d["planet_angles_deg"]),
        outer_planet_side=int(d["outer_planet_side"]),
        sun=_body(d["sun"]),
        planet_p=_body(d["planet_p"]),
        planet_d=_body(d["planet_d"]),
        carrier=_body(d["carrier"]),
        ring=_body(d["ring"]),
        stiffness=_springs(d["stiffness"]),
        damping=_springs(d["damping"]),
        youngs_modulus=d["material"]["youngs_modulus_MPa"] * 1e6,
        poisson=d["material"]["poisson_ratio"],
        torque=d["load"]["torque_Nmm"] * 1e-3,
        torque_member=d["load"]["member"],
        te=TESpec(
            driver=te["driver"],
            ef1=te["Ef1_um"] * 1e-6,
            ef2=te["Ef2_um"] * 1e-6,
            es=te["ES_um"] * 1e-6,
            pitch_error_sign=int(te["pitch_error_sign"]),
            shear_coefficient=te["shear_coefficient"],
            points_per_period=te["points_per_period"],
        ),
        relief=ReliefSpec(
            **{k: rl[k] for k in ("apply_to", "seed", "popsize", "maxiter", "tol", "landscape_points")},
            **bounds,  # type: ignore[arg-type]  # the (lo, hi) bound fields, by name
            load_study_torques=tuple(float(t) for t in rl["load_study_torques_Nm"]),
        ),
        # every forced-response field converted to the type of its default (the schema's number admits 1 for 1.0)
        forced=ForcedSpec(
            **{f.name: type(f.default)(d["forced_response"][f.name]) for f in fields(ForcedSpec)}  # type: ignore[misc]
        ),
        planet_angles_in_sun_terms=d["fixes"]["planet_angles_in_sun_terms"],
        plus_set_sign=d["fixes"]["plus_set_sign"],
        raw=d,
    )


def load(path: str | Path) -> PlusDesign:
    """Read, validate and build a plus-set design file (one-line :class:`ConfigError` on any problem)."""
    raw = load_design_dict(path)
    if raw["kind"] != "plus_planetary":
        raise ConfigError(f"{path}: kind = {raw['kind']!r} is not a plus planetary design")
    return design_from_dict(raw, str(path))


def default_design() -> PlusDesign:
    """The schema defaults (the values of the schema file), validated like any design."""
    return design_from_dict(validated({"kind": "plus_planetary"}, "plus_planetary.schema.json", "defaults"))
