"""The one validator of a workflow, before any job runs, behind ``geardyn check-design``, ``check-config`` and the
Snakefile alike: schema (with defaults), the semantic checks of each design (a KHV design's point and the segment
its runs stay inside), then every run against the designs it names; every problem one ConfigError line."""

from __future__ import annotations

import copy
from collections.abc import Mapping
from pathlib import Path

from geardyn.config import (
    ConfigError,
    check_expanded_size,
    load_design_dict,
    read_yaml,
    schema,
    validated,
)
from geardyn.config.run_checks import check_runs, selected_designs
from geardyn.jsontypes import Json
from geardyn.khv import design as khv_design
from geardyn.plus import design as plus_design
from geardyn.solve.precision import POINCARE_ERROR, measured_poincare_error


def read_config_file(path: str | Path) -> dict[str, Json]:
    """Read a workflow config file: YAML errors, an empty file or a top level that is not a mapping are
    one line each (schema validation follows in :func:`validate_workflow`)."""
    data = read_yaml(path)
    if data is None:
        raise ConfigError(f"{path}: the file is empty; expected a mapping with a 'designs' key")
    if not isinstance(data, dict):
        raise ConfigError(
            f"{path}: expected a mapping with a 'designs' key at the top level, got {type(data).__name__}"
        )
    return data


def check_design(raw: dict[str, Json], where: str) -> None:
    """The semantic checks of one schema-validated design (after :func:`geardyn.config.load_design_dict`)."""
    if raw["kind"] == "khv":
        khv_design.check_segment(khv_design.from_dict(raw, where), where)
    else:
        plus_design.design_from_dict(raw, where)


def validate_workflow(
    config: dict[str, Json], root: str | Path = "."
) -> tuple[dict[str, Json], dict[str, dict[str, Json]]]:
    """The config with presets resolved and defaults filled (:func:`fill_config`; an ``error_floor`` a run does not
    set from :data:`POINCARE_ERROR` at its designs' steps per period) and ``{design name: validated design dict}``,
    each design checked (:func:`check_design`), then every run against its designs."""
    filled = fill_config(config, "config")
    designs: dict[str, dict[str, Json]] = {}
    for name, rel in filled["designs"].items():
        path = Path(root) / rel
        raw = load_design_dict(path)
        if raw["name"] != name:
            raise ConfigError(f"{path}: name = {raw['name']!r} differs from its key {name!r} in config designs")
        check_design(raw, str(path))
        designs[name] = raw
    check_runs(filled, designs)
    _fill_error_floors(filled, designs)
    return filled, designs


#: Blocks a preset may hold, per section that may name one.
PRESET_KEYS = {
    "sweeps": ("integration", "classifier", "start_from", "coexistence"),
    "maps": ("integration", "classifier", "start_from", "coexistence"),
    "calibration": ("integration", "classifier"),
    "responses": ("integration", "classifier"),
    "probabilities": ("integration", "classifier", "start_from", "coexistence"),
}


def poincare_error(steps: int, where: str) -> float:
    """The measured Poincare error at ``steps`` steps per period (:data:`POINCARE_ERROR`, a fact of the
    solver: :mod:`geardyn.solve.precision`): the table's value at an entry, log-log interpolation between
    entries; outside the table a :class:`ConfigError` line (``where`` names the key that gave ``steps``)."""
    error = measured_poincare_error(steps)
    if error is None:
        known = sorted(POINCARE_ERROR)
        raise ConfigError(
            f"{where} = {steps} is not allowed without classifier.error_floor: integer >= "
            f"{known[0]} and <= {known[-1]} (the step counts of the measured Poincare error, "
            "docs/model.md Sec. 6); set classifier.error_floor for other step counts"
        )
    return error


