"""Adapter: classify one chunk of a two-parameter regime map -> partial map (netCDF)."""

from geardyn import design, io, logs, maps
from geardyn.integrators import warm_up

log = logs.to_file(snakemake.log[0])
spec = maps.MapSpec.from_config(snakemake.wildcards.map, snakemake.params.spec, snakemake.wildcards.design)
model = design.load(snakemake.input.design)
warm_up()
chunk = int(snakemake.wildcards.chunk)
ds = maps.run_chunk(model, spec, chunk)
log.info("chunk %d: %d points in %.1f s", chunk, int(ds["computed"].sum()), ds.attrs["wall_time_s"])
attrs = io.provenance(title=f"{spec.name} chunk {chunk}", paper="li2013",
                      config={"design": model.raw, "map": snakemake.params.spec},
                      model_variant=model.stiffness.label, extra={"chunk": chunk, "n_chunks": spec.n_chunks})
io.write_netcdf(ds, snakemake.output[0], {**ds.attrs, **attrs})
