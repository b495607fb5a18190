"""Damaged netCDF files set aside: a merge never reads a truncated or corrupted chunk (``docs/operations.md``, Damaged
chunk)."""

from __future__ import annotations

import os
from pathlib import Path

import xarray as xr

from geardyn.io import read_dataset

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def netcdf_problem(path: str | os.PathLike[str]) -> str | None:
    """Why the netCDF file ``path`` cannot be trusted (one short line), or ``None`` if it reads back whole: the
    signature, then every variable read (with ``checksum=True`` files, any altered byte is found too)."""
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


def read_chunks(paths: list[str] | tuple[str, ...]) -> list[xr.Dataset]:
    """Load the chunk files of a merge (inside the merge job, never while Snakemake plans).  Every existing chunk
    that :func:`netcdf_problem` rejects is first renamed to ``<name>.damaged`` (kept for inspection), then one
    ``ValueError`` names them: the chunk is missing, so the same command again recomputes exactly those."""
    moved = []
    for p in paths:
        problem = netcdf_problem(p) if os.path.exists(p) else None
        if problem is not None:
            os.replace(p, f"{p}.damaged")
            moved.append(f"{p} ({problem})")
    if moved:
        problems = ", ".join(moved)
        raise ValueError(
            f"damaged chunk(s) {problems} set aside as .damaged; run the same command again to recompute them"
        )
    return [read_dataset(path) for path in paths]
