"""Every netCDF output of a build in one :class:`xarray.DataTree`: ``results/<design>/<kind>/<name>.nc`` becomes
the node ``/<design>/<kind>/<name>`` (``benchmarks/<name>.nc`` the node ``/benchmarks/<name>``).

Lazy in two ways.  The tree holds each file's header only: its dimensions, coordinates, attributes and the
shapes of its variables (read when the tree is built, the file closed again at once: no handle is kept, so a
tree of every file of a build does not exhaust the process's file descriptors).  A variable's values are read
from its file only when they are used (xarray's lazily indexed backend arrays, the file reopened for the read).
"""

from __future__ import annotations

import os
from pathlib import Path

import xarray as xr

#: The global attribute of each node that names the file it was read from.
SOURCE = "source_file"


def result_files(path: str | os.PathLike[str] = "results") -> list[Path]:
    """The merged netCDF outputs below ``path``: every ``*.nc`` but the chunks of a study still being merged
    (``<study>/chunk_<i>.nc``) and the temporary files of a writer (hidden names)."""
    root = Path(path)
    return sorted(
        p
        for p in root.rglob("*.nc")
        if not p.name.startswith(("chunk_", "."))
        and not any(part.startswith(".") for part in p.relative_to(root).parts)
    )


def _header(path: Path) -> xr.Dataset:
    """The dataset of ``path`` with no value read (coordinates of a dimension excepted: xarray indexes them),
    its file closed; the values are read on use.  ``SOURCE``: the file's path."""
    ds = xr.open_dataset(path, engine="netcdf4", cache=False)
    ds.close()
    ds.attrs[SOURCE] = str(path)
    return ds


def open_results(path: str | os.PathLike[str] = "results") -> xr.DataTree:
    """The tree of every output below ``path`` (see the module docstring): one node per design, under it one per
    study kind (``sweeps``, ``maps``, ``curves``, ``points``, ``orbits``, ``response``, ``probabilities``,
    ``data``, ``calibration``), under that one per file with the file's attributes (its provenance) and
    variables; ``ds.geardyn`` reads each node's labels by name and draws its figure."""
    root = Path(path)
    if not root.is_dir():
        raise FileNotFoundError(f"results path {str(root)!r}: not a directory (run the workflow first)")
    files = result_files(root)
    if not files:
        raise FileNotFoundError(f"results path {str(root)!r}: no netCDF output below it (run the workflow first)")
    return xr.DataTree.from_dict({"/" + p.relative_to(root).with_suffix("").as_posix(): _header(p) for p in files})
