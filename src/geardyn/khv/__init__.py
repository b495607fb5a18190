"""The KHV model family (paper 1's kind of drive): a planet meshing inside an annulus with a small
teeth-number difference, driven through a crank (carrier).

==============  ======================================================================
design          a validated design file: the pair, its admissible segment, stiffness options
point           the dimensionless model at one operating point (controls x1, b, e, w, ...)
model           physical parameters -> dimensionless coefficients (corrected Eqs. 2-16)
mesh_table      mesh quantities along the admissible segment (Figs. 4-5)
closed_graph    every geometric constraint on an (x1, x2) grid (Fig. 3)
calibrate       search of a design's unknown parameters against a paper's regime sequence
==============  ======================================================================
"""
