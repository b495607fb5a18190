"""Design file and JSON Schema of paper 2 (plus planetary set)."""

from dataclasses import replace
from pathlib import Path

import jsonschema
import pytest

from geardyn import config
from geardyn.config import ConfigError
from geardyn.plus.design import default_design, design_from_dict, load


def schema():
    return config.schema("plus_planetary.schema.json")


ROOT = Path(__file__).resolve().parents[1]
YAML = ROOT / "config" / "designs" / "yue2014.yaml"


def _walk(node, path="$"):
    yield path, node
    for key, sub in node.get("properties", {}).items():
        yield from _walk(sub, f"{path}.{key}")


def test_schema_is_valid_2020_12():
    jsonschema.Draft202012Validator.check_schema(schema())
    assert schema()["$schema"].endswith("2020-12/schema")


def test_every_key_documented_with_default_and_closed_objects():
    for path, node in _walk(schema()):
        if path == "$":
            continue
        assert node.get("description"), path
        assert "default" in node, path
        if node.get("type") == "object":
            assert node.get("additionalProperties") is False, path
        if node.get("type") in ("number", "integer"):
            assert any(k in node for k in ("minimum", "exclusiveMinimum")) and "maximum" in node, path


def test_yaml_validates_and_has_table1_values():
    d = load(YAML)
    assert (d.sun.teeth, d.planet_p.teeth, d.planet_d.teeth, d.ring.teeth) == (32, 19, 20, 77)
    assert d.stiffness.sun_planet == pytest.approx(21e6)  # Table 1: 21 MN/m
    assert d.sun.base_radius == pytest.approx(0.058)
    assert d.torque == pytest.approx(43.0)  # 43000 N mm
    # the YAML and the schema defaults describe the same design
    assert replace(d, title="", paper=None) == default_design()
    assert d.paper == "yue2014"


@pytest.mark.parametrize(
    "patch",
    [
        {"unknown_key": 1},
        {"module_mm": -4},
        {"sun": {"teeth": 32, "inertia_kgm2": 0.1, "colour": "red"}},
        {"kind": "khv"},
        {"outer_planet_side": 0},
        {"stiffness": {"sun_planet": "2.1e7"}},
    ],
)
def test_invalid_designs_rejected(patch):
    raw = {"kind": "plus_planetary", **patch}
    with pytest.raises(ConfigError, match=r"is not allowed|unknown key|kind"):
        design_from_dict(config.validated(raw, "plus_planetary.schema.json", "design"))


def test_reversed_bounds_rejected():
    raw = config.validated(
        {"kind": "plus_planetary", "relief": {"physical_amount_mm": [0.03, 0.0]}},
        "plus_planetary.schema.json",
        "design",
    )
    with pytest.raises(ConfigError, match="lower bound"):
        design_from_dict(raw)


def test_base_radii_imply_25_degrees():
    d = default_design()
    for body in (d.sun, d.planet_p, d.planet_d, d.ring):
        # Table 1 prints base radii to 0.1 mm (p: 34.44 printed 34.5): m z cos(25 deg)/2 within 0.07 mm
        assert body.base_radius == pytest.approx(d.module * body.teeth / 2 * 0.906307787, abs=7e-5)
