"""Adapter: dense runs at the points of one figure (paper 1 Figs. 8, 10, 12) -> netCDF."""

from geardyn import design, io, khv, logs, points
from geardyn.integrators import warm_up

log = logs.to_file(snakemake.log[0])
spec = snakemake.params.points
model = design.load(snakemake.input.design)
warm_up()
settings = khv.integration_settings(model)
ds = points.dense_points(model, spec.get("fixed", {}), spec["cases"], settings, spec["samples_per_period"])
attrs = io.provenance(title=f"Dense runs {snakemake.wildcards.points}, {model.title}", paper="li2013",
                      config={"design": model.raw, "points": spec}, model_variant=model.stiffness.label)
io.write_netcdf(ds, snakemake.output.data, {**ds.attrs, **attrs})
