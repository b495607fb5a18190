"""Adapter: draw the closed graph (paper 1 Fig. 3 for a paper design) from its cube."""

from geardyn import io
from geardyn.io import logs
from geardyn.khv import design
from geardyn.papers import paper_of
from geardyn.plots import save_figure
from geardyn.plots.closed_graph import caption_closed_graph, plot_closed_graph

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)
ds = io.read_dataset(snakemake.input.data)
caption = caption_closed_graph(ds, paper_of(drive.paper), (drive.x1_min, drive.x1_max))
save_figure(plot_closed_graph(ds), snakemake.output.figure, caption)
log.info("wrote %s", snakemake.output.figure)
