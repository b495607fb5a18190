"""Adapter: the figure (with its caption) and the table of one probabilities study."""

from geardyn import io
from geardyn.io import logs, tables
from geardyn.plots import probabilities as plots
from geardyn.plots import save_figure

log = logs.to_file(snakemake.log[0])
ds = io.read_dataset(snakemake.input.cube)
name = snakemake.wildcards.prob
title = snakemake.params.spec.get("title") or name
save_figure(plots.probabilities_figure(ds, title), snakemake.output.figure, plots.caption(name, ds))
io.write_text(tables.table_markdown(ds, f"{title} ({snakemake.wildcards.design})"), snakemake.output.table)
log.info("%s: figure and table of %d samples", name, int((ds["sample_block"] >= 0).sum()))
