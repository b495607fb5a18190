"""Fuzzing the inputs: mutated designs and configs either validate or give one geardyn line, never a
traceback. Mutations: deleted keys, swapped types, NaN, infinities, huge, negative and zero values,
unicode, empty containers, and duplicate keys in the YAML text; 150 designs and 150 configs a run."""

import copy

import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from _examples import EXAMPLE_SCALE
import _workflow as wf
from geardyn.config import ConfigError, load_design_dict
from geardyn.validate import check_design, read_config_file, validate_workflow

VALUES = [float("nan"), float("inf"), -float("inf"), 1e308, -1e308, 1e30, -1.0, 0, 0.0, -7, "", "ünïcødé ✓ 試験",
          [], {}, None, True, "1e6", 10**30, [1, 2], {"x": 1}, "line4", "50%", 2.5]
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
@given(design=st.sampled_from(sorted(DESIGNS)), mutations=st.lists(MUTATION, min_size=1, max_size=3),
       duplicate=st.booleans())
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
