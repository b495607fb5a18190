"""SLURM, for real: the workflow through ``workflow/profiles/slurm`` on a single-node SLURM cluster on
this machine (``tests/cluster/local_slurm.sh``). Every chunk job goes to SLURM, every job SLURM ran
finished once, the merges and figures run on the login node, and the outputs equal those of a local
``--cores 2`` run; each rule's runtime and memory reach sbatch (read back from slurmctld with ``scontrol show job``); a
job cancelled mid-run is resubmitted, one cancelled twice fails the run, and the rerun completes with
nothing lost; Ctrl-C on the login node cancels the run's jobs and the same command resumes; the
per-job overhead against local execution is measured and printed.

Opt-in (marker ``cluster``): every test here is skipped unless ``GEARDYN_CLUSTER_TEST=1``. Needs root
and SLURM + munge installed (``tests/cluster/local_slurm.sh install``). The cluster is started for the
session and stopped at its end, unless it was already running. Without pytest-xdist's ``-n`` (one
cluster per session); ``-s`` shows the measured times:

    GEARDYN_CLUSTER_TEST=1 .venv/bin/python -m pytest tests/test_cluster.py -v -s
"""

from __future__ import annotations

import datetime as dt
import os
import re
import signal
import subprocess
import time
from collections import Counter
from pathlib import Path

import pytest
import xarray as xr
import yaml

import _workflow as wf

pytestmark = [
    pytest.mark.cluster,
    pytest.mark.skipif(
        os.environ.get("GEARDYN_CLUSTER_TEST") != "1",
        reason="needs a live SLURM cluster: set GEARDYN_CLUSTER_TEST=1 (root, see docs/operations.md)",
    ),
]

SCRIPT = wf.ROOT / "tests" / "cluster" / "local_slurm.sh"
PROFILE = "workflow/profiles/slurm"

CUBES = {"sweep": "results/li2013/sweeps/fig07_small.nc", "map": "results/li2013_calibrated/maps/map_small.nc"}
FIGURES = ["results/li2013/figures/fig07_small.png", "results/li2013_calibrated/figures/map_small.png"]
SWEEP_CHUNKS = 3
MAP_CHUNKS = 2

#: Per-rule requests written into the test's copy of the profile: values no default and no shipped
#: setting has, so that finding them on the SLURM jobs cannot happen by accident.
RESOURCES = {"sweep_chunk": {"runtime": 7, "mem_mb": 1111}, "map_chunk": {"runtime": 9, "mem_mb": 1333}}
#: Job status checked 2 s after a check that saw a job end (plugin default: 40 s; the interval grows
#: by 10 s with each check that sees none). Only where stated: where the test waits for retries.
FAST_POLLING = {"slurm-init-seconds-before-status-checks": 2, "seconds-between-status-checks": 2}
#: Global attributes that say when, from which checkout and how fast a file was made, not what it holds
#: (and the curves' ``time_<step>_s``).
PROVENANCE = ("history", "git_commit", "chunk_wall_time_s")


def _config():
    """One x1 sweep of three cases (three lines, so 3 chunks of 40 points, the design's own integrator
    settings) and one 6 x 4 regime map (2 chunks) with the shipped map settings."""
    cfg = wf.sweep_config(chunks=SWEEP_CHUNKS, num=40)
    del cfg["sweeps"]["fig07_small"]["integration"]
    cfg["sweeps"]["fig07_small"]["cases"] = [{"b": 2.0}, {"b": 1.5}, {"b": 1.0}]
    cfg["designs"]["li2013_calibrated"] = "config/designs/li2013_calibrated.yaml"
    cfg["maps"] = {
        "map_small": {
            "designs": ["li2013_calibrated"],
            "title": "small map",
            "x": {"parameter": "x1", "start": 0.416, "stop": 0.835, "num": 6},
            "y": {"parameter": "b", "start": 0.0, "stop": 2.2, "num": 4},
            "fixed": {"e": 5.0},
            "chunks": MAP_CHUNKS,
            "integration": {"steps_per_period": 128, "transient_periods": 400, "recorded_periods": 50},
            "classifier": {"error_floor": 1.9e-5, "tangent_periods": 200},
        }
    }
    return cfg


