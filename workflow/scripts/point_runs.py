"""Adapter: dense runs at the points of one figure (paper 1 Figs. 8, 10, 12) -> netCDF."""

from geardyn import io, logs
from geardyn.khv import design, point
from geardyn.runs import points
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)
spec = design.resolve_fractions(snakemake.params.spec, drive.segment)
warm_up(point.point_coefficients(drive))
ds = points.dense_points(drive, spec.get("fixed", {}), spec["cases"], point.integration_settings(drive),
                         spec["samples_per_period"])
attrs = io.provenance(title=f"Dense runs {snakemake.wildcards.points}, {drive.title}", paper=drive.paper,
                      config={"design": drive.raw, "points": spec}, model_variant=drive.stiffness.label)
io.write_netcdf(ds, snakemake.output.data, {**ds.attrs, **attrs})
