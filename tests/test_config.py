"""Config and design validation: one clear line per problem, defaults filled, nothing run on error."""

import itertools
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from geardyn import config
from geardyn.config import validate
from geardyn.khv import design
from geardyn.label.indicators import ClassifierSettings
from geardyn.runs.continuation import OrbitSpec

ROOT = Path(__file__).resolve().parents[1]
LI2013 = ROOT / "config" / "designs" / "li2013.yaml"


def _li2013():
    return yaml.safe_load(LI2013.read_text())


def _write(tmp_path, data, name="d.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def test_shipped_config_and_designs_validate():
    cfg = validate.fill_config(validate.read_config_file(ROOT / "config" / "config.yaml"))
    _, designs = validate.validate_workflow(cfg, ROOT)
    assert "li2013" in designs
    spec = design.load(LI2013)
    assert spec.stiffness.q_variant == "iso" and spec.stiffness.form == "corrected"
    assert spec.base.x2 == pytest.approx(0.80, abs=0.02)  # x2 on line 4 at x1 = 0.626, between M and N


def test_defaults_are_filled(tmp_path):
    data = {
        "kind": "khv",
        "name": "minimal",
        "pair": {"z1": 30, "z2": 33, "module": 3.5, "addendum": 0.8},
        "admissible": {"x1_min": 0.5, "x1_max": 0.7},
    }
    raw = config.load_design_dict(_write(tmp_path, data))
    assert raw["pair"]["pressure_angle_deg"] == 20.0 and raw["paper"] is None
    assert raw["admissible"]["min_tip_thickness"] == 0.25 and raw["stiffness"]["form"] == "corrected"
    # the admissible segment has no default (it would be some paper's): a design must state it
    del data["admissible"]
    with pytest.raises(config.ConfigError, match="missing required key 'admissible'"):
        config.load_design_dict(_write(tmp_path, data))


#: Optional keys whose default is computed by the validator, not stated in the schema: a classifier's
#: error_floor follows the run's steps_per_period (geardyn.config.validate.POINCARE_ERROR).
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


@pytest.mark.parametrize(
    ("mutate", "message"),
    [
        (lambda d: d.update(stifness={}), "unknown key 'stifness' (did you mean 'stiffness'?)"),
        (lambda d: d["stiffness"].update(form="swapped"), "stiffness.form = 'swapped' is not allowed: one of"),
        (lambda d: d.pop("pair"), "missing required key 'pair'"),
        (lambda d: d.update(kind="kvh"), "kind = 'kvh' is not allowed: one of 'khv'"),
        (lambda d: d["admissible"].update(x1_min=0.9), "admissible.x1_min = 0.9 must be below admissible.x1_max"),
    ],
)
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
    for item in ("workflow", "config"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / item)
    return tmp_path


def test_snakemake_refuses_bad_design_before_any_job(tmp_path):
    work = _workflow_copy(tmp_path)
    data = _li2013()
    data["pair"]["module"] = -1
    (work / "config" / "designs" / "li2013.yaml").write_text(yaml.safe_dump(data))
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    run = subprocess.run(
        [sys.executable, "-m", "snakemake", "--cores", "1"],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode != 0
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, run.stderr
    assert lines[0].startswith("geardyn config error:") and "pair.module = -1 is not allowed" in lines[0]
    assert "Traceback" not in run.stderr + run.stdout
    assert not (work / "results").exists()


# --- presets, the error floor table, names, degenerate maps, alias bombs -----------------------------

BEFORE = ROOT / "tests" / "data" / "config_filled_before_presets.json"
NEW_RUN_KEYS = {"start_from": "follow", "coexistence": False}
#: classifier keys added with the labeller's torus test and long periods (their defaults)
NEW_CLASSIFIER_KEYS = {
    "torus_margin": 2.5,
    "chaos_margin": 1.5,
    "torus_min_n": 50,
    "torus_extend": 1,
    "torus_max_periods": 4000,
    "order_min_n": 800,
    "long_max_n": 240,
}


#: studies whose undecided points run on longer than the classifier's default (the sweeps' preset and
#: map_x1_e's own setting; docs/performance.md)
LONGER_RECORDS = {
    **{
        ("sweeps", name): 16000
        for name in (
            "fig07_bifurcation_x1",
            "fig09_bifurcation_b",
            "fig11_bifurcation_e",
            "bifurcation_x1",
            "bifurcation_b",
            "bifurcation_e",
        )
    },
    ("maps", "map_x1_e"): 16000,
}


def _with_new_keys(old: dict, section: str, name: str = "") -> dict:
    classifier = {**old["classifier"], **NEW_CLASSIFIER_KEYS}
    if (section, name) in LONGER_RECORDS:
        classifier["torus_max_periods"] = LONGER_RECORDS[section, name]
    return {**old, **NEW_RUN_KEYS, "classifier": classifier}


def _config(**sections):
    """A config of design li2013 (the shipped file) with the given sections."""
    return {"designs": {"li2013": "config/designs/li2013.yaml"}, **sections}


def _sweep(**extra):
    return {"designs": ["li2013"], "parameter": "b", "start": 0.0, "stop": 2.0, "num": 5, "fixed": {"e": 5.0}, **extra}


def _map(**extra):
    return {
        "designs": ["li2013"],
        "x": {"parameter": "x1", "start": 0.45, "stop": 0.8, "num": 4},
        "y": {"parameter": "b", "start": 0.0, "stop": 2.0, "num": 4},
        **extra,
    }


def _refused(cfg):
    with pytest.raises(config.ConfigError) as info:
        validate.validate_workflow(cfg, ROOT)
    text = str(info.value)
    assert "\n" not in text and "Traceback" not in text
    return text


def test_shipped_config_with_presets_resolves_to_the_values_it_had_before():

    before = json.loads(BEFORE.read_text())
    raw = validate.read_config_file(ROOT / "config" / "config.yaml")
    assert all("preset" in spec for spec in raw["maps"].values())  # the maps do use presets
    filled, _ = validate.validate_workflow(raw, ROOT)
    for section in ("sweeps", "maps"):
        assert set(filled[section]) == set(before[section])
        for name, old in before[section].items():
            new = {k: v for k, v in filled[section][name].items() if k != "curves"}  # the maps' curves: a new key
            assert new == _with_new_keys(old, section, name), (section, name)
    assert filled["points"] == before["points"]
    for name, old in before["calibration"].items():
        new = filled["calibration"][name]
        old = {k: v for k, v in old.items() if k not in ("grid", "chunks")}  # the grid calibration is gone
        assert "preset" not in new and set(new) == set(old)
        assert {k: v for k, v in new.items() if k != "classifier"} == {
            k: v for k, v in old.items() if k != "classifier"
        }
        assert old["classifier"].items() <= new["classifier"].items()  # now complete; the set values unchanged


def test_preset_blocks_are_overridden_key_by_key():
    presets = {
        "cheap": {
            "integration": {"steps_per_period": 128, "transient_periods": 400},
            "classifier": {"tangent_periods": 200, "k_chaos": 0.4},
            "start_from": "fixed",
        }
    }
    cfg = _config(
        presets=presets,
        sweeps={
            "s": _sweep(
                preset="cheap", integration={"transient_periods": 100}, classifier={"k_chaos": 0.6}, coexistence=True
            )
        },
        maps={"m": _map(preset="cheap", start_from="follow")},
        calibration={
            "c": {
                "design": "li2013",
                "search": {"bounds": {"w": {"low": 0.5, "high": 1.5}}, "budget": {"popsize": 1, "maxiter": 1}},
                "preset": "cheap",
            }
        },
    )
    filled, _ = validate.validate_workflow(cfg, ROOT)
    s, m, c = filled["sweeps"]["s"], filled["maps"]["m"], filled["calibration"]["c"]
    assert s["integration"] == {"steps_per_period": 128, "transient_periods": 100}
    assert (s["classifier"]["k_chaos"], s["classifier"]["tangent_periods"]) == (0.6, 200)
    assert (s["start_from"], s["coexistence"]) == ("fixed", True)
    assert (m["start_from"], m["coexistence"], m["classifier"]["k_chaos"]) == ("follow", False, 0.4)
    assert c["integration"] == presets["cheap"]["integration"] and "start_from" not in c
    assert all("preset" not in spec for spec in (s, m, c))
    assert s["classifier"]["error_floor"] == m["classifier"]["error_floor"] == 1.9e-5  # 128 steps


def test_unknown_preset_is_one_line():
    cfg = _config(presets={"map": {"integration": {"steps_per_period": 128}}}, maps={"m": _map(preset="mpa")})
    assert "config: maps.m.preset = 'mpa' is not allowed: one of 'map'" in _refused(cfg)
    cfg = _config(sweeps={"s": _sweep(preset="cheap")})
    assert (
        "sweeps.s.preset = 'cheap' is not allowed: the name of an entry of presets, and the config has none"
        in _refused(cfg)
    )
    cfg = _config(presets={"p": {"integration": {"steps": 128}}})
    assert "config: unknown key 'presets.p.integration.steps' (allowed keys: early_stop," in _refused(cfg)


def test_error_floor_follows_steps_per_period():
    assert validate.POINCARE_ERROR[128] == 1.9e-5 and validate.POINCARE_ERROR[512] == 7.5e-8
    runs = {f"s{n}": _sweep(integration={"steps_per_period": n}) for n in (64, 128, 181, 512, 1024)}
    runs["design_steps"] = _sweep()  # li2013.yaml: 512 steps per period
    runs["own_floor"] = _sweep(integration={"steps_per_period": 16}, classifier={"error_floor": 1e-3})
    filled, _ = validate.validate_workflow(_config(sweeps=runs), ROOT)
    floor = {name: spec["classifier"]["error_floor"] for name, spec in filled["sweeps"].items()}
    assert (floor["s64"], floor["s128"], floor["s512"], floor["s1024"]) == (3.0e-4, 1.9e-5, 7.5e-8, 4.7e-9)
    assert floor["design_steps"] == 7.5e-8 and floor["own_floor"] == 1e-3
    # log-log interpolation: 181 steps is about half way (in log) between 128 and 256
    assert floor["s181"] == pytest.approx((1.9e-5 * 1.2e-6) ** 0.5, rel=0.01)
    errors = [validate.poincare_error(n, "x") for n in range(32, 1025)]
    assert all(a > b for a, b in itertools.pairwise(errors))
    text = _refused(_config(sweeps={"s": _sweep(integration={"steps_per_period": 16})}))
    assert "sweeps.s.integration.steps_per_period = 16 is not allowed without classifier.error_floor" in text


@pytest.mark.parametrize(
    ("designs", "message"),
    [
        (
            {"all": "config/designs/li2013.yaml"},
            "designs name 'all' is not allowed: a name other than the selector words",
        ),
        ({"own": "config/designs/li2013.yaml"}, "designs name 'own' is not allowed"),
        ({"paper:li2013": "config/designs/li2013.yaml"}, "designs name 'paper:li2013' is not allowed"),
        ({"d" * 300: "config/designs/li2013.yaml"}, "(300 characters) is not allowed: at most 64 characters"),
        ({"a/b": "config/designs/li2013.yaml"}, "designs name 'a/b' is not allowed: letters, digits, _ and -"),
        ({"{x}": "config/designs/li2013.yaml"}, "designs name '{x}' is not allowed"),
    ],
)
def test_unusable_design_names_are_one_line(designs, message):
    assert message in _refused({"designs": designs})


def test_unusable_run_and_preset_names_are_one_line():
    assert "sweeps name 'fig 7' is not allowed" in _refused(_config(sweeps={"fig 7": _sweep()}))
    assert "presets name " in _refused(_config(presets={"p" * 65: {}}))
    assert "maps name '-m' is not allowed" in _refused(_config(maps={"-m": _map()}))
    filled, _ = validate.validate_workflow(_config(sweeps={"s" * 64: _sweep()}), ROOT)  # the limit itself is fine
    assert "s" * 64 in filled["sweeps"]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            lambda m: m["y"].update(parameter="x1", start=0.5, stop=0.7),
            "maps.m.y.parameter = 'x1' is not allowed: a parameter other than x.parameter ('x1')",
        ),
        (lambda m: m["x"].update(num=1), "maps.m.x.num = 1 is not allowed: integer >= 2"),
        (
            lambda m: m["y"].update(start=1.0, stop=1.0),
            "maps.m.y.stop = 1.0 is not allowed: a value other than y.start",
        ),
        (lambda m: m["x"].update(start="50%", stop="50%"), "maps.m.x.stop = '50%' is not allowed"),
    ],
)
def test_degenerate_maps_are_one_line_whatever_they_select(change, message):
    for selector in (["li2013"], "own"):  # 'own' selects no design here: still refused
        spec = _map(designs=selector)
        change(spec)
        assert message in _refused(_config(maps={"m": spec}))


