"""The one validator of a workflow: the config and every design it lists, before any job runs.

The same checks, in the same order, serve ``geardyn check-design``, ``geardyn check-config`` and the
Snakefile: schema (with defaults), then the semantic checks of each design kind (for a KHV design the
design point and the admissible segment the runs stay inside), then every run of the config against
the designs it names.  Every problem is one :class:`~geardyn.config.ConfigError` line.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import jsonschema

from geardyn.config import ConfigError, allowed_text, load_design_dict, read_yaml, schema, validate
from geardyn.khv import design as khv_design


def read_config_file(path: str | Path) -> dict[str, Any]:
    """Read a workflow config file: YAML errors, an empty file or a top level that is not a mapping are
    one line each (schema validation follows in :func:`validate_workflow`)."""
    data = read_yaml(path)
    if data is None:
        raise ConfigError(f"{path}: the file is empty; expected a mapping with a 'designs' key")
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a mapping with a 'designs' key at the top level, got "
                          f"{type(data).__name__}")
    return data


def check_design(raw: dict[str, Any], where: str) -> None:
    """The semantic checks of one schema-validated design (after :func:`geardyn.config.load_design_dict`)."""
    if raw["kind"] == "khv":
        khv_design.check_segment(khv_design.from_dict(raw, where), where)
    else:
        from geardyn.plus import design as plus_design

        plus_design.design_from_dict(raw, where)


def validate_workflow(config: dict[str, Any], root: str | Path = ".") -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
    """Validate the workflow config and every design it lists, before any job runs.

    Returns the config with defaults filled and ``{design name: validated design dict}``.
    Each design is also checked semantically (:func:`check_design`; for a KHV design z2 - z1, the design
    point and the admissible segment the runs stay inside), then every run against its designs.
    """
    filled = validate(config, "config.schema.json", "config")
    designs: dict[str, dict[str, Any]] = {}
    for name, rel in filled["designs"].items():
        path = Path(root) / rel
        raw = load_design_dict(path)
        if raw["name"] != name:
            raise ConfigError(f"{path}: name = {raw['name']!r} differs from its key {name!r} in config designs")
        check_design(raw, str(path))
        designs[name] = raw
    _check_runs(filled, designs)
    return filled, designs


#: The control parameters of :mod:`geardyn.khv` (``khv.CONTROLS``) with the values a run may give them,
#: as schema nodes. b and e are in um; their limits are those of the design file's ``backlash`` and
#: ``te_amplitude`` (m). Any other override must be a ``dynamics.parameters`` key, with that key's limits.
CONTROL_LIMITS: dict[str, dict[str, Any]] = {
    "x1": {"type": "number", "minimum": -1.0, "maximum": 2.0, "description": "planet profile-shift coefficient x1 (-)"},
    "b": {"type": "number", "minimum": 0, "maximum": 1000, "description": "half backlash b (um)"},
    "e": {"type": "number", "minimum": 0, "maximum": 1000, "description": "transmission-error amplitude e (um)"},
    "w": {"type": "number", "exclusiveMinimum": 0, "maximum": 100,
          "description": "dimensionless mesh frequency w_m / w_n (-)"},
    "speed": {"type": "number", "exclusiveMinimum": 0, "maximum": 1000000, "description": "input speed (rpm)"},
}


def _override_node(key: str, where: str) -> Mapping[str, Any]:
    """The schema node an override ``key`` is checked against; unknown keys are refused with a hint."""
    if key in CONTROL_LIMITS:
        return CONTROL_LIMITS[key]
    params = schema("dynamics.schema.json")["properties"]["parameters"]["properties"]
    if key in params:
        return params[key]
    allowed = sorted(CONTROL_LIMITS) + sorted(params)
    close = difflib.get_close_matches(key, allowed, n=1)
    hint = f" (did you mean '{close[0]}'?)" if close else f" (allowed: {', '.join(allowed)})"
    raise ConfigError(f"{where}: unknown control parameter '{key}'{hint}")


def _check_value(key: str, value: Any, where: str) -> None:
    node = _override_node(key, where)
    if not jsonschema.Draft202012Validator(node).is_valid(value):
        desc = node.get("description", "")
        raise ConfigError(f"{where}: {key} = {value!r} is not allowed: {allowed_text(node)}" + (f" ({desc})" if desc else ""))


def _check_range(rng: Mapping[str, Any], where: str) -> None:
    if rng["num"] > 1 and not rng["stop"] > rng["start"]:
        raise ConfigError(f"{where}: stop = {rng['stop']} must be above start = {rng['start']}")


def selected_designs(selector: Any, designs: Mapping[str, Mapping[str, Any]]) -> list[str]:
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


def _segment(raw: Mapping[str, Any]) -> tuple[float, float]:
    return (raw["admissible"]["x1_min"], raw["admissible"]["x1_max"])


def _check_runs(filled: dict[str, Any], designs: dict[str, dict[str, Any]]) -> None:
    """Semantic checks of every run against every design it selects: known KHV design, known control
    parameters with values in range (NaN and inf refused), ranges that go upwards, x1 inside the design's
    admissible segment, percentages only for x1; claims and calibrations only for paper designs."""
    from geardyn.khv.design import resolve_fractions

    khv = [name for name, raw in designs.items() if raw["kind"] == "khv"]
    for axis in ("x1", "x2"):
        _check_range(filled["closed_graph"][axis], f"config: closed_graph.{axis}")
    for i, x1 in enumerate(filled["stiffness_table"]["fig05_x1"]):
        for name in khv:
            _check_x1(resolve_fractions(x1, _segment(designs[name])), designs[name],
                      f"config: stiffness_table.fig05_x1[{i}]")
    for section in ("sweeps", "points", "calibration", "maps"):
        for name, spec in filled.get(section, {}).items():
            where = f"config: {section}.{name}"
            selector = spec["designs"] if "designs" in spec else [spec["design"]]
            _no_fraction_but_x1(spec, where)
            for design_name in selected_designs(selector, designs):
                if design_name not in designs or designs[design_name]["kind"] != "khv":
                    raise ConfigError(f"{where}: design {design_name!r} is not allowed: one of "
                                      + ", ".join(repr(d) for d in khv))
                raw = designs[design_name]
                if section == "calibration" and not raw.get("paper"):
                    raise ConfigError(f"{where}: design {design_name!r} names no paper: a calibration fits a "
                                      "design's unknowns to its paper's results (set 'paper:' in the design file)")
                _check_overrides(section, resolve_fractions(spec, _segment(raw)), raw, where)
    for name, spec in filled.get("orbits", {}).items():
        where = f"config: orbits.{name}"
        if name not in filled["sweeps"]:
            raise ConfigError(f"{where}: {name!r} is not allowed: the name of a sweep, one of "
                              + (", ".join(repr(s) for s in filled["sweeps"]) or "none"))
        swept = selected_designs(filled["sweeps"][name]["designs"], designs)
        for design_name in selected_designs(spec["designs"], designs):
            if design_name not in swept:
                raise ConfigError(f"{where}: design {design_name!r} is not allowed: one of "
                                  + ", ".join(repr(d) for d in swept) + f" (the designs of sweep {name})")
    for design_name in filled["claims"]["designs"]:
        where = "config: claims.designs"
        if design_name not in designs or designs[design_name].get("paper") != "li2013":
            raise ConfigError(f"{where}: design {design_name!r} is not allowed: one of "
                              + (", ".join(repr(d) for d in khv if designs[d].get("paper") == "li2013") or "none")
                              + " (the claims are paper 1's: the design must name paper: li2013)")
        for needed, section in (("fig07_bifurcation_x1", "sweeps"), ("fig09_bifurcation_b", "sweeps"),
                                ("fig11_bifurcation_e", "sweeps"), ("fig08_points_x1", "points")):
            spec = filled[section].get(needed)
            if spec is None or design_name not in selected_designs(spec["designs"], designs):
                raise ConfigError(f"{where}: design {design_name!r} needs {section}.{needed} to run for it "
                                  "(the claims are checked on that run)")


def _no_fraction_but_x1(spec: Mapping[str, Any], where: str) -> None:
    """Percentages of the admissible segment are x1 values: refuse them for any other parameter."""
    from geardyn.khv.design import is_fraction

    def walk(node: Any, key: str | None, path: str) -> None:
        if isinstance(node, Mapping):
            param = node.get("parameter") if isinstance(node.get("parameter"), str) else None
            for k, v in node.items():
                sub = param if k in ("start", "stop") and param else k
                walk(v, sub, f"{path}.{k}")
        elif isinstance(node, list):
            for i, v in enumerate(node):
                walk(v, key, f"{path}[{i}]")
        elif is_fraction(node) and key != "x1":
            raise ConfigError(f"{path} = {node!r} is not allowed: a number (percentages of the admissible "
                              "segment are for x1 only)")

    walk(spec, None, where)


def _check_x1(value: float, raw: dict[str, Any], where: str) -> None:
    lo, hi = raw["admissible"]["x1_min"], raw["admissible"]["x1_max"]
    if not lo - 1e-12 <= value <= hi + 1e-12:
        raise ConfigError(f"{where}: x1 = {value} is not allowed: number >= {lo} and "
                          f"<= {hi} (the admissible segment of design {raw['name']})")


def _check_overrides(section: str, spec: dict[str, Any], raw: dict[str, Any], where: str) -> None:
    """Overrides of one run against one design: known keys, values in range, x1 inside the segment M-N."""
    overrides = [("fixed", spec.get("fixed", {}))] + [
        (f"cases[{i}]", case) for i, case in enumerate(spec.get("cases", []))]
    if section == "sweeps":
        _override_node(spec["parameter"], f"{where}.parameter")
        _check_range(spec, where)
        overrides.append(("start", {spec["parameter"]: spec["start"]}))
        overrides.append(("stop", {spec["parameter"]: spec["stop"]}))
    if section == "maps":
        for ax in ("x", "y"):
            a = spec[ax]
            _override_node(a["parameter"], f"{where}.{ax}.parameter")
            _check_range(a, f"{where}.{ax}")
            overrides.append((f"{ax}.start", {a["parameter"]: a["start"]}))
            overrides.append((f"{ax}.stop", {a["parameter"]: a["stop"]}))
    if section == "calibration":
        _check_range(spec["x1"], f"{where}.x1")
        overrides.append(("x1.start", {"x1": spec["x1"]["start"]}))
        overrides.append(("x1.stop", {"x1": spec["x1"]["stop"]}))
        for key, values in spec.get("grid", {}).items():
            overrides += [(f"grid.{key}[{i}]", {key: v}) for i, v in enumerate(values)]
    for label, values in overrides:
        for key, value in values.items():
            if key == "x1" and raw["kind"] == "khv":
                _check_x1(value, raw, f"{where}.{label}")
            _check_value(key, value, f"{where}.{label}")
