"""Adapter: label image of a regime map with the sweeps' 1-D cuts drawn on it."""

from geardyn import io, logs
from geardyn.plots import captions
from geardyn.plots.dynamics import plot_map

log = logs.to_file(snakemake.log[0])
ds = io.read_dataset(snakemake.input.cube)
spec = snakemake.params.spec
title = spec.get("title") or snakemake.wildcards.map
io.save_figure(
    plot_map(ds, title, spec.get("cuts_x", []), spec.get("cuts_y", [])),
    snakemake.output.figure,
    captions.regime_map(snakemake.wildcards.map, ds),
)
