"""The runs: how a design is explored.  Sweeps, maps, frequency responses and point runs are layouts of the one
study runner (:mod:`~geardyn.runs.study`; sweep and map chunks merged by :mod:`~geardyn.runs.cube`);
continuation, attractors and the regime bands work on the sweep cubes (README, Layout)."""
