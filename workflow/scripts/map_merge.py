"""Adapter: merge the chunks of one regime map."""

from geardyn import io
from geardyn.io import logs, provenance, quarantine
from geardyn.khv import design
from geardyn.runs import cube

log = logs.to_file(snakemake.log[0])
drive = design.header(snakemake.input.design)  # results only: no geometry
parts = quarantine.read_chunks(snakemake.input.chunks)  # a damaged chunk is refused by name, never merged
merged = cube.merge_chunks(parts)
attrs = provenance.attributes(
    title=f"Regime map {snakemake.wildcards.map}, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "map": snakemake.params.spec},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(merged, snakemake.output[0], {**merged.attrs, **attrs})
log.info("merged %d chunks; label shares %s", len(parts), cube.fractions(merged))
