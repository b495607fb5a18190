"""Self-describing outputs, written atomically: netCDF with CF attributes, compressed losslessly, and tables, each
with its provenance (:mod:`geardyn.io.provenance`; ``docs/operations.md``, Compression and provenance)."""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr
from numpy.typing import DTypeLike

from geardyn.io import provenance
from geardyn.jsontypes import Json

#: zlib level of every netCDF variable (with the shuffle filter); measured in docs/operations.md.
ZLIB_LEVEL = 1


@dataclass(frozen=True)
class Var:
    """One CF variable of an output, a row of its writer's table.  ``units``: None for a flag or a name; ``flags``
    (meaning -> code, as every code table of the package) give ``flag_values`` in the variable's ``dtype`` (int8
    unless given) and ``flag_meanings``; ``fill``: where nothing was computed; ``attrs``: the other attributes."""

    name: str
    dims: str | tuple[str, ...]
    units: str | None
    long_name: str
    flags: Mapping[str, int] | None = None
    dtype: DTypeLike | None = None
    fill: Json = np.nan
    attrs: Mapping[str, Json] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "dims", (self.dims,) if isinstance(self.dims, str) else tuple(self.dims))
        if self.flags is not None and self.dtype is None:
            object.__setattr__(self, "dtype", np.int8)

    def attributes(self) -> dict[str, Json]:
        """The CF attributes: ``units``, ``long_name``, the flags', the others."""
        out: dict[str, Json] = ({} if self.units is None else {"units": self.units}) | {"long_name": self.long_name}
        if self.flags is not None:
            out["flag_values"] = np.array(list(self.flags.values()), self.dtype)
            out["flag_meanings"] = " ".join(self.flags)
        return out | dict(self.attrs)

    def __call__(self, values: Json) -> tuple[tuple[str, ...], Json, dict[str, Json]]:
        """The variable holding ``values`` (in its dtype) as :class:`xarray.Dataset` takes it."""
        dims: tuple[str, ...] = self.dims  # type: ignore[assignment]  # a tuple after __post_init__
        return dims, values if self.dtype is None else np.asarray(values, self.dtype), self.attributes()

    def empty(self, shape: tuple[int, ...]) -> tuple[tuple[str, ...], Json, dict[str, Json]]:
        """The variable of ``shape`` holding its fill value."""
        return self(np.full(shape, self.fill, self.dtype))


def variables(table: Iterable[Var], values: Mapping[str, Json] | Iterable[Json]) -> dict[str, tuple]:
    """The variables of ``table`` holding ``values`` (by name, or in the table's order) as xarray takes them."""
    table = list(table)
    named = values if isinstance(values, Mapping) else dict(zip([v.name for v in table], values, strict=True))
    return {v.name: v(named[v.name]) for v in table}


