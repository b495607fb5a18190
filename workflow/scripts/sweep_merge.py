"""Adapter: merge the chunk cubes of one sweep into a single bifurcation cube, and write its regime bands with
transition points (CSV + Markdown)."""

from geardyn import io
from geardyn.io import logs, provenance, quarantine
from geardyn.khv import design
from geardyn.runs import bands, cube

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
io.write_netcdf(merged, snakemake.output.cube, {**merged.attrs, **attrs})
log.info("merged %d chunks into %s", len(parts), snakemake.output.cube)
# the bands of the cube as written (read back, as every reader of the cube sees it)
written = io.read_dataset(snakemake.output.cube)
rows = bands.band_rows(written)
title = f"{snakemake.params.spec.get('title') or snakemake.wildcards.sweep} ({snakemake.wildcards.design})"
io.write_text(bands.bands_csv(rows), snakemake.output.csv)
io.write_text(bands.bands_markdown(rows, title, written.attrs["control_parameter"]), snakemake.output.md)
log.info("%d bands written", len(rows))
