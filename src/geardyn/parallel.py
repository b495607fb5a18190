"""One thread-pool map for the Python parts of a batch run (numba's loops and numpy's array work
release the GIL)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

T = TypeVar("T")
R = TypeVar("R")


def threaded_map(fn: Callable[[T], R], items: Sequence[T], min_items: int = 2, chunksize: int = 1) -> list[R]:
    """``[fn(x) for x in items]``, in a thread pool as wide as the numba thread count when there are at
    least ``min_items`` items.  The items must be independent, so the results do not depend on the
    threads."""
    import numba  # noqa: PLC0415 - loaded by every job that computes; not by those that read results

    workers = numba.get_num_threads()
    if workers <= 1 or len(items) < min_items:
        return [fn(x) for x in items]
    with ThreadPoolExecutor(workers) as ex:
        return list(ex.map(fn, items, chunksize=chunksize))
