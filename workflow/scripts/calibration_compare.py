"""Adapter: how far the pipeline's calibration search lies from the committed calibrated design."""

import json
from pathlib import Path

from geardyn import io
from geardyn.io import logs
from geardyn.khv import committed, design
from geardyn.khv.calibrate import optimise, products

log = logs.to_file(snakemake.log[0])
drive = design.load(snakemake.input.design)
problem, _ = optimise.problem_from_config(drive, snakemake.params.spec)
found = json.loads(Path(snakemake.input.best).read_text())["result"]
try:
    result = committed.compare(products.result_of(Path(snakemake.input.committed).read_text()), found, problem.space)
except ValueError as err:  # a search of other unknowns than the committed design's: nothing to compare
    io.write_text(
        f"# Calibration {snakemake.wildcards.calibration} against {snakemake.input.committed}\n\n"
        f"Not comparable: {err}.\n",
        snakemake.output[0],
    )
    log.info("not comparable: %s", err)
else:
    io.write_text(result.markdown(), snakemake.output[0])
    log.info(
        "search %s against %s: largest distance %.3f of a range, score %+.3f: %s",
        result.search,
        snakemake.input.committed,
        result.max_unit_distance,
        result.score_difference,
        "same optimum" if result.same_optimum else "different optimum",
    )
