"""Adapter: merge the chunk cubes of one sweep into a single bifurcation cube."""

import xarray as xr

from geardyn import design, io, logs, sweep

log = logs.to_file(snakemake.log[0])
model = design.load(snakemake.input.design)
parts = []
for path in snakemake.input.chunks:
    problem = io.netcdf_problem(path)  # damaged since the DAG was built: refuse, never merge it
    if problem:
        raise ValueError(f"{path}: damaged chunk ({problem}); rerun snakemake to recompute it")
    with xr.open_dataset(path) as ds:
        parts.append(ds.load())
cube = sweep.merge_chunks(parts)
for key in ("chunk", "n_chunks"):  # attributes of chunk 0, not of the merged cube
    cube.attrs.pop(key, None)
attrs = io.provenance(title=f"Bifurcation cube {snakemake.wildcards.sweep}, {model.title}", paper="li2013",
                      config={"design": model.raw, "sweep": snakemake.params.sweep},
                      model_variant=model.stiffness.label)
io.write_netcdf(cube, snakemake.output[0], {**cube.attrs, **attrs})
log.info("merged %d chunks into %s", len(parts), snakemake.output[0])
