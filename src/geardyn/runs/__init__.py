"""The runs: how a design is explored.

========  ==========================================================================
study     the one study runner: spec base, layouts, the per-point variables' builder and store
cube      state names, per-point variables and the one chunk merge of sweeps and maps
points    dense runs at single points (trajectory, Poincare map, spectrum), on the attractor the labeller found
sweep     one-parameter sweeps (bifurcation cubes) in chunks
maps      two-parameter regime maps in chunks
response  frequency responses: swept up and down, hysteresis, jumps
bands     regime bands of a sweep (tables)
========  ==========================================================================
"""
