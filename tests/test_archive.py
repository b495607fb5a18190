"""Results archives: what build() writes verifies; every kind of damage is refused with one line."""

import datetime
import gzip
import hashlib
import io as _io
import json
import tarfile

import numpy as np
import pytest
import xarray as xr

from geardyn import __version__, cli, io
from geardyn.io import archive, provenance


def _cube(n=5):
    x = np.linspace(0, 1, n)
    return xr.Dataset(
        {"k": ("x1", x**2, {"units": "N m-1", "long_name": "stiffness"})},
        coords={"x1": ("x1", x, {"units": "1", "long_name": "profile shift"})},
    )


@pytest.fixture
def built(tmp_path):
    data = tmp_path / "src"
    a = io.write_netcdf(_cube(), data / "a.nc", provenance.attributes(title="a", paper="li2013"))
    b = io.write_netcdf(_cube(7), data / "sweeps" / "b.nc", provenance.attributes(title="b", paper="li2013"))
    cfg = data / "config.yaml"
    cfg.write_text("designs: {d: config/designs/d.yaml}\n")
    des = data / "d.yaml"
    des.write_text("kind: khv\nname: d\n")
    out = tmp_path / "d_archive.tar.gz"
    manifest = archive.build(
        out,
        "d",
        {"results/d/a.nc": a, "results/d/sweeps/b.nc": b},
        {"config.yaml": cfg, "designs/d.yaml": des},
        effective_config={"designs": {"d": "config/designs/d.yaml"}},
    )
    return out, manifest


def _members(path):
    with tarfile.open(path, "r:gz") as tar:
        return {m.name: tar.extractfile(m).read() for m in tar if m.isfile()}


def _repack(members, path):
    with tarfile.open(path, "w:gz") as tar:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, _io.BytesIO(data))
    return path


def test_archive_holds_cubes_configs_manifest_and_readme(built):
    out, manifest = built
    members = _members(out)
    assert set(members) == {
        f"d_archive/{n}"
        for n in (
            "MANIFEST.json",
            "SHA256SUMS",
            "README.txt",
            "config/config.yaml",
            "config/designs/d.yaml",
            "config/effective_config.yaml",
            "results/d/a.nc",
            "results/d/sweeps/b.nc",
        )
    }
    listed = json.loads(members["d_archive/MANIFEST.json"])
    assert listed == manifest
    assert listed["geardyn_version"] == __version__ and listed["git_commit"] == provenance.git_commit()
    for entry in listed["files"]:  # sums computed independently of the module
        assert hashlib.sha256(members[f"d_archive/{entry['path']}"]).hexdigest() == entry["sha256"]
    cube = next(e for e in listed["files"] if e["path"] == "results/d/a.nc")
    assert cube["kind"] == "netcdf" and cube["geardyn_version"] == __version__
    sums = members["d_archive/SHA256SUMS"].decode().splitlines()
    assert f"{cube['sha256']}  results/d/a.nc" in sums  # the format `sha256sum -c` reads
    readme = members["d_archive/README.txt"].decode()
    assert "xr.open_dataset" in readme and "geardyn verify-archive d_archive.tar.gz" in readme


def test_the_gzip_header_names_no_file_and_bears_the_archives_time(built):
    """RFC 1952: FLG bit 3 (FNAME) unset, MTIME (bytes 4-7, little-endian) the manifest's creation time, so the
    same members give the same bytes whatever temporary name the writer used."""
    out, manifest = built
    head = out.read_bytes()[:10]
    assert head[:3] == b"\x1f\x8b\x08" and head[3] & 0x08 == 0
    created = datetime.datetime.fromisoformat(manifest["created"])
    assert int.from_bytes(head[4:8], "little") == int(created.timestamp())


def test_good_archive_verifies(built, capsys):
    out, _ = built
    summary = archive.verify(out)
    assert (summary.files, summary.cubes, summary.design, summary.own_sum) == (7, 2, "d", True)
    assert cli.main(["verify-archive", str(out)]) == 0
    assert "OK, its own sha256 matches" in capsys.readouterr().out
    # the archive's own sum beside it, as `sha256sum -c` reads it (computed independently of the module)
    digest = hashlib.sha256(out.read_bytes()).hexdigest()
    assert (out.parent / f"{out.name}.sha256").read_text() == f"{digest}  {out.name}\n"


def test_a_byte_flipped_anywhere_is_refused(built, tmp_path):
    """A byte flipped at 50 seeded positions: the gzip header's time stamp, 30 drawn, and the last 16 bytes
    (deflate's last block and the gzip trailer, CRC-32 and length, which tar never reads: it stops at its
    end-of-archive blocks).  Each is refused by the archive's own sum, and beyond the header (its time stamp,
    flags, OS and file name are under no CRC) also without it: the whole gzip stream is read."""
    data = built[0].read_bytes()
    header = data.index(b"\0", 10) + 1 if data[3] & 0x08 else 10  # with the file name (FNAME) the header holds
    drawn = np.random.default_rng(0).choice(np.arange(header, len(data) - 16), 30, replace=False)
    positions = [4, 5, 6, 7, *drawn, *range(len(data) - 16, len(data))]
    (tmp_path / "bad").mkdir()
    bad, own_sum = tmp_path / "bad" / built[0].name, tmp_path / "bad" / f"{built[0].name}.sha256"
    for pos in positions:
        flipped = bytearray(data)
        flipped[pos] ^= 0xFF
        bad.write_bytes(flipped)
        own_sum.write_bytes((built[0].parent / own_sum.name).read_bytes())
        with pytest.raises(archive.ArchiveError):
            archive.verify(bad)
        own_sum.unlink()
        if pos >= header:
            with pytest.raises(archive.ArchiveError):
                archive.verify(bad)
    assert len(set(positions)) == 50


