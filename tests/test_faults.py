"""Faults, measured: a run killed mid-sweep resumes without recomputing finished chunks and gives the
same cube; damaged chunks are recomputed, never merged; cubes do not depend on the number of cores or
chunks; sweep jobs log their progress.  Chunk files are ``temp()``: removed once their merge succeeded,
kept while it has not (a failed merge, an interrupted run).  A job whose write fails on the disk says so in
one line on stderr and leaves nothing behind.

All runs use a copy of the workflow in a temporary directory (see _workflow.py).
"""

import base64
import os
import re
import shutil
import signal
import subprocess
import sys
import zlib

import numpy as np
import pytest
import xarray as xr

import _workflow as wf

CUBE = "results/li2013/sweeps/fig07_small.nc"
CHUNKS = 3  # the fewest that let a run be stopped with two chunks done and one to go
#: A sweep of 18 points (6 per chunk): each chunk job is mostly start-up, about 2 s.
INTEGRATION = {"steps_per_period": 128, "transient_periods": 100, "recorded_periods": 20}


def _config(chunks=CHUNKS):
    # every point from the fixed start, so the chunks are free to cut the one line anywhere
    cfg = wf.sweep_config(chunks=chunks, num=18, integration=INTEGRATION)
    cfg["sweeps"]["fig07_small"]["start_from"] = "fixed"
    return cfg


def _chunk_paths(work):
    return sorted((work / "results/li2013/sweeps/fig07_small").glob("chunk_*.nc"))


def _run(work, *args):
    return wf.snakemake(work, *args, CUBE, timeout=300)


def _jobs(run, rule):
    """How many jobs of ``rule`` a run executed (from Snakemake's 'Job stats' table)."""
    match = re.search(rf"^{rule}\s+(\d+)$", run.stderr + run.stdout, re.M)
    return int(match.group(1)) if match else 0


def _open(path):
    with xr.open_dataset(path) as ds:
        return ds.load()


def assert_same_cube(a, b, ignore=("history",)):
    """Values, coordinates, dimensions and variable attributes identical; global attributes too, but
    for ``ignore`` (the creation time, and the config hash when the chunk count differs)."""
    xr.testing.assert_equal(a, b)
    for name in a.variables:
        assert a[name].attrs.keys() == b[name].attrs.keys(), name
    strip = lambda attrs: {k: v for k, v in attrs.items() if k not in ignore}  # noqa: E731
    assert strip(a.attrs) == strip(b.attrs)


def _reference_run(work):
    wf.workflow_copy(work, _config())
    run = _run(work, "--cores", "2")
    assert _jobs(run, "sweep_chunk") == CHUNKS


def _premerge_run(work):
    """Every chunk computed, the merge not yet run: the chunks asked for as targets (so kept, temp or not)."""
    wf.workflow_copy(work, _config())
    targets = [f"results/li2013/sweeps/fig07_small/chunk_{i}.nc" for i in range(CHUNKS)]
    run = wf.snakemake(work, "--cores", "2", *targets, timeout=300)
    assert _jobs(run, "sweep_chunk") == CHUNKS and len(_chunk_paths(work)) == CHUNKS


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """An uninterrupted `snakemake --cores 2` run (once per session): its directory and merged cube."""
    work = wf.shared(tmp_path_factory, "reference", _reference_run)
    return work, _open(work / CUBE)


@pytest.fixture(scope="module")
def premerge(tmp_path_factory):
    """A workflow copy with every chunk of the reference's sweep computed and not merged (once per session)."""
    return wf.shared(tmp_path_factory, "premerge", _premerge_run)


def test_chunks_are_removed_after_their_merge(reference):
    """temp(): the reference run merged its chunks and left none (the logs stay)."""
    assert _chunk_paths(reference[0]) == []
    assert not (reference[0] / "results/li2013/sweeps/fig07_small").exists() or not any(
        (reference[0] / "results/li2013/sweeps/fig07_small").iterdir()
    )
    assert (reference[0] / "results/li2013/logs/sweep_fig07_small_0.log").exists()


def _recorded_chunks(work):
    """Chunk files that exist and whose job Snakemake recorded as finished (no 'incomplete' marker)."""
    marked = (
        {
            base64.b64decode(p.name).decode()
            for p in (work / ".snakemake" / "incomplete").glob("*")
            if p.name != "migration_underway"
        }
        if (work / ".snakemake" / "incomplete").exists()
        else set()
    )
    return {p.name for p in _chunk_paths(work) if str(p.relative_to(work)) not in marked}


