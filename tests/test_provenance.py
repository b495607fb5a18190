"""Where an output was computed (geardyn.io.provenance): library versions and CPU features in every netCDF file
and table, printed by ``geardyn verify-archive``; every variable compressed losslessly; the pinned environment."""

import json
import os
import re
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import llvmlite.binding as llvm
import netCDF4
import numpy as np
import pytest
import xarray as xr
from numpy._core import _multiarray_umath as mu

import _model_oracle as oracle
from geardyn import io
from geardyn.io import archive, provenance

ROOT = Path(__file__).resolve().parents[1]


def _cube(n=300):
    rng = np.random.default_rng(1)
    x = np.linspace(0.4, 0.8, n)
    return xr.Dataset(
        {
            "x_vh": (("case", "x1"), np.cumsum(rng.normal(size=(2, n)), axis=1), {"units": "1", "long_name": "x"}),
            "label": (
                ("case", "x1"),
                rng.integers(-2, 9, size=(2, n)).astype(np.int16),
                {"long_name": "motion label", "flag_values": np.arange(-2, 9, dtype=np.int16)},
            ),
        },
        coords={
            "x1": ("x1", x, {"units": "1", "long_name": "profile shift"}),
            "case": ("case", ["a", "b"], {"long_name": "case"}),
        },
    )


def _cpuinfo_field(name):
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.split(":")[0].strip() == name:
            return line.split(":", 1)[1].strip()
    return None


def test_runtime_provenance_names_versions_and_cpu():
    rt = provenance.runtime()
    assert set(rt) >= set(provenance.RUNTIME_KEYS)
    # versions as the package metadata has them (an independent source)
    for pkg in ("numpy", "scipy", "numba", "llvmlite", "xarray", "netCDF4", "snakemake"):
        assert rt[f"{pkg.lower()}_version"] == metadata.version(pkg)
    assert rt["python_version"] == ".".join(map(str, sys.version_info[:3]))
    if Path("/proc/cpuinfo").exists():
        assert rt["cpu_model"] == _cpuinfo_field("model name")
        flags = set(_cpuinfo_field("flags").split())
        assert set(rt["cpu_simd_flags"].split()) <= flags and "sse2" in rt["cpu_simd_flags"].split()
        assert ("avx2" in flags) == ("avx2" in rt["cpu_simd_flags"].split())

    assert rt["numpy_cpu_baseline"].split() == list(mu.__cpu_baseline__)
    assert set(rt["numpy_cpu_dispatch"].split()) <= set(mu.__cpu_dispatch__) | {"none"}

    assert rt["numba_cpu_name"] == (__import__("numba").config.CPU_NAME or llvm.get_host_cpu_name())


def test_runtime_of_keeps_the_runtime_keys_and_the_text_names_the_cpu():
    """runtime_of keeps only the keys that say where a file was computed; the tables' provenance text names
    the version and the CPU."""
    assert provenance.runtime_of({"cpu_model": "x", "env_NUMBA_CPU_NAME": "y", "title": "t"}) == {
        "cpu_model": "x",
        "env_NUMBA_CPU_NAME": "y",
    }
    text = provenance.provenance_text("# ")
    assert text.startswith("# geardyn_version: ") and f"# cpu_model: {provenance.runtime()['cpu_model']}\n" in text


def test_every_variable_is_compressed_losslessly_with_provenance(tmp_path):
    ds = _cube(20000)
    ds["x_vh"][:, ::2] = np.nan  # as in a chunk file: NaN where another chunk computes
    plain = io.write_netcdf(ds, tmp_path / "plain.nc", zlib_level=0)
    packed = io.write_netcdf(ds, tmp_path / "packed.nc", checksum=True)
    with netCDF4.Dataset(packed) as nc:
        for name in ("x_vh", "label", "x1"):
            f = nc[name].filters()
            assert f["zlib"] and f["shuffle"] and f["complevel"] == io.ZLIB_LEVEL and f["fletcher32"], name
    with netCDF4.Dataset(plain) as nc:
        assert not nc["x_vh"].filters()["zlib"]
    a, b = io.read_dataset(plain), io.read_dataset(packed)
    xr.testing.assert_identical(a, b)  # lossless, bit for bit
    np.testing.assert_array_equal(b["x_vh"].values, ds["x_vh"].values)
    assert packed.stat().st_size < 0.8 * plain.stat().st_size
    for key, value in provenance.runtime().items():
        assert b.attrs[key] == value
    with pytest.raises(ValueError, match="zlib_level"):
        io.write_netcdf(ds, tmp_path / "bad.nc", zlib_level=10)


