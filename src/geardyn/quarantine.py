"""Damaged netCDF files set aside: a merge never reads a truncated or corrupted chunk.

A chunk job writes atomically (:func:`geardyn.io.write_netcdf`), but a machine that dies or a disk that
fills can still leave a bad file.  :func:`read_chunks` checks every chunk of a merge first
(:func:`netcdf_problem`), renames the bad ones to ``<name>.damaged`` (:func:`set_aside_damaged`) and
refuses the merge by name, so that running the same command again recomputes exactly those chunks.
"""

from __future__ import annotations

import os
from pathlib import Path

import xarray as xr

from geardyn.io import read_dataset

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
    return [read_dataset(path) for path in paths]
