"""geardyn: reproducible nonlinear dynamics of planetary gear drives.

A pure library (numbers, arrays and frozen dataclasses in, arrays or xarray Datasets out; files:
:mod:`geardyn.io`).  Importing it fixes OpenBLAS's kernels (:data:`BLAS_CORETYPE`, one thread) and the C
library's math build of the processes it starts (:mod:`geardyn.libm`): ``docs/reproducibility.md``.
"""

import os as _os

__version__ = "0.1.0"

#: OpenBLAS kernels used on x86-64 (the same bits on every CPU): docs/reproducibility.md sections 0 and 2.
BLAS_CORETYPE = "Nehalem"

# Before numpy loads OpenBLAS (geardyn.libm imports numpy): the kernels whatever the environment says.
_os.environ.update({"OPENBLAS_CORETYPE": BLAS_CORETYPE, "OPENBLAS_NUM_THREADS": "1"})

from geardyn import libm as _libm  # noqa: E402  (after the setting above: it loads numpy)

assert _libm.BLAS_CORETYPE == BLAS_CORETYPE
_os.environ.update(_libm.canonical_environ(_os.environ))

# ds.geardyn and ds.cf on every xarray Dataset (geardyn.accessor); open_results and simulate loaded on first use.
from geardyn import accessor as _accessor  # noqa: E402, F401
from geardyn._lazy import lazy_attributes as _lazy_attributes  # noqa: E402

__getattr__ = _lazy_attributes("geardyn", {"open_results": "io.tree", "simulate": "solve"})
