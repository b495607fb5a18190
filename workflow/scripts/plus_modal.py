"""Adapter: modal analysis of a plus set -> modal.nc, natural frequencies, stiffness scaling, key elements
(paper 2 Tables 2 and 5 beside ours for a design that names the paper)."""

import pandas as pd

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.papers import paper_of
from geardyn.plots import captions
from geardyn.plus import design, tables

log = logs.to_file(snakemake.log[0])
out = snakemake.output
plus = design.load(snakemake.input.design)
paper = paper_of(plus.paper)
ds = tables.modal_dataset(plus)
io.write_netcdf(
    ds,
    out.modal,
    provenance.attributes(
        title=ds.attrs["title"], paper=plus.paper, config=dict(plus.raw), model_variant=ds.attrs["model_variant"]
    ),
)
t2 = tables.frequency_table(plus, paper)
t5 = tables.key_element_table(plus, paper)
if paper is None:
    tables.write_table(t2, out.table02_csv, out.table02_md, captions.table02_header(None))
    tables.write_table(t5, out.table05_csv, out.table05_md, captions.KEY_ELEMENT_HEADER)
    note = pd.DataFrame([{"note": "no paper to compare with: the design names none"}])
    tables.write_table(note, out.scaling_csv, out.scaling_md, "# Stiffness scaling against a paper: not applicable")
else:
    tables.write_table(t2, out.table02_csv, out.table02_md, captions.table02_header(paper))
    tables.write_table(t5, out.table05_csv, out.table05_md, captions.paper_says(paper, "table05"))
    sc = tables.scaling_table(plus, paper)
    best = float(sc.uniform_factor.iloc[0])
    factors = [1.0] + [float(v) for v in tables.stiffness_comparison(plus)["ratio_to_table1"].iloc[[2, 3, 4]]] + [best]
    fixed = pd.DataFrame(
        [
            {**tables.fixed_factor_residual(plus, paper, f), "why": why}
            for f, why in zip(factors, captions.FIXED_FACTOR_WHY, strict=True)
        ]
    )
    scaled = tables.scaled_frequency_table(plus, paper, best)[
        [
            "condition",
            "order",
            "stiffness_factor",
            "freq_hz",
            "mode_type",
            "paper_theoretical_hz",
            "err_theoretical_pct",
            "err_experimental_pct",
        ]
    ]
    tables.write_table(sc, out.scaling_csv, None)
    io.write_text(
        captions.paper_says(paper, "scaling")
        + tables.to_markdown(sc)
        + "\n## Residual against the theoretical column for given stiffness factors\n\n"
        + tables.to_markdown(fixed)
        + f"\n## Table 2 with every stiffness x {best:.3g}\n\n"
        + tables.to_markdown(scaled),
        out.scaling_md,
    )
    log.info("uniform stiffness factor %.3g, residual rms %.1f %%", best, float(sc.uniform_rms_pct.iloc[0]))
log.info("first elastic frequencies (Hz): %s", t2.groupby("condition").freq_hz.first().round(1).to_dict())
