"""Adapter: global search of a paper design's unknowns, scored by the paper's claims (resumes from its cache)."""

import dataclasses
import json
import time
from pathlib import Path

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.khv import design, point
from geardyn.khv.calibrate import evaluate, optimise, products, space
from geardyn.label import Policy
from geardyn.papers import paper_of

log = logs.to_file(snakemake.log[0])
spec = snakemake.params.spec
drive = design.load(snakemake.input.design)
paper = paper_of(drive.paper)
problem, budget = optimise.problem_from_config(drive, spec)
start = [products.design_values(drive, problem.space)]
if spec["search"].get("start"):
    start.append({**start[0], **spec["search"]["start"]})
cache = Path(snakemake.output.scores).with_name(f"{snakemake.wildcards.calibration}_cache.jsonl")
t0, c0 = time.time(), time.process_time()
best, ev = optimise.search(problem, cache, init=start, workers=snakemake.threads, **budget)
wall = time.time() - t0
records = ev.searched()  # this search's candidates (the cache may hold others)
# the best few again at the design's own integration settings and the default classifier
full = dataclasses.replace(problem, policy=Policy(point.integration_settings(drive)))
with evaluate.Evaluator(
    full, cache.with_name(f"{snakemake.wildcards.calibration}_verify_cache.jsonl"), snakemake.threads
) as vev:
    best, verified, pairs = optimise.verified_choice(
        records, vev.records, spec["search"].get("verify_top", 5), problem.require
    )
cost = {
    "candidates": len(records),
    "new evaluations": ev.new,
    "reused from cache": ev.reused,
    "wall s": wall,
    "wall s per new candidate (all workers)": wall / max(ev.new, 1),
    "points per candidate": problem.grids.n_points,
}
ds = products.records_dataset(records, problem.space, problem.grids)
attrs = provenance.attributes(
    title=f"Calibration search {snakemake.wildcards.calibration}",
    paper=drive.paper,
    config={"design": drive.raw, "calibration": spec},
    model_variant=drive.stiffness.label,
)
io.write_netcdf(ds, snakemake.output.scores, attrs)
cost["wall s with verification"] = time.time() - t0
result = products.search_result(best, snakemake.wildcards.calibration, len(records), verified, problem.require)
io.write_text(
    json.dumps(
        {
            "result": result,
            "record": best.to_json(),
            "verified": verified.to_json(),
            "cost": cost,
            "verified_top": [
                {
                    "values": a.values,
                    "search_score": a.score,
                    "verified_score": b.score,
                    "verified_agree": b.agree,
                    "interior": space.interior(a.unit),
                }
                for a, b in pairs
            ],
        },
        indent=1,
        sort_keys=True,
    ),
    snakemake.output.best,
)
name = spec["search"].get("design_name") or f"{drive.name}_calibrated"
io.write_text(
    products.search_design_text(Path(snakemake.input.design).read_text(), name, result), snakemake.output.design
)
io.write_text(
    products.search_table(records, problem.space, paper, best, cost, verified=verified, pairs=pairs),
    snakemake.output.table,
)
log.info(
    "search: %d candidates (%d new), best score %.3f (%d agree), %.1f s",
    len(records),
    ev.new,
    best.score,
    best.agree,
    wall,
)
