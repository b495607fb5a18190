"""geardyn: reproducible nonlinear dynamics of planetary gear drives.

A pure library (numbers, arrays and frozen dataclasses in, arrays or xarray Datasets out; files:
:mod:`geardyn.io`).  Importing it fixes OpenBLAS's kernels (:data:`BLAS_CORETYPE`, one thread) and the C
library's math build of the processes it starts (:mod:`geardyn.libm`): ``docs/reproducibility.md``.  It registers
``ds.geardyn`` (:mod:`geardyn.accessor`) and ``ds.cf`` on every xarray Dataset; ``geardyn.open_results`` opens a
build's outputs as one tree (``docs/notebook.md``).
"""

import importlib as _importlib
import os as _os

__version__ = "0.1.0"

#: OpenBLAS kernels used on x86-64 (the same bits on every CPU): docs/reproducibility.md sections 0 and 2.
BLAS_CORETYPE = "Nehalem"

# Before numpy loads OpenBLAS (geardyn.libm imports numpy): the kernels whatever the environment says.
_os.environ.update({"OPENBLAS_CORETYPE": BLAS_CORETYPE, "OPENBLAS_NUM_THREADS": "1"})

from geardyn import libm as _libm  # noqa: E402  (after the setting above: it loads numpy)

assert _libm.BLAS_CORETYPE == BLAS_CORETYPE
_os.environ.update(_libm.canonical_environ(_os.environ))

#: Names loaded on first use: ``geardyn.open_results`` (every output of a build in one tree) and ``geardyn.simulate``.
_HOMES = {"open_results": "geardyn.io.tree", "simulate": "geardyn.solve"}


def __getattr__(name: str) -> object:
    if name in _HOMES:
        return getattr(_importlib.import_module(_HOMES[name]), name)
    raise AttributeError(f"module 'geardyn' has no attribute {name!r}")


# ds.geardyn and ds.cf on every xarray Dataset (docs/notebook.md).  Loaded by name, last: the accessor uses the
# package's own modules (io, label), which import this package; a static import here would make the package
# depend on every one of them.
_importlib.import_module("geardyn.accessor")
