"""Adapter: paper 1's statements against our cubes, point runs, stiffness table, closed graph."""

import numpy as np
import xarray as xr

from geardyn import claims, design, io, khv, logs
from geardyn.integrators import simulate, warm_up

log = logs.to_file(snakemake.log[0])


def _open(path):
    with xr.open_dataset(path) as ds:
        return ds.load()


inp = snakemake.input
model = design.load(inp.design)
warm_up()
# amplitude in the paper's P1 range: peak-to-peak X_VH of dense runs (b = 2, e = 5 as in Fig. 7)
settings = khv.integration_settings(model)
x1 = np.linspace(0.416, 0.56, snakemake.params.spec["amplitude_points"])
ptp = []
for v in x1:
    res = simulate(khv.point_coefficients(model, {"x1": float(v), "b": 2.0, "e": 5.0}), settings, dense=True)
    ptp.append(float(np.ptp(res.states[:, 1])) if not res.diverged else float("nan"))
rows = claims.claims(_open(inp.closed_graph), _open(inp.stiffness), _open(inp.fig07), _open(inp.fig09),
                     _open(inp.fig11), _open(inp.fig08_points), {"x1": x1, "ptp": np.array(ptp)})
note = (f"Design `{model.name}` ({model.title}). Labels: geardyn.classify.classify_point on the sweep cubes "
        "(period-n by return distance; QP / chaos by the largest Lyapunov exponent, cross-checked by the 0-1 test and "
        "the spectral flatness). Paper labels compared: P1 = synchronous, QP, P5, P6, chaos.")
io.write_text(claims.to_markdown(rows, model.name, note), snakemake.output.md)
io.write_text(claims.to_csv(rows), snakemake.output.csv)
log.info("claims: %s", claims.counts(rows))
