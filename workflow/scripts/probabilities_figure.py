"""Adapter: the figure (with its caption) and the table of one probabilities study."""

from geardyn import io
from geardyn.io import logs
from geardyn.plots import probabilities as plots
from geardyn.plots import save_figure
from geardyn.runs import probability_stats

log = logs.to_file(snakemake.log[0])
ds = io.read_dataset(snakemake.input.cube)
name = snakemake.wildcards.prob
title = snakemake.params.spec.get("title") or name
skipped = " ".join(f"{line}." for line in snakemake.params.skipped)
caption = f"{plots.caption(name, ds)} {skipped}".rstrip()
save_figure(plots.probabilities_figure(ds, title), snakemake.output.figure, caption)
table = probability_stats.table_markdown(ds, f"{title} ({snakemake.wildcards.design})")
io.write_text(f"{table}\n{skipped}\n" if skipped else table, snakemake.output.table)
for line in snakemake.params.skipped:
    log.info("%s", line)
log.info("%s: figure and table of %d samples", name, ds.sizes["sample"])
