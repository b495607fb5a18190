"""Fuzzing the inputs: mutated designs and configs either validate or give one geardyn line, never a
traceback. Mutations: deleted keys, swapped types, NaN, infinities, huge, negative and zero values,
unicode, empty containers, and duplicate keys in the YAML text; 150 designs and 150 configs a run."""

import contextlib
import copy
import io

import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import _workflow as wf
from _examples import EXAMPLE_SCALE
from geardyn import cli
from geardyn.config import ConfigError, load_design_dict
from geardyn.config.validate import check_design, read_config_file, validate_workflow

VALUES = [
    float("nan"),
    float("inf"),
    -float("inf"),
    1e308,
    -1e308,
    1e30,
    -1.0,
    0,
    0.0,
    -7,
    "",
    "ünïcødé ✓ 試験",
    [],
    {},
    None,
    True,
    "1e6",
    10**30,
    [1, 2],
    {"x": 1},
    "line4",
    "50%",
    2.5,
]
DESIGNS = {"li2013": wf.shipped("config/designs/li2013.yaml"), "yue2014": wf.shipped("config/designs/yue2014.yaml")}
CONFIG = wf.sweep_config(num=3, chunks=1)


def _paths(node, prefix=()):
    if isinstance(node, dict):
        for k, v in node.items():
            yield (*prefix, k)
            yield from _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield (*prefix, i)
            yield from _paths(v, (*prefix, i))


def _mutate(data, draw_path, draw_op, draw_value):
    out = copy.deepcopy(data)
    paths = list(_paths(out))
    path = paths[draw_path % len(paths)]
    parent = out
    for key in path[:-1]:
        parent = parent[key]
    if draw_op == 0 and isinstance(parent, dict):
        del parent[path[-1]]
    else:
        parent[path[-1]] = VALUES[draw_value % len(VALUES)]
    return out


MUTATION = st.tuples(st.integers(0, 10**6), st.integers(0, 2), st.integers(0, 10**6))


def _one_line_or_ok(call):
    try:
        call()
    except ConfigError as err:
        text = str(err)
        assert text and "\n" not in text and "Traceback" not in text, text


@settings(max_examples=150 * EXAMPLE_SCALE, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    design=st.sampled_from(sorted(DESIGNS)),
    mutations=st.lists(MUTATION, min_size=1, max_size=3),
    duplicate=st.booleans(),
)
@example(design="li2013", mutations=[(838, 1, 1000000)], duplicate=False)  # x1 = -1: G_s > 0 where it is defined
def test_mutated_design_validates_or_gives_one_line(tmp_path_factory, design, mutations, duplicate):
    raw = DESIGNS[design]
    for m in mutations:
        raw = _mutate(raw, *m)
    text = yaml.safe_dump(raw, allow_unicode=True, sort_keys=False)
    if duplicate:
        lines = text.splitlines()
        top = [line for line in lines if line and not line.startswith((" ", "-"))]
        text += top[len(mutations) % len(top)] + "\n" if top else ""
    path = tmp_path_factory.mktemp("fuzz") / f"{design}.yaml"
    path.write_text(text, encoding="utf-8")
    _one_line_or_ok(lambda: check_design(load_design_dict(path), str(path)))


@settings(max_examples=150 * EXAMPLE_SCALE, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(mutations=st.lists(MUTATION, min_size=1, max_size=3))
def test_mutated_config_validates_or_gives_one_line(tmp_path_factory, mutations):
    cfg = CONFIG
    for m in mutations:
        cfg = _mutate(cfg, *m)
    work = tmp_path_factory.mktemp("fuzzcfg")
    (work / "config/designs").mkdir(parents=True)
    (work / "config/designs/li2013.yaml").write_text(yaml.safe_dump(DESIGNS["li2013"]))
    (work / "config/config.yaml").write_text(yaml.safe_dump(cfg, allow_unicode=True), encoding="utf-8")
    _one_line_or_ok(lambda: validate_workflow(read_config_file(work / "config/config.yaml"), work))


# --- classes of inputs that used to slip through or hang: alias bombs, selector-word and over-long
# names, degenerate maps, unknown presets. Each gives exactly one line naming the key, in-process and
# from `geardyn check-config` (exit code non-zero, nothing on stdout, no traceback).


def _bomb_text(depth, width, where):
    """YAML text whose alias ``*a<depth>`` stands for ``width ** depth`` values, placed at ``where``."""
    lines = ["a0: &a0 [lol]"] + [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * width)}]" for i in range(1, depth + 1)]
    tail = {
        "designs": f"designs: *a{depth}",
        "sweeps": f"sweeps: {{s: {{parameter: b, start: 0, stop: 1, num: 2, cases: *a{depth}}}}}",
        "presets": f"presets: {{p: *a{depth}}}",
    }[where]
    return "\n".join(lines) + "\n" + tail + "\n"


