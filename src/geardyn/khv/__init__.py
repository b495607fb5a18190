"""The KHV model family (paper 1's drive: a planet meshing inside an annulus with a small teeth-number difference,
driven through a crank): design, point (the model at an operating point), model, mesh_table, closed_graph, calibrate."""
