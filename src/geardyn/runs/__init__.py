"""The runs: how a design is explored.

=======  ==========================================================================
cube     state names, per-point label variables and the one chunk merge of sweeps and maps
points   dense runs at single points (trajectory, Poincare map, spectrum), on the attractor the labeller found
sweep    one-parameter sweeps (bifurcation cubes) in chunks
maps     two-parameter regime maps in chunks
bands    regime bands of a sweep (tables)
=======  ==========================================================================
"""