# SIGINT is Ctrl-C in the terminal (to the whole process group); SIGKILL a power cut or the OOM killer.
# (SIGTERM is not used: Snakemake 9.27's SIGTERM handler takes a lock the main thread may hold, and
# the run can hang; see docs/operations.md.) The interruption is deterministic: the third chunk job
# sends the signal to the process group as it starts (tests/faults/sitecustomize.py), with --cores 1.
@pytest.mark.parametrize("sig", ["SIGINT", "SIGKILL"])
def test_killed_run_resumes_without_recomputing_and_gives_the_same_cube(tmp_path, reference, sig):
    work = wf.workflow_copy(tmp_path / "w", _config())
    env = wf.env()
    env.update(
        PYTHONPATH=f"{wf.ROOT / 'tests' / 'faults'}{os.pathsep}{env['PYTHONPATH']}",
        GEARDYN_FAULT=f"sweep_chunk:3:{sig}",
        GEARDYN_FAULT_COUNTER=str(tmp_path / "count"),
    )
    # SIGINT back to its default in the child: a test runner started in the background by a shell without job
    # control inherits SIGINT ignored, and Snakemake would then never see the Ctrl-C this test sends
    proc = subprocess.run(
        wf.snakemake_cmd("--cores", "1", CUBE),
        cwd=work,
        env=env,
        capture_output=True,
        start_new_session=True,
        timeout=300,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    assert proc.returncode != 0
    recorded = _recorded_chunks(work)
    done = {p.name: p.stat().st_mtime_ns for p in _chunk_paths(work) if p.name in recorded}
    assert len(done) == 2, done  # interrupted as the third chunk started
    assert not (work / CUBE).exists()
    if sig == "SIGKILL":  # README: after a hard kill, `--unlock` first (Snakemake's lock is left)
        wf.snakemake(work, "--unlock")
    rerun = _run(work, "--cores", "2", "--rerun-incomplete")  # README: the command with --rerun-incomplete
    # the finished chunks were kept (temp files are removed only after their merge) and not recomputed
    assert _jobs(rerun, "sweep_chunk") == CHUNKS - len(done)
    assert _chunk_paths(work) == []  # merged, so removed
    assert_same_cube(_open(work / CUBE), reference[1])


def _copy_of(premerge, tmp_path):
    """The reference sweep with every chunk done but the merge not yet run (as after a run stopped then)."""
    work = tmp_path / "w"
    shutil.copytree(premerge, work, symlinks=True)  # copy2: mtimes kept, so Snakemake sees no change
    assert not (work / CUBE).exists()
    dry = wf.snakemake(work, "-n", "--cores", "2", CUBE)
    assert _jobs(dry, "sweep_chunk") == 0 and _jobs(dry, "sweep_merge") == 1
    return work


def _damaged_then_recomputed(work, victim, reference, problem):
    """The merge job finds the damaged chunk, sets it aside and fails naming it; the same command run
    again recomputes that chunk only and merges a cube identical to the reference."""
    others = {p.name: p.stat().st_mtime_ns for p in _chunk_paths(work) if p != victim}
    first = wf.snakemake(work, "--cores", "2", CUBE, timeout=300, check=False)
    assert first.returncode != 0
    assert f"{victim.name} ({problem}" in first.stderr and "run the same command again" in first.stderr
    assert not (work / CUBE).exists() and not victim.exists()
    assert (victim.parent / f"{victim.name}.damaged").exists()  # kept for inspection
    # the failed merge removed no temp chunk: the good ones wait, unchanged, for the next run
    assert {p.name: p.stat().st_mtime_ns for p in _chunk_paths(work)} == others
    rerun = _run(work, "--cores", "2")
    assert _jobs(rerun, "sweep_chunk") == 1 and _jobs(rerun, "sweep_merge") == 1
    assert _chunk_paths(work) == []  # merged, so removed (temp); the damaged copy stays
    assert (victim.parent / f"{victim.name}.damaged").exists()
    assert_same_cube(_open(work / CUBE), reference[1])


def test_truncated_chunk_is_recomputed_not_merged(tmp_path, reference, premerge):
    work = _copy_of(premerge, tmp_path)
    victim = work / "results/li2013/sweeps/fig07_small/chunk_2.nc"
    data = victim.read_bytes()
    victim.write_bytes(data[: len(data) // 3])  # a copy cut short, a disk that filled up
    _damaged_then_recomputed(work, victim, reference, "does not read back")
    assert (victim.parent / "chunk_2.nc.damaged").stat().st_size == len(data) // 3


def _stored_offset(data: bytes, value: np.float64) -> int:
    """An offset inside the compressed HDF5 chunk (zlib after byte shuffle) that holds ``value``: the zlib
    streams of the file are tried until one decompresses, unshuffled, to data containing it."""
    want = np.float64(value).tobytes()
    for at in range(len(data) - 2):
        if data[at] != 0x78 or data[at + 1] not in (0x01, 0x5E, 0x9C, 0xDA):
            continue
        d = zlib.decompressobj()
        try:
            raw = d.decompress(data[at:])
        except zlib.error:
            continue
        if not d.eof:
            continue
        n = len(raw) // 8  # HDF5 shuffles whole 8-byte values; a rest (the Fletcher-32 sum) is left as it is
        plain = np.frombuffer(raw[: 8 * n], np.uint8).reshape(8, n).T.tobytes()  # undo the shuffle
        if want in plain:
            used = len(data) - at - len(d.unused_data)
            return at + used // 2  # the middle of that stream
    return -1


def test_silently_flipped_byte_in_a_chunk_is_found_by_its_checksum(tmp_path, reference, premerge):
    work = _copy_of(premerge, tmp_path)
    victim = work / "results/li2013/sweeps/fig07_small/chunk_0.nc"
    stat = victim.stat()
    with xr.open_dataset(victim) as ds:  # flip a byte inside the stored x_vh data, not in the metadata
        values = ds["x_vh"].values
        finite = values[np.isfinite(values)]
    data = bytearray(victim.read_bytes())
    at = _stored_offset(bytes(data), finite[len(finite) // 2])
    assert at > 0
    data[at] ^= 0x01
    victim.write_bytes(bytes(data))
    os.utime(victim, ns=(stat.st_atime_ns, stat.st_mtime_ns))  # bit rot: same size, same time stamp
    _damaged_then_recomputed(work, victim, reference, "does not read back")


def test_planning_never_touches_chunk_files(tmp_path, premerge):
    """A dry run (Snakemake planning) leaves a damaged chunk where it is: only a job sets it aside."""
    work = _copy_of(premerge, tmp_path)
    victim = work / "results/li2013/sweeps/fig07_small/chunk_1.nc"
    victim.write_bytes(victim.read_bytes()[:5000])
    wf.snakemake(work, "-n", "--cores", "2", CUBE)
    assert victim.exists() and not (victim.parent / "chunk_1.nc.damaged").exists()


def test_cubes_do_not_depend_on_cores_or_chunks(tmp_path, reference):
    one_core = wf.workflow_copy(tmp_path / "cores1", _config())
    _run(one_core, "--cores", "1")
    assert_same_cube(_open(one_core / CUBE), reference[1])
    other_chunks = wf.workflow_copy(tmp_path / "chunks2", _config(chunks=2))
    run = _run(other_chunks, "--cores", "2")
    assert _jobs(run, "sweep_chunk") == 2
    # the config (hence its hash) says 2 chunks instead of 3 (9 points a chunk, not 6); everything else is identical
    assert_same_cube(_open(other_chunks / CUBE), reference[1], ignore=("history", "config_hash", "config_json"))


def test_sweep_jobs_log_progress_and_remaining_time(reference):
    log = (reference[0] / "results/li2013/logs/sweep_fig07_small_0.log").read_text()
    lines = re.findall(r"fig07_small chunk 0: (\d+)/(\d+) points, ([\d.]+) s elapsed, ([\d.]+) s remaining", log)
    # a line every 10 % of a chunk's lines; the 6 points of this chunk start from the fixed state, each a
    # line of its own, all labelled in one step
    assert len(lines) >= 1 and lines[-1][:2] == ("6", "6") and float(lines[-1][3]) == 0.0


#: An adapter (the closed graph's) run in an interpreter of its own, its writer failing on a disk that is full
#: (netCDF's error names no errno; the disk, asked again, says ENOSPC) or over its quota (an OSError without a
#: file name, as a Python writer raises it), or with a writer error that is not the disk's.
WRITE_FAILS = """
import errno, os, sys
import xarray as xr
import _workflow as wf

mode, out, log = sys.argv[1:]

def to_netcdf(self, path, *args, **kwargs):  # half a file written, then the writer's own error
    with open(path, "wb") as fh:
        fh.write(b"half a netCDF file")
    if mode == "quota":
        raise OSError(errno.EDQUOT, os.strerror(errno.EDQUOT))
    raise RuntimeError("NetCDF: HDF error")

def fsync(fd):
    if mode == "full disk":
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

xr.Dataset.to_netcdf, os.fsync = to_netcdf, fsync
grid = {"x1": {"start": 0.2, "stop": 1.1, "num": 4}, "x2": {"start": 0.3, "stop": 1.4, "num": 4}}
design = wf.ROOT / "config" / "designs" / "li2013.yaml"
job = wf.Job(input={"design": design}, output=[out], params={"spec": grid}, log=[log])
wf.run_script(wf.ROOT / "workflow" / "scripts" / "closed_graph.py", job)
"""


@pytest.mark.parametrize(
    ("mode", "line"),
    [("full disk", "No space left on device (ENOSPC)"), ("quota", "Disk quota exceeded (EDQUOT)"), ("other", None)],
)
def test_a_write_that_fails_on_the_disk_is_one_line_and_leaves_nothing(tmp_path, mode, line):
    out, log = tmp_path / "data" / "closed_graph.nc", tmp_path / "logs" / "closed_graph.log"
    env = {**wf.env(), "PYTHONPATH": os.pathsep.join([str(wf.ROOT / "src"), str(wf.ROOT / "tests")])}
    args = [sys.executable, "-c", WRITE_FAILS, mode, str(out), str(log)]
    run = subprocess.run(args, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 1
    assert not list(out.parent.iterdir())  # neither the output nor its temporary file
    if line is None:  # an error that is not the disk's keeps its traceback
        assert "Traceback" in run.stderr and run.stderr.rstrip().endswith("RuntimeError: NetCDF: HDF error")
    else:
        assert run.stderr == f"geardyn: {line}: {out}\n"  # one line, no traceback
        assert line in log.read_text() and "Traceback" in log.read_text()  # the traceback in the job's log
