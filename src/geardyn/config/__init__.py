"""Load and validate configuration and design files against the JSON Schemas in ``schemas/``, with the schema's
defaults filled in; every problem is one :class:`ConfigError` line naming the file, the key, the value and what
is allowed (``my_drive.yaml: pair.module = -3.5 is not allowed: number > 0 and <= 100 (Module m (mm).)``)."""

from __future__ import annotations

import copy
import dataclasses
import difflib
import json
import math
import re
from collections.abc import Mapping
from functools import cache
from importlib import resources
from pathlib import Path
from typing import get_type_hints

import jsonschema
import yaml

from geardyn.jsontypes import Json

#: Design kinds and the schema that validates each.
DESIGN_SCHEMAS = {"khv": "khv.schema.json", "plus_planetary": "plus_planetary.schema.json"}


class ConfigError(ValueError):
    """A configuration or design value is invalid; the message is one line meant for the user."""


@cache
def _raw_schema(name: str) -> dict[str, Json]:
    return json.loads(resources.files("geardyn.config").joinpath("schemas", name).read_text(encoding="utf-8"))


def schema(name: str) -> dict[str, Json]:
    """The named schema with references to other schema files inlined (local ``#/$defs`` kept; a reference
    with a JSON pointer inlined without its ``default``; keys beside ``$ref`` win: ``docs/operations.md``)."""
    return _inline(copy.deepcopy(_raw_schema(name)))