def fill_config(config: dict[str, Json], where: str = "config") -> dict[str, Json]:
    """The workflow config with presets resolved, defaults filled, maps checked (the size with aliases expanded
    first) and the ``error_floor`` of each entry that sets ``integration.steps_per_period``."""
    check_expanded_size(config, where)
    checked = validated(config, "config.schema.json", where)
    resolved = _resolve_presets(copy.deepcopy(config), checked["presets"], where)
    filled = validated(resolved, "config.schema.json", where)
    _check_maps(filled, where)
    for section in PRESET_KEYS:
        for name, spec in filled[section].items():
            steps = spec["integration"].get("steps_per_period")
            if "error_floor" not in spec["classifier"] and steps is not None:
                spec["classifier"]["error_floor"] = poincare_error(
                    steps, f"{where}: {section}.{name}.integration.steps_per_period"
                )
    return filled


def _resolve_presets(config: dict[str, Json], presets: Mapping[str, Json], where: str) -> dict[str, Json]:
    """Replace each entry's ``preset: <name>`` by the preset's blocks, in place in the raw ``config`` (no defaults
    yet, so a key the entry sets is its author's: it overrides the preset's, key by key within a block)."""
    for section, keys in PRESET_KEYS.items():
        for name, spec in (config.get(section) or {}).items():
            if "preset" not in spec:
                continue
            chosen = spec.pop("preset")
            if chosen not in presets:
                allowed = (
                    "one of " + ", ".join(repr(p) for p in presets)
                    if presets
                    else "the name of an entry of presets, and the config has none"
                )
                raise ConfigError(f"{where}: {section}.{name}.preset = {chosen!r} is not allowed: {allowed}")
            raw_preset = (config.get("presets") or {})[chosen]
            for key in keys:
                if key not in raw_preset:
                    continue
                if isinstance(raw_preset[key], dict):
                    spec[key] = {**copy.deepcopy(raw_preset[key]), **spec.get(key, {})}
                elif key not in spec:
                    spec[key] = raw_preset[key]
    return config


def _check_maps(config: Mapping[str, Json], where: str) -> None:
    """Degenerate maps and curves studies, whatever designs they select: both axes the same parameter, an axis
    whose ends are the same value (the schema refuses num < 2); a curves study named like a map."""
    for section, name, spec in [(s, n, e) for s in ("maps", "curves") for n, e in config.get(s, {}).items()]:
        x, y = spec["x"], spec["y"]
        if x["parameter"] == y["parameter"]:
            raise ConfigError(
                f"{where}: {section}.{name}.y.parameter = {y['parameter']!r} is not allowed: a parameter "
                f"other than x.parameter ({x['parameter']!r}); a map spans two parameters"
            )
        for ax, a in (("x", x), ("y", y)):
            if a["start"] == a["stop"]:
                raise ConfigError(
                    f"{where}: {section}.{name}.{ax}.stop = {a['stop']!r} is not allowed: a value "
                    f"other than {ax}.start ({a['start']!r}); an axis spans a range"
                )
        if section == "curves" and name in config["maps"]:
            raise ConfigError(f"{where}: curves name {name!r} is not allowed: a name other than the maps' (figures)")


def _fill_error_floors(filled: dict[str, Json], designs: Mapping[str, Mapping[str, Json]]) -> None:
    """Every classifier ``error_floor`` still unset: the measured Poincare error (:func:`poincare_error`)
    at the steps per period of the designs the run selects (the largest error when they differ)."""
    default_steps = schema("dynamics.schema.json")["properties"]["integration"]["properties"]["steps_per_period"][
        "default"
    ]
    for section in PRESET_KEYS:
        for name, spec in filled[section].items():
            if "error_floor" in spec["classifier"]:
                continue
            selector = spec["designs"] if "designs" in spec else [spec["design"]]
            floors = [
                poincare_error(
                    designs[d]["dynamics"]["integration"]["steps_per_period"],
                    f"config: {section}.{name}: design {d}'s dynamics.integration.steps_per_period",
                )
                for d in selected_designs(selector, designs)
                if d in designs
            ]
            spec["classifier"]["error_floor"] = (
                max(floors)
                if floors
                else poincare_error(default_steps, f"config: {section}.{name}: dynamics.integration.steps_per_period")
            )
