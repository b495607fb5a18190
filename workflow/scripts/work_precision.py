"""Adapter: the work-precision study of python -m geardyn.bench as a pipeline target."""

from pathlib import Path

from geardyn import bench, io, logs

log = logs.to_file(snakemake.log[0])
out = bench.run(quick=snakemake.params.spec["quick"], log=log.info)
io.write_netcdf(
    bench.to_dataset(out),
    snakemake.output.data,
    io.provenance(title="Work-precision study of the KHV integrators", model_variant="benchmark"),
)
io.write_text(bench.markdown(out), snakemake.output.table)
bench.figure(out, Path(snakemake.output.figure))
