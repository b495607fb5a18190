"""Adapter: closed graph of profile-shift coefficients on the configured (x1, x2) grid -> netCDF."""

import numpy as np

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import closed_graph, design
from geardyn.papers import paper_of

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)
grid = snakemake.params.spec
x1 = np.linspace(grid["x1"]["start"], grid["x1"]["stop"], grid["x1"]["num"])
x2 = np.linspace(grid["x2"]["start"], grid["x2"]["stop"], grid["x2"]["num"])
paper = paper_of(drive.paper)
ds = closed_graph.closed_graph(
    drive.base,
    x1,
    x2,
    min_tip_thickness=drive.min_tip_thickness,
    cutter=drive.cutter,
    reference_points=paper.POINTS if paper is not None else None,
)
attrs = provenance.attributes(
    title=f"Closed graph of profile-shift coefficients, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "grid": grid},
    model_variant="geometry",
)
io.write_netcdf(ds, snakemake.output[0], attrs)
log.info("closed graph %d x %d written to %s", x1.size, x2.size, snakemake.output[0])
