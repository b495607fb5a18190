"""Adapter: compile (or load from numba's cache) the solver's loops once -> a record of the compile."""

import time

import numba

from geardyn import io, logs
from geardyn.khv import design, point
from geardyn.solve import warm_up

log = logs.to_file(snakemake.log[0])
t0 = time.perf_counter()
warm_up(point.point_coefficients(design.load(snakemake.input.design)))
elapsed = time.perf_counter() - t0
log.info("the compiled loops ready in %.1f s", elapsed)
cpu = io.runtime_provenance()
io.write_text(
    f"numba {numba.__version__}, CPU {cpu['numba_cpu_name']}: the compiled loops ready in {elapsed:.1f} s "
    "(compiled, or loaded from numba's cache)\n",
    snakemake.output[0],
)
