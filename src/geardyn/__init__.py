"""geardyn: reproducible nonlinear dynamics of planetary gear drives.

The library is pure: functions take numbers, arrays and frozen dataclasses and
return arrays or xarray Datasets.  File I/O lives in :mod:`geardyn.io` (figures: :func:`geardyn.plots.save_figure`;
damaged chunks: :mod:`geardyn.quarantine`) and the Snakemake adapters in ``workflow/scripts``.

Importing geardyn sets two process settings.  First, before numpy loads OpenBLAS if it has not yet:
``OPENBLAS_CORETYPE`` = :data:`BLAS_CORETYPE`, whatever the environment says, and one OpenBLAS thread.
OpenBLAS otherwise picks its kernels by CPU (SkylakeX with AVX-512, Haswell/Zen with AVX2, ...), or
takes the environment's, and those round differently,
so eigenvalues and solves of the small matrices here (Floquet multipliers, Newton steps, the static
state) differed in the last bit between machines.  The Nehalem kernels (SSE4.2, no FMA) run on every
CPU numpy itself runs on (numpy's baseline is x86-64-v2) and give the same bits everywhere; they are
as fast as the native ones for 6 x 6 matrices (docs/reproducibility.md).  The Snakefile imports
geardyn first, so every job inherits the setting; :func:`geardyn.io.runtime_provenance` records the
kernels actually in use.

Second, ``GLIBC_TUNABLES`` (:mod:`geardyn.libm`): the processes started after the import (the
Snakemake jobs, the test workers) run the C library's plain math functions instead of the builds with
fused multiply-adds that glibc picks on CPUs with FMA, so ``sin``, ``exp``, ``atan`` ... give the same
bits on every x86-64 CPU.  The running process keeps the build it started with; the entry points restart
themselves with the setting, and the provenance records the build in use (``libm_variant``).
"""

import os as _os

__version__ = "0.1.0"

#: OpenBLAS kernels used on x86-64 (the same bits on every CPU); see the module docstring.
BLAS_CORETYPE = "Nehalem"

# Before numpy loads OpenBLAS (geardyn.libm imports numpy): the kernels whatever the environment says.
_os.environ.update({"OPENBLAS_CORETYPE": BLAS_CORETYPE, "OPENBLAS_NUM_THREADS": "1"})

from geardyn import libm as _libm  # noqa: E402  (after the setting above: it loads numpy)

assert _libm.BLAS_CORETYPE == BLAS_CORETYPE
_os.environ.update(_libm.canonical_environ(_os.environ))