def test_tables_carry_provenance(tmp_path):
    md = io.write_text("# t\n\n| a |\n|---|\n| 1 |\n", tmp_path / "t.md")
    text = md.read_text()
    assert text.startswith("# t\n\n| a |") and text.rstrip().endswith("-->")
    found = oracle.read_provenance_text(text)
    assert (
        found["numpy_version"] == metadata.version("numpy") and found["cpu_model"] == provenance.runtime()["cpu_model"]
    )
    csv = io.write_text("a,b\n1,2\n", tmp_path / "t.csv")
    assert csv.read_text() == "a,b\n1,2\n"  # a CSV stays plain: its provenance is beside it
    side = json.loads(io.provenance_sidecar(csv).read_text())
    assert side["file"] == "t.csv" and side["numba_version"] == metadata.version("numba")
    cap = io.write_text("caption\n", tmp_path / "fig.png.txt")  # captions are not tables
    assert cap.read_text() == "caption\n" and not io.provenance_sidecar(cap).exists()


def test_verify_archive_prints_where_the_cubes_were_computed(tmp_path):
    cube = io.write_netcdf(_cube(), tmp_path / "a.nc", provenance.attributes(title="a", paper="li2013"))
    cfg = tmp_path / "config.yaml"
    cfg.write_text("designs: {d: config/designs/d.yaml}\n")
    out = tmp_path / "d_archive.tar.gz"
    manifest = archive.build(out, "d", {"results/d/a.nc": cube}, {"config.yaml": cfg})
    entry = next(e for e in manifest["files"] if e["kind"] == "netcdf")
    assert entry["cpu_model"] == provenance.runtime()["cpu_model"]
    run = subprocess.run(
        [sys.executable, "-m", "geardyn.cli", "verify-archive", str(out)], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stderr
    rt = provenance.runtime()
    for key in (
        "numpy_version",
        "scipy_version",
        "numba_version",
        "llvmlite_version",
        "xarray_version",
        "netcdf4_version",
        "snakemake_version",
        "python_version",
        "cpu_model",
        "cpu_simd_flags",
        "numpy_cpu_dispatch",
        "numba_cpu_name",
        "numba_cpu_features",
        "libm_variant",
    ):
        assert f"    {key}: {rt[key]}\n" in run.stdout + "\n", key
    assert re.search(r"computed with \(1 of 1 cubes\)", run.stdout)


def test_readme_and_ci_install_from_the_pins_and_the_pins_are_this_environment():
    readme = (ROOT / "README.md").read_text()
    commands = re.findall(r"^python3\.11 -m venv .*$", readme, re.M)
    assert len(commands) == 2 and all("-c requirements/constraints.txt" in c for c in commands)
    assert commands[1] in (ROOT / ".ci" / "run").read_text().splitlines()  # verbatim
    pins = {}
    for line in (ROOT / "requirements" / "constraints.txt").read_text().splitlines():
        if line and not line.startswith("#"):
            name, _, version = line.partition("==")
            assert version and "<" not in version and ">" not in version, line
            pins[name.lower().replace("_", "-")] = version
    for pkg in ("numpy", "scipy", "numba", "llvmlite", "xarray", "netcdf4", "snakemake", "pytest", "hypothesis"):
        assert pkg in pins, pkg
        assert metadata.version(pkg) == pins[pkg], f"{pkg}: installed {metadata.version(pkg)}, pinned {pins[pkg]}"


@pytest.mark.parametrize(
    "env",
    [
        {},
        {"NUMBA_CPU_NAME": "generic"},
        {"NUMBA_CPU_NAME": "skylake"},
        {"NUMBA_CPU_NAME": "x", "NUMBA_CPU_FEATURES": "+avx"},
    ],
)
def test_the_cpu_numba_compiles_for_is_recorded_without_importing_numba(env, tmp_path):
    # what numba's own config says (numba imported first) against what a job that never imports numba records
    code = (
        "import json, sys{}; from geardyn.io import provenance; r = provenance.runtime(); "
        "print(json.dumps([r['numba_cpu_name'], r['numba_cpu_features'], 'numba' in sys.modules]))"
    )
    base = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CPU")}

    def run(c: str) -> list:
        out = subprocess.run(
            [sys.executable, "-c", c], capture_output=True, text=True, check=True, env={**base, **env}, cwd=tmp_path
        )
        return json.loads(out.stdout)

    with_numba, without = run(code.format(", numba")), run(code.format(""))
    assert with_numba[:2] == without[:2] and with_numba[2] and not without[2]
