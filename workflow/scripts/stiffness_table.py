"""Adapter: mesh quantities and k(t) along the admissible segment -> netCDF."""

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, mesh_table

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)
spec = snakemake.params.spec
x1 = design.x1_grid(drive, spec["points"])
ds = mesh_table.stiffness_table(drive, x1, spec["phase_points"])
attrs = provenance.attributes(
    title=f"Mesh stiffness along the admissible segment, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "stiffness_table": spec},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(ds, snakemake.output[0], attrs)
log.info("%d points from x1 = %.3f to %.3f written", x1.size, x1[0], x1[-1])
