"""Where and how an output was made: :func:`attributes`, a dataset's global attributes (CF basics, version,
git commit, config hash, model variant, reference), and :func:`runtime`, where it was computed
(each key: ``docs/operations.md``).  :mod:`geardyn.io` writes them into every netCDF file and table."""

from __future__ import annotations

import datetime as _dt
import functools
import hashlib
import json
import os
import platform
import re
import subprocess
import sys
from collections.abc import Iterable, Mapping
from importlib import metadata
from pathlib import Path

import numpy as np

from geardyn import __version__, libm
from geardyn.jsontypes import Json
from geardyn.papers import paper_of

try:
    from numpy._core import _multiarray_umath as mu  # type: ignore[attr-defined]  # not in numpy's stubs
except ImportError:  # numpy < 2
    from numpy.core import _multiarray_umath as mu

#: The CF conventions every dataset follows.
CONVENTIONS = "CF-1.10"
#: The packages whose versions every output records (distribution names).
PROVENANCE_PACKAGES = ("numpy", "scipy", "numba", "llvmlite", "xarray", "netCDF4", "snakemake")
#: /proc/cpuinfo flags that name SIMD instruction sets (the ones that can change floating-point results).
_SIMD_FLAG = re.compile(
    r"^(mmx|sse\w*|ssse3|avx\w*|fma\w*|f16c|amx\w*|\w*vnni\w*|vaes|vpclmulqdq|gfni|neon|asimd\w*|sve\w*)$"
)


def _package_version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "not installed"


def _cpuinfo() -> tuple[str, list[str]]:
    """CPU model name and its SIMD flags from /proc/cpuinfo (Linux), else from :mod:`platform`."""
    generic = ("unknown", platform.machine(), platform.processor())
    flags: list[str]
    model, flags = platform.processor() or platform.machine() or "unknown", []
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return model, flags
    for line in text.splitlines():
        key, _, value = (part.strip() for part in line.partition(":"))
        if key in ("model name", "Model", "cpu model") and model in generic:
            model = value
        elif key in ("flags", "Features") and not flags:
            flags = sorted(f for f in value.split() if _SIMD_FLAG.match(f))
    return model, flags


def _numpy_cpu() -> dict[str, str]:
    """The instruction sets numpy was built for (baseline) and dispatches to at run time on this CPU
    (after ``NPY_DISABLE_CPU_FEATURES``), and its BLAS/LAPACK."""
    found = getattr(mu, "__cpu_features__", {})
    dispatch = [f for f in getattr(mu, "__cpu_dispatch__", []) if found.get(f)]
    out = {
        "numpy_cpu_baseline": " ".join(getattr(mu, "__cpu_baseline__", [])),
        "numpy_cpu_dispatch": " ".join(dispatch) or "none",
    }
    out |= {f"{m}_blas_core": libm.blas_core(m) for m in ("numpy", "scipy")}
    try:
        cfg = np.show_config(mode="dicts")["Build Dependencies"]
        out["numpy_blas"] = " ".join(str(cfg["blas"].get(k, "")) for k in ("name", "version")).strip()
        out["numpy_lapack"] = " ".join(str(cfg["lapack"].get(k, "")) for k in ("name", "version")).strip()
    except Exception:
        out["numpy_blas"] = out["numpy_lapack"] = "unknown"
    return out


def _numba_cpu() -> dict[str, str]:
    """The CPU name and features numba compiles for: ``NUMBA_CPU_NAME`` / ``NUMBA_CPU_FEATURES`` when set,
    else the host's (llvmlite)."""
    try:
        import llvmlite.binding as llvm  # noqa: PLC0415 - the JIT only when provenance is asked for
    except ImportError:
        return {"numba_cpu_name": "not installed", "numba_cpu_features": ""}
    cpu_name, cpu_features = _numba_cpu_settings()
    name = cpu_name or llvm.get_host_cpu_name()
    if cpu_features is not None:
        feats = cpu_features
    elif cpu_name:
        feats = "(those of the named CPU)"
    else:
        feats = llvm.get_host_cpu_features().flatten()
    simd = sorted(f[1:] for f in feats.split(",") if f.startswith("+") and _SIMD_FLAG.match(f[1:].replace(".", "_")))
    return {"numba_cpu_name": name, "numba_cpu_features": " ".join(simd) if simd else feats}


def _numba_cpu_settings() -> tuple[str | None, str | None]:
    """numba's ``config.CPU_NAME`` and ``config.CPU_FEATURES``.  A job that writes results without integrating
    does not import numba for them (0.3 CPU-s): they are read from the environment as numba reads them, unless
    numba is loaded already or a ``.numba_config.yaml`` in the working folder may set them."""
    if "numba" in sys.modules or Path(".numba_config.yaml").is_file():
        try:
            import numba  # noqa: PLC0415 - the JIT only when provenance is asked for
        except ImportError:
            return None, None
        return numba.config.CPU_NAME, numba.config.CPU_FEATURES
    name = os.environ.get("NUMBA_CPU_NAME")
    return name, os.environ.get("NUMBA_CPU_FEATURES", "" if str(name).lower() == "generic" else None)


