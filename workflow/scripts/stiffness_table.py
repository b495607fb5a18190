"""Adapter: mesh quantities and k(t) along the admissible segment M-N -> netCDF."""

from geardyn import design, io, logs, mesh_table

log = logs.to_file(snakemake.log[0])
spec = design.load(snakemake.input.design)
params = snakemake.params.spec
x1 = design.x1_grid(spec, params["points"])
ds = mesh_table.stiffness_table(spec, x1, params["phase_points"])
attrs = io.provenance(title=f"Mesh stiffness along M-N, {spec.title}", paper="li2013",
                      config={"design": spec.raw, "stiffness_table": params},
                      model_variant=spec.stiffness.label)
io.write_netcdf(ds, snakemake.output[0], attrs)
log.info("%d points from x1 = %.3f to %.3f written", x1.size, x1[0], x1[-1])
