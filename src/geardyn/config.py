"""Load and validate configuration and design files against the JSON Schemas in ``schemas/``.

Every problem is reported as a single :class:`ConfigError` line that names the file, the key,
the offending value and what is allowed, e.g.::

    config/designs/li2013.yaml: pair.module = -3.5 is not allowed: number > 0 and <= 100 (Module m (mm).)

Defaults declared in the schema are filled in, so downstream code sees every key.
"""

from __future__ import annotations

import copy
import difflib
import json
from collections.abc import Mapping
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema
import yaml

#: Design kinds and the schema that validates each.
DESIGN_SCHEMAS = {"khv": "khv.schema.json", "plus_planetary": "plus_planetary.schema.json"}


class ConfigError(ValueError):
    """A configuration or design value is invalid; the message is one line meant for the user."""


@cache
def _raw_schema(name: str) -> dict[str, Any]:
    text = resources.files("geardyn").joinpath("schemas", name).read_text(encoding="utf-8")
    return json.loads(text)


def schema(name: str) -> dict[str, Any]:
    """The named schema with references to other schema files inlined (local ``#/$defs`` kept)."""
    return _inline(copy.deepcopy(_raw_schema(name)))


def _inline(node: Any) -> Any:
    if isinstance(node, dict):
        ref = node.get("$ref")
        if isinstance(ref, str) and ref.endswith(".schema.json"):
            target = schema(ref)
            target.pop("$schema", None)
            target.pop("$id", None)
            rest = {k: v for k, v in node.items() if k != "$ref"}
            return {**target, **rest}
        return {k: _inline(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_inline(v) for v in node]
    return node


def read_yaml(path: str | Path) -> Any:
    """Parse a YAML file, turning unreadable/undecodable/ill-formed files into one-line errors."""
    path = Path(path)
    try:
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except UnicodeDecodeError as err:
        raise ConfigError(f"{path}: not UTF-8 text (byte {err.start}); save the file as UTF-8") from None
    except OSError as err:
        raise ConfigError(f"{path}: cannot read ({err.strerror})") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise ConfigError(f"{path}: YAML syntax error at{where}: {problem}") from None


#: How each JSON Schema bound reads in an error message, in the order it is printed.
_BOUND_TEXT = (
    ("minimum", ">= {}"), ("exclusiveMinimum", "> {}"), ("maximum", "<= {}"), ("exclusiveMaximum", "< {}"),
    ("minItems", "with at least {} items"), ("maxItems", "with at most {} items"), ("pattern", "matching {}"),
)


def _allowed(node: Mapping[str, Any]) -> str:
    """Human-readable description of what a schema node accepts."""
    if "const" in node:
        return repr(node["const"])
    if "enum" in node:
        return "one of " + ", ".join(repr(v) for v in node["enum"])
    for key in ("anyOf", "oneOf"):
        if key in node:
            return " or ".join(_allowed(sub) for sub in node[key])
    kind = node.get("type", "value")
    kind = {"integer": "integer", "number": "number", "string": "string", "boolean": "true/false",
            "array": "list", "object": "mapping"}.get(kind, str(kind))
    bounds = [text.format(node[key]) for key, text in _BOUND_TEXT if key in node]
    return kind + (" " + " and ".join(bounds) if bounds else "")


def _key(path: Any) -> str:
    parts = [f"[{p}]" if isinstance(p, int) else str(p) for p in path]
    return ".".join(parts).replace(".[", "[") or "(top level)"


def _format(error: jsonschema.ValidationError, where: str) -> str:
    key = _key(error.absolute_path)
    node = error.schema if isinstance(error.schema, Mapping) else {}
    if error.validator == "additionalProperties":
        allowed = sorted(node.get("properties", {}))
        extra = sorted(set(error.instance) - set(allowed)) if isinstance(error.instance, Mapping) else []
        bad = extra[0] if extra else "?"
        full = f"{key}.{bad}" if error.absolute_path else bad
        close = difflib.get_close_matches(bad, allowed, n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else f" (allowed keys: {', '.join(allowed)})"
        return f"{where}: unknown key '{full}'{hint}"
    if error.validator == "required":
        missing = error.message.split("'")[1] if "'" in error.message else error.message
        full = f"{key}.{missing}" if error.absolute_path else missing
        return f"{where}: missing required key '{full}'"
    # point at the schema node of the offending value (the property, not the sub-branch of anyOf)
    value_node = _node_for(error)
    desc = value_node.get("description", "")
    return (f"{where}: {key} = {error.instance!r} is not allowed: {_allowed(value_node)}"
            + (f" ({desc})" if desc else ""))


def _node_for(error: jsonschema.ValidationError) -> Mapping[str, Any]:
    parent = error
    while parent.parent is not None and parent.parent.absolute_path == error.absolute_path:
        parent = parent.parent
    node = parent.schema
    return node if isinstance(node, Mapping) else {}


def _fill_defaults(node: Mapping[str, Any], value: Any, root: Mapping[str, Any] | None = None) -> Any:
    """Insert schema defaults into ``value`` (in place), through properties, maps and local $refs."""
    root = root if root is not None else node
    ref = node.get("$ref")
    if isinstance(ref, str) and ref.startswith("#/"):
        target: Any = root
        for part in ref[2:].split("/"):
            target = target[part]
        node = {**target, **{k: v for k, v in node.items() if k != "$ref"}}
    if not isinstance(value, dict):
        return value
    props = node.get("properties", {})
    for name, sub in props.items():
        if name not in value and "default" in sub:
            value[name] = copy.deepcopy(sub["default"])
        if name in value:
            value[name] = _fill_defaults(sub, value[name], root)
    extra = node.get("additionalProperties")
    if isinstance(extra, Mapping):
        for name in value:
            if name not in props:
                value[name] = _fill_defaults(extra, value[name], root)
    return value


def validate(data: Any, schema_name: str, where: str) -> dict[str, Any]:
    """Validate ``data`` against a schema; return a copy with defaults filled in.

    Raises :class:`ConfigError` with one line for the first problem (the most specific one).
    """
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ConfigError(f"{where}: expected a mapping of keys to values at the top level, got {type(data).__name__}")
    sch = schema(schema_name)
    filled = _fill_defaults(sch, copy.deepcopy(data))
    validator = jsonschema.Draft202012Validator(sch)
    errors = sorted(validator.iter_errors(filled), key=lambda e: (len(e.absolute_path), str(e.absolute_path)))
    if errors:
        best = jsonschema.exceptions.best_match(errors)
        raise ConfigError(_format(best, where))
    return filled


def load_config(path: str | Path) -> dict[str, Any]:
    """Read and validate the workflow configuration (``config/config.yaml``)."""
    return validate(read_yaml(path), "config.schema.json", str(path))


def load_design_dict(path: str | Path) -> dict[str, Any]:
    """Read and schema-validate one design file; the schema is chosen by its ``kind`` key."""
    data = read_yaml(path)
    where = str(path)
    if not isinstance(data, dict):
        raise ConfigError(f"{where}: expected a mapping with a 'kind' key at the top level")
    kind = data.get("kind")
    if kind not in DESIGN_SCHEMAS:
        raise ConfigError(f"{where}: kind = {kind!r} is not allowed: one of "
                          + ", ".join(repr(k) for k in DESIGN_SCHEMAS))
    return validate(data, DESIGN_SCHEMAS[kind], where)


def validate_workflow(config: dict[str, Any], root: str | Path = ".") -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
    """Validate the workflow config and every design it lists, before any job runs.

    Returns the config with defaults filled and ``{design name: validated design dict}``.
    KHV designs are also checked semantically (z2 - z1, feasibility of the design point and of the
    admissible segment M-N that sweeps, point runs and calibrations stay inside).
    """
    from geardyn.khv import design as _design  # local: design imports geometry, which is heavier

    filled = validate(config, "config.schema.json", "config")
    designs: dict[str, dict[str, Any]] = {}
    for name, rel in filled["designs"].items():
        path = Path(root) / rel
        raw = load_design_dict(path)
        if raw["name"] != name:
            raise ConfigError(f"{path}: name = {raw['name']!r} differs from its key {name!r} in config designs")
        if raw["kind"] == "khv":
            _design.check_segment(_design.from_dict(raw, str(path)), str(path))
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
        raise ConfigError(f"{where}: {key} = {value!r} is not allowed: {_allowed(node)}" + (f" ({desc})" if desc else ""))


def _check_range(rng: Mapping[str, Any], where: str) -> None:
    if rng["num"] > 1 and not rng["stop"] > rng["start"]:
        raise ConfigError(f"{where}: stop = {rng['stop']} must be above start = {rng['start']}")


def _check_runs(filled: dict[str, Any], designs: dict[str, dict[str, Any]]) -> None:
    """Semantic checks of sweeps, point runs and calibrations: known design, known control parameters
    with values in range, ranges that go upwards, x1 inside every design's admissible segment M-N."""
    khv_designs = [raw for raw in designs.values() if raw["kind"] == "khv"]
    for axis in ("x1", "x2"):
        _check_range(filled["closed_graph"][axis], f"config: closed_graph.{axis}")
    for i, x1 in enumerate(filled["stiffness_table"]["fig05_x1"]):
        for raw in khv_designs:
            _check_x1(x1, raw, f"config: stiffness_table.fig05_x1[{i}]")
    for section in ("sweeps", "points", "calibration", "maps"):
        for name, spec in filled.get(section, {}).items():
            where = f"config: {section}.{name}"
            names = spec["designs"] if "designs" in spec else [spec["design"]]
            for design_name in names:
                if design_name not in designs or designs[design_name]["kind"] != "khv":
                    raise ConfigError(f"{where}: design {design_name!r} is not allowed: one of "
                                      + ", ".join(repr(d) for d, r in designs.items() if r["kind"] == "khv"))
            for design_name in names:
                _check_overrides(section, spec, designs[design_name], where)


def _check_x1(value: float, raw: dict[str, Any], where: str) -> None:
    lo, hi = raw["admissible"]["x1_min"], raw["admissible"]["x1_max"]
    if not lo - 1e-12 <= value <= hi + 1e-12:
        raise ConfigError(f"{where}: x1 = {value} is not allowed: number >= {lo} and "
                          f"<= {hi} (the admissible segment M-N of design {raw['name']})")


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
        for key, values in spec["grid"].items():
            overrides += [(f"grid.{key}[{i}]", {key: v}) for i, v in enumerate(values)]
    for label, values in overrides:
        for key, value in values.items():
            if key == "x1" and raw["kind"] == "khv":
                _check_x1(value, raw, f"{where}.{label}")
            _check_value(key, value, f"{where}.{label}")
