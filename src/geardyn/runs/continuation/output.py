"""The outputs of a sweep's continuation: all branches as one CF dataset (netCDF), the table of
bifurcation points (CSV), and the branches read back from a dataset."""

from __future__ import annotations

import csv
from collections.abc import Mapping, Sequence
from io import StringIO
from typing import Any

import numpy as np
import xarray as xr

from geardyn import libm
from geardyn.khv import point
from geardyn.runs.continuation.branch import BIFURCATION_TYPES, TYPE_CODES, Bifurcation, Branch
from geardyn.runs.continuation.family import Family, cycle_states
from geardyn.runs.continuation.spec import STATE_VARS

_ONE = {"units": "1"}
_D = 6  # state dimension of the KHV model


def _point_vars(
    branches: Sequence[tuple[int, Branch]], families: Mapping[int, Family], units: str, long_name: str, nmax: int
) -> dict[str, Any]:
    """The per-point variables (dimension ``point``, all branches one after the other)."""
    one, d = _ONE, _D
    rows = sum(len(b) for _, b in branches)
    bid = np.zeros(rows, np.int32)
    case = np.zeros(rows, np.int32)
    per = np.zeros(rows, np.int16)
    pv = np.zeros(rows)
    st = np.zeros((rows, d))
    mu = np.zeros((rows, d), complex)
    arc = np.zeros(rows)
    graz = np.zeros(rows)
    cyc = np.full((rows, nmax), np.nan)
    k = 0
    for j, (c, b) in enumerate(branches):
        m = len(b)
        sl = slice(k, k + m)
        bid[sl], case[sl], per[sl] = j, c, b.n
        pv[sl], st[sl], mu[sl], arc[sl], graz[sl] = b.p, b.states, b.multipliers, b.arclength, b.grazing
        for i in range(m):
            cyc[k + i, : b.n] = (
                cycle_states(families[c], float(b.p[i]), b.states[i], b.n)[:, 1] if b.n > 1 else b.states[i, 1]
            )
        k += m
    radius = np.max(libm.cabs(mu), axis=1)  # (rows,), also for no rows
    return {
        "branch": ("point", bid, {**one, "long_name": "index of the continued branch"}),
        "case_index": ("point", case, {**one, "long_name": "index of the sweep case (fixed overrides)"}),
        "orbit_period": ("point", per, {**one, "long_name": "period of the orbit in mesh periods"}),
        "parameter": ("point", pv, {"units": units, "long_name": long_name}),
        "orbit_state": (
            ("point", "state"),
            st,
            {**one, "long_name": "orbit state at mesh phase 0 (x / b_c, dx/dtau / b_c)"},
        ),
        "multiplier_real": (("point", "multiplier"), mu.real, {**one, "long_name": "Floquet multiplier, real part"}),
        "multiplier_imag": (
            ("point", "multiplier"),
            mu.imag,
            {**one, "long_name": "Floquet multiplier, imaginary part"},
        ),
        "spectral_radius": (
            "point",
            radius,
            {**one, "long_name": "largest Floquet multiplier modulus (< 1: stable)"},
        ),
        "stable": (
            "point",
            (radius < 1.0).astype(np.int8),
            {
                "long_name": "orbit asymptotically stable",
                "flag_values": np.array([0, 1], np.int8),
                "flag_meanings": "unstable stable",
            },
        ),
        "arclength": ("point", arc, {**one, "long_name": "arclength along the branch in scaled variables"}),
        "grazing_margin": (
            "point",
            graz,
            {**one, "long_name": "min over the cycle of |X_VH| / b_c - b (< 0: contact lost)"},
        ),
        "cycle_x_vh": (("point", "cycle"), cyc, {**one, "long_name": "X_VH / b_c at the phase-0 points of the cycle"}),
    }


def _bifurcation_vars(bifs: Sequence[tuple[int, int, Bifurcation]], units: str, long_name: str) -> dict[str, Any]:
    """The per-bifurcation variables (dimension ``bifurcation``); ``bifs``: (branch, case, point)."""
    one, d, nb = _ONE, _D, len(bifs)
    return {
        "bifurcation_branch": (
            "bifurcation",
            np.array([j for j, _, _ in bifs], np.int32),
            {**one, "long_name": "branch of the bifurcation point"},
        ),
        "bifurcation_type": (
            "bifurcation",
            np.array([TYPE_CODES[bf.kind] for _, _, bf in bifs], np.int8),
            {
                "long_name": "type of the bifurcation point",
                "flag_values": np.arange(len(BIFURCATION_TYPES), dtype=np.int8),
                "flag_meanings": " ".join(BIFURCATION_TYPES),
            },
        ),
        "bifurcation_parameter": (
            "bifurcation",
            np.array([bf.p for _, _, bf in bifs]),
            {"units": units, "long_name": f"{long_name} at the bifurcation point"},
        ),
        "bifurcation_x_vh": (
            "bifurcation",
            np.array([bf.state[1] for _, _, bf in bifs]),
            {**one, "long_name": "X_VH / b_c of the orbit at the bifurcation point (phase 0)"},
        ),
        "critical_multiplier_real": (
            "bifurcation",
            np.array([bf.critical.real for _, _, bf in bifs]),
            {**one, "long_name": "crossing multiplier, real part (NaN for grazing)"},
        ),
        "critical_multiplier_imag": (
            "bifurcation",
            np.array([bf.critical.imag for _, _, bf in bifs]),
            {**one, "long_name": "crossing multiplier, imaginary part"},
        ),
        "rotation_number": (
            "bifurcation",
            np.array([bf.rotation_number for _, _, bf in bifs]),
            {**one, "long_name": "arg(mu) / (2 pi) of the Neimark-Sacker pair (NaN otherwise)"},
        ),
        "located": (
            "bifurcation",
            np.array([int(bf.located) for _, _, bf in bifs], np.int8),
            {
                "long_name": "point refined on the branch (else interpolated between two points)",
                "flag_values": np.array([0, 1], np.int8),
                "flag_meanings": "bracketed located",
            },
        ),
        "bifurcation_multiplier_real": (
            ("bifurcation", "multiplier"),
            np.array([bf.multipliers.real for _, _, bf in bifs]).reshape(nb, d),
            {**one, "long_name": "Floquet multipliers at the bifurcation point, real part"},
        ),
        "bifurcation_multiplier_imag": (
            ("bifurcation", "multiplier"),
            np.array([bf.multipliers.imag for _, _, bf in bifs]).reshape(nb, d),
            {**one, "long_name": "Floquet multipliers at the bifurcation point, imaginary part"},
        ),
    }


