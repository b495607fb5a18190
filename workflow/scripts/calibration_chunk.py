"""Adapter: score one chunk of calibration candidates against the paper's regime sequence."""

import numpy as np

from geardyn import calibrate, design, io, khv, logs
from geardyn.integrators import warm_up

log = logs.to_file(snakemake.log[0])
spec = snakemake.params.spec
model = design.load(snakemake.input.design)
warm_up()
candidates = calibrate.candidate_grid(spec["grid"])
part = calibrate.chunk_slice(len(candidates), spec["chunks"], int(snakemake.wildcards.chunk))
x1 = np.linspace(spec["x1"]["start"], spec["x1"]["stop"], spec["x1"]["num"])
settings = khv.integration_settings(model, **spec.get("integration", {}))
ds = calibrate.run_candidates(model, candidates[part], spec.get("fixed", {}), x1, settings, first_index=part.start)
attrs = io.provenance(title=f"Calibration {snakemake.wildcards.calibration} chunk {snakemake.wildcards.chunk}",
                      paper="li2013", config={"design": model.raw, "calibration": spec},
                      model_variant=model.stiffness.label)
io.write_netcdf(ds, snakemake.output[0], attrs, checksum=True)  # Fletcher-32: damage is found before a merge
log.info("scored candidates %d..%d, best score %.3f", part.start, part.stop - 1,
         float(ds["score"].max()) if ds.sizes["candidate"] else float("nan"))
