"""Self-describing netCDF output: CF-style global attributes, provenance, atomic writes.

Every dataset written by the pipeline goes through :func:`write_netcdf`, so every file
says where it came from (package version, git commit, config hash, model variant) and on what
(:func:`runtime_provenance`: Python and library versions, CPU model and its SIMD features, the
instruction sets numpy dispatches to and the CPU numba compiles for), and no reader ever sees a
half-written file (write to a temporary name, then rename).  Every variable is stored compressed,
losslessly (zlib with the shuffle filter, level :data:`ZLIB_LEVEL`, chosen by measurement in
``docs/operations.md``).  Tables written by :func:`write_text` carry the same runtime provenance:
Markdown as a closing HTML comment, CSV and JSON in a ``<name>.provenance.json`` beside them.
"""

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
import tempfile
from collections.abc import Mapping
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from geardyn import __version__, libm
from geardyn.papers import paper_of

try:
    from numpy._core import _multiarray_umath as mu
except ImportError:  # numpy < 2
    from numpy.core import _multiarray_umath as mu  # type: ignore[no-redef]

CONVENTIONS = "CF-1.10"
#: zlib level of every netCDF variable (with the shuffle filter); measured in docs/operations.md.
ZLIB_LEVEL = 1
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
    model, flags = platform.processor() or platform.machine() or "unknown", []
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return model, flags
    for line in text.splitlines():
        key, _, value = line.partition(":")
        key = key.strip()
        if key in ("model name", "Model", "cpu model") and model in (
            "unknown",
            platform.machine(),
            platform.processor(),
        ):
            model = value.strip()
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
    out["numpy_blas_core"] = libm.blas_core("numpy")
    out["scipy_blas_core"] = libm.blas_core("scipy")
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
        import numba  # noqa: PLC0415 - likewise
    except ImportError:
        return {"numba_cpu_name": "not installed", "numba_cpu_features": ""}
    name = numba.config.CPU_NAME or llvm.get_host_cpu_name()
    if numba.config.CPU_FEATURES is not None:
        feats = numba.config.CPU_FEATURES
    elif numba.config.CPU_NAME:
        feats = "(those of the named CPU)"
    else:
        feats = llvm.get_host_cpu_features().flatten()
    simd = sorted(f[1:] for f in feats.split(",") if f.startswith("+") and _SIMD_FLAG.match(f[1:].replace(".", "_")))
    return {"numba_cpu_name": name, "numba_cpu_features": " ".join(simd) if simd else feats}


#: The keys of :func:`runtime_provenance` (besides ``env_<VARIABLE>`` for the overrides that are set).
RUNTIME_KEYS = (
    "python_version",
    "python_implementation",
    *(f"{p.lower()}_version" for p in PROVENANCE_PACKAGES),
    "platform",
    "cpu_model",
    "cpu_simd_flags",
    "numpy_cpu_baseline",
    "numpy_cpu_dispatch",
    "numpy_blas",
    "numpy_lapack",
    "numpy_blas_core",
    "scipy_blas_core",
    "numba_cpu_name",
    "numba_cpu_features",
    "libm_variant",
)


def runtime_of(attrs: Mapping[str, Any]) -> dict[str, str]:
    """The runtime provenance recorded in a file's global attributes (:data:`RUNTIME_KEYS`, ``env_*``)."""
    return {k: str(v) for k, v in attrs.items() if k in RUNTIME_KEYS or k.startswith("env_")}


@functools.lru_cache(maxsize=1)
def runtime_provenance() -> dict[str, str]:
    """Where an output was computed: Python and library versions, CPU and the instruction sets in use.

    Keys: ``python_version``, ``<package>_version`` for :data:`PROVENANCE_PACKAGES`, ``platform``,
    ``cpu_model``, ``cpu_simd_flags`` (SIMD flags of /proc/cpuinfo), ``numpy_cpu_baseline`` /
    ``numpy_cpu_dispatch`` (numpy's compiled-in and run-time-dispatched instruction sets, after
    ``NPY_DISABLE_CPU_FEATURES``), ``numpy_blas`` / ``numpy_lapack``, ``numpy_blas_core`` /
    ``scipy_blas_core`` (the OpenBLAS kernels in use, :data:`geardyn.BLAS_CORETYPE`), ``numba_cpu_name`` /
    ``numba_cpu_features`` (the target numba compiles for), ``libm_variant`` (the C library's math build
    in use, :func:`geardyn.libm.variant`) and the numba environment overrides.
    Computed once per process (the values cannot change while it runs).
    """
    out = {"python_version": platform.python_version(), "python_implementation": sys.implementation.name}
    for pkg in PROVENANCE_PACKAGES:
        out[f"{pkg.lower()}_version"] = _package_version(pkg)
    model, flags = _cpuinfo()
    out.update({"platform": platform.platform(), "cpu_model": model, "cpu_simd_flags": " ".join(flags) or "unknown"})
    out.update(_numpy_cpu())
    out.update(_numba_cpu())
    out["libm_variant"] = libm.variant()
    for var in (
        "NPY_DISABLE_CPU_FEATURES",
        "NUMBA_CPU_NAME",
        "NUMBA_CPU_FEATURES",
        "NUMBA_FASTMATH",
        "OPENBLAS_CORETYPE",
        "OPENBLAS_L2_SIZE",
    ):
        if os.environ.get(var):
            out[f"env_{var}"] = os.environ[var]
    assert set(out) - {k for k in out if k.startswith("env_")} == set(RUNTIME_KEYS)
    return out


