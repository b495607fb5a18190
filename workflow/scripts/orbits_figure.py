"""Adapter: draw the continued branches over the sweep's bifurcation diagram."""

from geardyn import io
from geardyn.io import logs
from geardyn.khv import design
from geardyn.plots import save_figure
from geardyn.plots.orbits import plot_branches

log = logs.to_file(snakemake.log[0])
drive = design.header(snakemake.input.design)  # results only: no geometry
cube = io.read_dataset(snakemake.input.cube)
branches = io.read_dataset(snakemake.input.branches)
title = snakemake.params.sweep.get("title") or snakemake.wildcards.sweep
n_bif = int(branches.sizes.get("bifurcation", 0))
caption = (
    f"Continued periodic orbits of sweep {snakemake.wildcards.sweep} (design {drive.name}) over its "
    f"Poincare points (grey): solid stable, dashed unstable (Floquet multipliers from the variational "
    f"equations); {n_bif} typed bifurcation points marked (table: "
    f"orbits/{snakemake.wildcards.sweep}_bifurcations.csv)."
)
save_figure(plot_branches(cube, branches, title), snakemake.output.figure, caption)
