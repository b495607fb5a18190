"""The whole pipeline on small grids, in a temporary copy: every netCDF file it writes follows the CF
conventions (attributes, and the IOOS CF checker), `snakemake --report` groups the figures by paper and
figure number with their captions, each design's archive verifies, and the SLURM profile keeps the
cheap rules local.
"""

import json
import re
import subprocess
import sys
import tarfile
from pathlib import Path

import netCDF4
import pytest
import xarray as xr
import yaml

import _workflow as wf
from geardyn import io
from geardyn.io import archive, provenance


def _small_pipeline(work):
    wf.workflow_copy(work, wf.small_config(), wf.small_designs())  # the benchmark at its smoke-test size
    wf.snakemake(work, "--cores", "2", "all", "calibration", "archive", timeout=900)  # archives: the cubes of `all`
    wf.snakemake(work, "--report", "results/report.html", timeout=300)


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    """The small pipeline, its archives and report, built once per session."""
    return wf.shared(tmp_path_factory, "pipeline", _small_pipeline)


def _netcdf_files(work):
    return sorted(p for p in (work / "results").rglob("*.nc"))


#: Every kind of netCDF file the pipeline writes (paths below results/).
KINDS = [
    "li2013/data/closed_graph.nc",
    "li2013/data/stiffness_table.nc",
    "li2013/sweeps/fig07_small.nc",
    "li2013/points/fig08_small.nc",
    "li2013/calibration/small_search.nc",
    "li2013/probabilities/small_prob.nc",
    "benchmarks/work_precision.nc",
    "yue2014/data/modal.nc",
    "yue2014/data/te.nc",
    "yue2014/data/relief_landscape.nc",
    "yue2014/data/forced_response.nc",
]


def test_every_netcdf_file_carries_cf_attributes(small_run):
    files = _netcdf_files(small_run)
    found = {str(p.relative_to(small_run / "results")) for p in files}
    assert set(KINDS) <= found
    # chunk files are temp(): removed once merged (sweeps, maps, calibration grids)
    assert not [f for f in found if Path(f).name.startswith("chunk_")]
    runtime = set(provenance.RUNTIME_KEYS)
    for path in files:
        with xr.open_dataset(path) as ds:
            for key in ("Conventions", "title", "source", "history", "references"):
                assert str(ds.attrs.get(key, "")).strip(), f"{path.name}: global attribute {key}"
            assert ds.attrs["Conventions"].startswith("CF-1.")
            for key in ("geardyn_version", "git_commit"):
                assert ds.attrs.get(key), f"{path.name}: {key}"
            assert io.missing_cf_attributes(ds) == [], path
            assert runtime <= set(ds.attrs), f"{path.name}: runtime provenance"
            for name, var in {**ds.coords, **ds.data_vars}.items():
                assert var.attrs.get("long_name"), f"{path.name}: {name} long_name"
                if var.dtype.kind not in "OSU" and "flag_values" not in var.attrs:
                    assert var.attrs.get("units") is not None, f"{path.name}: {name} units"


def test_every_netcdf_variable_is_compressed(small_run):

    for path in _netcdf_files(small_run):
        with netCDF4.Dataset(path) as nc:
            for name, var in nc.variables.items():
                if var.ndim and var.size and getattr(var.dtype, "kind", "O") in "biuf":
                    f = var.filters()
                    assert f["zlib"] and f["shuffle"] and f["complevel"] == io.ZLIB_LEVEL, f"{path.name}: {name}"


#: Findings of the IOOS checker that do not apply, with the reason.
NOT_APPLICABLE = [
    # The dense point runs have a coordinate named `time` in mesh periods (dimensionless, units "1"); the
    # checker takes any variable named `time` for a CF time axis, which needs time units.
    ("§5.1", "Coordinate variable 'time' should have standard_name='time'"),
]


