"""Adapter: integrate one chunk of a bifurcation sweep -> partial cube (netCDF, with checksums)."""

import numba

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, point
from geardyn.runs import sweep
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
numba.set_num_threads(snakemake.threads)  # the chunk's points run in parallel on the job's cores
drive = design.load(snakemake.input.design)
spec = sweep.SweepSpec.from_config(snakemake.wildcards.sweep, snakemake.params.spec, drive.name, drive.segment)
chunk = int(snakemake.wildcards.chunk)
warm_up(point.point_coefficients(drive))  # load the compiled kernels from numba's cache before timing starts
cube = sweep.run_chunk(drive, spec, chunk)
attrs = provenance.attributes(
    title=f"{spec.name} chunk {chunk}",
    paper=drive.paper,
    config={"design": drive.raw, "sweep": snakemake.params.spec},
    model_variant=drive.stiffness.label,
    extra={"chunk": chunk, "n_chunks": spec.n_chunks},
)
io.write_netcdf(cube, snakemake.output[0], attrs, checksum=True)  # Fletcher-32: damage is found before a merge
