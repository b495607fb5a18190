"""Adapter: merge the chunks of one probabilities study and add its statistics (probabilities, quantiles,
sensitivities)."""

from geardyn import io
from geardyn.io import logs, provenance, quarantine
from geardyn.khv import design
from geardyn.runs import cube, probabilities, probability_stats

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)  # the samples are drawn again from the design and the spec
spec = probabilities.ProbabilitySpec.from_config(
    snakemake.wildcards.prob, snakemake.params.spec, drive.name, drive.segment
)
merged = cube.merge_chunks(quarantine.read_chunks(snakemake.input.chunks))
ds = probability_stats.summarize(merged, spec, probabilities.samples(drive, spec))
attrs = provenance.attributes(
    title=f"Regime probabilities {spec.name}, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "probabilities": snakemake.params.spec},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(ds, snakemake.output[0], {**ds.attrs, **attrs})
log.info("%s: leading inputs %s", spec.name, {k: v for k, v in ds.attrs.items() if k.startswith("leading")})