def _profile(work: Path, resources=None, **settings) -> None:
    """Edit the copy's SLURM profile: per-rule resources and extra settings."""
    path = work / PROFILE / "config.yaml"
    profile = yaml.safe_load(path.read_text(encoding="utf-8"))
    for rule, res in (resources or {}).items():
        profile["set-resources"][rule] = dict(res)
    profile.update(settings)
    path.write_text(yaml.safe_dump(profile, sort_keys=False), encoding="utf-8")


def slurm_jobs(work: Path, rule: str = "") -> list[dict[str, str]]:
    """Every job slurmctld knows of (finished ones too, for MinJobAge) that ran in ``work`` (of ``rule`` only,
    when given), by job id, with ``rule`` and ``wildcards`` from the comment the executor plugin gives each job."""
    out = subprocess.run(
        ["scontrol", "show", "job", "-o"], capture_output=True, text=True, check=True, timeout=60
    ).stdout
    jobs = []
    for line in out.splitlines():
        fields = dict(re.findall(r"(\S+?)=(\S*)", line))
        if fields.get("WorkDir") and Path(fields["WorkDir"]).resolve() == work.resolve():
            name, _, wildcards = fields["Comment"].removeprefix("rule_").partition("_wildcards_")
            jobs.append({**fields, "rule": name, "wildcards": wildcards})
    return sorted((j for j in jobs if j["rule"] == (rule or j["rule"])), key=lambda job: int(job["JobId"]))


def _seconds(job, start, end):
    return (dt.datetime.fromisoformat(job[end]) - dt.datetime.fromisoformat(job[start])).total_seconds()


def _time_limit(minutes: int) -> str:
    return f"{minutes // 60:02d}:{minutes % 60:02d}:00"


def _open(path: Path) -> xr.Dataset:
    with xr.open_dataset(path) as ds:
        return ds.load()


def assert_same_data(a: xr.Dataset, b: xr.Dataset) -> None:
    """Identical values, coordinates, dtypes and attributes, but for the provenance time stamps."""
    a, b = a.copy(), b.copy()
    for ds in (a, b):
        for key in [k for k in ds.attrs if k in PROVENANCE or re.fullmatch(r"time_\w+_s", k)]:
            ds.attrs.pop(key)
    xr.testing.assert_identical(a, b)


def _timed(work: Path, *args: str, timeout: float = 900):
    t0 = time.monotonic()
    run = wf.snakemake(work, *args, timeout=timeout)
    return run, time.monotonic() - t0


