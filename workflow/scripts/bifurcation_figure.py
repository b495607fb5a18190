"""Adapter: draw a bifurcation diagram (paper 1 Figs. 7, 9, 11) from its cube."""

import xarray as xr

from geardyn import captions, io, logs
from geardyn.plots.dynamics import plot_bifurcation

log = logs.to_file(snakemake.log[0])
with xr.open_dataset(snakemake.input.cube) as cube:
    cube.load()
title = snakemake.params.sweep.get("title") or snakemake.wildcards.sweep
io.save_figure(plot_bifurcation(cube, title), snakemake.output.figure,
               captions.bifurcation(snakemake.wildcards.sweep, cube))
