"""Adapter: regime bands with transition points of one sweep cube -> CSV + Markdown."""

import xarray as xr

from geardyn import classify, io, logs

log = logs.to_file(snakemake.log[0])
with xr.open_dataset(snakemake.input.cube) as cube:
    cube.load()
rows = classify.band_rows(cube)
title = f"{snakemake.params.sweep.get('title') or snakemake.wildcards.sweep} ({snakemake.wildcards.design})"
io.write_text(classify.bands_csv(rows), snakemake.output.csv)
io.write_text(classify.bands_markdown(rows, title, cube.attrs["control_parameter"]), snakemake.output.md)
log.info("%d bands written", len(rows))
