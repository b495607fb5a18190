"""Adapter: the frequency response of one design (mesh frequency swept up and down) -> cube and figure."""

import numba

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, point
from geardyn.plots import captions, save_figure
from geardyn.plots.response import frequency_response_figure
from geardyn.runs import response
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
numba.set_num_threads(snakemake.threads)  # the up and down lines run in parallel on the job's cores
drive = design.load(snakemake.input.design)
name = snakemake.wildcards.response
spec = response.ResponseSpec.from_config(name, snakemake.params.spec, drive.name, drive.segment)
warm_up(point.point_coefficients(drive))  # load the compiled kernels from numba's cache
ds = response.run(drive, spec)
attrs = provenance.attributes(
    title=f"Frequency response {name}, {drive.title}",
    paper=drive.paper,
    config={"design": drive.raw, "response": snakemake.params.spec},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(ds, snakemake.output.cube, {**ds.attrs, **attrs})
save_figure(
    frequency_response_figure(ds, snakemake.params.spec.get("title") or name),
    snakemake.output.figure,
    captions.frequency_response(name, ds),
)
hysteresis = ds.w.values[ds.hysteresis.values == 1]
log.info(
    "%s: jumps up %s, down %s; hysteresis (up and down on different attractors) at w = %s",
    name,
    ds.attrs["jumps_up"],
    ds.attrs["jumps_down"],
    ",".join(f"{v:.4g}" for v in hysteresis) or "none",
)
