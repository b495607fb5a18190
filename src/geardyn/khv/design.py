"""A KHV design: the validated design file turned into a gear pair and its mesh at any x1 (x2 on line 4, the
contact ratio and the constraints from :mod:`geardyn.gears`, k_C, k' and k(t)), the one place where a design
file meets the numerics."""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from geardyn.config import ConfigError, load_design_dict
from geardyn.gears import constraints, geometry, interference, stiffness
from geardyn.jsontypes import Json


@dataclass(frozen=True)
class StiffnessOptions:
    """Paper 1 Eqs. (7)-(9) choices; see ``docs/paper1.md``."""

    q_variant: stiffness.QVariant = "iso"
    constants: str = "iso"
    form: stiffness.KForm = "corrected"

    @property
    def label(self) -> str:
        return f"q={self.q_variant},C={self.constants},k(t)={self.form}"


@dataclass(frozen=True)
class DesignHeader:
    """What a job that only reads results needs of a KHV design: name, title, paper (a key of geardyn.papers, or
    None), stiffness options (the model variant) and the validated file with defaults (provenance)."""

    name: str
    title: str
    paper: str | None
    stiffness: StiffnessOptions
    raw: dict[str, Json]

    @staticmethod
    def fields_of(raw: dict[str, Json]) -> dict[str, Json]:
        """The header fields of a schema-validated design file."""
        return {
            "name": raw["name"],
            "title": raw.get("title", ""),
            "paper": raw.get("paper"),
            "stiffness": StiffnessOptions(**raw["stiffness"]),
            "raw": raw,
        }


@dataclass(frozen=True)
class KHVDesign(DesignHeader):
    """A validated KHV design (paper 1 type): the header and the geometry."""

    base: geometry.GearPair  # x1, x2 of the configured design point
    x1_min: float
    x1_max: float
    min_tip_thickness: float
    cutter: geometry.ShaperCutter
    enforce_cutter_constraints: bool
    dynamics: dict[str, Json]

    @property
    def segment(self) -> tuple[float, float]:
        """The admissible segment (x1_min, x1_max) on which every run of this design stays."""
        return (self.x1_min, self.x1_max)

    @property
    def x2_on_line4(self) -> bool:
        return self.raw["pair"].get("x2", "line4") == "line4"


@dataclass(frozen=True)
class MeshProperties:
    """Derived mesh quantities of the pair at one design point (SI units for stiffness)."""

    x1: float
    x2: float
    working_pressure_angle_deg: float
    contact_ratio: float
    q: float  # mm um / N
    k_c: float  # N/m, pitch point single pair
    k_prime: float  # N/m, single pair at entry/exit
    k_mean: float  # N/m, exact mean of k(t)
    k_min: float  # N/m, smallest k(t) over a period


#: The keys of a design file's ``pair`` that are :class:`~geardyn.gears.geometry.GearPair` fields as they are.
_PAIR_KEYS = ("z1", "z2", "module", "x1", "pressure_angle_deg", "addendum", "clearance", "facewidth")


def _pair_from(raw: dict[str, Json], x2: float) -> geometry.GearPair:
    """The internal pair of a design file with annulus shift ``x2``."""
    return geometry.GearPair(**{k: raw["pair"][k] for k in _PAIR_KEYS}, x2=x2, internal=True)


def x2_for(design: KHVDesign, x1: float) -> float:
    """x2 at ``x1``: on line 4 (G_s = 0) when the design says 'line4', else the fixed x2."""
    return _x2(design.base, design.x2_on_line4, float(x1))


@functools.lru_cache(maxsize=4096)
def _x2(base: geometry.GearPair, on_line4: bool, x1: float) -> float:
    """x2 of :func:`x2_for` (a pure function of its arguments, so kept: a design's checks, its mesh
    properties and its pairs ask for the same x1, each a root solve)."""
    return float(constraints.x2_on_overlap_boundary(x1, base)) if on_line4 else base.x2


def mesh_properties(design: KHVDesign, x1: float) -> MeshProperties:
    """Contact ratio and ISO 6336 stiffness of ``design`` at ``x1`` (paper 1 Eqs. 7-10)."""
    return _mesh_properties(design.name, design.base, design.x2_on_line4, design.stiffness, float(x1))


