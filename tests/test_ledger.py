"""The cost ledger (benchmarks/ledger.py): its committed reference names every workload once, and its table
marks a workload more than 10 % dearer than the reference.  Nothing here is timed."""

from __future__ import annotations

import logging

from snakemake import logging as smk_logging
from snakemake_interface_logger_plugins.common import LogEvent

from benchmarks import ledger


def test_the_reference_costs_every_workload_of_the_ledger():
    reference = ledger.read_reference()
    names = [name for name, _, _ in ledger.WORKLOADS]
    assert len(set(names)) == len(names)
    assert list(reference["workloads"]) == names
    assert reference["kernel_ns_per_point_step"] > 0
    for w in reference["workloads"].values():
        assert w["cost_M_point_steps"] == round(w["cpu_s"] * 1e3 / reference["kernel_ns_per_point_step"], 1)


def test_a_workload_more_than_ten_percent_dearer_is_named():
    reference = {
        "kernel_ns_per_point_step": 10.0,
        "workloads": {"a": {"cost_M_point_steps": 100.0}, "b": {"cost_M_point_steps": 100.0}},
    }
    now = {
        "kernel_ns_per_point_step": 5.0,
        "workloads": {
            "a": {"cpu_s": 0.5, "cost_M_point_steps": 111.0},
            "b": {"cpu_s": 0.5, "cost_M_point_steps": 109.0},
        },
    }
    table = ledger.markdown(now, reference)
    assert "| a | 0.50 | 111 | 100.0 | 1.11 **dearer** |" in table
    assert "| b | 0.50 | 109 | 100.0 | 1.09 |" in table
    assert table.rstrip().endswith("more than 1.10x dearer: a")


#: a build's Snakemake log cut to its job lines, as Snakemake 9 writes them: the target rule `all` (no output),
#: the kernels job 10 s, two map chunks side by side (100 s and 90 s), a figure 2 s (Snakemake 7's finishing
#: line), and a sweep chunk that never finished (a cut build)
BUILD_LOG = """Building DAG of jobs...
Using shell: /usr/bin/bash
Provided cores: 2
Job stats:
job          count
---------  -------
all              1
kernels          1
map_chunk        2
total            4

Select jobs to execute...

[Mon Dec  7 21:00:00 2026]
rule kernels:
    input: config/designs/li2013.yaml
    output: results/li2013/kernels.txt
    log: results/li2013/logs/kernels.log
    jobid: 3
    reason: Missing output files: results/li2013/kernels.txt
    wildcards: design=li2013
    priority: 10
    resources: tmpdir=/tmp, kernels=1

[Mon Dec  7 21:00:10 2026]
Finished jobid: 3 (Rule: kernels)
1 of 6 steps (17%) done
Select jobs to execute...

[Mon Dec  7 21:00:10 2026]
rule map_chunk:
    input: results/li2013/kernels.txt, config/designs/li2013.yaml
    output: results/li2013/maps/map_x1_e/chunk_0.nc
    log: results/li2013/logs/map_map_x1_e_0.log
    jobid: 7
    reason: Missing output files: results/li2013/maps/map_x1_e/chunk_0.nc
    wildcards: design=li2013, map=map_x1_e, chunk=0
    priority: 2
    resources: tmpdir=/tmp

[Mon Dec  7 21:00:11 2026]
rule map_chunk:
    input: results/li2013/kernels.txt, config/designs/li2013.yaml
    output: results/li2013/maps/map_x1_e/chunk_1.nc
    log: results/li2013/logs/map_map_x1_e_1.log
    jobid: 8
    reason: Missing output files: results/li2013/maps/map_x1_e/chunk_1.nc
    wildcards: design=li2013, map=map_x1_e, chunk=1
    priority: 2
    resources: tmpdir=/tmp

[Mon Dec  7 21:01:41 2026]
Finished jobid: 8 (Rule: map_chunk)
2 of 6 steps (33%) done

[Mon Dec  7 21:01:50 2026]
Finished jobid: 7 (Rule: map_chunk)
3 of 6 steps (50%) done

[Mon Dec  7 21:01:50 2026]
localrule map_figure:
    input: results/li2013/maps/map_x1_e.nc
    output: results/li2013/figures/map_x1_e.png, results/li2013/figures/map_x1_e.png.txt
    log: results/li2013/logs/figure_map_x1_e.log
    jobid: 9
    wildcards: design=li2013, map=map_x1_e
    resources: tmpdir=/tmp

[Mon Dec  7 21:01:52 2026]
Finished job 9.
4 of 6 steps (67%) done

[Mon Dec  7 21:01:52 2026]
rule sweep_chunk:
    input: results/li2013/kernels.txt, config/designs/li2013.yaml
    output: results/li2013/sweeps/fig07_bifurcation_x1/chunk_0.nc
    jobid: 11
    wildcards: design=li2013, sweep=fig07_bifurcation_x1, chunk=0

[Mon Dec  7 21:01:53 2026]
localrule all:
    input: results/li2013/figures/map_x1_e.png
    jobid: 0
    reason: Input files updated by another job: results/li2013/figures/map_x1_e.png
    resources: tmpdir=/tmp

[Mon Dec  7 21:01:53 2026]
Finished jobid: 0 (Rule: all)
"""


