"""Adapter: label image of a regime map with the paper's 1-D cuts drawn on it."""

import xarray as xr

from geardyn import io, logs, maps
from geardyn.plots.dynamics import plot_map

log = logs.to_file(snakemake.log[0])
with xr.open_dataset(snakemake.input.cube) as ds:
    ds.load()
spec = snakemake.params.spec
title = spec.get("title") or snakemake.wildcards.map
shares = ", ".join(f"{k} {100 * v:.1f} %" for k, v in sorted(maps.fractions(ds).items(), key=lambda kv: -kv[1]))
caption = (f"{snakemake.wildcards.map}: motion label over ({ds.attrs['x_parameter']}, {ds.attrs['y_parameter']}), "
           f"{ds.sizes['x']} x {ds.sizes['y']} points, fixed {ds.attrs['fixed_overrides']}; "
           f"{ds.attrs['steps_per_period']} steps per period, {ds.attrs['transient_periods']} transient + "
           f"{ds.attrs['recorded_periods']} recorded periods, classifier cheap path (periodic points get no exponent; "
           f"the others {ds.attrs['classifier_tangent_periods']} more periods with the tangent vector). "
           f"Label shares: {shares}. Lines: the paper's 1-D cuts (Figs. 7, 9, 11) and the designs' mesh frequencies.")
io.save_figure(plot_map(ds, title, spec.get("cuts_x", []), spec.get("cuts_y", [])), snakemake.output.figure, caption)