#: The keys of :func:`runtime` (besides ``env_<VARIABLE>`` for the overrides that are set).
RUNTIME_KEYS = (
    "python_version",
    "python_implementation",
    *(f"{p.lower()}_version" for p in PROVENANCE_PACKAGES),
    *"platform cpu_model cpu_simd_flags numpy_cpu_baseline numpy_cpu_dispatch numpy_blas numpy_lapack".split(),
    *"numpy_blas_core scipy_blas_core numba_cpu_name numba_cpu_features libm_variant".split(),
)
#: The environment variables that override what the CPU and the libraries choose, recorded when set.
OVERRIDES = (
    "NPY_DISABLE_CPU_FEATURES NUMBA_CPU_NAME NUMBA_CPU_FEATURES NUMBA_FASTMATH OPENBLAS_CORETYPE OPENBLAS_L2_SIZE"
)


def runtime_of(attrs: Mapping[str, Json]) -> dict[str, str]:
    """The runtime provenance recorded in a file's global attributes (:data:`RUNTIME_KEYS`, ``env_*``)."""
    return {k: str(v) for k, v in attrs.items() if k in RUNTIME_KEYS or k.startswith("env_")}


def distinct_runtimes(attrs: Iterable[Mapping[str, Json]]) -> list[tuple[dict[str, str], int]]:
    """The distinct runtime provenances (:func:`runtime_of`) of several files' global attributes, in the order
    they first appear, and how many files recorded each (files that recorded none left out)."""
    found = [rt for rt in map(runtime_of, attrs) if rt]
    return [(rt, found.count(rt)) for k, rt in enumerate(found) if rt not in found[:k]]


@functools.lru_cache(maxsize=1)
def runtime() -> dict[str, str]:
    """Where an output was computed (:data:`RUNTIME_KEYS` and ``env_<VARIABLE>`` for the overrides that are set:
    Python and library versions, CPU, the instruction sets, OpenBLAS kernels and C math build in use; each
    key: ``docs/operations.md``).  Computed once per process (the values cannot change while it runs)."""
    out = {"python_version": platform.python_version(), "python_implementation": sys.implementation.name}
    out |= {f"{pkg.lower()}_version": _package_version(pkg) for pkg in PROVENANCE_PACKAGES}
    model, flags = _cpuinfo()
    out |= {"platform": platform.platform(), "cpu_model": model, "cpu_simd_flags": " ".join(flags) or "unknown"}
    out |= _numpy_cpu() | _numba_cpu() | {"libm_variant": libm.variant()}
    out |= {f"env_{var}": os.environ[var] for var in OVERRIDES.split() if os.environ.get(var)}
    assert set(out) - {k for k in out if k.startswith("env_")} == set(RUNTIME_KEYS)
    return out


def info() -> dict[str, str]:
    """:func:`runtime` with the geardyn version and git commit first."""
    return {"geardyn_version": __version__, "git_commit": git_commit(), **runtime()}


def provenance_text(prefix: str = "") -> str:
    """:func:`info` as ``key: value`` lines."""
    return "".join(f"{prefix}{k}: {v}\n" for k, v in info().items())


def config_hash(config: Mapping[str, Json]) -> str:
    """Short sha256 of a configuration mapping, independent of key order."""
    return hashlib.sha256(json.dumps(config, sort_keys=True, default=_json_default).encode()).hexdigest()[:16]


def _json_default(obj: Json) -> Json:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return str(obj)


def git_commit(repo: str | os.PathLike[str] | None = None) -> str:
    """The current git commit of the source tree (with ``-dirty``), or ``unknown`` outside git."""
    where = Path(repo) if repo is not None else Path(__file__).resolve().parent
    cmd = ["git", "describe", "--always", "--dirty", "--abbrev=12"]
    try:
        out = subprocess.run(cmd, cwd=where, capture_output=True, text=True, timeout=10, check=True)
        return out.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def attributes(
    *,
    title: str,
    paper: str | None = None,
    config: Mapping[str, Json] | None = None,
    model_variant: str | None = None,
    extra: Mapping[str, Json] | None = None,
) -> dict[str, str]:
    """Global attributes for a dataset: CF basics plus where and how it was made."""
    now = _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat()
    attrs: dict[str, str] = {
        "Conventions": CONVENTIONS,
        "title": title,
        "institution": "geardyn project",
        "source": f"geardyn {__version__}",
        "history": f"{now} created by geardyn {__version__}",
        "references": getattr(paper_of(paper), "REFERENCE", "geardyn documentation (docs/)"),
        "geardyn_version": __version__,
        "git_commit": git_commit(),
        **runtime(),
    }
    if paper:
        attrs["paper"] = paper
    if config is not None:
        attrs["config_hash"] = config_hash(config)
        attrs["config_json"] = json.dumps(config, sort_keys=True, default=_json_default)
    if model_variant is not None:
        attrs["model_variant"] = model_variant
    for key, value in (extra or {}).items():
        attrs[key] = value if isinstance(value, str) else json.dumps(value, default=_json_default)
    return attrs
