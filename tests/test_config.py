"""Config and design validation: one clear line per problem, defaults filled, nothing run on error."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from geardyn import config
from geardyn.khv import design
from geardyn import validate

ROOT = Path(__file__).resolve().parents[1]
LI2013 = ROOT / "config" / "designs" / "li2013.yaml"


def _li2013():
    return yaml.safe_load(LI2013.read_text())


def _write(tmp_path, data, name="d.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def test_shipped_config_and_designs_validate():
    cfg = config.load_config(ROOT / "config" / "config.yaml")
    filled, designs = validate.validate_workflow(cfg, ROOT)
    assert "li2013" in designs
    spec = design.load(LI2013)
    assert spec.stiffness.q_variant == "iso" and spec.stiffness.form == "corrected"
    assert spec.base.x2 == pytest.approx(0.80, abs=0.02)  # x2 on line 4 at x1 = 0.626, between M and N


def test_defaults_are_filled(tmp_path):
    data = {"kind": "khv", "name": "minimal", "pair": {"z1": 30, "z2": 33, "module": 3.5, "addendum": 0.8},
            "admissible": {"x1_min": 0.5, "x1_max": 0.7}}
    raw = config.load_design_dict(_write(tmp_path, data))
    assert raw["pair"]["pressure_angle_deg"] == 20.0 and raw["paper"] is None
    assert raw["admissible"]["min_tip_thickness"] == 0.25 and raw["stiffness"]["form"] == "corrected"
    # the admissible segment has no default (it would be some paper's): a design must state it
    del data["admissible"]
    with pytest.raises(config.ConfigError, match="missing required key 'admissible'"):
        config.load_design_dict(_write(tmp_path, data))


#: Optional keys whose default is computed by the validator, not stated in the schema: a classifier's
#: error_floor follows the run's steps_per_period (geardyn.validate.POINCARE_ERROR).
COMPUTED_DEFAULTS = {"error_floor"}


def test_every_schema_key_has_description_and_defaults_where_optional():
    def walk(node, path):
        if isinstance(node, dict):
            for name, sub in node.get("properties", {}).items():
                assert "description" in sub, f"{path}.{name} lacks a description"
                if name not in node.get("required", []) and "$ref" not in sub and name not in COMPUTED_DEFAULTS:
                    assert "default" in sub, f"{path}.{name} is optional but has no default"
                walk(sub, f"{path}.{name}")

    for name in ("khv.schema.json", "config.schema.json", "plus_planetary.schema.json", "dynamics.schema.json"):
        walk(config.schema(name), name)


BAD_PAIRS = [
    ({"z1": 30.5}, "pair.z1 = 30.5 is not allowed: integer"),
    ({"z1": 3}, "pair.z1 = 3 is not allowed: integer >= 8"),
    ({"z2": 30}, "pair.z2 - pair.z1 = 0 is not allowed"),
    ({"z2": 29}, "pair.z2 - pair.z1 = -1 is not allowed"),
    ({"module": 0}, "pair.module = 0 is not allowed: number > 0"),
    ({"module": -3.5}, "pair.module = -3.5 is not allowed: number > 0"),
    ({"pressure_angle_deg": 0}, "pair.pressure_angle_deg = 0 is not allowed: number > 0 and < 45"),
    ({"pressure_angle_deg": 45}, "pair.pressure_angle_deg = 45 is not allowed: number > 0 and < 45"),
    ({"z_1": 30}, "unknown key 'pair.z_1' (did you mean 'z1'?)"),
    ({"x2": "line 4"}, "pair.x2 = 'line 4' is not allowed: number >= -1.0 and <= 3.0 or 'line4'"),
    ({"x1": 0.2, "x2": 0.2}, "design point (x1, x2) = (0.2000, 0.2000) is outside the feasible region: overlap"),
]


@pytest.mark.parametrize(("change", "message"), BAD_PAIRS)
def test_bad_design_values_give_one_clear_line(tmp_path, change, message):
    data = _li2013()
    data["pair"].update(change)
    with pytest.raises(config.ConfigError) as info:
        design.load(_write(tmp_path, data))
    text = str(info.value)
    assert "\n" not in text
    assert message in text
    assert text.startswith(str(tmp_path / "d.yaml"))


@pytest.mark.parametrize(("mutate", "message"), [
    (lambda d: d.update(stifness={}), "unknown key 'stifness' (did you mean 'stiffness'?)"),
    (lambda d: d["stiffness"].update(form="swapped"), "stiffness.form = 'swapped' is not allowed: one of"),
    (lambda d: d.pop("pair"), "missing required key 'pair'"),
    (lambda d: d.update(kind="kvh"), "kind = 'kvh' is not allowed: one of 'khv'"),
    (lambda d: d["admissible"].update(x1_min=0.9), "admissible.x1_min = 0.9 must be below admissible.x1_max"),
])
def test_bad_design_structure(tmp_path, mutate, message):
    data = _li2013()
    mutate(data)
    with pytest.raises(config.ConfigError, match=None) as info:
        design.load(_write(tmp_path, data))
    assert message in str(info.value) and "\n" not in str(info.value)


def test_yaml_syntax_and_encoding_errors(tmp_path):
    bad = tmp_path / "syntax.yaml"
    bad.write_text("kind: khv\npair: {z1: 30\n")
    with pytest.raises(config.ConfigError, match=r"YAML syntax error at line \d+, column \d+"):
        config.load_design_dict(bad)
    latin = tmp_path / "latin1.yaml"
    latin.write_bytes("kind: khv\nname: caf\xe9\n".encode("latin-1"))
    with pytest.raises(config.ConfigError, match="not UTF-8"):
        config.load_design_dict(latin)
    with pytest.raises(config.ConfigError, match="file not found"):
        config.load_design_dict(tmp_path / "missing.yaml")


def _workflow_copy(tmp_path):
    for item in ("Snakefile", "workflow", "config"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / item)
    return tmp_path


def test_snakemake_refuses_bad_design_before_any_job(tmp_path):
    work = _workflow_copy(tmp_path)
    data = _li2013()
    data["pair"]["module"] = -1
    (work / "config" / "designs" / "li2013.yaml").write_text(yaml.safe_dump(data))
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    run = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "1"], cwd=work, env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode != 0
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, run.stderr
    assert lines[0].startswith("geardyn config error:") and "pair.module = -1 is not allowed" in lines[0]
    assert "Traceback" not in run.stderr + run.stdout
    assert not (work / "results").exists()