@pytest.fixture(scope="session")
def cluster():
    """The local cluster: started here (and stopped at the end) unless it already runs."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        pytest.fail("run the cluster tests without -n: one cluster serves the whole session")
    already_up = subprocess.run([SCRIPT, "status"], capture_output=True, timeout=60).returncode == 0
    if not already_up:
        start = subprocess.run([SCRIPT, "start"], capture_output=True, text=True, timeout=120)
        assert start.returncode == 0, f"local cluster did not start:\n{start.stdout}{start.stderr}"
    yield
    if not already_up:
        stop = subprocess.run([SCRIPT, "stop"], capture_output=True, text=True, timeout=120)
        assert stop.returncode == 0, stop.stderr


@pytest.fixture(scope="module")
def local(tmp_path_factory):
    """The small study run locally, ``--cores 2``: its directory and wall time."""
    work = wf.workflow_copy(tmp_path_factory.mktemp("local") / "w", _config())
    _, wall = _timed(work, "--cores", "2", *FIGURES)
    return work, wall


@pytest.fixture(scope="module")
def study(cluster, local, tmp_path_factory):
    """The same study through the SLURM profile (as shipped, but for the distinctive RESOURCES)."""
    work = wf.workflow_copy(tmp_path_factory.mktemp("slurm") / "w", _config())
    _profile(work, RESOURCES)
    run, wall = _timed(work, "--profile", PROFILE, *FIGURES)
    print(
        f"\n[cluster] small study ({SWEEP_CHUNKS} sweep + {MAP_CHUNKS} map chunk jobs, the map's curves, merges, "
        f"2 figures): local --cores 2 {local[1]:.1f} s, SLURM profile {wall:.1f} s "
        f"(load average {os.getloadavg()[0]:.1f})"
    )
    return work, run, slurm_jobs(work)


def _outputs(work: Path) -> set[str]:
    return {str(p.relative_to(work)) for p in (work / "results").rglob("*") if p.is_file()}


def test_study_through_slurm_equals_local_run(local, study):
    """What the profile promises, whichever rules it sends to the cluster: every chunk job went to SLURM, every
    job Snakemake submitted ran there once and finished, the merges and figures ran on the login node, and
    every output equals the local run's."""
    work, run, jobs = study
    text = run.stdout + run.stderr
    ran = Counter((job["rule"], job["wildcards"]) for job in jobs)
    assert set(ran.values()) == {1} and {(job["JobState"], job["ExitCode"]) for job in jobs} == {("COMPLETED", "0:0")}
    submitted = Counter(re.findall(r"^rule (\w+):", text, re.M))  # Snakemake's line for a job it submits
    assert Counter(job["rule"] for job in jobs) == submitted
    assert submitted["sweep_chunk"] == SWEEP_CHUNKS and submitted["map_chunk"] == MAP_CHUNKS
    for rule in ("sweep_merge", "map_merge", "map_figure"):
        assert re.search(rf"^localrule {rule}:", text, re.M) and rule not in submitted, rule
    assert _outputs(work) == _outputs(local[0])
    cubes = sorted(path for path in _outputs(work) if path.endswith(".nc"))
    assert {*CUBES.values(), "results/li2013_calibrated/maps/map_small_curves.nc"} <= set(cubes)
    for cube in cubes:
        assert_same_data(_open(work / cube), _open(local[0] / cube))
    for figure in FIGURES:
        assert (work / figure).stat().st_size > 0 and (work / f"{figure}.txt").exists()


def test_rule_resources_reach_sbatch(study):
    shipped = yaml.safe_load((wf.ROOT / PROFILE / "config.yaml").read_text(encoding="utf-8"))
    for rule, res in RESOURCES.items():  # the check below cannot pass on shipped or default values
        assert res["runtime"] not in (
            shipped["default-resources"]["runtime"],
            shipped["set-resources"][rule]["runtime"],
        )
        assert res["mem_mb"] not in (shipped["default-resources"]["mem_mb"], shipped["set-resources"][rule]["mem_mb"])
    partition = subprocess.run(["sinfo", "-h", "-o", "%P"], capture_output=True, text=True, check=True).stdout
    default_partition = next(p.rstrip("*") for p in partition.split() if p.endswith("*"))
    jobs = study[2]
    assert {job["rule"] for job in jobs} >= set(RESOURCES)
    for job in jobs:  # the test's requests for the chunk rules, the profile's for the others
        res = RESOURCES.get(job["rule"]) or {
            **shipped["default-resources"],
            **shipped["set-resources"].get(job["rule"], {}),
        }
        assert job["TimeLimit"] == _time_limit(res["runtime"]), job["Comment"]
        assert job["MinMemoryNode"] == f"{res['mem_mb']}M", job["Comment"]
        assert job["Partition"] == default_partition, job["Comment"]
        # the chunk rules take both cores of a node (the profile's set-threads: 2): SLURM must reserve them
        assert job["rule"] not in RESOURCES or job["NumCPUs"] == "2", job["Comment"]


