"""Adapter: the work-precision study of ``python -m benchmarks.bench`` as a pipeline target.

The benchmarks live beside the package at the repository root (``benchmarks/``), as scipy keeps its
own, so the repository root is put on the import path first (two levels above this script).
"""

import sys
from pathlib import Path

from geardyn import io
from geardyn.io import logs, provenance

sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))
from benchmarks import work_precision

log = logs.to_file(snakemake.log[0])
out = work_precision.run(quick=snakemake.params.spec["quick"], log=log.info)
io.write_netcdf(
    work_precision.to_dataset(out),
    snakemake.output.data,
    provenance.attributes(title="Work-precision study of the KHV integrators", model_variant="benchmark"),
)
io.write_text(work_precision.markdown(out), snakemake.output.table)
work_precision.figure(out, Path(snakemake.output.figure))
