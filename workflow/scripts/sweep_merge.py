"""Adapter: merge the chunk cubes of one sweep into a single bifurcation cube."""

from geardyn import design, io, logs, sweep

log = logs.to_file(snakemake.log[0])
model = design.load(snakemake.input.design)
parts = io.read_chunks(snakemake.input.chunks)
cube = sweep.merge_chunks(parts)
for key in ("chunk", "n_chunks"):  # attributes of chunk 0, not of the merged cube
    cube.attrs.pop(key, None)
attrs = io.provenance(title=f"Bifurcation cube {snakemake.wildcards.sweep}, {model.title}", paper="li2013",
                      config={"design": model.raw, "sweep": snakemake.params.sweep},
                      model_variant=model.stiffness.label)
io.write_netcdf(cube, snakemake.output[0], {**cube.attrs, **attrs})
log.info("merged %d chunks into %s", len(parts), snakemake.output[0])
