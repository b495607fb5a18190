"""geardyn: reproducible nonlinear dynamics of planetary gear drives.

The library is pure: functions take numbers, arrays and frozen dataclasses and
return arrays or xarray Datasets.  File I/O lives in :mod:`geardyn.io` and the
Snakemake adapters in ``workflow/scripts``.
"""

__version__ = "0.1.0"
