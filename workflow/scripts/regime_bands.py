"""Adapter: regime bands with transition points of one sweep cube -> CSV + Markdown."""

from geardyn import io
from geardyn.io import logs
from geardyn.runs import bands

log = logs.to_file(snakemake.log[0])
cube = io.read_dataset(snakemake.input.cube)
rows = bands.band_rows(cube)
title = f"{snakemake.params.spec.get('title') or snakemake.wildcards.sweep} ({snakemake.wildcards.design})"
io.write_text(bands.bands_csv(rows), snakemake.output.csv)
io.write_text(bands.bands_markdown(rows, title, cube.attrs["control_parameter"]), snakemake.output.md)
log.info("%d bands written", len(rows))
