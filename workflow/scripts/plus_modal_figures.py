"""Adapter: modal strain and kinetic energy and mode shapes (paper 2 Figs. 6-7 style) from modal.nc."""

from geardyn import io, logs
from geardyn.papers import paper_of
from geardyn.plots import captions, save_figure
from geardyn.plots import plus as plots
from geardyn.plus import design

log = logs.to_file(snakemake.log[0])
plus = design.load(snakemake.input.design)
paper = paper_of(plus.paper)
ds = io.read_dataset(snakemake.input.modal)
save_figure(plots.modal_strain_energy_figure(ds), snakemake.output.fig06, captions.modal_strain(ds, paper))
save_figure(plots.modal_kinetic_energy_figure(ds), snakemake.output.fig07, captions.modal_kinetic(ds, paper))
save_figure(plots.mode_shape_figure(ds), snakemake.output.fig07b, captions.mode_shapes(ds, paper))
log.info("figures written")
