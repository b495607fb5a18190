"""Adapter: the probability that each claim of a design's paper decided along the study's line holds, over the
study's samples -> Markdown and CSV beside claims.md."""

from geardyn import io
from geardyn.io import logs, tables
from geardyn.khv import design
from geardyn.papers import paper_of
from geardyn.runs import probability_stats

log = logs.to_file(snakemake.log[0])
drive = design.header(snakemake.input.design)
paper = paper_of(drive.paper)
ds = io.read_dataset(snakemake.input.cube)
role = snakemake.params.spec["claims"]
name, values = (
    snakemake.params.spec.get("given", {}).get("parameter"),
    snakemake.params.spec.get("given", {}).get("values", [None]),
)
# a study given values of an operating condition: its lines stacked value by value, `each` at each value, of
# which n are the probabilities' samples (sample_block >= 0; claim_probabilities counts those only)
each = ds.sizes["sample"] // len(values)
n = int((ds["sample_block"] >= 0).sum()) // len(values)
rows = [
    {**({name: v} if name else {}), **row, "id": f"{row['id']} ({name} = {v:g})" if name else row["id"]}
    for c, v in enumerate(values)
    for row in probability_stats.claim_probabilities(paper, ds.isel(sample=slice(c * each, (c + 1) * each)), role)
]
note = (
    f"Design `{drive.name}`: the claims of {paper.SHORT} decided along {paper.CLAIM_LINES[role].get('text', role)}, "
    f"each checked (geardyn.claims, as in claims.md) on every one of the {n} samples of the probabilities of study "
    f"`{snakemake.wildcards.prob}`: {ds.attrs['inputs']}. Sampling: {ds.attrs['sampling']}. P(holds): the share of "
    "the samples on which the claim agrees, with its 95 % Wilson interval"
    + (f", given each value of {name} (P(holds | {name}): the rows of one value share its samples)." if name else ".")
)
title = f"Claims of {paper.SHORT} under the study's inputs ({snakemake.wildcards.prob})"
io.write_text(tables.claims_markdown(rows, title, note), snakemake.output.md)
io.write_text(tables.claims_csv(rows), snakemake.output.csv)
log.info("%s: %s", snakemake.wildcards.prob, {r["id"]: round(r["agree"], 3) for r in rows})
