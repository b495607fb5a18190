"""The checks of a workflow's runs against the designs they name: known KHV designs, known control parameters
with values in their schema's range, ranges that go upwards, x1 inside the admissible segment, the
probabilities' inputs and sampling, claims and calibrations for paper designs; every problem one ConfigError line
(:func:`check_runs`, called by :func:`geardyn.config.validate.fill_config`)."""

from __future__ import annotations

import difflib
from collections.abc import Mapping

import jsonschema

from geardyn.config import (
    ConfigError,
    allowed_text,
    schema,
)
from geardyn.jsontypes import Json
from geardyn.khv import design as khv_design
from geardyn.khv.design import resolve_fractions
from geardyn.papers import paper_of


def controls() -> dict[str, Mapping[str, Json]]:
    """The schema nodes of the values a run may give a control parameter: the control parameters of a KHV
    drive (``$defs/controls`` of the config schema: x1, b and e in um, w, speed), then every
    ``dynamics.parameters`` key with that key's limits (each group in alphabetical order)."""
    groups = (
        schema("config.schema.json")["$defs"]["controls"]["properties"],
        schema("dynamics.schema.json")["properties"]["parameters"]["properties"],
    )
    return {k: group[k] for group in groups for k in sorted(group)}


def _override_node(key: str, where: str) -> Mapping[str, Json]:
    """The schema node an override ``key`` is checked against; unknown keys are refused with a hint."""
    known = controls()
    if key in known:
        return known[key]
    close = difflib.get_close_matches(key, list(known), n=1)
    hint = f" (did you mean '{close[0]}'?)" if close else f" (allowed: {', '.join(known)})"
    raise ConfigError(f"{where}: unknown control parameter '{key}'{hint}")


def _check_value(key: str, value: Json, where: str) -> None:
    node = _override_node(key, where)
    if not jsonschema.Draft202012Validator(node).is_valid(value):
        desc = node.get("description", "")
        raise ConfigError(
            f"{where}: {key} = {value!r} is not allowed: {allowed_text(node)}" + (f" ({desc})" if desc else "")
        )


def _check_range(rng: Mapping[str, Json], where: str) -> None:
    if rng["num"] > 1 and not rng["stop"] > rng["start"]:
        raise ConfigError(f"{where}: stop = {rng['stop']} must be above start = {rng['start']}")


def skip_reason(spec: Mapping[str, Json], raw: Mapping[str, Json]) -> str:
    """Why a study skips a design, "" where it does not: ``tolerances: design`` on a design that states no
    tolerance class (the design's block is optional: the study is the one thing it cannot build)."""
    if spec.get("tolerances") == "design" and "tolerances" not in raw:
        return "it states no tolerances: block (the study takes tolerances: design)"
    return ""


def study_designs(spec: Mapping[str, Json], designs: Mapping[str, Mapping[str, Json]]) -> list[str]:
    """The designs a run builds: those its selector names (``designs:``, or a calibration's ``design:``) but
    those it skips (:func:`skip_reason`)."""
    chosen = selected_designs(spec["designs"] if "designs" in spec else [spec["design"]], designs)
    return [d for d in chosen if d not in designs or not skip_reason(spec, designs[d])]


def _skips(filled: Mapping[str, Json], designs: Mapping[str, Mapping[str, Json]]) -> list[tuple[str, str, str]]:
    return [
        (name, d, skip_reason(spec, designs[d]))
        for name, spec in filled.get("probabilities", {}).items()
        for d in selected_designs(spec["designs"], designs)
        if d in designs and skip_reason(spec, designs[d])
    ]


def skipped_runs(filled: Mapping[str, Json], designs: Mapping[str, Mapping[str, Json]]) -> list[str]:
    """One line per (study, design) that a study skips: ``probabilities.regimes_w skips design 'x': ...``."""
    return [f"probabilities.{name} skips design {d!r}: {why}" for name, d, why in _skips(filled, designs)]


def skipped_studies(raw: Mapping[str, Json], filled: Mapping[str, Json]) -> list[str]:
    """The studies of a config (``filled``) that would select the design ``raw`` and skip it for a block it
    lacks, one line each (``geardyn check-design``)."""
    return [f"probabilities.{name}: {why}" for name, _, why in _skips(filled, {raw["name"]: raw})]