def _bomb(depth=9, width=9, key="designs"):
    """A "billion laughs" YAML text: ``width ** depth`` values from ``depth + 1`` lines."""
    lines = ["a0: &a0 [lol]"] + [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * width)}]" for i in range(1, depth + 1)]
    return "\n".join(lines) + f"\n{key}: *a{depth}\n"


def test_alias_bomb_is_refused_before_anything_walks_it(tmp_path):
    path = tmp_path / "config.yaml"
    path.write_text(_bomb())
    with pytest.raises(config.ConfigError) as info:
        validate.read_config_file(path)
    text = str(info.value)
    # the size is computed on the alias graph (linear in the file), not by walking 9 ** 9 values
    assert text.startswith(f"{path}: expanded size of designs = ") and "\n" not in text
    assert int(text.split("= ")[1].split()[0]) > 9**9
    assert f"at most {config.MAX_EXPANDED_VALUES} values" in text
    design = tmp_path / "design.yaml"
    design.write_text("kind: khv\n" + _bomb(key="pair"))
    with pytest.raises(config.ConfigError, match=r"design\.yaml: expanded size of pair = "):
        config.load_design_dict(design)
    loop = tmp_path / "loop.yaml"
    loop.write_text("designs: &a {x: *a}\n")
    with pytest.raises(config.ConfigError, match="a structure may not contain itself"):
        validate.read_config_file(loop)
    # the same check guards data handed over in memory (the Snakefile's merged config)
    shared = [1] * 100
    for _ in range(5):
        shared = [shared] * 100
    with pytest.raises(config.ConfigError, match=r"config: expanded size of sweeps = \d+ values"):
        validate.validate_workflow({"designs": {}, "sweeps": {"s": {"cases": shared}}}, ROOT)


