"""Adapter: merge calibration chunks, write all scores, the best design file and a Markdown table."""

from pathlib import Path

import xarray as xr

from geardyn import io, logs
from geardyn.khv import calibrate, design

log = logs.to_file(snakemake.log[0])
spec = snakemake.params.spec
drive = design.load(snakemake.input.design)
parts = io.read_chunks(snakemake.input.chunks)
scores = xr.concat(parts, dim="candidate", data_vars="minimal", coords="minimal", compat="override",
                   combine_attrs="override")
attrs = io.provenance(title=f"Calibration {snakemake.wildcards.calibration}", paper=drive.paper,
                      config={"design": drive.raw, "calibration": spec}, model_variant=drive.stiffness.label)
io.write_netcdf(scores, snakemake.output.scores, attrs)
index, values, best_score = calibrate.best(scores)
text = calibrate.calibrated_design_text(Path(snakemake.input.design).read_text(), f"{drive.name}_calibrated", values,
                                        best_score, scores.sizes["candidate"])
io.write_text(text, snakemake.output.design)
io.write_text(calibrate.score_table(scores), snakemake.output.table)
log.info("best candidate %d: %s, score %.3f", index, values, best_score)
