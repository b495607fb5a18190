"""Adapter: modal strain and kinetic energy and mode shapes (paper 2 Figs. 6-7 style) from modal.nc."""

from geardyn import io
from geardyn.io import logs
from geardyn.papers import paper_of
from geardyn.plots import captions, save_figure
from geardyn.plots import plus as plots
from geardyn.plus import design

log = logs.to_file(snakemake.log[0])
plus = design.load(snakemake.input.design)
paper = paper_of(plus.paper)
ds = io.read_dataset(snakemake.input.modal)
for kind, path in (("strain", snakemake.output.fig06), ("kinetic", snakemake.output.fig07)):
    save_figure(plots.modal_energy_figure(ds, kind), path, captions.modal_energy(ds, paper, kind))
save_figure(plots.mode_shape_figure(ds), snakemake.output.fig07b, captions.mode_shapes(ds, paper))
log.info("figures written")
