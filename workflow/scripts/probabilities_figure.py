"""Adapter: the figure (with its caption) and the table of one probabilities study."""

from geardyn import io
from geardyn.io import logs, tables
from geardyn.plots import probabilities as plots
from geardyn.plots import save_figure

log = logs.to_file(snakemake.log[0])
ds = io.read_dataset(snakemake.input.cube)
name = snakemake.wildcards.prob
title = snakemake.params.spec.get("title") or name
skipped = " ".join(f"{line}." for line in snakemake.params.skipped)
heading = f"{title} ({snakemake.wildcards.design})"
if "tolerance_class" in ds.dims:  # a class study
    figure, caption = plots.class_figure(ds, title), plots.class_caption(name, ds)
    table = tables.class_table_markdown(ds, heading)
    n = ds.attrs.get("samples_per_class")
else:
    figure, caption = plots.probabilities_figure(ds, title), plots.caption(name, ds)
    table = tables.table_markdown(ds, heading)
    n = int((ds["sample_block"] >= 0).sum())
caption = f"{caption} {skipped}".rstrip()
save_figure(figure, snakemake.output.figure, caption)
io.write_text(f"{table}\n{skipped}\n" if skipped else table, snakemake.output.table)
for line in snakemake.params.skipped:
    log.info("%s", line)
log.info("%s: figure and table of %s samples", name, n)
