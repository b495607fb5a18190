"""Adapter: merge the chunk cubes of one sweep into a single bifurcation cube."""

import xarray as xr

from geardyn import design, io, logs, sweep

log = logs.to_file(snakemake.log[0])
model = design.load(snakemake.input.design)
parts = []
for path in snakemake.input.chunks:
    with xr.open_dataset(path) as ds:
        parts.append(ds.load())
cube = sweep.merge_chunks(parts)
attrs = io.provenance(title=f"Bifurcation cube {snakemake.wildcards.sweep}, {model.title}", paper="li2013",
                      config={"design": model.raw, "sweep": snakemake.params.sweep},
                      model_variant=model.stiffness.label)
io.write_netcdf(cube, snakemake.output[0], {**cube.attrs, **attrs})
log.info("merged %d chunks into %s", len(parts), snakemake.output[0])
