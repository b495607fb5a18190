"""Adapter: the regime boundaries of a map or a curves study drawn with their codimension-2 points (and the
map's labels behind them) -> figure, caption, table of the codimension-2 points and of the pixel check."""

from geardyn import io
from geardyn.io import logs
from geardyn.plots import curves, save_figure
from geardyn.plots.dynamics import label_image

log = logs.to_file(snakemake.log[0])
ds = io.read_dataset(snakemake.input.curves)
name = getattr(snakemake.wildcards, "map", None) or snakemake.wildcards.study
cube = getattr(snakemake.input, "cube", None)
background = label_image(io.read_dataset(cube)) if cube else None
title = snakemake.params.spec.get("title") or name
title += "" if "boundar" in title.lower() else ": regime boundaries"
save_figure(
    curves.plot_curves(ds, title, background), snakemake.output.figure, curves.caption(name, ds, cube is not None)
)
io.write_text(curves.codim2_table(name, ds) + curves.check_table(name, ds), snakemake.output.table)
log.info("%s: %s", name, curves.summary(ds)["curves"])
