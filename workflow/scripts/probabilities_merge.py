"""Adapter: merge the chunks of one probabilities study and add its statistics (probabilities, quantiles,
sensitivities)."""

from geardyn import io
from geardyn.io import logs, provenance, quarantine
from geardyn.khv import design
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
io.write_netcdf(ds, snakemake.output[0], {**ds.attrs, **attrs})
log.info("%s: leading inputs %s", spec.name, {k: v for k, v in ds.attrs.items() if k.startswith("leading")})
if spec.classes:
    log.info("%s: coarsest class per point %s", spec.name, ds["coarsest_class"].values.tolist())
