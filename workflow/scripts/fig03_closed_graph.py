"""Adapter: draw paper 1 Fig. 3 from the closed-graph cube."""

import xarray as xr

from geardyn import io, logs
from geardyn.plots.closed_graph import caption_closed_graph, plot_closed_graph

log = logs.to_file(snakemake.log[0])
with xr.open_dataset(snakemake.input.data) as ds:
    ds.load()
io.save_figure(plot_closed_graph(ds), snakemake.output.figure, caption_closed_graph(ds))
log.info("wrote %s", snakemake.output.figure)
