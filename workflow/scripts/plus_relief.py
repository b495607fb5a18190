"""Adapter: TE of the p-d pair, tip-relief optima (differential evolution), mesh stiffness against ISO and
the load study -> te.nc and tables (paper 2 Sec. 4 beside ours for a design that names the paper)."""

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.papers import paper_of
from geardyn.plots import captions
from geardyn.plus import design, ishikawa, relief, tables

log = logs.to_file(snakemake.log[0])
out = snakemake.output
plus = design.load(snakemake.input.design)
paper = paper_of(plus.paper)
grid = ishikawa.design_grid(plus)
optima = [relief.optimise(plus, shape, bounds, grid=grid) for shape in relief.SHAPES for bounds in relief.BOUND_SETS]
for o in optima:
    log.info(
        "%s/%s: amount %.3f um, length %.4f mm, ptp %.3f um (%.1f %%), %d evaluations",
        o.shape,
        o.bounds,
        o.amount * 1e6,
        o.length * 1e3,
        o.ptp * 1e6,
        100 * o.reduction,
        o.nfev,
    )
rt = tables.relief_table(optima, paper)
ours = [o.ptp * 1e6 for o in optima]
if paper is not None:  # our TE at the paper's relief, beside the paper's row
    pr = paper.PAPER_RELIEF
    ours.append(
        ishikawa.design_te(
            plus, relief_amount=pr["amount_mm"] * 1e-3, relief_length=pr["length_mm"] * 1e-3, relief_shape="linear"
        ).ptp
        * 1e6
    )
rt["ours_at_this_relief_um"] = ours
tables.write_table(rt, out.optima_csv, out.optima_md, captions.relief_header(ishikawa.pd_mesh_load(plus), plus, paper))
ds = tables.te_dataset(plus, optima)
io.write_netcdf(
    ds,
    out.te,
    provenance.attributes(
        title=ds.attrs["title"], paper=plus.paper, config=dict(plus.raw), model_variant=ds.attrs["model_variant"]
    ),
)
tables.write_table(tables.stiffness_comparison(plus), out.stiffness_csv, out.stiffness_md, captions.STIFFNESS_HEADER)
lt = relief.load_study(plus, tuple(plus.relief.load_study_torques))
tables.write_table(lt, out.load_csv, out.load_md, captions.load_study_header(plus, paper))
log.info("load study: %s", lt.round(2).to_dict("records"))