@functools.lru_cache(maxsize=4096)
def _mesh_properties(
    name: str, base: geometry.GearPair, on_line4: bool, opts: StiffnessOptions, x1: float
) -> MeshProperties:
    """:func:`mesh_properties` of the design with these fields (a pure function of them, so kept: the
    b and e sweeps and the calibration's tracks ask for the same x1 many times)."""
    pair = dataclasses.replace(base, x1=x1, x2=_x2(base, on_line4, x1))
    c = stiffness.PRINTED_C if opts.constants == "printed" else stiffness.ISO_C
    q = float(stiffness.flexibility_q(pair.z1, pair.z2, pair.x1, pair.x2, variant=opts.q_variant, constants=c))
    k_c = float(stiffness.pitch_point_stiffness(q, pair.facewidth))
    k_prime = float(stiffness.tip_stiffness(k_c))
    eps = float(interference.contact_ratio(pair))
    if not eps >= 1.0:  # also NaN: no working pressure angle
        raise ConfigError(
            f"{name}: contact ratio eps = {eps:.4f} at x1 = {x1:.4f} is not allowed: >= 1 "
            "(below 1 the gears do not mesh continuously)"
        )
    if opts.form == "printed" and not eps < 2.0:
        raise ConfigError(
            f"{name}: contact ratio eps = {eps:.4f} at x1 = {x1:.4f} is not allowed with "
            "stiffness.form = 'printed': < 2 (the printed Eq. (9) is stated for 1 <= eps < 2)"
        )
    k_t = stiffness.ParabolicStiffness(eps, k_prime, opts.form)
    return MeshProperties(
        x1=pair.x1,
        x2=pair.x2,
        working_pressure_angle_deg=math.degrees(float(geometry.working_pressure_angle(pair))),
        contact_ratio=eps,
        q=q,
        k_c=k_c,
        k_prime=k_prime,
        k_mean=k_t.mean(),
        k_min=k_t.minimum(),
    )


def _check(design_raw: dict[str, Json], where: str) -> None:
    p = design_raw["pair"]
    if p["z2"] - p["z1"] < 1:
        raise ConfigError(
            f"{where}: pair.z2 - pair.z1 = {p['z2'] - p['z1']} is not allowed: "
            "the annulus needs at least one tooth more than the planet (z2 - z1 >= 1)"
        )
    adm = design_raw["admissible"]
    if not adm["x1_min"] < adm["x1_max"]:
        raise ConfigError(
            f"{where}: admissible.x1_min = {adm['x1_min']} must be below admissible.x1_max = {adm['x1_max']}"
        )


#: Margin below which a constraint counts as violated: points on line 4 have G_s = 0 up to round-off.
FEASIBILITY_TOLERANCE = 1e-6


def violated_constraints(
    pair: geometry.GearPair, min_tip_thickness: float, enforce_cutter: bool, cutter: geometry.ShaperCutter | None = None
) -> list[str]:
    """Names of the closed-graph constraints that ``pair`` violates (margin < -1e-6 mm or rad, or no margin
    at all: NaN where the pair has no working pressure angle)."""
    values = constraints.constraints(pair, min_tip_thickness=min_tip_thickness, cutter=cutter)
    return [
        name
        for name, v in values.items()
        if not float(v) >= -FEASIBILITY_TOLERANCE and (enforce_cutter or name not in constraints.CUTTER_DEPENDENT)
    ]


def meshing_problem(pair: geometry.GearPair) -> str | None:
    """Why ``pair`` cannot mesh at all (no working pressure angle), in words, or None."""
    inv_w = float(geometry.working_involute(pair))
    if inv_w > 0.0:
        return None
    return (
        f"(x1, x2) = ({pair.x1:.4f}, {pair.x2:.4f}) has no working pressure angle: inv a' = 2 (x2 - x1) tan a "
        f"/ (z2 - z1) + inv a = {inv_w:.4g} <= 0, so x2 - x1 = {pair.x2 - pair.x1:.4f} is too small for "
        f"z2 - z1 = {pair.z2 - pair.z1}"
    )


def _infeasible(pair: geometry.GearPair, min_tip: float, enforce_cutter: bool, cutter: geometry.ShaperCutter) -> str:
    """The constraints ``pair`` violates (:func:`violated_constraints`) with their margins, in words ('' if none)."""
    bad = violated_constraints(pair, min_tip, enforce_cutter, cutter)
    values = constraints.constraints(pair, min_tip_thickness=min_tip, cutter=cutter) if bad else {}
    return ", ".join(
        f"{name} = {float(values[name]):.4g} (needs >= 0)"
        if math.isfinite(float(values[name]))
        else f"{name} undefined"
        for name in bad
    )


def from_dict(raw: dict[str, Json], where: str = "design", check: bool = True) -> KHVDesign:
    """Build a :class:`KHVDesign` from a schema-validated dict, with the semantic checks (``check=False``:
    only what is needed to build it, for printing the geometry of a design that does not pass)."""
    _check(raw, where)
    p = raw["pair"]
    provisional = _pair_from(raw, 0.0)
    if p["x2"] == "line4":
        try:
            x2 = float(constraints.x2_on_overlap_boundary(p["x1"], provisional))
        except ValueError as err:
            raise ConfigError(f"{where}: pair.x1 = {p['x1']}: no x2 on line 4 (G_s = 0): {err}") from None
    else:
        x2 = float(p["x2"])
    base = _pair_from(raw, x2)
    adm, c = raw["admissible"], raw.get("cutter", {})
    cutter = (  # the configured cutter, or the nominal one
        interference.default_cutter(base)
        if c.get("teeth") is None
        else geometry.ShaperCutter(c["teeth"], c.get("shift", 0.0), c.get("addendum"))
    )
    problem = meshing_problem(base)
    if problem and check:
        raise ConfigError(f"{where}: design point {problem}")
    feasibility = adm["check_feasibility"] and check
    detail = (
        _infeasible(base, adm["min_tip_thickness"], adm["enforce_cutter_constraints"], cutter) if feasibility else ""
    )
    if detail:
        raise ConfigError(
            f"{where}: design point (x1, x2) = ({base.x1:.4f}, {base.x2:.4f}) is outside the feasible region: {detail}"
        )
    return KHVDesign(
        **DesignHeader.fields_of(raw),
        base=base,
        x1_min=adm["x1_min"],
        x1_max=adm["x1_max"],
        min_tip_thickness=adm["min_tip_thickness"],
        cutter=cutter,
        enforce_cutter_constraints=adm["enforce_cutter_constraints"],
        dynamics=raw.get("dynamics", {}),
    )


