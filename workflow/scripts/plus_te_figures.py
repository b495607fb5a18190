"""Adapter: TE before and after relief (paper 2 Figs. 4 and 9 style) and the objective landscape."""

import pandas as pd

from geardyn import io
from geardyn.io import logs
from geardyn.papers import paper_of
from geardyn.plots import captions, save_figure
from geardyn.plots import plus as plots
from geardyn.plus import design

log = logs.to_file(snakemake.log[0])
plus = design.load(snakemake.input.design)
paper = paper_of(plus.paper)
te = io.read_dataset(snakemake.input.te)
land = io.read_dataset(snakemake.input.landscape)
optima = pd.read_csv(snakemake.input.optima_csv)
save_figure(plots.te_unmodified_figure(te), snakemake.output.fig04, captions.te_unmodified(plus, te, paper))
save_figure(plots.te_relief_figure(te, paper), snakemake.output.fig09, captions.te_relief(plus, te, optima, paper))
save_figure(
    plots.relief_landscape_figure(land, optima, plus),
    snakemake.output.fig09b,
    captions.relief_landscape(te, land, plus, optima, paper),
)
log.info("figures written")
