"""Names that a package loads from its submodules on first use (PEP 562 module ``__getattr__``), so that
importing the package, or a light submodule of it, does not import the heavy ones (numba and the compiled
loops): each workflow job is a new process, and its imports are its start-up."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any


# Any: a package's __getattr__ returns whichever attribute is named (a module, a function, a class).
def lazy_attributes(package: str, homes: Mapping[str, str]) -> Callable[[str], Any]:
    """The module ``__getattr__`` of ``package`` that loads each name of ``homes`` (name -> submodule) from
    its submodule on first use, and raises AttributeError for any other name."""

    def __getattr__(name: str) -> Any:
        if name in homes:
            return getattr(importlib.import_module(f"{package}.{homes[name]}"), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
