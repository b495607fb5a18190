"""Adapter: the compiled loops of the solver and the labeller put into numba's on-disk cache (or loaded from
it) by one job, before the jobs that integrate; the output is the runtime they were compiled for."""

import numpy as np

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, point
from geardyn.label import indicators, torus
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
warm_up(point.point_coefficients(design.load(snakemake.input.design)))
points = np.random.default_rng(0).normal(size=(64, 6))  # the labeller's own loops, on any record
indicators.strict_periods([points])
indicators.falling_return_distances(points, 12)
torus.torus_digits(points, torus.coordinates)
log.info("kernels compiled or loaded from numba's cache")
io.write_text(provenance.provenance_text(), snakemake.output[0])
