"""Adapter: dense runs at the points of one figure (paper 1 Figs. 8, 10, 12) -> netCDF."""

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, point
from geardyn.label import Policy
from geardyn.runs import points
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)
spec = design.resolve_fractions(snakemake.params.spec, drive.segment)
warm_up(point.point_coefficients(drive))
policy = Policy.from_spec(point.integration_settings(drive), spec)
ds = points.dense_points(drive, spec.get("fixed", {}), spec["cases"], policy, spec["samples_per_period"])
attrs = provenance.attributes(
    title=f"Dense runs {snakemake.wildcards.points}, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "points": spec},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(ds, snakemake.output.data, {**ds.attrs, **attrs})
