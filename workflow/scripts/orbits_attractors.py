"""Adapter: coexisting attractors and basin fractions at a subset of one sweep's points."""

import numba

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, point
from geardyn.runs import attractors, sweep
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
numba.set_num_threads(snakemake.threads)  # the job's cores: idle OpenMP threads spin on the others
drive = design.load(snakemake.input.design)
name = snakemake.wildcards.sweep
entry = snakemake.params.spec
spec = sweep.SweepSpec.from_config(name, snakemake.params.sweep, drive.name, drive.segment)
cube = io.read_dataset(snakemake.input.cube)
branches = io.read_dataset(snakemake.input.branches)
warm_up(point.point_coefficients(drive))
ds = attractors.sweep_attractors(drive, spec, cube, branches, entry.get("attractors") or {})
attrs = provenance.attributes(
    title=f"{name}: coexisting attractors",
    paper=drive.paper,
    config={"design": drive.raw, "sweep": snakemake.params.sweep, "orbits": entry},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(ds, snakemake.output.data, attrs)
