"""Adapter: the regime boundaries of one `curves:` study (a plane of two parameters, no map) -> curves file."""

import numba

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, point
from geardyn.runs.continuation import boundaries, curve_maps
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
numba.set_num_threads(snakemake.threads)  # the job's cores: idle OpenMP threads spin on the others
drive = design.load(snakemake.input.design)
entry = snakemake.params.spec
name = snakemake.wildcards.study
region = boundaries.Region.from_config(entry, drive.segment)
settings_of = boundaries.BoundarySpec.from_config(entry)
warm_up(point.point_coefficients(drive))
integration = point.integration_settings(drive, **dict(entry.get("integration", {})))
bd, _ = curve_maps.boundary_curves(drive, region, settings_of, integration)
ds = curve_maps.boundary_dataset(bd)
log.info("%d curves in %.1f s", len(bd.curves), bd.timing["total"])
attrs = provenance.attributes(
    title=f"Regime boundaries {name}, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "curves": entry},
    model_variant=drive.stiffness.label,
    extra={"study": name, "design": drive.name, "steps_per_period": integration.steps_per_period},
)
io.write_netcdf(ds, snakemake.output[0], {**ds.attrs, **attrs})
