"""Adapter: linear forced response of the plus set to the static TE of the p-d meshes (without and with each
optimal tip relief of te.nc) against input speed -> forced_response.nc and its figure."""

from geardyn import io
from geardyn.io import logs, provenance
from geardyn.papers import paper_of
from geardyn.plots import captions, save_figure
from geardyn.plots import plus as plots
from geardyn.plus import design, forced

log = logs.to_file(snakemake.log[0])
plus = design.load(snakemake.input.design)
te = io.read_dataset(snakemake.input.te)
cases = tuple(str(c) for c in te.case.values)
res = forced.forced_response(plus, te.transmission_error.values * 1e-6, cases)
ds = forced.to_dataset(res, plus)
io.write_netcdf(
    ds,
    snakemake.output.data,
    provenance.attributes(
        title=ds.attrs["title"],
        paper=plus.paper,
        config=dict(plus.raw),
        model_variant="linear modal, modal damping, static TE excitation",
    ),
)
save_figure(
    plots.forced_response_figure(ds), snakemake.output.figure, captions.forced_response(plus, ds, paper_of(plus.paper))
)
log.info("forced response: %d speeds, %d harmonics, cases %s", ds.sizes["speed"], ds.sizes["harmonic"], cases)
