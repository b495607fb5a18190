"""Adapter: objective landscape of the tip-relief optimisation -> relief_landscape.nc."""

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.plus import design, tables

log = logs.to_file(snakemake.log[0])
plus = design.load(snakemake.input.design)
ds = tables.landscape_dataset(plus)
io.write_netcdf(
    ds,
    snakemake.output.landscape,
    provenance.attributes(
        title=ds.attrs["title"], paper=plus.paper, config=dict(plus.raw), model_variant="Ishikawa static TE"
    ),
)
log.info("landscape %s, ptp range %.2f-%.2f um", dict(ds.sizes), float(ds.te_ptp.min()), float(ds.te_ptp.max()))
