"""One command builds one design: `snakemake <design>` plans that design's studies and nothing else, and a
design named like a rule is refused before anything runs."""

import re

import pytest
import yaml

import _workflow as wf


def _planned_outputs(run):
    """The output files of every job of a dry run (Snakemake's 'output:' lines)."""
    outputs = []
    for line in run.stdout.splitlines():
        m = re.match(r"\s+output: (.*)$", line)
        if m:
            outputs += [f.strip() for f in m.group(1).split(",")]
    return outputs


@pytest.fixture(scope="module")
def shipped(tmp_path_factory):
    return wf.workflow_copy(tmp_path_factory.mktemp("design_targets"))


@pytest.fixture(scope="module")
def full_plan(shipped):
    return _planned_outputs(wf.snakemake(shipped, "-n"))


@pytest.mark.parametrize("design", ["yue2014", "li2013"])
def test_one_design_plans_only_its_own_outputs(shipped, full_plan, design):
    run = wf.snakemake(shipped, "-n", design)
    outputs = _planned_outputs(run)
    assert len(outputs) >= 20, run.stdout[-2000:]
    strays = [f for f in outputs if not f.startswith(f"results/{design}/")]
    assert strays == []
    # and it plans every study of rule all under that design: the same files as the full plan
    full = [f for f in full_plan if f.startswith(f"results/{design}/")]
    assert sorted(outputs) == sorted(full)


def test_a_design_named_like_a_rule_is_refused(tmp_path):
    cfg = wf.shipped("config/config.yaml")
    cfg["designs"] = {"archive": "config/designs/archive.yaml"}
    for section in ("sweeps", "points", "maps", "orbits", "calibration"):
        cfg[section] = {}
    cfg["claims"] = {"designs": []}
    raw = wf.shipped("config/designs/yue2014.yaml")
    raw["name"] = "archive"
    work = wf.workflow_copy(tmp_path / "w", config=cfg, designs={"archive": raw})
    run = wf.snakemake(work, "-n", check=False)
    assert run.returncode == 1
    errors = [line for line in run.stderr.splitlines() if "geardyn config error" in line]
    assert len(errors) == 1 and "'archive' is the name of a rule" in errors[0], run.stderr[-2000:]
    assert not (work / "results").exists()
