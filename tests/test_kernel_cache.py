"""numba's cache of the compiled loops is renewed as a whole when any kernel source changes
(:mod:`geardyn.solve._cache`): numba itself renews a function's cache only when its own file changes."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from numba.core.caching import _CacheLocator

from geardyn.solve import _cache


def _copy_sources(tmp_path: Path) -> Path:
    folder = tmp_path / "solve"
    folder.mkdir()
    for name in _cache.SOURCES:
        shutil.copy(Path(_cache.__file__).parent / name, folder / name)
    return folder


def _cached(where: Path) -> list[str]:
    return sorted(f.name for f in where.glob("*.nb?"))


def test_cache_is_deleted_when_any_source_changes_and_kept_otherwise(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    folder = _copy_sources(tmp_path)
    where = folder / "__pycache__"
    assert _cache.cache_dir(folder) == where
    where.mkdir()
    files = ["_batch.run_batch-44.py311.1.nbc", "_batch.run_batch-44.py311.nbi", "_kernel.run-237.py311.nbi"]

    def fill() -> None:
        for name in files:
            (where / name).write_bytes(b"compiled")

    fill()
    assert _cache.renew(folder)  # no stamp yet: made from unknown sources
    assert _cached(where) == [] and (where / _cache.STAMP).read_text().strip() == _cache.sources_hash(folder)
    fill()
    assert not _cache.renew(folder) and _cached(where) == sorted(files)  # the same sources: kept
    with (folder / "_model.py").open("a") as f:  # a change in a called file only
        f.write("# changed\n")
    assert _cache.renew(folder) and _cached(where) == []
    assert (where / _cache.STAMP).read_text().strip() == _cache.sources_hash(folder)
    (where / "other.pyc").write_bytes(b"")
    fill()
    (folder / "base.py").write_text((folder / "base.py").read_text() + "# the layout's constants\n")
    assert _cache.renew(folder) and (where / "other.pyc").exists()  # only numba's files go


def test_cache_dir_is_numbas_own(tmp_path, monkeypatch):
    folder = _copy_sources(tmp_path)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    sub = _CacheLocator.get_suitable_cache_subpath(str(folder / "_kernel.py"))
    assert _cache.cache_dir(folder) == tmp_path / "numba" / sub
    where = _cache.cache_dir(folder)
    where.mkdir(parents=True)
    (where / "_kernel.run-237.py311.nbi").write_bytes(b"")
    assert _cache.renew(folder) and _cached(where) == []


def test_sources_hash_reads_every_source(tmp_path):
    folder = _copy_sources(tmp_path)
    before = _cache.sources_hash(folder)
    for name in _cache.SOURCES:
        text = (folder / name).read_bytes()
        (folder / name).write_bytes(text + b"\n")
        assert _cache.sources_hash(folder) != before, name
        (folder / name).write_bytes(text)
    assert _cache.sources_hash(folder) == before
    (folder / "_kernel.py").unlink()
    with pytest.raises(FileNotFoundError):
        _cache.sources_hash(folder)


def test_every_cached_module_is_a_source_and_imports_the_renewal():
    """Every module of geardyn.solve with cached loops is hashed, and calls the renewal before its loops."""
    folder = Path(_cache.__file__).parent
    cached = {f.name for f in folder.glob("*.py") if "@njit(cache=True" in f.read_text()}
    assert cached and cached <= set(_cache.SOURCES)
    for name in cached:
        text = (folder / name).read_text()
        assert "\n_cache.renew_once()" in text, name
        assert text.index("\n_cache.renew_once()") < text.index("\n@njit"), name
