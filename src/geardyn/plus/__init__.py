"""The plus (double-planet) planetary gear set, the model family of paper 2 (Yue et al. 2014).

Design, 11-DOF modal model, Ishikawa TE, tip relief, forced response, tables and the quantities
its claims read; the modules, the derivation and the comparison: docs/paper2.md.
"""

from .design import PlusDesign, default_design, design_from_dict

__all__ = ["PlusDesign", "default_design", "design_from_dict"]