def _flip_member(out, name, tmp_path):
    members = _members(out)
    data = bytearray(members[f"d_archive/{name}"])
    data[len(data) // 2] ^= 0xFF
    members[f"d_archive/{name}"] = bytes(data)
    return _repack(members, tmp_path / "bad.tar.gz")


def _cube_replaced_and_relisted(out, tmp_path):
    """A damaged cube whose manifest entry was recomputed: only opening the cube finds it."""
    members = _members(out)
    bad = members["d_archive/results/d/a.nc"][:200]
    members["d_archive/results/d/a.nc"] = bad
    manifest = json.loads(members["d_archive/MANIFEST.json"])
    for entry in manifest["files"]:
        if entry["path"] == "results/d/a.nc":
            entry.update(bytes=len(bad), sha256=hashlib.sha256(bad).hexdigest())
    members["d_archive/MANIFEST.json"] = json.dumps(manifest).encode()
    return _repack(members, tmp_path / "bad.tar.gz")


def _truncated(out, tmp_path):
    data = out.read_bytes()
    bad = tmp_path / "bad.tar.gz"
    bad.write_bytes(data[: len(data) // 2])
    return bad


def _without(name):
    def make(out, tmp_path):
        members = _members(out)
        del members[f"d_archive/{name}"]
        return _repack(members, tmp_path / "bad.tar.gz")

    return make


def _with_extra(out, tmp_path):
    members = _members(out)
    members["d_archive/results/d/extra.nc"] = b"not listed"
    return _repack(members, tmp_path / "bad.tar.gz")


def _not_gzip(out, tmp_path):
    bad = tmp_path / "bad.tar.gz"
    bad.write_bytes(b"this is not an archive\n")
    return bad


def _plain_gzip(out, tmp_path):
    bad = tmp_path / "bad.tar.gz"
    bad.write_bytes(gzip.compress(b"a gzip file that holds no tar"))
    return bad


DAMAGE = [
    (lambda out, tmp: _flip_member(out, "results/d/a.nc", tmp), "results/d/a.nc sha256 mismatch"),
    (lambda out, tmp: _flip_member(out, "config/designs/d.yaml", tmp), "config/designs/d.yaml sha256 mismatch"),
    (_cube_replaced_and_relisted, "results/d/a.nc does not open as netCDF"),
    (_truncated, "not a readable .tar.gz archive (damaged or truncated"),
    (_without("results/d/sweeps/b.nc"), "results/d/sweeps/b.nc is listed in the manifest but missing from the archive"),
    (_without("MANIFEST.json"), "no d_archive/MANIFEST.json in the archive"),
    (_with_extra, "results/d/extra.nc is in the archive but not in the manifest"),
    (_not_gzip, "not a readable .tar.gz archive"),
    (_plain_gzip, "not a readable .tar.gz archive"),
]


@pytest.mark.parametrize(("damage", "message"), DAMAGE)
def test_damaged_archive_is_refused_with_one_line(built, tmp_path, capsys, damage, message):
    out, _ = built
    bad = damage(out, tmp_path)
    with pytest.raises(archive.ArchiveError) as info:
        archive.verify(bad)
    text = str(info.value)
    assert message in text and text.startswith(str(bad)) and "\n" not in text
    assert cli.main(["verify-archive", str(bad)]) == 1
    err = capsys.readouterr().err
    assert err.strip() == f"error: {text}"


def test_missing_archive(tmp_path):
    with pytest.raises(archive.ArchiveError, match="file not found"):
        archive.verify(tmp_path / "none.tar.gz")


def test_an_archive_without_cubes_is_an_error(tmp_path, built):
    cfg = tmp_path / "config.yaml"
    cfg.write_text("designs: {d: config/designs/d.yaml}\n")
    with pytest.raises(archive.ArchiveError, match="no netCDF cube of design 'd'"):
        archive.build(tmp_path / "empty" / "d_archive.tar.gz", "d", {}, {"config.yaml": cfg})
    assert not (tmp_path / "empty").exists()
    # an archive whose cubes were all taken out, manifest and all, does not verify either
    members = {k: v for k, v in _members(built[0]).items() if not k.endswith(".nc")}
    manifest_name = next(k for k in members if k.endswith("MANIFEST.json"))
    manifest = json.loads(members[manifest_name])
    manifest["files"] = [e for e in manifest["files"] if e["kind"] != "netcdf"]
    members[manifest_name] = json.dumps(manifest).encode()
    with pytest.raises(archive.ArchiveError, match="holds no netCDF cube"):
        archive.verify(_repack(members, tmp_path / "empty_archive.tar.gz"))