def selected_designs(selector: Json, designs: Mapping[str, Mapping[str, Json]]) -> list[str]:
    """The KHV designs a run's ``designs`` selector names: a list, 'all', 'own' (no paper) or
    'paper:<key>', in the order of the config's ``designs``."""
    khv = [name for name, raw in designs.items() if raw["kind"] == "khv"]
    if isinstance(selector, list):
        return list(selector)
    if selector == "all":
        return khv
    if selector == "own":
        return [name for name in khv if not designs[name].get("paper")]
    key = str(selector).removeprefix("paper:")
    return [name for name in khv if designs[name].get("paper") == key]


def _segment(raw: Mapping[str, Json]) -> tuple[float, float]:
    return (raw["admissible"]["x1_min"], raw["admissible"]["x1_max"])


def check_runs(filled: dict[str, Json], designs: dict[str, dict[str, Json]]) -> None:
    """Every run against every design it selects: a known KHV design, known control parameters with values in
    range, ranges that go upwards, x1 inside the admissible segment; claims and calibrations for paper designs."""
    khv = [name for name, raw in designs.items() if raw["kind"] == "khv"]
    taken = {n for s in ("sweeps", "points", "maps", "curves", "responses") for n in filled.get(s, {})}
    for name in set(filled.get("probabilities", {})) & taken:
        raise ConfigError(f"config: probabilities name {name!r} is not allowed: a name other than the other studies'")
    for axis in ("x1", "x2"):
        _check_range(filled["closed_graph"][axis], f"config: closed_graph.{axis}")
    for i, x1 in enumerate(filled["stiffness_table"]["fig05_x1"]):
        for name in khv:
            _check_x1(
                resolve_fractions(x1, _segment(designs[name])), designs[name], f"config: stiffness_table.fig05_x1[{i}]"
            )
    for section in ("sweeps", "points", "calibration", "maps", "responses", "curves", "probabilities"):
        for name, spec in filled.get(section, {}).items():
            where = f"config: {section}.{name}"
            selector = spec["designs"] if "designs" in spec else [spec["design"]]
            for design_name in selected_designs(selector, designs):
                if design_name not in designs or designs[design_name]["kind"] != "khv":
                    raise ConfigError(
                        f"{where}: design {design_name!r} is not allowed: one of " + ", ".join(repr(d) for d in khv)
                    )
                raw = designs[design_name]
                if skip_reason(spec, raw):
                    continue
                if section == "calibration" and not raw.get("paper"):
                    raise ConfigError(
                        f"{where}: design {design_name!r} names no paper: a calibration fits a "
                        "design's unknowns to its paper's results (set 'paper:' in the design file)"
                    )
                _check_overrides(section, resolve_fractions(spec, _segment(raw)), raw, where)
                if section == "probabilities":
                    _check_probabilities(resolve_fractions(spec, _segment(raw)), raw, where)
    for name, spec in filled.get("orbits", {}).items():
        where = f"config: orbits.{name}"
        if name not in filled["sweeps"]:
            raise ConfigError(
                f"{where}: {name!r} is not allowed: the name of a sweep, one of "
                + (", ".join(repr(s) for s in filled["sweeps"]) or "none")
            )
        swept = selected_designs(filled["sweeps"][name]["designs"], designs)
        for design_name in selected_designs(spec["designs"], designs):
            if design_name not in swept:
                raise ConfigError(
                    f"{where}: design {design_name!r} is not allowed: one of "
                    + ", ".join(repr(d) for d in swept)
                    + f" (the designs of sweep {name})"
                )
    # the claims of a paper checked on a KHV drive's runs: designs whose paper names the runs (CLAIM_RUNS)
    checked = [d for d in khv if getattr(paper_of(designs[d].get("paper")), "CLAIM_RUNS", None)]
    for design_name in filled["claims"]["designs"]:
        where = "config: claims.designs"
        if design_name not in checked:
            raise ConfigError(
                f"{where}: design {design_name!r} is not allowed: one of "
                + (", ".join(repr(d) for d in checked) or "none")
                + " (the claims are checked on a KHV design that names a paper whose claims read its runs)"
            )
        for section, needed in paper_of(designs[design_name]["paper"]).CLAIM_RUNS.values():
            spec = filled[section].get(needed)
            if spec is None or design_name not in selected_designs(spec["designs"], designs):
                raise ConfigError(
                    f"{where}: design {design_name!r} needs {section}.{needed} to run for it "
                    "(the claims are checked on that run)"
                )


