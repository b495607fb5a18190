"""Adapter: draw a bifurcation diagram (paper 1 Figs. 7, 9, 11 for a paper design) from its cube."""

from geardyn import io
from geardyn.io import logs
from geardyn.khv import design
from geardyn.papers import paper_of
from geardyn.plots import captions, save_figure
from geardyn.plots.dynamics import plot_bifurcation

log = logs.to_file(snakemake.log[0])
drive = design.header(snakemake.input.design)  # results only: no geometry
cube = io.read_dataset(snakemake.input.cube)
title = snakemake.params.spec.get("title") or snakemake.wildcards.sweep
save_figure(
    plot_bifurcation(cube, title),
    snakemake.output.figure,
    captions.bifurcation(snakemake.wildcards.sweep, cube, paper_of(drive.paper)),
)