def test_ioos_cf_checker_finds_no_errors(small_run, tmp_path):
    checker = Path(sys.executable).parent / "compliance-checker"  # the console script of the test extra
    if not checker.exists():
        pytest.skip("compliance-checker is not installed (pip install -e '.[test]')")
    files = [str(p) for p in _netcdf_files(small_run)]
    out = tmp_path / "cf.json"
    run = subprocess.run(
        [str(checker), "--test", "cf:1.10", "--format", "json_new", "--output", str(out), *files],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert out.exists(), run.stderr[-2000:]
    report = json.loads(out.read_text())
    assert set(report) == set(files)
    errors = []
    for path, result in report.items():
        for item in result["cf:1.10"]["high_priorities"]:
            if item["value"][0] >= item["value"][1]:
                continue
            msgs = [
                m
                for m in item["msgs"]
                if not any(item["name"].startswith(sec) and text in m for sec, text in NOT_APPLICABLE)
            ]
            errors += [f"{path}: {item['name']}: {m}" for m in msgs]
    assert errors == []


def test_report_groups_figures_by_paper_and_figure_with_captions(small_run):
    report = small_run / "results" / "report.html"
    html = report.read_text(encoding="utf-8", errors="replace")
    assert report.stat().st_size > 100_000
    for text in (
        "Paper 1: Li et al. (2013), KHV drive",
        "Paper 2: Yue et al. (2014), plus planetary set",
        "Benchmarks",
        "Fig. 03: closed graph",
        "Fig. 05: mesh stiffness",
        "Fig. 07: fig07_small",
        "Fig. 08: fig08_small",
        "Fig. 09: tip relief",
        "fig07_small.png",
        "fig09_te_relief.png",
        "Regime probabilities",
        "small_prob.png",
        "claims_small_prob.csv",
    ):
        assert text in html, text
    # a caption: the family's .rst, with the caption text the figure's job wrote included
    caption = (small_run / "results/li2013/figures/fig07_small.png.txt").read_text().splitlines()[0]
    assert "Caption written by the job" in html
    assert caption.split(":")[0] + ": Poincare points of X_VH" in html


def _cubes_on_disk(work, design):
    base = work / "results" / design
    # the archive holds the default build's cubes; the calibration searches are a target of their own
    return {
        str(p.relative_to(base))
        for p in base.rglob("*.nc")
        if not p.name.startswith("chunk_") and p.parent.name != "calibration"
    }


@pytest.mark.parametrize("design", ["li2013", "yue2014"])
def test_archive_holds_every_cube_and_verifies(small_run, design):
    path = small_run / "results" / f"{design}_archive.tar.gz"
    summary = archive.verify(path)
    manifest = json.loads(_archive_member(path, "MANIFEST.json"))
    cubes = {e["path"].removeprefix(f"results/{design}/") for e in manifest["files"] if e["kind"] == "netcdf"}
    assert cubes == _cubes_on_disk(small_run, design) and summary.cubes == len(cubes) > 0
    assert summary.own_sum  # the rule wrote <archive>.sha256 beside it, and it matches
    configs = {e["path"] for e in manifest["files"] if e["kind"] == "config"}
    assert configs == {"config/config.yaml", f"config/designs/{design}.yaml", "config/effective_config.yaml"}
    run = subprocess.run(
        [sys.executable, "-m", "geardyn.cli", "verify-archive", str(path)],
        env=wf.env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0 and "OK" in run.stdout


def _archive_member(path, name):

    with tarfile.open(path, "r:gz") as tar:
        member = next(m for m in tar if m.name.endswith("/" + name))
        return tar.extractfile(member).read()


def test_corrupted_archive_is_refused_with_a_clear_line(small_run, tmp_path):
    data = bytearray((small_run / "results" / "li2013_archive.tar.gz").read_bytes())
    data[len(data) // 2] ^= 0xFF
    bad = tmp_path / "li2013_archive.tar.gz"
    bad.write_bytes(bytes(data))
    run = subprocess.run(
        [sys.executable, "-m", "geardyn.cli", "verify-archive", str(bad)],
        env=wf.env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 1
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {bad}: ")
    assert re.search(r"(sha256 mismatch|not a readable \.tar\.gz archive|does not open)", lines[0])


def test_slurm_profile_keeps_cheap_rules_local(tmp_path):
    pytest.importorskip("snakemake_executor_plugin_slurm")
    profile = yaml.safe_load((wf.ROOT / "workflow/profiles/slurm/config.yaml").read_text())
    assert profile["executor"] == "slurm"
    for rule, res in profile["set-resources"].items():
        assert res["runtime"] > 0 and res["mem_mb"] > 0, rule
    work = wf.workflow_copy(tmp_path / "w", wf.small_config(), wf.small_designs())
    run = wf.snakemake(work, "-n", "--profile", "workflow/profiles/slurm", timeout=300)
    text = run.stdout + run.stderr
    # the same jobs as a local dry run
    plain = wf.snakemake(work, "-n", "--cores", "2", timeout=300)
    stats = lambda t: sorted(re.findall(r"^(\w+)\s+(\d+)$", t[t.index("Job stats") :], re.M))  # noqa: E731
    assert stats(text) == stats(plain.stdout + plain.stderr)
    assert re.search(r"^sweep_chunk\s+2$", text, re.M)
    # cheap rules stay on the submitting host (a dry run does not print which; Snakemake refuses a
    # `localrules` name that is no rule, so the dry run above also checked that every name exists)
    block = (wf.ROOT / "workflow/rules/cluster.smk").read_text().split("localrules:")[1]
    local = set(re.findall(r"^\s+(\w+),", block, re.M))
    assert {
        "sweep_merge",
        "point_figure",
        "fig03_closed_graph",
        "closed_graph_figure",
        "stiffness_figures",
        "stiffness_figures_own",
        "plus_modal_figures",
        "plus_modal_figures_own",
        "plus_te_figures",
        "plus_te_figures_own",
        "plus_forced_response",
        "claims",
        "map_merge",
        "map_figure",
        "probabilities_merge",
        "probabilities_claims",
        "calibration_compare",
    } == local
    assert "localrule: True" in (wf.ROOT / "workflow/rules/archive.smk").read_text()
    heavy = {
        "sweep_chunk",
        "calibration_search",
        "map_chunk",
        "point_runs",
        "work_precision",
        "plus_relief",
        "plus_landscape",
    }
    assert heavy <= set(profile["set-resources"]) and not local & set(profile["set-resources"])
    planned = set(re.findall(r"^rule (\w+):", text, re.M))
    remote = planned - local - {"all"}
    # the small run has no maps, and its calibration search is a target of its own (not planned here)
    assert heavy & planned <= remote and {"sweep_chunk"} <= remote
