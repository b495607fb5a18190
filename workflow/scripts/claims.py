"""Adapter: a paper's statements against the cubes, point runs, stiffness table and closed graph of a
design that names that paper."""

import numpy as np

from geardyn import claims, io, logs
from geardyn.khv import calibrate, design, point
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
# the labels the calibration scores: slow transients labelled QP or undetermined are checked by shooting
# for a stable periodic orbit the run approaches (geardyn.khv.calibrate.relabel_track)
c07, c09, c11 = (io.read_dataset(p) for p in (inp.fig07, inp.fig09, inp.fig11))
f07 = calibrate.relabel_track(drive, claims.track_of_cube(c07), "x1", paper.FIG07_FIXED, settings)
f09 = {x: calibrate.relabel_track(drive, t, "b", {"e": paper.FIG07_FIXED["e"], "x1": x}, settings)
       for x, t in claims.tracks_of_cube(c09, paper.CASE_X1).items()}
f11 = {x: calibrate.relabel_track(drive, t, "e", {"b": paper.FIG07_FIXED["b"], "x1": x}, settings)
       for x, t in claims.tracks_of_cube(c11, paper.CASE_X1).items()}
rows = claims.evaluate(paper, f07, f09, f11, io.read_dataset(inp.closed_graph), io.read_dataset(inp.stiffness),
                       io.read_dataset(inp.fig08_points), {"x1": x1, "ptp": np.array(ptp)})
io.write_text(claims.to_markdown(rows, drive.name, claims.note(drive.name, drive.title)), snakemake.output.md)
io.write_text(claims.to_csv(rows), snakemake.output.csv)
log.info("claims: %s", claims.counts(rows))
