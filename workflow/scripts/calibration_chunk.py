"""Adapter: score one chunk of calibration candidates against the design's paper's regime sequence."""

import numpy as np

from geardyn import io, logs
from geardyn.khv import calibrate, design, point
from geardyn.papers import paper_of
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
spec = snakemake.params.spec
drive = design.load(snakemake.input.design)
warm_up(point.point_coefficients(drive))
candidates = calibrate.candidate_grid(spec["grid"])
part = calibrate.chunk_slice(len(candidates), spec["chunks"], int(snakemake.wildcards.chunk))
x1 = np.linspace(spec["x1"]["start"], spec["x1"]["stop"], spec["x1"]["num"])
settings = point.integration_settings(drive, **spec.get("integration", {}))
ds = calibrate.run_candidates(drive, candidates[part], spec.get("fixed", {}), x1, settings,
                              paper_of(drive.paper).SEQUENCE, first_index=part.start)
attrs = io.provenance(title=f"Calibration {snakemake.wildcards.calibration} chunk {snakemake.wildcards.chunk}",
                      paper=drive.paper, config={"design": drive.raw, "calibration": spec},
                      model_variant=drive.stiffness.label)
io.write_netcdf(ds, snakemake.output[0], attrs, checksum=True)  # Fletcher-32: damage is found before a merge
log.info("scored candidates %d..%d, best score %.3f", part.start, part.stop - 1,
         float(ds["score"].max()) if ds.sizes["candidate"] else float("nan"))