def _check_x1(value: float, raw: dict[str, Json], where: str) -> None:
    lo, hi = raw["admissible"]["x1_min"], raw["admissible"]["x1_max"]
    if not lo - 1e-12 <= value <= hi + 1e-12:
        raise ConfigError(
            f"{where}: x1 = {value} is not allowed: number >= {lo} and "
            f"<= {hi} (the admissible segment of design {raw['name']})"
        )


#: The ranges of a run, by section: (the key that holds the range, "" for the entry itself; the parameter
#: it spans, ``None`` when the range names it in its ``parameter``).  Each goes upwards and its ends are
#: values of its parameter.
RANGES: dict[str, tuple[tuple[str, str | None], ...]] = {
    "sweeps": (("", None),),
    "maps": (("x", None), ("y", None)),
    "curves": (("x", None), ("y", None)),
    "calibration": (("x1", "x1"),),
    "responses": (("", "w"),),
    "probabilities": (("axis", None),),
}


def _check_overrides(section: str, spec: dict[str, Json], raw: dict[str, Json], where: str) -> None:
    """Overrides of one run against one design: known keys, values in range, x1 inside the segment M-N."""
    overrides = [("fixed", spec.get("fixed", {}))] + [
        (f"cases[{i}]", case) for i, case in enumerate(spec.get("cases", []))
    ]
    for key, parameter in [(k, p) for k, p in RANGES.get(section, ()) if not k or k in spec]:
        rng, at = (spec[key], f"{key}.") if key else (spec, "")
        if parameter is None:
            parameter = rng["parameter"]
            _override_node(parameter, f"{where}.{at}parameter")
        _check_range({"num": 2, **rng}, f"{where}.{key}" if key else where)
        overrides += [(f"{at}{end}", {parameter: rng[end]}) for end in ("start", "stop")]
    for label, values in overrides:
        for key, value in values.items():
            if key == "x1" and raw["kind"] == "khv":
                _check_x1(value, raw, f"{where}.{label}")
            _check_value(key, value, f"{where}.{label}")


#: The shapes of an input's distribution: (the keys it needs, the keys it may have).
SHAPES = (
    ({"low", "high"}, {"low", "high", "scale"}),
    ({"std"}, {"std", "mean", "low", "high"}),
    ({"tolerance"}, {"tolerance"}),
    ({"relative_tolerance"}, {"relative_tolerance"}),
)


