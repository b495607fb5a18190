"""Adapter: trajectory / Poincare map / spectrum panels (paper 1 Figs. 8, 10, 12)."""

import xarray as xr

from geardyn import captions, io, logs
from geardyn.plots.dynamics import plot_points

log = logs.to_file(snakemake.log[0])
with xr.open_dataset(snakemake.input.data) as ds:
    ds.load()
title = snakemake.params.points.get("title") or snakemake.wildcards.points
io.save_figure(plot_points(ds, title), snakemake.output.figure, captions.points(snakemake.wildcards.points, ds))
