"""Adapter: trajectory / Poincare map / spectrum panels (paper 1 Figs. 8, 10, 12 for a paper design)."""

from geardyn import io
from geardyn.io import logs
from geardyn.khv import design
from geardyn.papers import paper_of
from geardyn.plots import captions, save_figure
from geardyn.plots.dynamics import plot_points

log = logs.to_file(snakemake.log[0])
drive = design.header(snakemake.input.design)  # results only: no geometry
ds = io.read_dataset(snakemake.input.data)
title = snakemake.params.spec.get("title") or snakemake.wildcards.points
save_figure(
    plot_points(ds, title),
    snakemake.output.figure,
    captions.points(snakemake.wildcards.points, ds, paper_of(drive.paper)),
)