def test_a_builds_log_gives_its_job_seconds_per_stage(tmp_path) -> None:
    # the seconds counted by hand from the stamps of BUILD_LOG above
    path = tmp_path / "build.snakemake.log"
    path.write_text(BUILD_LOG)
    assert ledger.build_jobs(BUILD_LOG) == [
        ("kernels", 0.0, 10.0),
        ("map_chunk", 11.0, 101.0),
        ("map_chunk", 10.0, 110.0),
        ("map_figure", 110.0, 112.0),
    ]
    stages = ledger.build_stages(path)
    assert stages["map chunks"] == (190.0, 2)
    assert stages["kernels (compiling once)"] == (10.0, 1)
    assert stages["sweep chunks"] == (0.0, 0)
    assert stages[ledger.OTHER] == (2.0, 1)
    assert stages["all"] == (202.0, 4)
    assert stages["wall"] == (112.0, 0)
    table = ledger.stage_markdown(stages, {**stages, "map chunks": (95.0, 2), "all": (107.0, 4)})
    assert "| map chunks | 190 (2 jobs) | 95 (2 jobs) | 2.00 |" in table
    assert "| **all** | 202 (4 jobs) | 107 (4 jobs) | 1.89 |" in table
    assert "| sweep chunks | 0 | 0 | - |" in table


def test_the_stage_table_reads_what_snakemakes_own_formatter_writes(monkeypatch) -> None:
    # a job's lines written by Snakemake's log formatter (the installed Snakemake, not a copy of its format)
    fmt = smk_logging.DefaultFormatter()
    stamps = iter(["Mon Dec  7 21:00:05 2026", "Mon Dec  7 21:00:42 2026"])
    monkeypatch.setattr(smk_logging.time, "asctime", lambda: next(stamps))
    info = {
        "rule_msg": None,
        "local": False,
        "is_checkpoint": False,
        "rule_name": "orbit_branches",
        "input": ["results/li2013/sweeps/fig07_bifurcation_x1.nc"],
        "output": ["results/li2013/orbits/fig07_bifurcation_x1.nc"],
        "log": ["results/li2013/logs/orbits_fig07_bifurcation_x1.log"],
        "jobid": 21,
        "benchmark": None,
        "reason": "Missing output files",
        "wildcards": {"design": "li2013", "sweep": "fig07_bifurcation_x1"},
        "priority": 0,
        "threads": 1,
        "resources": {"tmpdir": "/tmp"},
    }
    lines = []
    for event, extra in ((LogEvent.JOB_INFO, info), (LogEvent.JOB_FINISHED, {})):
        record = logging.LogRecord("snakemake", logging.INFO, __file__, 0, "", None, None)
        record.__dict__.update(extra, event=event)
        if event is LogEvent.JOB_FINISHED:
            record.msg = "Finished jobid: 21 (Rule: orbit_branches)"
        lines.append(fmt.format(record))
    stages = ledger.stage_seconds(ledger.build_jobs("\n".join(lines)))
    assert stages[ledger.STAGES[3][0]] == (37.0, 1)