def _check_probabilities(spec: dict[str, Json], raw: dict[str, Json], where: str) -> None:
    """A probabilities study against one KHV design: an input at all, each a known override other than the axis
    and the fixed ones, of one distribution's shape, its range going upwards (low > 0 on a log scale) and inside
    the override's limits; a tolerance class to take, in ISO 1328-1's scope; a power of 2 of samples for
    Sobol' indices; the claims' line one of the paper's, along the axis, at the study's fixed values."""
    from geardyn.khv import point  # noqa: PLC0415 - only with such a study
    from geardyn.runs.probabilities import OPERATING, distribution, tolerance_inputs  # noqa: PLC0415

    drive, fixed, tol = khv_design.from_dict(raw, where), spec["fixed"], spec.get("tolerances")
    held = {*fixed, spec.get("axis", {}).get("parameter")}
    try:
        inputs = tolerance_inputs(drive, raw["tolerances"] if tol == "design" else tol) if tol else []
    except ValueError as err:
        raise ConfigError(f"{where}.tolerances: {err}") from None
    inputs = [i for i in inputs if i.name not in held]
    if spec.get("classes") and not tol:
        raise ConfigError(f"{where}.classes is not allowed without tolerances: a class study needs a tolerance block")
    given = spec.get("given")
    if given and (spec.get("classes") or given["parameter"] in {*held, *spec["inputs"]}):
        raise ConfigError(
            f"{where}.given.parameter = {given['parameter']!r} is not allowed: a parameter other than the axis, the "
            "fixed ones and the inputs, in a study without classes"
        )
    for i, value in enumerate(given["values"] if given is not None else ()):
        _check_value(given["parameter"], value, f"{where}.given.values[{i}]")  # type: ignore[index]  # given set
    if spec.get("classes") and spec.get("claims"):
        raise ConfigError(f"{where}.claims is not allowed with classes: a class study checks no claims")
    if (spec.get("classes") or given) and spec["sensitivity"]["method"] == "sobol":
        raise ConfigError(
            f"{where}.sensitivity.method = 'sobol' is not allowed with classes or given: rbd_fast or pawn"
        )
    places = {i.name: f"{where}.tolerances" for i in inputs}
    for name, dist in spec["inputs"].items():
        at = places[name] = f"{where}.inputs.{name}"
        _override_node(name, f"{where}.inputs")
        if name in OPERATING and not dist.get("operating"):
            raise ConfigError(
                f"{at}: input {name} is not allowed: an operating condition ({', '.join(OPERATING)}) is an axis or "
                "a fixed value, or an input marked operating: true (its probabilities then are shares of the box)"
            )
        dist = {k: v for k, v in dist.items() if k != "operating"}
        if not any(needs <= set(dist) <= may for needs, may in SHAPES):
            raise ConfigError(
                f"{at} = {dist!r} is not allowed: low and high (scale), std (mean, low, high), tolerance or "
                "relative_tolerance"
            )
        inputs = [i for i in inputs if i.name != name] + [distribution(name, dist, point.nominal(drive, name, fixed))]
    for inp in inputs:
        at = places[inp.name]
        if inp.name in fixed or inp.name == spec.get("axis", {}).get("parameter"):
            raise ConfigError(f"{at}: input {inp.name} is not allowed: an input other than the axis and the fixed ones")
        if not inp.low < inp.high or (inp.log and inp.low <= 0) or (inp.std and not inp.low <= inp.mean <= inp.high):
            raise ConfigError(
                f"{at}: {inp.text} is not allowed: low < high (low > 0 on a log scale, the mean between them)"
            )
        for value in (inp.low, inp.high):
            if inp.name == "x1":
                _check_x1(value, raw, at)
            _check_value(inp.name, value, at)
    _check_sampling(spec, raw, where, bool(inputs))


def _check_sampling(spec: dict[str, Json], raw: dict[str, Json], where: str, inputs: bool) -> None:
    """An uncertain input at all, a power of 2 of samples for Sobol' indices, the claims' line one of the
    design's paper's, without cases, along the axis and at the study's fixed values."""
    if not inputs and "initial_state" not in spec:
        raise ConfigError(f"{where}.inputs = {{}} is not allowed: an input, or a tolerance class or initial_state")
    n = spec["samples"]
    if spec["sensitivity"]["method"] == "sobol" and n & (n - 1):
        raise ConfigError(f"{where}.samples = {n} is not allowed: a power of 2 with sensitivity.method sobol")
    if "claims" not in spec:
        return
    lines = getattr(paper_of(raw.get("paper")), "CLAIM_LINES", {})
    line = lines.get(spec["claims"], {})
    if not line or "cases" in line or line["parameter"] != spec.get("axis", {}).get("parameter"):
        raise ConfigError(
            f"{where}.claims = {spec['claims']!r} is not allowed for design {raw['name']!r}: one of "
            + (", ".join(repr(k) for k, v in lines.items() if "cases" not in v) or "none (it names no such paper)")
            + ", a line along the study's axis parameter"
        )
    differ = {k: v for k, v in line.get("fixed", {}).items() if spec["fixed"].get(k) != v}
    if differ:
        raise ConfigError(f"{where}.fixed is not allowed: the claims' line holds {differ} (set them in fixed)")