def test_cancelled_jobs_are_resubmitted_then_fail_and_a_rerun_loses_nothing(cluster, local, tmp_path):
    """The first sweep chunk seen running is cancelled once (retries: 1 resubmits it, it completes);
    the second is cancelled on both attempts (the run fails, the other chunks complete); the same
    command again computes only that chunk and gives the local run's cube."""
    work = wf.workflow_copy(tmp_path / "w", _config())
    _profile(work, **FAST_POLLING)
    cube = CUBES["sweep"]
    log = tmp_path / "run1.log"
    with open(log, "w") as out:
        proc = subprocess.Popen(
            wf.snakemake_cmd("--profile", PROFILE, cube),
            cwd=work,
            env=wf.env(),
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    once = twice = None  # wildcards of the chunk cancelled once / on both attempts
    cancelled: dict[str, list[str]] = {}
    deadline = time.monotonic() + 600
    try:
        while proc.poll() is None and time.monotonic() < deadline:
            for job in slurm_jobs(work, "sweep_chunk"):  # the chunks (the kernels job runs before them)
                chunk, jobid = job["wildcards"], job["JobId"]
                if job["JobState"] != "RUNNING" or jobid in cancelled.get(chunk, []):
                    continue
                if once is None:
                    once = chunk
                elif chunk == once or (twice is not None and chunk != twice):
                    continue  # the resubmitted job of `once`, or the chunk left alone
                elif twice is None:
                    twice = chunk
                elif len(cancelled[twice]) == 2:
                    continue
                subprocess.run(["scancel", jobid], check=True, timeout=60)
                cancelled.setdefault(chunk, []).append(jobid)
            time.sleep(0.2)
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)  # Snakemake cancels its SLURM jobs
        proc.wait(timeout=300)
    text = log.read_text()
    assert proc.returncode != 0, "the run should fail: one chunk was cancelled on both attempts"
    assert once and twice and len(cancelled[once]) == 1 and len(cancelled[twice]) == 2, cancelled
    by_chunk: dict[str, list[str]] = {}
    for job in slurm_jobs(work, "sweep_chunk"):
        by_chunk.setdefault(job["wildcards"], []).append(job["JobState"])
    assert by_chunk.pop(once) == ["CANCELLED", "COMPLETED"]  # resubmitted (retries: 1) and completed
    assert by_chunk.pop(twice) == ["CANCELLED", "CANCELLED"]  # retry used up: the run reports it failed
    assert list(by_chunk.values()) == [["COMPLETED"]] * (SWEEP_CHUNKS - 2)
    assert text.count("SLURM status is: 'CANCELLED'") == 3 and text.count("Trying to restart job") == 2
    chunks = work / "results/li2013/sweeps/fig07_small"
    done = {p.name: p.stat().st_mtime_ns for p in chunks.glob("chunk_*.nc")}
    assert len(done) == SWEEP_CHUNKS - 1 and not (work / cube).exists()

    before = {job["JobId"] for job in slurm_jobs(work)}
    wf.snakemake(work, "--profile", PROFILE, cube)  # the same command; the profile has rerun-incomplete
    new = [job for job in slurm_jobs(work) if job["JobId"] not in before]
    # only the failed chunk was recomputed; the finished ones waited (temp files stay until their merge)
    assert [(job["wildcards"], job["JobState"]) for job in new] == [(twice, "COMPLETED")]
    assert not list(chunks.glob("chunk_*.nc"))  # merged, so removed (temp)
    assert_same_data(_open(work / cube), _open(local[0] / cube))


