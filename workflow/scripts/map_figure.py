"""Adapter: label image of a regime map with the sweeps' 1-D cuts drawn on it (and its regime boundaries as
curves, when the map computes them)."""

from geardyn import io
from geardyn.io import logs
from geardyn.plots import captions, save_figure
from geardyn.plots.curves import summary
from geardyn.plots.dynamics import plot_map

log = logs.to_file(snakemake.log[0])
ds = io.read_dataset(snakemake.input.cube)
spec = snakemake.params.spec
title = spec.get("title") or snakemake.wildcards.map
curves = io.read_dataset(snakemake.input.curves) if getattr(snakemake.input, "curves", None) else None
text = captions.regime_map(snakemake.wildcards.map, ds)
if curves is not None:
    found = summary(curves)["curves"]
    text += (
        "\nRegime boundaries drawn over the label and impact-class panels (solid: they bound a stable orbit; dotted: "
        "the orbit is already unstable; figures/"
        + snakemake.wildcards.map
        + "_curves.png, docs/orbits.md): "
        + ("; ".join(f"{v} {k}" for k, v in found.items()) or "none")
        + "."
    )
save_figure(plot_map(ds, title, spec.get("cuts_x", []), spec.get("cuts_y", []), curves), snakemake.output.figure, text)
