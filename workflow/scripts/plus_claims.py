"""Adapter: a paper's statements (its CLAIMS, stated as data) against the tables and datasets of a plus-set
design that names that paper -> claims.md and claims.csv."""

import pandas as pd

from geardyn import io
from geardyn.claims import verdicts
from geardyn.io import logs
from geardyn.papers import paper_of
from geardyn.plus import claims as plus_claims
from geardyn.plus import design

log = logs.to_file(snakemake.log[0])
inp = snakemake.input
plus = design.load(inp.design)
paper = paper_of(plus.paper)
products = plus_claims.PlusProducts(
    frequencies=pd.read_csv(inp.frequencies),
    scaling=pd.read_csv(inp.scaling),
    key_elements=pd.read_csv(inp.key_elements),
    modal=io.read_dataset(inp.modal),
    te=io.read_dataset(inp.te),
    optima=pd.read_csv(inp.optima),
    forced=io.read_dataset(inp.forced),
)
rows = plus_claims.plus_claims(paper, products)
note = plus_claims.products_note(plus.name, plus.title, paper)
io.write_text(verdicts.to_markdown(rows, plus.name, note, paper.SHORT), snakemake.output.md)
io.write_text(verdicts.to_csv(rows), snakemake.output.csv)
log.info("claims: %s", verdicts.counts(rows))
