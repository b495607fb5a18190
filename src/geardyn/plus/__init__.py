"""Paper 2 (Yue et al. 2014): plus (double-planet) planetary gear set.

Modules
-------
design    frozen dataclasses from a schema-validated dict (``design_from_dict``, ``default_design``)
modal     11-DOF Lagrangian model: ``matrices``, ``modes``, energy shares, ``classify``
ishikawa  Ishikawa tooth compliance and the static TE of the p-d pair (Eq. 9) with load sharing
relief    linear / parabolic tip relief, ``optimise`` (differential evolution), ``landscape``
forced    linear forced response to the static TE against speed (modal damping, frequency domain)
tables    Table 2 / Table 5 / scaling / TE tables and datasets (pandas, xarray)
files     file helpers for the Snakemake adapters (wrap ``geardyn.io`` and ``geardyn.config``)

See ``docs/paper2.md`` for the derivation, the fixes to the printed equations and the comparison.
"""

from .design import PlusDesign, default_design, design_from_dict

__all__ = ["PlusDesign", "default_design", "design_from_dict"]
