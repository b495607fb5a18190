"""Regime bands of a sweep: runs of equal motion labels along the control parameter, as rows,
CSV and Markdown."""

from __future__ import annotations

import numpy as np
import xarray as xr

from geardyn.io import markdown_table
from geardyn.label import vocabulary
from geardyn.runs.cube import labels_of_cube


def bands(values: np.ndarray, labels: np.ndarray) -> list[tuple[float, float, int]]:
    """Runs of equal labels along a sweep as (first value, last value, label)."""
    out: list[tuple[float, float, int]] = []
    start = 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[start]:
            out.append((float(values[start]), float(values[i - 1]), int(labels[start])))
            start = i
    return out


def band_rows(cube: xr.Dataset) -> list[dict]:
    """Regime bands of a sweep cube: runs of equal labels along the control parameter per (case,
    direction), with the median exponent and the transition point to the next band (midway between
    the last point of this band and the first of the next; NaN for the last band)."""
    par = cube.attrs["control_parameter"]
    values, labels = cube[par].values, labels_of_cube(cube)
    lam = cube["lyapunov"].values if "lyapunov" in cube else np.full(labels.shape, np.nan)
    rows = []
    for i, case in enumerate(cube["case"].values):
        for j, direction in enumerate(cube["direction"].values):
            runs = bands(values, labels[i, j])
            for r, (a, b, lab) in enumerate(runs):
                m = (values >= a) & (values <= b)
                nxt = 0.5 * (b + runs[r + 1][0]) if r + 1 < len(runs) else float("nan")
                lm = lam[i, j][m]
                rows.append(
                    {
                        "case": str(case),
                        "direction": str(direction),
                        "label": int(lab),
                        "name": vocabulary.short_name(lab),
                        "start": a,
                        "stop": b,
                        "n_points": int(m.sum()),
                        "lyapunov_median": float(np.nanmedian(lm)) if np.isfinite(lm).any() else float("nan"),
                        "transition_to_next": nxt,
                    }
                )
    return rows


def bands_csv(rows: list[dict]) -> str:
    columns = list(rows[0]) if rows else []  # the keys of band_rows, in its order
    cells = [[f"{r[c]:.6g}" if isinstance(r[c], float) else str(r[c]) for c in columns] for r in rows]
    return "\n".join(",".join(line) for line in [columns, *cells]) + "\n"


def bands_markdown(rows: list[dict], title: str, par: str) -> str:
    lines = [
        f"# Regime bands: {title}",
        "",
        f"Runs of equal motion labels along {par} (geardyn.label); transition = midway "
        "between the last point of a band and the first of the next (half a grid step uncertainty).",
        "",
    ]
    keys = ("case", "direction", "name", "start", "stop", "n_points", "lyapunov_median", "transition_to_next")
    header = ("case", "direction", "label", "from", "to", "points", "median lambda_max", "transition to next")
    fmt = {"start": ".4g", "stop": ".4g", "lyapunov_median": ".2e", "transition_to_next": ".4g"}
    lines.append(markdown_table(header, [[format(r[k], fmt.get(k, "")) for k in keys] for r in rows], "---rrrrr"))
    return "\n".join(lines) + "\n"
