"""The workflow's paths and producers: every path comes from the one helper of workflow/rules/common.smk
(results/logs/benchmarks), no rule names a design or one of its studies, and the claims read the runs
their paper declares (papers.li2013.CLAIM_RUNS)."""

import re

import pytest

import _workflow as wf
from geardyn.papers import li2013

RULE_FILES = [wf.ROOT / "workflow/Snakefile", *sorted((wf.ROOT / "workflow/rules").glob("*.smk"))]


def _code(path):
    """A rule file without its comments and docstrings."""
    text = re.sub(r'""".*?"""', "", path.read_text(encoding="utf-8"), flags=re.S)
    return "\n".join(line.split("#", 1)[0] for line in text.splitlines())


def _planned(run, field):
    """The files of every job of a dry run on Snakemake's ``output:`` or ``log:`` lines."""
    files = []
    for line in run.stdout.splitlines():
        m = re.match(rf"\s+{field}: (.*)$", line)
        if m:
            files += [f.strip() for f in m.group(1).split(",")]
    return sorted(files)


def test_no_rule_file_holds_a_literal_results_path():
    hits = [
        f"{path.name}: {line.strip()}"
        for path in RULE_FILES
        for line in _code(path).splitlines()
        if re.search(r"[\"']results/", line)
    ]
    assert hits == []


def test_no_rule_names_a_design_or_one_of_its_studies():
    cfg = wf.shipped("config/config.yaml")
    names = {name for section in ("designs", "sweeps", "points", "maps", "calibration") for name in cfg[section]}
    hits = [(path.name, name) for path in RULE_FILES for name in names if re.search(rf"\b{name}\b", _code(path))]
    assert hits == []


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    return wf.workflow_copy(tmp_path_factory.mktemp("paths"), wf.small_config(), wf.small_designs())


def test_the_results_root_is_one_line_of_common_smk(small, tmp_path):
    targets = ("all", "calibration", "archive")
    before = wf.snakemake(small, "-n", *targets)
    moved = wf.workflow_copy(tmp_path / "w", wf.small_config(), wf.small_designs())
    common = moved / "workflow/rules/common.smk"
    text = common.read_text(encoding="utf-8")
    assert text.count('RESULTS = "results"\n') == 1
    common.write_text(text.replace('RESULTS = "results"\n', 'RESULTS = "elsewhere/out"\n'), encoding="utf-8")
    after = wf.snakemake(moved, "-n", *targets)
    for field in ("output", "log"):
        old, new = _planned(before, field), _planned(after, field)
        assert len(old) >= 10 and all(f.startswith("results/") for f in old)
        assert new == sorted("elsewhere/out/" + f.removeprefix("results/") for f in old)


def test_the_claims_read_the_runs_their_paper_declares(tmp_path):
    work = wf.workflow_copy(tmp_path / "w")
    outputs = _planned(wf.snakemake(work, "-n", "results/li2013/claims.md"), "output")
    runs = {f for f in outputs if re.fullmatch(r"results/li2013/(sweeps|points)/\w+\.nc", f)}
    assert runs == {f"results/li2013/{section}/{name}.nc" for section, name in li2013.CLAIM_RUNS.values()}
    assert len(runs) == 4


@pytest.mark.parametrize(
    ("target", "merge"),
    [
        ("figures/fig07_small.png", "sweep_merge"),
        ("figures/fig07_small.png.txt", "sweep_merge"),
        ("figures/small_prob.png", "probabilities_merge"),
        ("tables/small_prob.md", "probabilities_merge"),
    ],
)
def test_a_figure_drawn_by_a_merge_is_a_target_of_its_own(small, target, merge):
    # a sweep's merge writes its cube, bands and bifurcation diagram in one job, a probabilities study's merge its
    # cube, figure and table; asking for one of them alone plans that job and the chunks it merges, nothing else
    run = wf.snakemake(small, "-n", f"results/li2013/{target}")
    jobs = dict(re.findall(r"^(\w+)\s+(\d+)$", run.stdout[run.stdout.index("Job stats") :], re.M))
    chunk = merge.replace("_merge", "_chunk")
    assert set(jobs) == {"kernels", chunk, merge, "total"} and jobs[merge] == "1" and int(jobs[chunk]) >= 1
    assert f"results/li2013/{target}" in _planned(run, "output")