def test_interrupted_run_cancels_its_jobs_and_the_same_command_resumes(cluster, local, tmp_path):
    """Ctrl-C on the login node's Snakemake while a chunk job runs: Snakemake scancels every job it
    submitted (none is left running or queued), and the same command completes the cube."""
    work = wf.workflow_copy(tmp_path / "w", _config())
    _profile(work, **FAST_POLLING)
    cube = CUBES["sweep"]
    proc = subprocess.Popen(
        wf.snakemake_cmd("--profile", PROFILE, cube),
        cwd=work,
        env=wf.env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    deadline = time.monotonic() + 300
    while proc.poll() is None and time.monotonic() < deadline:
        if any(job["JobState"] == "RUNNING" for job in slurm_jobs(work)):
            break
        time.sleep(0.2)
    assert proc.poll() is None, "the run ended before it could be interrupted"
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C in the login node's terminal
    proc.wait(timeout=300)
    assert proc.returncode != 0
    states = Counter(job["JobState"] for job in slurm_jobs(work))
    assert states["CANCELLED"] >= 1 and set(states) <= {"CANCELLED", "COMPLETED"}, states
    assert not (work / cube).exists()
    wf.snakemake(work, "--profile", PROFILE, cube)
    assert_same_data(_open(work / cube), _open(local[0] / cube))


def test_per_job_overhead_against_local_execution(cluster, tmp_path):
    """Six chunk jobs of one point each (milliseconds of compute), locally with --cores 2 and through
    the SLURM profile (as shipped, then with 2 s status polling). Prints the wall times and the
    overhead per job in core-seconds; asserts only that the chunks are the same."""
    n = 6
    cfg = wf.sweep_config(chunks=n, num=n)
    cfg["sweeps"]["fig07_small"]["start_from"] = "fixed"  # every point its own line: six one-point chunks
    targets = [f"results/li2013/sweeps/fig07_small/chunk_{i}.nc" for i in range(n)]
    walls, jobs = {}, {}
    for mode in ("local", "slurm", "slurm_fast_polling"):
        work = wf.workflow_copy(tmp_path / mode, cfg)
        if mode == "local":
            _, walls[mode] = _timed(work, "--cores", "2", *targets)
            continue
        if mode == "slurm_fast_polling":
            _profile(work, **FAST_POLLING)
        _, walls[mode] = _timed(work, "--profile", PROFILE, *targets)
        jobs[mode] = slurm_jobs(work, "sweep_chunk")
        assert [job["JobState"] for job in jobs[mode]] == ["COMPLETED"] * n
        for target in targets:
            assert_same_data(_open(work / target), _open(tmp_path / "local" / target))
    slots = 2  # both ways: two jobs at a time (2 cores; a 2-CPU node)
    per_job = {mode: wall * slots / n for mode, wall in walls.items()}
    both = jobs["slurm"] + jobs["slurm_fast_polling"]
    run_time = [_seconds(job, "StartTime", "EndTime") for job in both]
    wait = [_seconds(job, "SubmitTime", "StartTime") for job in both]
    print(
        f"\n[cluster] {n} one-point chunk jobs, wall time: local --cores 2 {walls['local']:.1f} s, "
        f"SLURM profile {walls['slurm']:.1f} s, SLURM with 2 s polling {walls['slurm_fast_polling']:.1f} s "
        f"(load average {os.getloadavg()[0]:.1f})"
    )
    print(
        f"[cluster] core-seconds per job: local {per_job['local']:.1f}, SLURM {per_job['slurm']:.1f} "
        f"(+{per_job['slurm'] - per_job['local']:.1f}), SLURM with 2 s polling {per_job['slurm_fast_polling']:.1f} "
        f"(+{per_job['slurm_fast_polling'] - per_job['local']:.1f})"
    )
    print(
        f"[cluster] per SLURM job (scontrol, 1 s resolution): {min(run_time):.0f}-{max(run_time):.0f} s "
        f"(mean {sum(run_time) / len(run_time):.1f} s) in its allocation for Snakemake and Python start-up "
        f"and one point; sbatch to start {min(wait):.0f} s on a free node, mean {sum(wait) / len(wait):.1f} s "
        f"with waiting for a free CPU"
    )
