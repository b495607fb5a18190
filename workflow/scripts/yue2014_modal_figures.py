"""Adapter: paper 2 modal energy figures (Figs. 6-7 analogues) from modal.nc."""


import matplotlib

matplotlib.use("Agg")

import xarray as xr

from geardyn.plots import plus as plots
from geardyn.plus import files


def _summary(ds: xr.Dataset, var: str, dim: str) -> str:
    lines = []
    for cond in ds.condition.values:
        sub = ds.sel(condition=cond)
        f = sub.natural_frequency.values
        groups = plots._distinct_groups(f)[:6]
        for k, grp in enumerate(groups, 1):
            vals = sub[var].isel(mode=grp).mean("mode")
            top = vals.sortby(vals, ascending=False)[:3]
            desc = ", ".join(f"{str(n)} {float(v):.2f}" for n, v in zip(top[dim].values, top.values))
            lines.append(f"  {cond}-{k} {f[grp[0]]:.0f} Hz ({sub.mode_type.values[grp[0]]}{', x2' if len(grp) == 2 else ''}): {desc}")
    return "\n".join(lines)


def main(modal_nc, fig06, fig07, fig07b, log_path=None):
    with files.logger(log_path, "yue2014_modal_figures") as log:
        with xr.open_dataset(modal_nc) as ds:
            ds = ds.load()
        common = ("Model: 11-DOF Lagrangian lumped model from Table 1 (k = 21 MN/m meshes, 3.2 MN/m sun bearing), "
                  "planet angles in the sun terms and the plus-set sign fixed (docs/paper2.md). Doubled planet modes are "
                  "averaged over the pair, which makes the bars independent of the basis chosen in the eigenspace. "
                  "The paper's Figs. 6-7 come from its SimulationX model (power loss and amplitude) at 4-10x higher "
                  "frequencies; compare the pattern, not the numbers.")
        f6 = plots.modal_strain_energy_figure(ds)
        files.write_figure(f6, fig06, "Fig. 6 analogue: share of the modal strain energy stored in each mesh (Table 3 "
                           "numbering 1-9) for the first six distinct elastic frequencies of working conditions I-III.\n"
                           + common + "\nLargest shares (element share):\n" + _summary(ds, "strain_energy_share", "element"))
        f7 = plots.modal_kinetic_energy_figure(ds)
        files.write_figure(f7, fig07, "Fig. 7 analogue: share of the modal kinetic energy in each component (Table 4 "
                           "numbering 1-12: planet revolution, planet rotations, sun incl. translation, ring, carrier).\n"
                           + common + "\nLargest shares (component share):\n" + _summary(ds, "kinetic_energy_share", "component"))
        f7b = plots.mode_shape_figure(ds)
        files.write_figure(f7b, fig07b, "Fig. 7 analogue (mode shapes): displacement of each coordinate in the first six "
                           "distinct elastic modes of conditions I-III; rotations times their lever arm (base radius; carrier: "
                           "sun-planet centre distance 102 mm), planets relative to the carrier, sun translation x_s, y_s; "
                           "normalised to a largest |value| of 1. Doubled (planet) modes: the member with y_s = 0.\n" + common +
                           "\nPlanet modes (doubled, shared by I-III at 339.8, 877.6, 1314.0 Hz) keep sun, ring and carrier "
                           "rotations at zero and move the sun on its bearing; overall modes move all planet sets alike.")
        log.info("figures written: %s, %s, %s", fig06, fig07, fig07b)


if "snakemake" in globals():
    sm = globals()["snakemake"]
    main(sm.input.modal, sm.output.fig06, sm.output.fig07, sm.output.fig07b, sm.log[0])
