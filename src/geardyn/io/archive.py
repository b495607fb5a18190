"""Archives of one design's results (:func:`build`: every netCDF cube, the configs, a sha256 manifest, a README,
and the archive's own sum beside it) and their check (:func:`verify`: any problem one :class:`ArchiveError` line
naming the archive and the member); the layout: ``docs/operations.md``, Archive."""

from __future__ import annotations

import datetime as _dt
import gzip
import hashlib
import io as _io
import json
import tarfile
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import xarray as xr
import yaml

from geardyn import __version__
from geardyn.io import atomic, write_text
from geardyn.io import provenance as prov
from geardyn.jsontypes import Json

MANIFEST = "MANIFEST.json"
SUMS = "SHA256SUMS"
FORMAT = 1

_README = """\
geardyn results archive: design {design}
==========================================

Made by geardyn {version} (git commit {commit}) on {created}.
Papers: Li et al. (2013), J. Vibroengineering 15(4) (KHV designs); Yue et al. (2014),
J. Vibroengineering 16(2) (plus planetary set).

Files
-----
results/   {n_cubes} netCDF-4 cubes, at the paths where the pipeline writes them (results/{design}/...)
config/    the workflow config file, the effective config the run used (defaults filled in), the design file
MANIFEST.json  sha256 and size of every file, geardyn version and git commit per cube
SHA256SUMS     the same sums, for `sha256sum -c SHA256SUMS` inside this folder

Check the archive (with geardyn installed):   geardyn verify-archive {design}_archive.tar.gz

Open a cube (Python, xarray + netCDF4):

    import xarray as xr
    ds = xr.open_dataset("{design}_archive/{example}")
    print(ds)                  # every variable has units and long_name
    print(ds.attrs["config_json"])   # the exact design and run settings behind it

or from a shell: ncdump -h {design}_archive/{example}

Every cube carries CF-1.10 global attributes (title, source, history, references) and its
provenance (geardyn_version, git_commit, config_hash, model_variant) and where it was computed
(python_version, numpy/scipy/numba/llvmlite/xarray/netcdf4/snakemake versions, cpu_model,
cpu_simd_flags, numpy_cpu_dispatch, numba_cpu_name, numba_cpu_features, libm_variant); `geardyn verify-archive`
prints them.  Every variable is stored compressed (zlib after the shuffle filter, lossless).
"""


class ArchiveError(ValueError):
    """An archive is unreadable, incomplete or altered; the message is one line for the user."""


@dataclass(frozen=True)
class Summary:
    """What :func:`verify` found in a good archive."""

    path: str
    design: str
    files: int
    cubes: int
    geardyn_version: str
    git_commit: str
    #: the distinct runtime provenances (:func:`geardyn.io.provenance.runtime_of`) of the cubes, and how many cubes each
    runtimes: tuple[tuple[dict[str, str], int], ...] = field(default_factory=tuple)
    #: whether the archive's own sum (``<archive>.sha256``) was beside it and matched
    own_sum: bool = False

    def line(self) -> str:
        return (
            f"{self.path}: OK{', its own sha256 matches' if self.own_sum else ''}, design {self.design}: {self.files} "
            f"files match their sha256, {self.cubes} netCDF cubes open (geardyn {self.geardyn_version}, commit "
            f"{self.git_commit})"
        )

    def text(self) -> str:
        """:meth:`line`, then where the cubes were computed: versions, CPU model, SIMD features in use."""
        lines = [self.line()]
        if not self.runtimes:
            lines.append("  no runtime provenance in the cubes (written before geardyn recorded it)")
        for k, (rt, n) in enumerate(self.runtimes, 1):
            lines.append(
                f"  computed with ({n} of {self.cubes} cubes{'' if len(self.runtimes) == 1 else f', set {k}'}):"
            )
            lines += [f"    {key}: {value}" for key, value in rt.items()]
        return "\n".join(lines)


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def build(
    out: str | Path,
    design: str,
    cubes: Mapping[str, str | Path],
    configs: Mapping[str, str | Path],
    effective_config: Mapping[str, Json] | None = None,
) -> dict[str, Json]:
    """Write the archive ``out`` (``.tar.gz``, atomically) and ``<out>.sha256``; return its manifest.  ``cubes`` maps
    a path inside the archive (``results/<design>/...``) to a file, ``configs`` a path inside ``config/``;
    ``effective_config`` (the validated workflow config) goes to ``config/effective_config.yaml``."""
    if not cubes:
        raise ArchiveError(f"{out}: no netCDF cube of design {design!r} to archive (its rules built none)")
    out = Path(out)
    top = f"{design}_archive"
    created = _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat()
    commit = prov.git_commit()
    members: dict[str, bytes] = {}
    entries: list[dict[str, Json]] = []

    def add(name: str, data: bytes, kind: str, extra: Mapping[str, str] | None = None) -> None:
        members[name] = data
        entries.append({"path": name, "kind": kind, "bytes": len(data), "sha256": sha256_bytes(data), **(extra or {})})

    for rel, src in sorted(configs.items()):
        add(f"config/{rel}", Path(src).read_bytes(), "config")
    if effective_config is not None:
        text = "# The workflow config as the run used it: validated, defaults filled in.\n" + yaml.safe_dump(
            json.loads(json.dumps(effective_config, default=str)), sort_keys=True
        )
        add("config/effective_config.yaml", text.encode(), "config")
    for rel, src in sorted(cubes.items()):
        with xr.open_dataset(src) as ds:  # the cube's provenance beside its sum
            made = {k: str(ds.attrs.get(k, "unknown")) for k in ("geardyn_version", "git_commit", "config_hash")}
            add(rel, Path(src).read_bytes(), "netcdf", made | prov.runtime_of(ds.attrs))
    example = min(cubes)
    readme = _README.format(
        design=design, version=__version__, commit=commit, created=created, n_cubes=len(cubes), example=example
    )
    add("README.txt", readme.encode(), "readme")
    manifest = {
        "format": FORMAT,
        "design": design,
        "geardyn_version": __version__,
        "git_commit": commit,
        "created": created,
        "files": entries,
    }
    add(SUMS, "".join(f"{e['sha256']}  {e['path']}\n" for e in entries).encode(), "sums")
    manifest_bytes = (json.dumps(manifest, indent=1) + "\n").encode()

    mtime = int(_dt.datetime.fromisoformat(created).timestamp())
    # the gzip header names no file and bears the archive's own time: the same members give the same bytes
    with (
        atomic(out) as tmp,
        tmp.open("wb") as raw,
        gzip.GzipFile("", "wb", fileobj=raw, mtime=mtime) as gz,
        tarfile.open(fileobj=gz, mode="w:") as tar,
    ):
        for name, data in [(MANIFEST, manifest_bytes), *sorted(members.items())]:
            info = tarfile.TarInfo(f"{top}/{name}")
            info.size, info.mtime, info.mode = len(data), mtime, 0o644
            tar.addfile(info, _io.BytesIO(data))
    write_text(f"{sha256_bytes(out.read_bytes())}  {out.name}\n", f"{out}.sha256")
    return manifest


