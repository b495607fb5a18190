"""Adapter: integrate one chunk of a bifurcation sweep -> partial cube (netCDF, with checksums)."""

import numba

from geardyn.io import logs
from geardyn.khv import design, point
from geardyn.runs import study, sweep
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
numba.set_num_threads(snakemake.threads)  # the chunk's points run in parallel on the job's cores
drive = design.load(snakemake.input.design)
spec = sweep.SweepSpec.from_config(snakemake.wildcards.sweep, snakemake.params.spec, drive.name, drive.segment)
chunk = int(snakemake.wildcards.chunk)
warm_up(point.point_coefficients(drive))  # load the compiled kernels from numba's cache before timing starts
cube = sweep.run_chunk(drive, spec, chunk)
study.write_chunk(cube, drive, spec, chunk, "sweep", snakemake.params.spec, snakemake.output[0])
