"""Adapter: continue the periodic orbits of one sweep -> branches (netCDF) and bifurcation table (CSV)."""

import numba

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, point
from geardyn.runs import continuation, sweep
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
numba.set_num_threads(snakemake.threads)  # the job's cores: idle OpenMP threads spin on the others
drive = design.load(snakemake.input.design)
name = snakemake.wildcards.sweep
entry = snakemake.params.spec
spec = sweep.SweepSpec.from_config(name, snakemake.params.sweep, drive.name, drive.segment)
orbits = continuation.OrbitSpec.from_config(entry)
cube = io.read_dataset(snakemake.input.cube)
warm_up(point.point_coefficients(drive))  # compiled kernels from numba's cache before timing starts
ds, rows = continuation.sweep_orbits(drive, spec, cube, orbits)
attrs = provenance.attributes(
    title=f"{name}: continued periodic orbits",
    paper=drive.paper,
    config={"design": drive.raw, "sweep": snakemake.params.sweep, "orbits": entry},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(ds, snakemake.output.data, attrs)
io.write_text(continuation.rows_to_csv(rows), snakemake.output.table)
