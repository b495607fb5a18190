"""Adapter: the regime boundaries of one map as curves, seeded along its cut lines and by its records, with the
pixel check against the map -> curves file (netCDF)."""

from geardyn import io, logs
from geardyn.khv import design, point
from geardyn.runs import maps
from geardyn.runs.continuation import curve_check, curve_maps, output
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)
entry = snakemake.params.spec
spec = maps.MapSpec.from_config(snakemake.wildcards.map, entry, drive.name, drive.segment)
settings_of = curve_maps.BoundarySpec.from_config(entry["curves"])
cube = io.read_dataset(snakemake.input.cube)
region = curve_maps.Region.of_map(spec)
lines = curve_maps.lines_of(
    region, settings_of.lines_x or entry.get("cuts_x", []), settings_of.lines_y or entry.get("cuts_y", [])
)
warm_up(point.point_coefficients(drive))  # compiled kernels from numba's cache before timing starts
integration = point.integration_settings(drive, **dict(spec.integration))
bd, plane = curve_maps.boundary_curves(drive, region, settings_of, integration, cube, lines)
check = curve_check.pixel_check(plane, bd, cube, settings_of.check_every)
bd.timing["check"] = check.seconds
ds = output.boundary_dataset(bd, check)
log.info("%d curves in %.1f s; pixel check %s", len(bd.curves), bd.timing["total"], check.attrs())
attrs = io.provenance(
    title=f"Regime boundaries of map {spec.name}, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "map": entry},
    model_variant=drive.stiffness.label,
    extra={"map": spec.name, "design": drive.name, "steps_per_period": integration.steps_per_period},
)
io.write_netcdf(ds, snakemake.output[0], {**ds.attrs, **attrs})
