"""Adapter: single-tooth stiffness, k(t) at three x1, and the backlash function (paper 1 Figs. 4-6)."""

from geardyn.io import logs
from geardyn.khv import design, mesh_table
from geardyn.papers import paper_of
from geardyn.plots import save_figure
from geardyn.plots import stiffness as plots

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)
spec = snakemake.params.spec
paper = paper_of(drive.paper)
x1_values = design.figure_x1(drive, spec["fig05_x1"], getattr(paper, "FIG05_X1", None))
middle = design.mesh_properties(drive, x1_values[len(x1_values) // 2])
save_figure(plots.plot_single_tooth(middle), snakemake.output.fig04, plots.caption_fig04(middle, paper))
curves = mesh_table.stiffness_table(drive, x1_values, spec["phase_points"])
save_figure(plots.plot_mesh_stiffness(curves), snakemake.output.fig05, plots.caption_fig05(curves, drive, paper))
save_figure(plots.plot_backlash(), snakemake.output.fig06, plots.caption_fig06(paper))
log.info("Figs. 4-6 written for x1 = %s", x1_values)
