"""Adapter: label the samples of one chunk of a probabilities study -> partial cube (netCDF, with checksums)."""

import numba

from geardyn.io import logs
from geardyn.khv import design, point
from geardyn.runs import probabilities, study
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
numba.set_num_threads(snakemake.threads)  # the chunk's samples run in parallel on the job's cores
drive = design.load(snakemake.input.design)
spec = probabilities.ProbabilitySpec.from_config(
    snakemake.wildcards.prob, snakemake.params.spec, drive.name, drive.segment
)
chunk = int(snakemake.wildcards.chunk)
warm_up(point.point_coefficients(drive))
ds = probabilities.run_chunk(drive, spec, chunk)
log.info("chunk %d: %d points in %.1f s", chunk, int(ds["computed"].sum()), ds.attrs["wall_time_s"])
study.write_chunk(ds, drive, spec, chunk, "probabilities", snakemake.params.spec, snakemake.output[0])
