"""Adapter: a paper's statements against the cubes, point runs, stiffness table and closed graph of a
design that names that paper."""

import numpy as np

from geardyn import claims, io
from geardyn.claims import verdicts
from geardyn.io import logs
from geardyn.khv import design, point
from geardyn.papers import paper_of
from geardyn.solve import simulate, warm_up

log = logs.to_file(snakemake.log[0])
inp = snakemake.input
drive = design.load(inp.design)
paper = paper_of(drive.paper)
warm_up(point.point_coefficients(drive))
# amplitude in the paper's P1 range: peak-to-peak X_VH of dense runs at the Fig. 7 values of b and e
settings = point.integration_settings(drive)
x1 = np.linspace(*paper.P1_AMPLITUDE_RANGE, snakemake.params.spec["amplitude_points"])
ptp = []
for v in x1:
    res = simulate(point.point_coefficients(drive, {"x1": float(v), **paper.FIG07_FIXED}), settings, dense=True)
    ptp.append(float(np.ptp(res.states[:, 1])) if not res.diverged else float("nan"))
# the cubes' labels, slow-transient check included (geardyn.label.settle): the labels the figures show
# and the calibration scores
rows = claims.claims(
    paper,
    {
        "closed_graph": io.read_dataset(inp.closed_graph),
        "stiffness": io.read_dataset(inp.stiffness),
        **{role: io.read_dataset(getattr(inp, role)) for role in paper.CLAIM_RUNS},
        "amplitude": {"x1": x1, "ptp": np.array(ptp)},
    },
)
io.write_text(
    verdicts.to_markdown(rows, drive.name, claims.note(drive.name, drive.title, paper), paper.SHORT),
    snakemake.output.md,
)
io.write_text(verdicts.to_csv(rows), snakemake.output.csv)
log.info("claims: %s", verdicts.counts(rows))
