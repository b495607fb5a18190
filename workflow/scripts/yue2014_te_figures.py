"""Adapter: TE before/after relief (Figs. 4 and 9 analogues) and the objective landscape."""


import matplotlib

matplotlib.use("Agg")

import numpy as np
import pandas as pd
import xarray as xr

from geardyn.plots import plus as plots
from geardyn.plus import files


def main(design_path, te_nc, landscape_nc, optima_csv, fig04, fig09, fig09b, log_path=None):
    with files.logger(log_path, "yue2014_te_figures") as log:
        design = files.read_design(design_path)
        with xr.open_dataset(te_nc) as te, xr.open_dataset(landscape_nc) as land:
            te, land = te.load(), land.load()
        opt = pd.read_csv(optima_csv)
        tr0 = te.transmission_error.sel(case="unmodified").values
        assumptions = (f"Assumptions: T = {design.torque*1e3:g} N mm on the sun shared by {design.n_planets} planets -> "
                       f"W = {te.attrs['load_N']:.1f} N on the p-d mesh; Ishikawa rectangle (root to base circle) + trapezoid "
                       f"(base circle to tip) teeth, shear factor {design.te.shear_coefficient:g}, Hertz 4(1-nu^2)W/(pi E b); "
                       f"Ef1 = Ef2 = {design.te.ef1*1e6:g} um constant (shift TE only); ES = {design.te.es*1e6:g} um as a "
                       "base-pitch difference (successive pairs differ by ES; the incoming pair has the excess material).")
        f4 = plots.te_unmodified_figure(te)
        files.write_figure(f4, fig04, (
            "Fig. 4 analogue: static transmission error TE = E - delta (Eq. 9) of the unmodified p-d pair over two mesh "
            "periods and the load on each tooth-pair slot.\n" + assumptions +
            f"\nResult: peak-to-peak {np.ptp(tr0):.2f} um (paper Fig. 9 FE: about 9 um; Fig. 4 Ishikawa: larger by about "
            f"7.8 %). Contact ratio {te.attrs['contact_ratio']:.3f}."))
        lines = [f"  {r.shape}/{r.bounds}: amount {r.amount_um:.2f} um, length {r.length_mm:.3f} mm, ptp "
                 f"{r.te_ptp_before_um:.2f} -> {r.te_ptp_after_um:.2f} um ({r.reduction_pct:+.1f} %)"
                 for r in opt.itertuples() if not r.shape.startswith("linear (paper)")]
        lines += [f"  paper's optimum (linear, {r.amount_um:.2f} um, {r.length_mm:.3f} mm) in our model: "
                  f"{r.ours_at_this_relief_um:.2f} um (unmodified {np.ptp(tr0):.2f} um)"
                  for r in opt.itertuples() if r.shape.startswith("linear (paper)")]
        f9 = plots.te_relief_figure(te)
        files.write_figure(f9, fig09, (
            "Fig. 9 analogue: static TE of the p-d pair (mean removed) before and after the optimal linear and parabolic "
            "tip relief, optimised with differential evolution within the paper's bounds (amount 20-80 um, length "
            "0.0001-2.6 mm) and within physically sensible bounds (amount 0-30 um, length 0-4.5 mm).\n" + assumptions +
            "\nResults (paper: 9 -> 6.5 um, -27.78 %, linear, amount 32.5 um, length 2.498 mm):\n" + "\n".join(lines)))
        r = design.relief
        boxes = {"paper": (r.paper_amount[0] * 1e6, r.paper_amount[1] * 1e6, r.paper_length[0] * 1e3, r.paper_length[1] * 1e3),
                 "physical": (r.physical_amount[0] * 1e6, r.physical_amount[1] * 1e6, r.physical_length[0] * 1e3, r.physical_length[1] * 1e3)}
        recs = opt.to_dict("records")
        for rec in recs:
            if rec["shape"].startswith("linear (paper)"):
                rec["ours_um"] = rec.get("ours_at_this_relief_um", float("nan"))
        f9b = plots.relief_landscape_figure(land, recs, boxes)
        z = land.te_ptp
        files.write_figure(f9b, fig09b, (
            "Objective landscape of the relief optimisation (no counterpart in the paper): peak-to-peak static TE of the "
            "p-d pair over relief amount and length, for linear and parabolic relief applied to both tips; dashed boxes: "
            "paper's and physical bounds; markers: DE optima and the paper's optimum.\n" + assumptions +
            f"\nGrid {z.sizes['amount']} x {z.sizes['length']}; ptp from {float(z.min()):.2f} to {float(z.max()):.2f} um; "
            f"unmodified {np.ptp(tr0):.2f} um. The paper's lower amount bound (20 um) lies above the optimum amount for "
            "this load, so the paper-bound optima sit on that bound."))
        log.info("figures written")


if "snakemake" in globals():
    sm = globals()["snakemake"]
    main(sm.input.design, sm.input.te, sm.input.landscape, sm.input.optima_csv, sm.output.fig04, sm.output.fig09,
         sm.output.fig09b, sm.log[0])