BOMB = st.tuples(st.integers(6, 14), st.integers(7, 12), st.sampled_from(["designs", "sweeps", "presets"])).filter(
    lambda t: t[1] ** t[0] > 10 * 100_000
)
SELECTOR_NAME = st.one_of(st.sampled_from(["all", "own"]), st.from_regex(r"\Apaper:[a-z0-9_]{0,12}\Z"))
LONG_NAME = st.integers(65, 400).map(lambda n: ("x" * n)[:n])
BAD_CHAR_NAME = st.tuples(st.sampled_from(list("/ {}*?:\\\"'$")), st.integers(0, 3)).map(
    lambda t: "ab"[: t[1]] + t[0] + "cd"
)
MAP_BREAK = st.sampled_from(["same-parameter", "num-1", "num-0", "start-is-stop", "percent-start-is-stop"])
PRESET_NAME = st.from_regex(r"\A[a-z][a-z0-9_]{0,20}\Z").filter(lambda n: n not in ("map", "sweep"))


def _case(kind, draw_value):
    """(config mapping or YAML text, the text the one line must contain) for one generated input."""
    cfg = copy.deepcopy(CONFIG)
    cfg["presets"] = {"map": {"integration": {"steps_per_period": 128}}, "sweep": {"start_from": "fixed"}}
    mp = {
        "designs": ["li2013"],
        "x": {"parameter": "x1", "start": 0.45, "stop": 0.8, "num": 3},
        "y": {"parameter": "b", "start": 0.0, "stop": 2.0, "num": 3},
        "preset": "map",
    }
    if kind == "bomb":
        depth, width, where = draw_value
        return _bomb_text(depth, width, where), f"expanded size of {where} = "
    if kind == "selector":
        cfg["designs"] = {draw_value: "config/designs/li2013.yaml"}
        return cfg, f"designs name {draw_value!r} is not allowed"
    if kind in ("long", "bad-char"):
        section, name = draw_value
        target = {
            "designs": "config/designs/li2013.yaml",
            "sweeps": cfg["sweeps"]["fig07_small"],
            "maps": mp,
            "presets": {},
        }[section]
        cfg.setdefault(section, {})
        cfg[section] = {name: target}
        return cfg, f"{section} name "
    if kind == "map":
        if draw_value == "same-parameter":
            mp["y"].update(parameter="x1", start=0.5, stop=0.7)
            key = "maps.m.y.parameter = 'x1'"
        elif draw_value.startswith("num"):
            mp["x"]["num"] = int(draw_value[-1])
            key = f"maps.m.x.num = {draw_value[-1]}"
        elif draw_value == "start-is-stop":
            mp["y"].update(start=1.5, stop=1.5)
            key = "maps.m.y.stop = 1.5"
        else:
            mp["x"].update(start="40%", stop="40%")
            key = "maps.m.x.stop = '40%'"
        cfg["maps"] = {"m": mp}
        return cfg, key
    section, name = draw_value  # an unknown preset
    entry = {"sweeps": cfg["sweeps"]["fig07_small"], "maps": mp}[section]
    entry["preset"] = name
    cfg[section] = {"s": entry} if section == "sweeps" else {"m": mp}
    return (
        cfg,
        f"{section}.{'s' if section == 'sweeps' else 'm'}.preset = {name!r} is not allowed: one of 'map', 'sweep'",
    )


BAD_CLASS = st.one_of(
    st.tuples(st.just("bomb"), BOMB),
    st.tuples(st.just("selector"), SELECTOR_NAME),
    st.tuples(st.just("long"), st.tuples(st.sampled_from(["designs", "sweeps", "maps", "presets"]), LONG_NAME)),
    st.tuples(st.just("bad-char"), st.tuples(st.sampled_from(["designs", "sweeps", "maps", "presets"]), BAD_CHAR_NAME)),
    st.tuples(st.just("map"), MAP_BREAK),
    st.tuples(st.just("preset"), st.tuples(st.sampled_from(["sweeps", "maps"]), PRESET_NAME)),
)


@settings(max_examples=60 * EXAMPLE_SCALE, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=BAD_CLASS)
@example(case=("bomb", (9, 9, "designs")))  # nine lines, nine aliases each: 9 ** 9 values
@example(case=("long", ("designs", "d" * 300)))  # a Snakemake PeriodicWildcardError before the limit
def test_generated_bad_inputs_give_one_line_naming_the_key(tmp_path_factory, case):

    data, key = _case(*case)
    work = tmp_path_factory.mktemp("badcls")
    (work / "config/designs").mkdir(parents=True)
    (work / "config/designs/li2013.yaml").write_text(yaml.safe_dump(DESIGNS["li2013"]))
    path = work / "config/config.yaml"
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data, allow_unicode=True), encoding="utf-8")
    try:
        validate_workflow(read_config_file(path), work)
    except ConfigError as err:
        text = str(err)
    else:
        raise AssertionError(f"accepted: {case}")
    assert "\n" not in text and key in text, (text, key)
    out, err_out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err_out):
        code = cli.main(["check-config", str(path)])
    lines = err_out.getvalue().strip().splitlines()
    assert code != 0 and out.getvalue() == "" and len(lines) == 1 and key in lines[0], (code, err_out.getvalue())
