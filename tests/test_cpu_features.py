"""Results do not depend on the CPU's SIMD features (docs/reproducibility.md).

The small study of ``_cpu_study.py`` runs once in this process (the machine's own features: AVX-512
where it has them) and once in a subprocess with every instruction set that numpy dispatches to at run
time disabled (``NPY_DISABLE_CPU_FEATURES``: numpy's baseline paths only, as on a machine without
AVX2 or AVX-512), numba compiling for a generic x86-64 CPU (``NUMBA_CPU_NAME=generic``) and the C
library's math functions dispatched as on a CPU without AVX and FMA (``GLIBC_TUNABLES``).  Every
number must be the same bit for bit, but the labels of chaotic points, which are compared by class (a
chaotic orbit amplifies any last-bit difference; this study has none unless the model changes).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy._core import _multiarray_umath as mu

import _cpu_study
from geardyn import libm
from geardyn.io import provenance
from geardyn.label import vocabulary

HERE = Path(__file__).resolve().parent
CHAOS = vocabulary.LABELS["chaotic"]


def _reduced_env() -> dict[str, str]:

    dispatched = [f for f in mu.__cpu_dispatch__ if mu.__cpu_features__.get(f)]
    env = {**os.environ, "NUMBA_CPU_NAME": "generic", "PYTHONPATH": os.pathsep.join([str(HERE), *sys.path])}
    env.pop("NUMBA_CPU_FEATURES", None)
    env["GLIBC_TUNABLES"] = "glibc.cpu.hwcaps=-AVX512F,-AVX2,-AVX,-FMA,-FMA4"  # glibc's SSE2 builds only
    if dispatched:
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(dispatched)
    return env


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    out = tmp_path_factory.mktemp("cpu") / "reduced.npz"
    env = _reduced_env()
    run = subprocess.run(
        [sys.executable, str(HERE / "_cpu_study.py"), str(out)], env=env, capture_output=True, text=True, timeout=600
    )
    assert run.returncode == 0, run.stderr[-3000:]
    check = subprocess.run(
        [sys.executable, "-c", "from geardyn.io import provenance as g; import json; print(json.dumps(g.runtime()))"],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    with np.load(out) as z:
        reduced = {k: z[k] for k in z.files}
    return _cpu_study.study(), reduced, check.stdout


def test_the_subprocess_really_ran_with_fewer_features(both):

    _, _, there = both
    rt = json.loads(there)
    assert rt["numba_cpu_name"] == "generic" and rt["env_NUMBA_CPU_NAME"] == "generic"

    if any(mu.__cpu_features__.get(f) for f in mu.__cpu_dispatch__):
        assert rt["numpy_cpu_dispatch"] == "none" != provenance.runtime()["numpy_cpu_dispatch"]
    assert rt["numpy_blas_core"] == provenance.runtime()["numpy_blas_core"]  # geardyn's pinned kernels
    assert rt["libm_variant"] == provenance.runtime()["libm_variant"]


def test_same_numbers_bit_for_bit_on_fewer_cpu_features(both):
    here, there, _ = both
    assert set(here) == set(there)
    assert bool(here["orbit/converged"]) and np.max(np.abs(here["orbit/multipliers"])) < 1.0  # a stable orbit
    labels = here["sweep/label"]
    chaotic = labels == CHAOS
    np.testing.assert_array_equal(labels, there["sweep/label"])  # labels always equal, chaotic ones by class
    differ = []
    for key, a in here.items():
        b = there[key]
        if key.startswith("sweep/") and a.shape[: labels.ndim] == labels.shape and chaotic.any():
            a, b = a[~chaotic], b[~chaotic]  # a chaotic point's numbers: compared by its label only
        if not np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"):
            differ.append(key)
    assert differ == [], f"differ with fewer CPU features: {differ}"
    assert int(np.sum(~chaotic)) >= 3  # the sweep has non-chaotic points to compare


def _variant_in(env: dict[str, str], code: str = "") -> str:
    run = subprocess.run(
        [sys.executable, "-c", f"from geardyn import libm; {code}print(libm.variant())"],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    return run.stdout.strip()


needs_glibc = pytest.mark.skipif(libm.variant() == "other", reason="not glibc on x86-64: no claim (docs)")


@needs_glibc
def test_the_tests_run_the_plain_c_library():
    assert libm.variant() == libm.CANONICAL
    assert provenance.runtime()["libm_variant"] == libm.CANONICAL
    assert "glibc.cpu.hwcaps=" in os.environ["GLIBC_TUNABLES"]  # set by importing geardyn, for subprocesses


@needs_glibc
def test_a_process_started_without_the_setting_is_seen_and_restarts():
    env = {k: v for k, v in os.environ.items() if k not in ("GLIBC_TUNABLES", "GEARDYN_LIBM_RESTARTED")}
    cpu_fma = {"fma", "avx2"} <= set(provenance.runtime()["cpu_simd_flags"].split())
    assert _variant_in(env) == ("glibc-fma" if cpu_fma else libm.CANONICAL)  # the probe tells the builds apart
    assert _variant_in(env, "libm.restart_canonical(); ") == libm.CANONICAL


def _labelling_warnings(env: dict[str, str]) -> list[str]:
    """The warnings of a process started with ``env`` that labels (no lines) twice."""
    code = (
        "import logging; logging.basicConfig(format='%(levelname)s %(message)s'); "
        "from geardyn.label import Policy, label_lines; from geardyn.solve import SimulationSettings; "
        "p = Policy(SimulationSettings()); label_lines([], p); label_lines([], p)"
    )
    run = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    return [line for line in run.stderr.splitlines() if line.startswith("WARNING")]


@needs_glibc
def test_labelling_in_a_process_of_the_fused_build_warns_once():
    """A script started without the setting labels with glibc's fused build (row 60 of li2013_calibrated's
    map_x1_e: 37 of 200 labels differ from the build's) and is told so, once; one started with it is not."""
    env = {k: v for k, v in os.environ.items() if k not in ("GLIBC_TUNABLES", "GEARDYN_LIBM_RESTARTED")}
    cpu_fma = {"fma", "avx2"} <= set(provenance.runtime()["cpu_simd_flags"].split())
    warned = _labelling_warnings(env)
    assert len(warned) == (1 if cpu_fma else 0)
    assert all("glibc-fma" in w and "restart_canonical" in w for w in warned)
    assert _labelling_warnings(dict(os.environ)) == []