def branch_dataset(
    branches: Sequence[tuple[int, Branch]], families: Mapping[int, Family], parameter: str, case_labels: Sequence[str]
):
    """All branches of a sweep as one CF dataset (points of all branches along ``point``)."""

    units, long_name = point.CONTROLS.get(parameter, (point.units_of(parameter), parameter))
    nmax = max([b.n for _, b in branches], default=1)
    bifs = [(j, c, bf) for j, (c, b) in enumerate(branches) for bf in b.bifurcations]
    data = {**_point_vars(branches, families, units, long_name, nmax), **_bifurcation_vars(bifs, units, long_name)}
    coords = {
        "state": ("state", list(STATE_VARS), {"long_name": "state component"}),
        "multiplier": (
            "multiplier",
            np.arange(_D, dtype=np.int32),
            {**_ONE, "long_name": "multiplier index (by decreasing modulus)"},
        ),
        "cycle": (
            "cycle",
            np.arange(nmax, dtype=np.int32),
            {**_ONE, "long_name": "index of the phase-0 point in the cycle"},
        ),
        "case": ("case", list(case_labels), {"long_name": "case (fixed overrides)"}),
    }
    ends = {
        f"branch_{j}_ends": f"down={b.end_status.get('down')} up={b.end_status.get('up')}"
        for j, (_, b) in enumerate(branches)
    }
    return xr.Dataset(data, coords=coords, attrs={"control_parameter": parameter, **ends})


TABLE_COLUMNS = (
    "case",
    "branch",
    "period",
    "type",
    "parameter",
    "value",
    "critical_multiplier",
    "modulus",
    "rotation_number",
    "located",
    "multipliers",
    "paper_transition",
    "paper_difference",
)


def bifurcation_rows(
    branches: Sequence[tuple[int, Branch]],
    parameter: str,
    case_labels: Sequence[str],
    paper_transitions: Sequence[float] | None = None,
) -> list[dict[str, Any]]:
    """One row per bifurcation point; ``paper_transitions``: the paper's transition values along the
    same parameter (only for a design that names its paper), nearest one and the difference."""
    rows = []
    for j, (c, b) in enumerate(branches):
        for bf in b.bifurcations:
            near, diff = "", ""
            if paper_transitions:
                t = min(paper_transitions, key=lambda v: abs(v - bf.p))
                near, diff = f"{t:g}", f"{bf.p - t:+.4f}"
            crit = bf.critical
            rows.append(
                {
                    "case": case_labels[c],
                    "branch": j,
                    "period": b.n,
                    "type": bf.kind,
                    "parameter": parameter,
                    "value": f"{bf.p:.7f}",
                    "critical_multiplier": "" if not np.isfinite(crit.real) else f"{crit.real:+.6f}{crit.imag:+.6f}j",
                    "modulus": "" if not np.isfinite(crit.real) else f"{abs(crit):.6f}",
                    "rotation_number": "" if not np.isfinite(bf.rotation_number) else f"{bf.rotation_number:.5f}",
                    "located": int(bf.located),
                    "multipliers": " ".join(f"{m.real:+.4f}{m.imag:+.4f}j" for m in bf.multipliers),
                    "paper_transition": near,
                    "paper_difference": diff,
                }
            )
    rows.sort(key=lambda r: (r["case"], float(r["value"])))
    return rows


def rows_to_csv(rows: Sequence[Mapping[str, Any]]) -> str:
    """The table as CSV text (columns :data:`TABLE_COLUMNS`, a header line, ``\\n`` line ends)."""

    buf = StringIO()
    w = csv.DictWriter(buf, fieldnames=list(TABLE_COLUMNS), lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow(r)
    return buf.getvalue()


def branches_from_dataset(ds: Any) -> list[tuple[int, Branch]]:
    """The branches of a :func:`branch_dataset` file (points, states, multipliers; no bifurcations)."""
    out = []
    ids = ds["branch"].values
    for b in np.unique(ids):
        m = ids == b
        mu = ds["multiplier_real"].values[m] + 1j * ds["multiplier_imag"].values[m]
        br = Branch(
            n=int(ds["orbit_period"].values[m][0]),
            p=ds["parameter"].values[m],
            states=ds["orbit_state"].values[m],
            multipliers=mu,
            arclength=ds["arclength"].values[m],
            grazing=ds["grazing_margin"].values[m],
            iterations=np.zeros(int(m.sum()), np.int32),
        )
        out.append((int(ds["case_index"].values[m][0]), br))
    return out
