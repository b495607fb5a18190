"""Adapter: merge the chunks of one regime map."""

from geardyn import design, io, logs, maps

log = logs.to_file(snakemake.log[0])
model = design.load(snakemake.input.design)
parts = io.read_chunks(snakemake.input.chunks)  # a damaged chunk is refused by name, never merged
out = maps.merge_chunks(parts)
attrs = io.provenance(title=f"Regime map {snakemake.wildcards.map}, {model.title}", paper="li2013",
                      config={"design": model.raw, "map": snakemake.params.spec}, model_variant=model.stiffness.label)
io.write_netcdf(out, snakemake.output[0], {**out.attrs, **attrs})
log.info("merged %d chunks; label shares %s", len(parts), maps.fractions(out))
