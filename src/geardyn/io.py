"""Self-describing netCDF output: CF-style global attributes, provenance, atomic writes.

Every dataset written by the pipeline goes through :func:`write_netcdf`, so every file
says where it came from (package version, git commit, config hash, model variant) and no
reader ever sees a half-written file (write to a temporary name, then rename).
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import os
import subprocess
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from geardyn import __version__

CONVENTIONS = "CF-1.10"
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
            cwd=where, capture_output=True, text=True, timeout=10, check=True,
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
    now = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()
    attrs: dict[str, str] = {
        "Conventions": CONVENTIONS,
        "title": title,
        "institution": "geardyn project",
        "source": f"geardyn {__version__}",
        "history": f"{now} created by geardyn {__version__}",
        "references": _reference(paper),
        "geardyn_version": __version__,
        "git_commit": git_commit(),
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
    from geardyn.papers import paper_of

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
) -> Path:
    """Write ``ds`` to ``path`` atomically (temporary file + rename) with global ``attrs`` merged in.

    Raises ``ValueError`` if a variable lacks ``units``/``long_name`` and ``require_cf`` is set, so
    no undocumented file is ever produced. Coordinate variables get no ``_FillValue`` (CF 2.5.1).
    With ``checksum`` every non-empty numeric variable is stored with HDF5's Fletcher-32 checksum,
    so that reading it back (:func:`netcdf_problem`) detects any damaged byte, not only truncation.
    """
    path = Path(path)
    out = ds.copy()
    out.attrs = {**ds.attrs, **(attrs or {})}
    if require_cf:
        missing = missing_cf_attributes(out)
        if missing:
            raise ValueError(f"dataset for {path.name} lacks CF attributes: {', '.join(missing)}")
    for name in out.coords:
        if name in out.dims and out[name].dtype.kind == "f":
            out[name].encoding = {**out[name].encoding, "_FillValue": None}
    if checksum:
        for name, var in out.variables.items():
            if var.ndim > 0 and var.size > 0 and var.dtype.kind in "biuf":
                var.encoding = {**var.encoding, "fletcher32": True}
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
    import netCDF4

    try:
        with netCDF4.Dataset(path) as nc:
            nc.set_auto_mask(False)
            for var in nc.variables.values():
                var[...]
    except Exception as err:  # noqa: BLE001 - any failure to read back is the answer
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


def write_text(text: str, path: str | os.PathLike[str]) -> Path:
    """Write a text file atomically (captions, Markdown tables)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)
    return path


def save_figure(fig: Any, path: str | os.PathLike[str], caption: str | None = None, dpi: int = 150) -> Path:
    """Save a matplotlib figure atomically, and its caption beside it as ``<name>.txt``."""
    import matplotlib.pyplot as plt

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
    plt.close(fig)
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
        raise ValueError(f"damaged chunk(s) {problems} set aside as .damaged; run the same command again to "
                         "recompute them")
    parts = []
    for path in paths:
        with xr.open_dataset(path) as ds:
            parts.append(ds.load())
    return parts
