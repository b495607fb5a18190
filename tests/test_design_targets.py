"""One command builds one design: `snakemake <design>` plans that design's studies and nothing else, and a
design named like a rule is refused before anything runs."""

import re

import pytest

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


@pytest.mark.parametrize("design", list(wf.shipped("config/config.yaml")["designs"]))
def test_one_design_plans_only_its_own_outputs(shipped, full_plan, design):
    run = wf.snakemake(shipped, "-n", design)
    outputs = _planned_outputs(run)
    # every KHV design has at least its closed graph and stiffness table with their figures (7 files)
    assert len(outputs) >= 7, run.stdout[-2000:]
    strays = [f for f in outputs if not f.startswith(f"results/{design}/")]
    assert strays == []
    # and it plans every study of rule all under that design: the same files as the full plan
    full = [f for f in full_plan if f.startswith(f"results/{design}/")]
    assert sorted(outputs) == sorted(full)


def test_a_design_named_like_a_rule_is_refused(tmp_path):
    cfg = wf.shipped("config/config.yaml")
    cfg["designs"] = {"archive": "config/designs/archive.yaml"}
    for section in ("sweeps", "points", "maps", "orbits", "calibration", "probabilities"):
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


def test_a_design_of_your_own_plans_names_without_paper_numbers(tmp_path):
    # the same plus set under a name of its own and with no paper: descriptive names only, its own outputs only
    cfg = wf.shipped("config/config.yaml")
    cfg["designs"] = {"yue2014": "config/designs/yue2014.yaml", "myplus": "config/designs/myplus.yaml"}
    for section in ("sweeps", "points", "maps", "orbits", "calibration", "probabilities"):
        cfg[section] = {}
    cfg["claims"] = {"designs": []}
    raw = wf.shipped("config/designs/yue2014.yaml")
    raw.update(name="myplus", paper=None)
    work = wf.workflow_copy(tmp_path / "w", config=cfg, designs={"myplus": raw})
    outputs = _planned_outputs(wf.snakemake(work, "-n", "myplus"))
    names = [f.rsplit("/", 1)[1] for f in outputs]
    assert all(f.startswith("results/myplus/") for f in outputs) and len(outputs) >= 25
    assert [n for n in names if re.match(r"(fig|table|sec)\d", n)] == []
    assert {"natural_frequencies.csv", "te_relief.png", "relief_optima.md", "forced_response.png"} <= set(names)
    paper = [f.rsplit("/", 1)[1] for f in _planned_outputs(wf.snakemake(work, "-n", "yue2014"))]
    assert {"table02_natural_frequencies.csv", "fig09_te_relief.png", "sec4_relief_optima.md"} <= set(paper)
