"""Adapter: classify one chunk of a two-parameter regime map -> partial map (netCDF, with checksums)."""

import numba

from geardyn.io import logs
from geardyn.khv import design, point
from geardyn.runs import maps, study
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
numba.set_num_threads(snakemake.threads)  # the chunk's points run in parallel on the job's cores
drive = design.load(snakemake.input.design)
spec = maps.MapSpec.from_config(snakemake.wildcards.map, snakemake.params.spec, drive.name, drive.segment)
chunk = int(snakemake.wildcards.chunk)
warm_up(point.point_coefficients(drive))
ds = maps.run_chunk(drive, spec, chunk)
log.info("chunk %d: %d points in %.1f s", chunk, int(ds["computed"].sum()), ds.attrs["wall_time_s"])
study.write_chunk(ds, drive, spec, chunk, "map", snakemake.params.spec, snakemake.output[0])
