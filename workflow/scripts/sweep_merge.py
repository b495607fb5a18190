"""Adapter: merge the chunk cubes of one sweep into a single bifurcation cube, write its regime bands with
transition points (CSV + Markdown) and draw its bifurcation diagram (paper 1 Figs. 7, 9, 11 for a paper design)."""

from geardyn import io
from geardyn.io import logs, provenance, quarantine
from geardyn.khv import design
from geardyn.papers import paper_of
from geardyn.plots import captions, save_figure
from geardyn.plots.dynamics import plot_bifurcation
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
# the bands and the diagram of the cube as written (read back, as every reader of the cube sees it)
written = io.read_dataset(snakemake.output.cube)
rows = bands.band_rows(written)
name = snakemake.params.spec.get("title") or snakemake.wildcards.sweep
title = f"{name} ({snakemake.wildcards.design})"
io.write_text(bands.bands_csv(rows), snakemake.output.csv)
io.write_text(bands.bands_markdown(rows, title, written.attrs["control_parameter"]), snakemake.output.md)
log.info("%d bands written", len(rows))
save_figure(
    plot_bifurcation(written, name),
    snakemake.output.figure,
    captions.bifurcation(snakemake.wildcards.sweep, written, paper_of(drive.paper)),
)