def test_a_config_of_normal_size_is_far_below_the_limit():
    raw = validate.read_config_file(ROOT / "config" / "config.yaml")
    assert 100 < config.expanded_size(raw) < config.MAX_EXPANDED_VALUES / 10


def test_check_config_refuses_an_alias_bomb_in_one_line(tmp_path):
    path = tmp_path / "config" / "config.yaml"
    path.parent.mkdir()
    path.write_text(_bomb())
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    run = subprocess.run(
        [sys.executable, "-m", "geardyn.cli", "check-config", str(path)],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode != 0 and run.stdout == ""
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "expanded size of designs = " in lines[0] and "Traceback" not in run.stderr, run.stderr


def test_error_table_is_the_one_of_the_work_precision_study():
    """POINCARE_ERROR is stated once in src/; docs/model.md Sec. 6 shows where it comes from."""
    rows = {
        line.split("|")[1].strip(): line
        for line in (ROOT / "docs" / "model.md").read_text().splitlines()
        if line.startswith("| ")
    }
    steps = [int(v) for v in rows["steps/period"].split("|")[2:-1]]
    errors = [float(v) for v in rows["rk4_event error"].split("|")[2:-1]]
    assert dict(zip(steps, errors, strict=True)) == validate.POINCARE_ERROR


def test_run_integration_block_is_defined_once_and_is_the_design_block_without_defaults():
    """Sweeps, maps, calibrations, frequency responses, curves and probabilities studies and presets share one
    $defs/integration, whose keys refer to the design's dynamics.integration (one statement of each key), without the
    defaults: a key a run does not set keeps the design's value."""

    raw = json.loads((ROOT / "src" / "geardyn" / "config" / "schemas" / "config.schema.json").read_text())
    assert json.dumps(raw).count('"#/$defs/integration"') == 7
    assert all(set(node) == {"$ref"} for node in raw["$defs"]["integration"]["properties"].values())
    design = config.schema("dynamics.schema.json")["properties"]["integration"]["properties"]
    run = config.schema("config.schema.json")["$defs"]["integration"]["properties"]
    for key, node in run.items():
        assert node == {k: v for k, v in design[key].items() if k != "default"}, key
    filled, _ = validate.validate_workflow(_config(sweeps={"s": _sweep(integration={"steps_per_period": 128})}), ROOT)
    assert filled["sweeps"]["s"]["integration"] == {"steps_per_period": 128}
    text = _refused(_config(sweeps={"s": _sweep(integration={"steps_per_period": 70000})}))
    assert "sweeps.s.integration.steps_per_period = 70000 is not allowed: integer >= 8 and <= 65536 (RK4 steps" in text


def test_an_integer_written_as_a_float_reaches_an_int_setting():
    """The schema's "integer" admits 6.0; every settings class built by settings_from gets the int 6."""
    assert type(OrbitSpec.from_config({"max_period": 6.0, "nodes": 101.0}).max_period) is int
    assert OrbitSpec.from_config({"max_period": 6.0}) == OrbitSpec.from_config({"max_period": 6})
    with pytest.raises(ValueError, match="unknown classifier settings"):
        config.settings_from(ClassifierSettings, {"nonsense": 1.0}, "classifier settings")