def dataset(table: Iterable[Var], values: Mapping[str, Json] | Iterable[Json], **attrs: Json) -> xr.Dataset:
    """The Dataset of :func:`variables` in the table's order (a variable named as its dimension is a coordinate),
    with the global ``attrs``."""
    return xr.Dataset(variables(table, values), attrs=attrs)


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[Json]], align: str = "") -> str:
    """A GitHub Markdown table: ``header``, its rule, a line per row (cells as ``str``, a ``|`` as ``/``: it would
    end the cell).  ``align``: a letter per column, ``r`` right, ``c`` centred, ``l`` left, ``-`` (or none) as is."""
    rule = [{"r": "---:", "c": ":---:", "l": ":---"}.get(a, "---") for a in align.ljust(len(header))]
    lines = ["| " + " | ".join(str(c).replace("|", "/") for c in cells) + " |" for cells in (header, *rows)]
    return "\n".join([lines[0], "|" + "|".join(rule) + "|", *lines[1:]])


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
    checksum: bool = False,
    zlib_level: int = ZLIB_LEVEL,
) -> Path:
    """Write ``ds`` to ``path`` atomically (temporary file + rename) with global ``attrs`` and
    :func:`geardyn.io.provenance.runtime` merged in; refuse a variable without ``units``/``long_name``.
    Numeric variables: shuffle + zlib at ``zlib_level`` (0 = off), Fletcher-32 with ``checksum``; coordinates
    without ``_FillValue`` (CF 2.5.1).  Why each: ``docs/operations.md``, Compression and provenance."""
    if not 0 <= zlib_level <= 9:
        raise ValueError(f"zlib_level must be 0 (off) to 9, got {zlib_level}")
    path = Path(path)
    out = ds.copy()
    out.attrs = {**ds.attrs, **(attrs or {}), **provenance.runtime()}
    missing = missing_cf_attributes(out)
    if missing:
        raise ValueError(f"dataset for {path.name} lacks CF attributes: {', '.join(missing)}")
    for name in out.coords:
        if name in out.dims and out[name].dtype.kind == "f":
            out[name].encoding = {**out[name].encoding, "_FillValue": None}
    for var in out.variables.values():
        if var.ndim > 0 and var.size > 0 and var.dtype.kind in "biuf":
            enc = {**var.encoding, "zlib": zlib_level > 0, "shuffle": zlib_level > 0, "complevel": zlib_level}
            if not zlib_level:
                del enc["complevel"]
            if checksum:
                enc["fletcher32"] = True
            var.encoding = enc
    with atomic(path) as tmp:
        out.to_netcdf(tmp, engine="netcdf4")
    return path


@contextmanager
def atomic(path: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary file beside ``path`` for the block to write, renamed to ``path`` when it ends (removed if it
    raises), the one writer of every output; a disk that fails it (full, quota) raises an :class:`OSError` naming
    ``path``, also where the writer named no errno (netCDF's "HDF error": one block appended asks the disk)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        try:
            yield Path(tmp)
        except OSError as err:
            err.filename = str(path) if err.filename in (None, tmp) else err.filename
            raise
        except Exception:
            try:
                with open(tmp, "ab", buffering=0) as fh:
                    fh.write(bytes(os.statvfs(tmp).f_bsize))
                    os.fsync(fh.fileno())
            except OSError as err:
                raise OSError(err.errno, err.strerror, str(path)) from None
            raise
        mask = os.umask(0)  # read, then restore: mkstemp makes 0600, the file gets the permissions of any other
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


#: Suffixes of generated tables that :func:`write_text` gives their provenance.
TABLE_SUFFIXES = (".md", ".csv", ".json")
PROVENANCE_SIDECAR = ".provenance.json"


def provenance_sidecar(path: str | os.PathLike[str]) -> Path:
    """The file that holds the provenance of a CSV or JSON table: ``<name>.provenance.json``."""
    path = Path(path)
    return path.with_name(path.name + PROVENANCE_SIDECAR)


def write_text(text: str, path: str | os.PathLike[str]) -> Path:
    """Write a text file atomically (captions, Markdown and CSV tables).  A table (a suffix of
    :data:`TABLE_SUFFIXES`) records :func:`provenance_text`: Markdown in a closing HTML comment, CSV and JSON
    (no comment syntax every reader accepts) in :func:`provenance_sidecar`."""
    path = Path(path)
    if path.suffix.lower() == ".md":
        text = text.rstrip("\n") + "\n\n<!-- provenance\n" + provenance.provenance_text() + "-->\n"
    elif path.suffix.lower() in TABLE_SUFFIXES and not path.name.endswith(PROVENANCE_SIDECAR):
        with atomic(provenance_sidecar(path)) as tmp:
            tmp.write_text(json.dumps({"file": path.name, **provenance.info()}, indent=1) + "\n", encoding="utf-8")
    with atomic(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def read_dataset(path: str | os.PathLike[str]) -> xr.Dataset:
    """Open a netCDF file, load it into memory and close it."""
    with xr.open_dataset(path) as ds:
        return ds.load()
