"""Adapter: robustness and sensitivity of the best candidate of a calibration search (tornado, 2-D map)."""

import json
from pathlib import Path

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design
from geardyn.khv.calibrate import evaluate, objective, optimise, records, robustness
from geardyn.papers import paper_of
from geardyn.plots import calibration as plots
from geardyn.plots import save_figure

log = logs.to_file(snakemake.log[0])
spec = snakemake.params.spec
drive = design.load(snakemake.input.design)
problem, _ = optimise.problem_from_config(drive, spec)
best = records.Record.from_json(json.loads(Path(snakemake.input.best).read_text())["record"])
cache = Path(snakemake.input.best).with_name(f"{snakemake.wildcards.calibration}_cache.jsonl")
sens = spec.get("sensitivity", {})
with evaluate.Evaluator(problem, cache, spec["search"].get("workers", 1)) as ev:
    oat, mp, text = robustness.sensitivity(
        problem, ev, best.values, sens.get("steps", [0.02, 0.1, 0.5]), sens.get("map_points", 7)
    )
attrs = provenance.attributes(
    title=f"Calibration sensitivity {snakemake.wildcards.calibration}",
    paper=drive.paper,
    config={"design": drive.raw, "calibration": spec},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(oat, snakemake.output.oat, attrs)
io.write_netcdf(mp, snakemake.output.map, attrs)
paper = paper_of(drive.paper)
leave = objective.paper_transitions(paper)["leave_p1"]
fixed = paper.CLAIM_LINES[paper.CALIBRATION["line"]]["fixed"]
save_figure(plots.plot_tornado(oat, leave), snakemake.output.tornado, plots.caption_tornado(oat, fixed, leave))
save_figure(plots.plot_score_map(mp), snakemake.output.map_figure, plots.caption_map(mp))
io.write_text(text, snakemake.output.table)
log.info("sensitivity: %d new evaluations, %d from the cache", ev.new, ev.reused)
