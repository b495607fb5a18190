"""Adapter: merge the chunk cubes of one sweep into a single bifurcation cube."""

from geardyn import io
from geardyn.io import logs, provenance, quarantine
from geardyn.khv import design
from geardyn.runs import cube

log = logs.to_file(snakemake.log[0])
drive = design.header(snakemake.input.design)  # results only: no geometry
parts = quarantine.read_chunks(snakemake.input.chunks)  # a damaged chunk is refused by name, never merged
merged = cube.merge_chunks(parts)
attrs = provenance.attributes(
    title=f"Bifurcation cube {snakemake.wildcards.sweep}, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "sweep": snakemake.params.spec},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(merged, snakemake.output[0], {**merged.attrs, **attrs})
log.info("merged %d chunks into %s", len(parts), snakemake.output[0])