def check_segment(design: KHVDesign, where: str = "design", points: int = 11) -> None:
    """Refuse a design whose admissible segment M-N leaves the region the model can run in: at ``points``
    evenly spaced x1 (ends included) x2 exists on line 4, eps is in [1, 2) (Eq. 9) and, with
    ``check_feasibility``, no closed-graph constraint is violated (runs stay inside the segment)."""
    adm = design.raw["admissible"]
    for x1 in np.linspace(design.x1_min, design.x1_max, points):
        leaves = f"{where}: admissible segment x1 = [{design.x1_min}, {design.x1_max}] leaves the"
        covers = f"{leaves} region the model covers at x1 = {x1:.4f}: "
        try:
            pair = dataclasses.replace(design.base, x1=float(x1), x2=x2_for(design, x1))
        except (ValueError, RuntimeError) as err:
            raise ConfigError(f"{covers}no x2 on line 4 (G_s = 0): {err}") from None
        problem = meshing_problem(pair)
        if problem:
            raise ConfigError(covers + problem)
        try:
            mesh_properties(design, x1)
        except (ValueError, RuntimeError) as err:  # ConfigError is a ValueError
            raise ConfigError(
                covers + (str(err).split(": ", 1)[-1] if isinstance(err, ConfigError) else str(err))
            ) from None
        if adm["check_feasibility"] and (
            detail := _infeasible(pair, design.min_tip_thickness, design.enforce_cutter_constraints, design.cutter)
        ):
            raise ConfigError(f"{leaves} feasible region at x1 = {x1:.4f}: {detail}")


def _read(path: str | Path) -> dict[str, Json]:
    """A KHV design file, read and schema-validated."""
    raw = load_design_dict(path)
    if raw["kind"] != "khv":
        raise ConfigError(f"{path}: kind = {raw['kind']!r} is not a KHV design")
    return raw


def load(path: str | Path) -> KHVDesign:
    """Read, validate and check a KHV design file (one-line :class:`ConfigError` on any problem)."""
    return from_dict(_read(path), str(path))


def header(path: str | Path) -> DesignHeader:
    """The :class:`DesignHeader` of a KHV design file, schema-validated, without the geometry: no profile shift is
    solved, so the jobs that merge, draw and tabulate start without scipy's root finders."""
    raw = _read(path)
    _check(raw, str(path))
    return DesignHeader(**DesignHeader.fields_of(raw))


def figure_x1(
    design: KHVDesign, configured: list[float | str], paper_values: tuple[float, ...] | None = None
) -> list[float]:
    """The x1 values of the k(t) figure: the paper's for a design that names a paper (``paper_values``),
    else the configured ones (numbers or percentages of the admissible segment)."""
    values = paper_values if paper_values is not None else configured
    return [along_segment(v, design.segment) for v in values]


def x1_grid(design: KHVDesign, num: int) -> np.ndarray:
    """``num`` evenly spaced x1 values over the admissible segment [x1_min, x1_max]."""
    return np.linspace(design.x1_min, design.x1_max, num)


def is_fraction(value: Json) -> bool:
    """Whether ``value`` is a percentage of the admissible segment such as ``"25%"``."""
    return isinstance(value, str) and value.endswith("%")


def along_segment(value: float | str, segment: tuple[float, float]) -> float:
    """x1 from a number (returned as it is) or a percentage of the segment (x1_min, x1_max): '0%' is
    x1_min, '100%' is x1_max."""
    if is_fraction(value):
        f = float(str(value)[:-1]) / 100.0
        return segment[0] + f * (segment[1] - segment[0])
    return float(value)


def resolve_fractions(spec: Json, segment: tuple[float, float]) -> Json:
    """A copy of a run's config entry with every percentage turned into x1 on the design's segment
    (percentages are allowed for x1 only; :mod:`geardyn.config.validate` refuses them elsewhere)."""
    if isinstance(spec, Mapping):
        return {k: resolve_fractions(v, segment) for k, v in spec.items()}
    if isinstance(spec, list | tuple):
        return [resolve_fractions(v, segment) for v in spec]
    return along_segment(spec, segment) if is_fraction(spec) else spec
