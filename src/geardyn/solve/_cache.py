"""numba's on-disk cache of the compiled loops, renewed as a whole when any of their sources changes.
Private to :mod:`geardyn.solve`; every module with ``cache=True`` loops calls :func:`renew_once` before
defining them (why: numba keys a cache on its own file only; ``docs/numerics.md``)."""

from __future__ import annotations

import functools
import hashlib
import os
from pathlib import Path

#: the files whose code or constants the compiled loops of this package contain
SOURCES = ("base.py", "_model.py", "_kernel.py", "_period.py", "_batch.py", "_response.py", "reference.py")
#: the file beside the cache that holds the hash of :data:`SOURCES` the cache was made from
STAMP = "geardyn-kernels.sha256"

_HERE = Path(os.path.abspath(__file__)).parent  # as numba names the sources (not resolved)


def sources_hash(folder: Path = _HERE) -> str:
    """SHA-256 of the :data:`SOURCES` in ``folder``, in that order (their bytes and names)."""
    h = hashlib.sha256()
    for name in SOURCES:
        h.update(name.encode() + b"\0" + (folder / name).read_bytes() + b"\0")
    return h.hexdigest()


def cache_dir(folder: Path = _HERE) -> Path | None:
    """Where numba caches the loops of the modules in ``folder``: under ``NUMBA_CACHE_DIR`` (numba's
    sub-folder: the folder's name and the SHA-1 of its path) when set, else ``folder/__pycache__`` when
    ``folder`` is writable; None otherwise (numba's per-user cache, not renewed here)."""
    root = os.environ.get("NUMBA_CACHE_DIR", "")
    if root:
        return Path(root) / f"{folder.name}_{hashlib.sha1(str(folder).encode()).hexdigest()}"
    return folder / "__pycache__" if os.access(folder, os.W_OK) else None


def renew(folder: Path = _HERE) -> bool:
    """Delete the numba cache files of the modules in ``folder`` when they were made from other sources
    than the present ones (the stamp is missing or holds another hash), then write the stamp.  Returns
    whether files were deleted."""
    where = cache_dir(folder)
    if where is None:
        return False
    stamp, now = where / STAMP, sources_hash(folder)
    try:
        if stamp.read_text().strip() == now:
            return False
    except OSError:
        pass
    stale = [f for ext in ("*.nbi", "*.nbc") for f in where.glob(ext)] if where.is_dir() else []
    for f in stale:
        f.unlink(missing_ok=True)
    try:
        where.mkdir(parents=True, exist_ok=True)
        tmp = where / f"{STAMP}.{os.getpid()}"
        tmp.write_text(now + "\n")
        tmp.replace(stamp)
    except OSError:
        pass  # an unwritable cache: numba does not write there either
    return bool(stale)


@functools.cache
def renew_once() -> bool:
    """:func:`renew` of this package's cache, once per process: the first of its compiled modules to be
    imported hashes the sources, the others reuse the answer."""
    return renew()
