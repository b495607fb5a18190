"""The plus (double-planet) planetary gear set of paper 2 (Yue et al. 2014): design, 11-DOF modal model, Ishikawa
TE, tip relief, forced response, tables and the quantities its claims read (docs/paper2.md)."""

from .design import PlusDesign, default_design, design_from_dict

__all__ = ["PlusDesign", "default_design", "design_from_dict"]
