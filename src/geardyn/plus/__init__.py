"""The plus (double-planet) planetary gear set, the model family of paper 2 (Yue et al. 2014).

Modules
-------
design    frozen dataclasses from a schema-validated dict (``design_from_dict``, ``default_design``)
modal     11-DOF Lagrangian model: ``matrices``, ``modes``, energy shares, ``classify``
ishikawa  Ishikawa tooth compliance and the static TE of the p-d pair (Eq. 9) with load sharing
relief    linear / parabolic tip relief, ``optimise`` (differential evolution), ``landscape``
forced    linear forced response to the static TE against speed (modal damping, frequency domain)
tables    frequencies, key elements, scaling, TE and relief tables and datasets (pandas, xarray)
captions  figure captions and table headers
claims    the quantities a paper's claims about a plus set read

See ``docs/paper2.md`` for the derivation, the fixes to the printed equations and the comparison.
"""

from .design import PlusDesign, default_design, design_from_dict

__all__ = ["PlusDesign", "default_design", "design_from_dict"]
