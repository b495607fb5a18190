"""Adapter: closed graph of paper 1 Fig. 3 on the configured (x1, x2) grid -> netCDF."""

import numpy as np

from geardyn import closed_graph, design, io, logs

log = logs.to_file(snakemake.log[0])
spec = design.load(snakemake.input.design)
grid = snakemake.params.grid
x1 = np.linspace(grid["x1"]["start"], grid["x1"]["stop"], grid["x1"]["num"])
x2 = np.linspace(grid["x2"]["start"], grid["x2"]["stop"], grid["x2"]["num"])
ds = closed_graph.closed_graph(spec.base, x1, x2, min_tip_thickness=spec.min_tip_thickness, cutter=spec.cutter)
attrs = io.provenance(title=f"Closed graph of profile-shift coefficients, {spec.title}", paper="li2013",
                      config={"design": spec.raw, "grid": grid}, model_variant="geometry")
io.write_netcdf(ds, snakemake.output[0], attrs)
log.info("closed graph %d x %d written to %s", x1.size, x2.size, snakemake.output[0])
