"""Adapter: merge the chunks of one probabilities study, add its statistics (probabilities, quantiles,
sensitivities), and draw its figure (with its caption) and write its table."""

from geardyn import io
from geardyn.io import logs, provenance, quarantine, tables
from geardyn.khv import design
from geardyn.plots import probabilities as plots
from geardyn.plots import save_figure
from geardyn.runs import cube, probabilities, probability_stats, tolerance_classes

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)  # the samples are drawn again from the design and the spec
spec = probabilities.ProbabilitySpec.from_config(
    snakemake.wildcards.prob, snakemake.params.spec, drive.name, drive.segment
)
merged = cube.merge_chunks(quarantine.read_chunks(snakemake.input.chunks))
if spec.classes:  # a class study: per class and point, and the coarsest class meeting the limits
    ds = tolerance_classes.summarize(merged, spec, drive)
else:
    ds = probability_stats.summarize(merged, spec, probabilities.study_samples(drive, spec))
attrs = provenance.attributes(
    title=f"Regime probabilities {spec.name}, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "probabilities": snakemake.params.spec},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(ds, snakemake.output.cube, {**ds.attrs, **attrs})
log.info("%s: leading inputs %s", spec.name, {k: v for k, v in ds.attrs.items() if k.startswith("leading")})
if spec.classes:
    log.info("%s: coarsest class per point %s", spec.name, ds["coarsest_class"].values.tolist())

# the figure and the table of the study as written (read back, as every reader of it sees it)
ds = io.read_dataset(snakemake.output.cube)
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
