"""Adapter: the regime boundaries of one map as curves, seeded along its cut lines and by its records, with the
pixel check against the map -> curves file (netCDF)."""

import numba

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, point
from geardyn.runs import maps
from geardyn.runs.continuation import curve_maps
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
numba.set_num_threads(snakemake.threads)  # the job's cores: idle OpenMP threads spin on the others
drive = design.load(snakemake.input.design)
entry = snakemake.params.spec
spec = maps.MapSpec.from_config(snakemake.wildcards.map, entry, drive.name, drive.segment)
cube = io.read_dataset(snakemake.input.cube)
warm_up(point.point_coefficients(drive))  # compiled kernels from numba's cache before timing starts
bd, check, integration = curve_maps.map_boundaries(drive, spec, entry, cube)
ds = curve_maps.boundary_dataset(bd, check)
log.info("%d curves in %.1f s; pixel check %s", len(bd.curves), bd.timing["total"], check.attrs())
attrs = provenance.attributes(
    title=f"Regime boundaries of map {spec.name}, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "map": entry},
    model_variant=drive.stiffness.label,
    extra={"map": spec.name, "design": drive.name, "steps_per_period": integration.steps_per_period},
)
io.write_netcdf(ds, snakemake.output[0], {**ds.attrs, **attrs})