def provenance_text(prefix: str = "") -> str:
    """:func:`runtime_provenance` (with geardyn version and git commit) as ``key: value`` lines."""
    info = {"geardyn_version": __version__, "git_commit": git_commit(), **runtime_provenance()}
    return "".join(f"{prefix}{k}: {v}\n" for k, v in info.items())


def config_hash(config: Mapping[str, Any]) -> str:
    """Short sha256 of a configuration mapping, independent of key order."""
    text = json.dumps(config, sort_keys=True, default=_json_default)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return str(obj)


def git_commit(repo: str | os.PathLike[str] | None = None) -> str:
    """The current git commit of the source tree (with ``-dirty``), or ``unknown`` outside git."""
    where = Path(repo) if repo is not None else Path(__file__).resolve().parent
    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=12"],
            cwd=where,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        )
        return out.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def provenance(
    *,
    title: str,
    paper: str | None = None,
    config: Mapping[str, Any] | None = None,
    model_variant: str | None = None,
    extra: Mapping[str, Any] | None = None,
) -> dict[str, str]:
    """Global attributes for a dataset: CF basics plus where and how it was made."""
    now = _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat()
    attrs: dict[str, str] = {
        "Conventions": CONVENTIONS,
        "title": title,
        "institution": "geardyn project",
        "source": f"geardyn {__version__}",
        "history": f"{now} created by geardyn {__version__}",
        "references": _reference(paper),
        "geardyn_version": __version__,
        "git_commit": git_commit(),
        **runtime_provenance(),
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


def _reference(paper: str | None) -> str:
    """The paper's full reference for a design that names one, else the project's documentation."""
    mod = paper_of(paper)
    return mod.REFERENCE if mod is not None else "geardyn documentation (docs/)"


def missing_cf_attributes(ds: xr.Dataset) -> list[str]:
    """Names of variables/coordinates lacking ``units`` or ``long_name`` (flags and masks need no units)."""
    missing = []
    for name, var in {**ds.coords, **ds.data_vars}.items():
        if "long_name" not in var.attrs:
            missing.append(f"{name}: long_name")
        if "units" not in var.attrs and "flag_values" not in var.attrs and var.dtype.kind not in "OSUb":
            missing.append(f"{name}: units")
    return missing


def write_netcdf(
    ds: xr.Dataset,
    path: str | os.PathLike[str],
    attrs: Mapping[str, str] | None = None,
    *,
    require_cf: bool = True,
    checksum: bool = False,
    zlib_level: int = ZLIB_LEVEL,
) -> Path:
    """Write ``ds`` to ``path`` atomically (temporary file + rename) with global ``attrs`` merged in.

    Raises ``ValueError`` if a variable lacks ``units``/``long_name`` and ``require_cf`` is set, so
    no undocumented file is ever produced. Coordinate variables get no ``_FillValue`` (CF 2.5.1).
    With ``checksum`` every non-empty numeric variable is stored with HDF5's Fletcher-32 checksum,
    so that reading it back (:func:`netcdf_problem`) detects any damaged byte, not only truncation.
    Every non-scalar numeric variable is compressed losslessly: zlib at ``zlib_level`` (1-9, 0 = off)
    after HDF5's byte shuffle (which groups the bytes of equal significance of neighbouring values,
    so slowly varying floats compress).  The global attributes include :func:`runtime_provenance`.
    """
    if not 0 <= zlib_level <= 9:
        raise ValueError(f"zlib_level must be 0 (off) to 9, got {zlib_level}")
    path = Path(path)
    out = ds.copy()
    out.attrs = {**ds.attrs, **(attrs or {}), **runtime_provenance()}
    if require_cf:
        missing = missing_cf_attributes(out)
        if missing:
            raise ValueError(f"dataset for {path.name} lacks CF attributes: {', '.join(missing)}")
    for name in out.coords:
        if name in out.dims and out[name].dtype.kind == "f":
            out[name].encoding = {**out[name].encoding, "_FillValue": None}
    for var in out.variables.values():
        if var.ndim > 0 and var.size > 0 and var.dtype.kind in "biuf":
            enc = {**var.encoding, "zlib": zlib_level > 0, "shuffle": zlib_level > 0}
            if zlib_level > 0:
                enc["complevel"] = zlib_level
            else:
                enc.pop("complevel", None)
            if checksum:
                enc["fletcher32"] = True
            var.encoding = enc
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        out.to_netcdf(tmp, engine="netcdf4")
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600: give the file the permissions of any other
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def netcdf_problem(path: str | os.PathLike[str]) -> str | None:
    """Why the netCDF file ``path`` cannot be trusted (one short line), or ``None`` if it reads back whole.

    Checks the signature, opens the file and reads every variable, which finds truncated and cut files
    and, for files written with ``checksum=True``, any byte that differs from what was written.
    """
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(8)
    except OSError as err:
        return f"cannot read ({err.strerror})"
    if not head:
        return "empty file"
    if head != HDF5_SIGNATURE and not head.startswith(b"CDF"):
        return "not a netCDF file (wrong signature)"
    import netCDF4  # noqa: PLC0415 - the HDF5 reader only for a file that looks like netCDF

    try:
        with netCDF4.Dataset(path) as nc:
            nc.set_auto_mask(False)
            for var in nc.variables.values():
                var[...]
    except Exception as err:
        text = str(err).splitlines()[0] if str(err) else ""
        return f"does not read back ({type(err).__name__}: {text})"
    return None


def set_aside_damaged(paths: list[str]) -> list[str]:
    """Rename every existing file of ``paths`` that :func:`netcdf_problem` rejects to ``<name>.damaged``.

    A damaged chunk then counts as missing, so Snakemake recomputes it instead of merging it; the
    damaged copy is kept for inspection.  Returns one line for each file set aside (path and problem).
    """
    moved = []
    for p in paths:
        if not os.path.exists(p):
            continue
        problem = netcdf_problem(p)
        if problem is None:
            continue
        os.replace(p, f"{p}.damaged")
        moved.append(f"{p} ({problem})")
    return moved


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


#: Suffixes of generated tables that :func:`write_text` gives their provenance.
TABLE_SUFFIXES = (".md", ".csv", ".json")
PROVENANCE_SIDECAR = ".provenance.json"


def provenance_sidecar(path: str | os.PathLike[str]) -> Path:
    """The file that holds the provenance of a CSV or JSON table: ``<name>.provenance.json``."""
    path = Path(path)
    return path.with_name(path.name + PROVENANCE_SIDECAR)


def write_text(text: str, path: str | os.PathLike[str], *, provenance: bool | None = None) -> Path:
    """Write a text file atomically (captions, Markdown and CSV tables).

    A table (``provenance`` None and a suffix in :data:`TABLE_SUFFIXES`, or ``provenance=True``) records
    where it was made (:func:`provenance_text`): a Markdown file ends with it as an HTML comment (not
    shown when rendered); a CSV or JSON file, which has no comment syntax every reader accepts, gets it
    in ``<name>.provenance.json`` beside it (:func:`provenance_sidecar`).
    """
    path = Path(path)
    if provenance is None:
        provenance = path.suffix.lower() in TABLE_SUFFIXES and not path.name.endswith(PROVENANCE_SIDECAR)
    if provenance and path.suffix.lower() == ".md":
        text = text.rstrip("\n") + "\n\n<!-- provenance\n" + provenance_text() + "-->\n"
    elif provenance:
        info = {"file": path.name, "geardyn_version": __version__, "git_commit": git_commit(), **runtime_provenance()}
        _write_atomic(json.dumps(info, indent=1) + "\n", provenance_sidecar(path))
    return _write_atomic(text, path)


def _write_atomic(text: str, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)
    return path


def read_provenance_text(text: str) -> dict[str, str]:
    """The ``key: value`` pairs of the provenance comment that :func:`write_text` put in a Markdown table."""
    start = text.rfind("<!-- provenance\n")
    if start < 0:
        return {}
    body = text[start + len("<!-- provenance\n") : text.find("-->", start)]
    return dict(line.split(": ", 1) for line in body.splitlines() if ": " in line)


def save_figure(fig: Any, path: str | os.PathLike[str], caption: str | None = None, dpi: int = 150) -> Path:
    """Save a matplotlib figure atomically, and its caption beside it as ``<name>.txt``.  The plots build
    :class:`matplotlib.figure.Figure` objects without pyplot (0.2-0.3 s of a figure job's start-up); a figure
    made with pyplot is closed after saving."""

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close(fig)
    os.replace(tmp, path)
    if caption is not None:
        write_text(caption.strip() + "\n", path.with_name(path.name + ".txt"))
    return path


def read_dataset(path: str | os.PathLike[str]) -> xr.Dataset:
    """Open a netCDF file, load it into memory and close it."""
    with xr.open_dataset(path) as ds:
        return ds.load()


def read_chunks(paths: list[str] | tuple[str, ...]) -> list[xr.Dataset]:
    """Load the chunk files of a merge; refuse any that does not read back whole.

    Runs inside the merge job (never while Snakemake plans): every damaged chunk is first set aside as
    ``<name>.damaged`` (kept for inspection), then one ``ValueError`` names them.  The chunk is then
    missing, so running the same command again recomputes exactly those chunks and merges.
    """
    moved = set_aside_damaged(list(paths))
    if moved:
        problems = ", ".join(moved)
        raise ValueError(
            f"damaged chunk(s) {problems} set aside as .damaged; run the same command again to recompute them"
        )
    parts = []
    for path in paths:
        with xr.open_dataset(path) as ds:
            parts.append(ds.load())
    return parts