def _inline(node: Json) -> Json:
    if isinstance(node, dict):
        ref = node.get("$ref")
        if isinstance(ref, str) and not ref.startswith("#") and ".schema.json" in ref:
            file, _, pointer = ref.partition("#")
            target: Json = schema(file)
            for part in [p for p in pointer.split("/") if p]:
                target = target[part]
            target = {k: v for k, v in target.items() if k not in ("$schema", "$id")}
            if pointer:
                target.pop("default", None)
            return {**target, **{k: _inline(v) for k, v in node.items() if k != "$ref"}}
        return {k: _inline(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_inline(v) for v in node]
    return node


class _Loader(yaml.SafeLoader):
    """YAML with the number syntax of YAML 1.2 and JSON (``1e6``, ``2e-6`` and ``1.0e6`` are numbers,
    not strings as YAML 1.1 reads them) and duplicate keys refused."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Json, Json]:
        seen: dict[Json, int] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            line = key_node.start_mark.line + 1
            if key in seen:
                raise ConfigError(
                    f"duplicate key {key!r} at line {line} (first at line {seen[key]}): each key may appear once"
                )
            seen[key] = line
        return super().construct_mapping(node, deep=deep)


_Loader.yaml_implicit_resolvers = {k: list(v) for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()}
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(
        r"""^(?:[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?(?:[eE][-+]?[0-9]+)
                   |[-+]?\.[0-9_]+(?:[eE][-+]?[0-9]+)?
                   |[-+]?(?:[0-9][0-9_]*)\.[0-9_]*
                   |[-+]?\.(?:inf|Inf|INF)
                   |\.(?:nan|NaN|NAN))$""",
        re.X,
    ),
    list("-+0123456789."),
)


def read_yaml(path: str | Path) -> Json:
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
        data = yaml.load(text, Loader=_Loader)
    except ConfigError as err:
        raise ConfigError(f"{path}: {err}") from None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise ConfigError(f"{path}: YAML syntax error at{where}: {problem}") from None
    check_expanded_size(data, str(path))
    return data


#: The most values (mappings, lists and scalars, every alias expanded) a config or design file may hold (the
#: shipped config.yaml about 500): a few aliases can stand for an exponentially large structure ("billion laughs").
MAX_EXPANDED_VALUES = 100_000


def expanded_size(data: Json, where: str = "input", sizes: dict[int, int] | None = None, finite: bool = False) -> int:
    """The number of values in ``data`` with every alias expanded, memoised by object id in ``sizes`` (an alias
    is its anchor's object: linear in the distinct objects); a structure that contains itself is refused, and
    with ``finite`` NaN and infinity (named by their key)."""
    sizes = {} if sizes is None else sizes
    open_ids: set[int] = set()

    def size(node: Json, path: tuple[Json, ...]) -> int:
        if not isinstance(node, (dict, list)):
            if finite and isinstance(node, float) and not math.isfinite(node):
                raise ConfigError(f"{where}: {_key(path)} = {node} is not allowed: a finite number")
            return 1
        key = id(node)
        if key in sizes:
            return sizes[key]
        if key in open_ids:
            raise ConfigError(
                f"{where}: an alias refers to a mapping or list that contains it: a structure may not contain itself"
            )
        open_ids.add(key)
        children = node.items() if isinstance(node, dict) else enumerate(node)
        total = 1 + sum(size(child, (*path, k)) for k, child in children)
        open_ids.discard(key)
        sizes[key] = total
        return total

    try:
        return size(data, ())
    except RecursionError:
        raise ConfigError(f"{where}: the structure is nested too deeply") from None


def check_expanded_size(data: Json, where: str, finite: bool = False) -> None:
    """Refuse ``data`` (one line) when its aliases expand to more than :data:`MAX_EXPANDED_VALUES`
    values, before anything walks the expanded structure (with ``finite``, NaN and infinity too)."""
    sizes: dict[int, int] = {}
    n = expanded_size(data, where, sizes, finite)
    if n > MAX_EXPANDED_VALUES:
        # name the top-level key whose value expands most, the last one of equals: an anchor is
        # defined before the key that uses it (the sizes are memoised: no new walk)
        path: list[Json] = []
        if isinstance(data, dict):
            sized = [(sizes.get(id(v), 1), k) for k, v in reversed(data.items())]
            top, key = max(sized, key=lambda item: item[0])
            if top > MAX_EXPANDED_VALUES:
                path, n = [key], top
        raise ConfigError(
            f"{where}: expanded size of {_key(path)} = {n} values (YAML aliases counted in full) is not "
            f"allowed: at most {MAX_EXPANDED_VALUES} values"
        )


#: How each JSON Schema bound reads in an error message, in the order it is printed.
_BOUND_TEXT = (
    ("minimum", ">= {}"),
    ("exclusiveMinimum", "> {}"),
    ("maximum", "<= {}"),
    ("exclusiveMaximum", "< {}"),
    ("minItems", "with at least {} items"),
    ("maxItems", "with at most {} items"),
    ("pattern", "matching {}"),
)


def allowed_text(node: Mapping[str, Json]) -> str:
    """Human-readable description of what a schema node accepts."""
    if "const" in node:
        return repr(node["const"])
    if "enum" in node:
        return "one of " + ", ".join(repr(v) for v in node["enum"])
    for key in ("anyOf", "oneOf"):
        if key in node:
            return " or ".join(allowed_text(sub) for sub in node[key])
    kind = str(node.get("type", "value"))
    kind = {"boolean": "true/false", "array": "list", "object": "mapping"}.get(kind, kind)
    bounds = [text.format(node[key]) for key, text in _BOUND_TEXT if key in node]
    return kind + (" " + " and ".join(bounds) if bounds else "")


def _key(path: Json) -> str:
    return ".".join([f"[{p}]" if isinstance(p, int) else str(p) for p in path]).replace(".[", "[") or "(top level)"


def _format(error: jsonschema.ValidationError, where: str) -> str:
    key = _key(error.absolute_path)
    node = error.schema if isinstance(error.schema, Mapping) else {}
    if "propertyNames" in error.absolute_schema_path:  # a name of a section's entry: the instance is the name
        text = str(error.instance)
        shown = repr(text if len(text) <= 80 else text[:40] + "..." + text[-20:])
        if error.validator == "maxLength":
            return (
                f"{where}: {key} name {shown} ({len(text)} characters) is not allowed: "
                f"at most {error.validator_value} characters"
            )
        return f"{where}: {key} name {shown} is not allowed: {node.get('description', allowed_text(node))}"
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
    parent = error
    while parent.parent is not None and parent.parent.absolute_path == error.absolute_path:
        parent = parent.parent
    value_node = parent.schema if isinstance(parent.schema, Mapping) else {}
    desc = value_node.get("description", "")
    return f"{where}: {key} = {error.instance!r} is not allowed: {allowed_text(value_node)}" + (
        f" ({desc})" if desc else ""
    )


def _fill_defaults(node: Mapping[str, Json], value: Json, root: Mapping[str, Json] | None = None) -> Json:
    """Insert schema defaults into ``value`` (in place), through properties, maps and local $refs."""
    root = root if root is not None else node
    ref = node.get("$ref")
    if isinstance(ref, str) and ref.startswith("#/"):
        target: Json = root
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


#: How a value of each Python type is named in a message.
_KINDS = {list: "a list", str: "a string", int: "a number", float: "a number", bool: "true/false"}


def validated(data: Json, schema_name: str, where: str) -> dict[str, Json]:
    """A copy of ``data`` with the schema's defaults filled in; :class:`ConfigError`, one line, for the first
    (most specific) problem."""
    if data is None:
        raise ConfigError(f"{where}: the file is empty; expected a mapping of keys to values")
    if not isinstance(data, dict):
        got = _KINDS.get(type(data), type(data).__name__)
        raise ConfigError(f"{where}: expected a mapping of keys to values at the top level, got {got}")
    check_expanded_size(data, where, finite=True)
    sch = schema(schema_name)
    filled = _fill_defaults(sch, copy.deepcopy(data))
    validator = jsonschema.Draft202012Validator(sch)
    errors = sorted(validator.iter_errors(filled), key=lambda e: (len(e.absolute_path), str(e.absolute_path)))
    if errors:
        raise ConfigError(_format(jsonschema.exceptions.best_match(errors), where))
    return filled


def settings_from(cls: type, spec: Mapping[str, Json] | None, what: str) -> Json:
    """A settings dataclass ``cls`` from a mapping of its field values; an unknown key is refused with
    one line naming it and the allowed keys (``what``: e.g. "classifier settings")."""
    spec = dict(spec or {})
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = set(spec) - names
    if unknown:
        raise ValueError(f"unknown {what} {sorted(unknown)}; allowed: {sorted(names)}")
    hints = get_type_hints(cls)
    # the schema's "integer" admits 6.0: an int field gets an int
    spec |= {k: int(v) for k, v in spec.items() if hints.get(k) is int and isinstance(v, float) and v.is_integer()}
    return cls(**spec)


def load_design_dict(path: str | Path) -> dict[str, Json]:
    """Read and schema-validate one design file; the schema is chosen by its ``kind`` key."""
    data = read_yaml(path)
    where = str(path)
    if not isinstance(data, dict):
        raise ConfigError(f"{where}: expected a mapping with a 'kind' key at the top level")
    kind = data.get("kind")
    if not isinstance(kind, str) or kind not in DESIGN_SCHEMAS:
        raise ConfigError(
            f"{where}: kind = {kind!r} is not allowed: one of " + ", ".join(repr(k) for k in DESIGN_SCHEMAS)
        )
    return validated(data, DESIGN_SCHEMAS[kind], where)