def _own_sum(path: Path) -> bool:
    """Whether ``<archive>.sha256`` lies beside the archive; raise if it does and the archive's sha256 differs."""
    sums = Path(f"{path}.sha256")
    if not sums.is_file():
        return False
    expected, digest = sums.read_text(encoding="utf-8").partition(" ")[0], sha256_bytes(path.read_bytes())
    if digest != expected:
        raise ArchiveError(f"{path}: sha256 mismatch: {sums.name} {expected[:16]}..., archive {digest[:16]}...")
    return True


def _read_members(path: Path) -> tuple[str, dict[str, bytes]]:
    """All regular files of the archive by their name below the top folder, and the top folder.  The gzip
    stream is read to its end (its CRC-32 and length checked), past tar's end-of-archive blocks."""
    where = str(path)
    if not path.is_file():
        raise ArchiveError(f"{where}: file not found")
    members: dict[str, bytes] = {}
    tops = set()
    try:
        with gzip.open(path) as gz, tarfile.open(fileobj=gz, mode="r:") as tar:
            for info in tar:
                name = info.name
                if name.startswith("/") or ".." in Path(name).parts:
                    raise ArchiveError(f"{where}: unsafe member path {name!r}")
                if info.isdir():
                    continue
                if not info.isfile():
                    raise ArchiveError(f"{where}: member {name!r} is not a regular file")
                top, _, rest = name.partition("/")
                tops.add(top)
                fh = tar.extractfile(info)
                members[rest] = fh.read() if fh is not None else b""
            while gz.read(1 << 20):  # tar stops at its end-of-archive blocks; the stream goes on to its trailer
                pass
    except ArchiveError:
        raise
    except (tarfile.TarError, EOFError, OSError, zlib.error) as err:
        raise ArchiveError(f"{where}: not a readable .tar.gz archive (damaged or truncated: {err})") from None
    if len(tops) != 1:
        raise ArchiveError(f"{where}: expected one top folder, found {sorted(tops) or 'none'}")
    return tops.pop(), members


def verify(path: str | Path) -> Summary:
    """Check an archive written by :func:`build`; raise :class:`ArchiveError` on the first problem."""
    path = Path(path)
    where = str(path)
    top, members = _read_members(path)
    own_sum = _own_sum(path)
    if MANIFEST not in members:
        raise ArchiveError(f"{where}: no {top}/{MANIFEST} in the archive")
    try:
        manifest = json.loads(members.pop(MANIFEST).decode("utf-8"))
        entries = {e["path"]: e for e in manifest["files"]}
    except (ValueError, KeyError, TypeError) as err:
        raise ArchiveError(f"{where}: {top}/{MANIFEST} is not a valid manifest ({err})") from None
    for name, entry in entries.items():
        if name not in members:
            raise ArchiveError(f"{where}: {top}/{name} is listed in the manifest but missing from the archive")
        data = members[name]
        if len(data) != entry["bytes"]:
            raise ArchiveError(f"{where}: {top}/{name} has {len(data)} bytes, the manifest says {entry['bytes']}")
        digest = sha256_bytes(data)
        if digest != entry["sha256"]:
            raise ArchiveError(
                f"{where}: {top}/{name} sha256 mismatch: manifest {entry['sha256'][:16]}..., archive {digest[:16]}..."
            )
    extra = sorted(set(members) - set(entries))
    if extra:
        raise ArchiveError(f"{where}: {top}/{extra[0]} is in the archive but not in the manifest")
    cubes = [name for name, e in entries.items() if e["kind"] == "netcdf"]
    if not cubes:
        raise ArchiveError(f"{where}: the archive holds no netCDF cube")
    attrs: list[dict[str, Json]] = []
    for name in cubes:
        try:
            with xr.open_dataset(members[name], engine="netcdf4") as ds:  # from memory: verifying writes nothing
                attrs.append(dict(ds.load().attrs))
        except Exception as err:
            text = str(err).splitlines()
            raise ArchiveError(
                f"{where}: {top}/{name} does not open as netCDF ({type(err).__name__}: {text[0] if text else ''})"
            ) from None
    return Summary(
        where,
        str(manifest.get("design", "?")),
        len(entries),
        len(cubes),
        str(manifest.get("geardyn_version", "?")),
        str(manifest.get("git_commit", "?")),
        tuple(prov.distinct_runtimes(attrs)),
        own_sum,
    )