def test_the_setting_joins_other_tunables():
    env = libm.canonical_environ({"GLIBC_TUNABLES": "glibc.malloc.arena_max=2:glibc.cpu.hwcaps=-AVX512F", "X": "1"})
    assert env["X"] == "1"
    assert env["GLIBC_TUNABLES"] == (
        "glibc.malloc.arena_max=2:glibc.cpu.hwcaps=-AVX512F,-FMA,-FMA4,-FMA_Usable,-FMA4_Usable"
    )
    assert libm.canonical_environ(env) == env  # idempotent
    assert libm.canonical_environ({})["GLIBC_TUNABLES"] == "glibc.cpu.hwcaps=-FMA,-FMA4,-FMA_Usable,-FMA4_Usable"


def _blas_in(env: dict[str, str], code: str) -> str:
    run = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    return run.stdout.strip()


@pytest.mark.skipif(libm.blas_core() == "unknown", reason="numpy without its bundled OpenBLAS: no claim (docs)")
def test_openblas_runs_geardyns_kernels_whatever_the_environment_says():
    """A machine's environment may name other OpenBLAS kernels (OPENBLAS_CORETYPE=Haswell on one of this
    project's machines): importing geardyn before numpy replaces the setting, and a process that loaded
    numpy first with other kernels is seen (needs_restart) and restarted onto geardyn's."""
    env = {k: v for k, v in os.environ.items() if k != "GEARDYN_LIBM_RESTARTED"}
    env["OPENBLAS_CORETYPE"] = "Haswell"
    show = "from geardyn import libm; print(libm.blas_core('numpy'), libm.blas_core('scipy'), libm.needs_restart())"
    assert _blas_in(env, f"import geardyn; {show}") == f"{libm.BLAS_CORETYPE} {libm.BLAS_CORETYPE} False"
    assert _blas_in(env, f"import numpy; {show}") == f"Haswell {libm.BLAS_CORETYPE} True"
    assert _blas_in(env, f"import scipy.linalg; {show}") == "Haswell Haswell True"
    restarted = _blas_in(env, f"import numpy; from geardyn import libm; libm.restart_canonical(); {show}")
    assert restarted == f"{libm.BLAS_CORETYPE} {libm.BLAS_CORETYPE} False"
