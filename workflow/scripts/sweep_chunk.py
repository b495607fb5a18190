"""Adapter: integrate one chunk of a bifurcation sweep -> partial cube (netCDF)."""

from geardyn import design, io, khv, logs, sweep
from geardyn.integrators import warm_up

log = logs.to_file(snakemake.log[0])
spec = sweep.SweepSpec.from_config(snakemake.wildcards.sweep, snakemake.params.sweep, snakemake.wildcards.design)
model = design.load(snakemake.input.design)
warm_up()  # load the compiled kernels from numba's cache before timing starts
chunk = int(snakemake.wildcards.chunk)
cube = sweep.run_chunk(model, spec, chunk)
settings = khv.integration_settings(model, **dict(spec.integration))
attrs = io.provenance(title=f"{spec.name} chunk {chunk}", paper="li2013",
                      config={"design": model.raw, "sweep": snakemake.params.sweep},
                      model_variant=model.stiffness.label, extra={"chunk": chunk, "n_chunks": spec.n_chunks})
io.write_netcdf(cube, snakemake.output[0], attrs, checksum=True)  # Fletcher-32: damage is found before a merge
