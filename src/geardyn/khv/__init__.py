"""The KHV model family (paper 1's kind of drive): a planet meshing inside an annulus with a small teeth-number
difference, driven through a crank.  Modules: design (the validated design file), point (the model at one
operating point), model (the corrected equations), mesh_table (Figs. 4-5), closed_graph (Fig. 3), calibrate.
"""
