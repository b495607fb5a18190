"""The outputs of continuation: the branches of a sweep and the curves of a plane as CF datasets (netCDF,
each built from a table of (name, dims, values, attributes)), the table of bifurcation points (CSV), and
the branches read back from a dataset."""

from __future__ import annotations

import csv
from collections.abc import Mapping, Sequence
from io import StringIO
from typing import Any

import numpy as np
import xarray as xr

from geardyn import libm
from geardyn.khv import point
from geardyn.runs.continuation.branch import Branch
from geardyn.runs.continuation.curves import Curve, bounds_stable
from geardyn.runs.continuation.family import Family
from geardyn.runs.cube import STATES
from geardyn.solve import bifurcations as kinds
from geardyn.solve.bifurcations import CODES

_D = 6  # state dimension of the KHV model
#: Kinds of the curves file: the library's four and the grazing of the back flank (onset of back-side contact).
FILE_KINDS = (*kinds.CURVE_KINDS, "back_grazing")
#: Fates of a map record as a seed of curves (``record_fate``).
RECORD_FATES = ("on_curve", "started_curve", "not_reproduced", "period_out_of_range")


def flags(names: Sequence[str], long_name: str) -> dict[str, Any]:
    """The attributes of a flag variable with values 0, 1, ... meaning ``names``."""
    return dict(long_name=long_name, flag_values=np.arange(len(names), dtype=np.int8), flag_meanings=" ".join(names))


def variables(spec: Sequence[tuple[str, tuple[str, ...], Any, Any]]) -> dict[str, Any]:
    """Dataset variables from (name, dims, values, attributes or a long name of a quantity of units 1): flags
    as int8, int64 as int32."""
    data = {}
    for name, dims, values, attrs in spec:
        a = attrs if isinstance(attrs, dict) else {"units": "1", "long_name": attrs}
        v = np.asarray(values, dtype=np.int8 if "flag_values" in a else None)
        data[name] = (dims, v.astype(np.int32) if v.dtype == np.int64 else v, a)
    return data


def _joined(parts: list[np.ndarray], dtype: Any, shape: tuple[int, ...] = (0,)) -> np.ndarray:
    """The branches' arrays one after the other (empty of ``shape`` without branches)."""
    return np.concatenate([np.asarray(v, dtype) for v in parts]) if parts else np.zeros(shape, dtype)


def _point_vars(
    branches: Sequence[tuple[int, Branch]], families: Mapping[int, Family], units: str, long_name: str, nmax: int
) -> dict[str, Any]:
    """The per-point variables (dimension ``point``, all branches one after the other)."""
    cyc = np.full((sum(len(b) for _, b in branches), nmax), np.nan)
    k = 0
    for c, b in branches:
        for i in range(len(b)):
            x = b.states[i]
            cyc[k + i, : b.n] = families[c].cycle(float(b.p[i]), x, b.n)[:, 1]
        k += len(b)

    def cat(attr: str, dtype: Any = float, shape: tuple[int, ...] = (0,)) -> np.ndarray:
        return _joined([getattr(b, attr) for _, b in branches], dtype, shape)

    def each(values: Sequence[int], dtype: Any) -> np.ndarray:
        """One value per branch, repeated on its points."""
        return _joined([np.full(len(b), v) for v, (_, b) in zip(values, branches, strict=True)], dtype)

    mu = cat("multipliers", complex, (0, _D))
    radius = np.max(libm.cabs(mu), axis=1)  # (rows,), also for no rows
    P, PM = ("point",), ("point", "multiplier")
    state = "orbit state at mesh phase 0 (x / b_c, dx/dtau / b_c)"
    margin = "min over the cycle of |X_VH| / b_c - b (< 0: contact lost)"
    return variables(
        [
            ("branch", P, each(range(len(branches)), np.int32), "index of the continued branch"),
            ("case_index", P, each([c for c, _ in branches], np.int32), "index of the sweep case (fixed overrides)"),
            ("orbit_period", P, each([b.n for _, b in branches], np.int16), "period of the orbit in mesh periods"),
            ("parameter", P, cat("p"), {"units": units, "long_name": long_name}),
            ("orbit_state", ("point", "state"), cat("states", float, (0, _D)), state),
            ("multiplier_real", PM, mu.real, "Floquet multiplier, real part"),
            ("multiplier_imag", PM, mu.imag, "Floquet multiplier, imaginary part"),
            ("spectral_radius", P, radius, "largest Floquet multiplier modulus (< 1: stable)"),
            ("stable", P, radius < 1.0, flags(("unstable", "stable"), "orbit asymptotically stable")),
            ("arclength", P, cat("arclength"), "arclength along the branch in scaled variables"),
            ("grazing_margin", P, cat("grazing"), margin),
            ("cycle_x_vh", ("point", "cycle"), cyc, "X_VH / b_c at the phase-0 points of the cycle"),
        ]
    )


def _bifurcation_vars(branches: Sequence[tuple[int, Branch]], units: str, long_name: str) -> dict[str, Any]:
    """The per-bifurcation variables (dimension ``bifurcation``)."""
    bifs = [(j, bf) for j, (_, b) in enumerate(branches) for bf in b.bifurcations]
    B, BM = ("bifurcation",), ("bifurcation", "multiplier")
    mu = np.array([bf.multipliers for _, bf in bifs]).reshape(len(bifs), _D)
    crit = np.array([bf.critical for _, bf in bifs], complex)
    types = kinds.flags(kinds.BRANCH_KINDS, "type of the bifurcation point")
    located = flags(("bracketed", "located"), "point refined on the branch (else interpolated between two points)")
    at_bif = "at the bifurcation point"
    at = {"units": units, "long_name": f"{long_name} {at_bif}"}
    rot = "arg(mu) / (2 pi) of the Neimark-Sacker pair (NaN otherwise)"
    x_vh = f"X_VH / b_c of the orbit {at_bif} (phase 0)"
    return variables(
        [
            ("bifurcation_branch", B, np.array([j for j, _ in bifs], np.int32), "branch of the bifurcation point"),
            ("bifurcation_type", B, [CODES[bf.kind] for _, bf in bifs], types),
            ("bifurcation_parameter", B, np.array([bf.p for _, bf in bifs]), at),
            ("bifurcation_x_vh", B, np.array([bf.state[1] for _, bf in bifs]), x_vh),
            ("critical_multiplier_real", B, crit.real, "crossing multiplier, real part (NaN for grazing)"),
            ("critical_multiplier_imag", B, crit.imag, "crossing multiplier, imaginary part"),
            ("rotation_number", B, np.array([bf.rotation_number for _, bf in bifs]), rot),
            ("located", B, [int(bf.located) for _, bf in bifs], located),
            ("bifurcation_multiplier_real", BM, mu.real, f"Floquet multipliers {at_bif}, real part"),
            ("bifurcation_multiplier_imag", BM, mu.imag, f"Floquet multipliers {at_bif}, imaginary part"),
        ]
    )


def branch_dataset(
    branches: Sequence[tuple[int, Branch]], families: Mapping[int, Family], parameter: str, case_labels: Sequence[str]
) -> xr.Dataset:
    """All branches of a sweep as one CF dataset (points of all branches along ``point``)."""
    units, long_name = point.CONTROLS.get(parameter, (point.units_of(parameter), parameter))
    nmax = max([b.n for _, b in branches], default=1)
    data = {**_point_vars(branches, families, units, long_name, nmax), **_bifurcation_vars(branches, units, long_name)}
    coords = variables(
        [
            ("state", "state", list(STATES), {"long_name": "state component"}),
            ("multiplier", "multiplier", np.arange(_D, dtype=np.int32), "multiplier index (by decreasing modulus)"),
            ("cycle", "cycle", np.arange(nmax, dtype=np.int32), "index of the phase-0 point in the cycle"),
            ("case", "case", list(case_labels), {"long_name": "case (fixed overrides)"}),
        ]
    )
    ends = {
        f"branch_{j}_ends": f"down={b.end_status.get('down')} up={b.end_status.get('up')}"
        for j, (_, b) in enumerate(branches)
    }
    return xr.Dataset(data, coords=coords, attrs={"control_parameter": parameter, **ends})


#: The columns of the table of bifurcation points.
TABLE_COLUMNS = tuple(
    "case branch period type parameter value critical_multiplier modulus rotation_number located multipliers "
    "paper_transition paper_difference".split()
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


def _attrs(name: str, units: Mapping[str, str] | None, long_names: Mapping[str, str] | None) -> dict[str, str]:
    u = units[name] if units and name in units else point.units_of(name, "1")
    ln = (long_names or {}).get(name) or (point.CONTROLS[name][1] if name in point.CONTROLS else name)
    return {"units": u, "long_name": ln}


def curve_dataset(
    curves: Sequence[Curve],
    names: tuple[str, str],
    units: Mapping[str, str] | None = None,
    long_names: Mapping[str, str] | None = None,
) -> xr.Dataset:
    """The curves as one CF dataset: dimension ``point`` (every curve's points in order, ``curve_index``
    the curve's), ``curve`` (kind, period, first point, length; end statuses as attributes
    ``curve_<k>_end``) and ``codim2`` (type, curve, (p, q), multipliers, located)."""
    d = curves[0].points[0].z.size - 2 if curves and curves[0].points else 0
    rows = [(k, pt) for k, c in enumerate(curves) for pt in c.points]
    c2 = [(k, b) for k, c in enumerate(curves) for b in c.codim2]
    mu = np.array([pt.multipliers for _, pt in rows]).reshape(len(rows), d)
    mu2 = np.array([b.multipliers for _, b in c2]).reshape(len(c2), d)
    pa, qa = _attrs(names[0], units, long_names), _attrs(names[1], units, long_names)
    P, PM, C2, C2M = ("point",), ("point", "multiplier"), ("codim2",), ("codim2", "multiplier")
    g = "defining condition G (fold: mu - 1, period doubling: mu + 1, Neimark-Sacker: |mu|^2 - 1, grazing: g)"
    spec: list[tuple[str, tuple[str, ...], Any, Any]] = [
        ("curve_index", P, np.array([k for k, _ in rows], np.int32), "index of the curve"),
        (names[0], P, [pt.z[-2] for _, pt in rows], pa),
        (names[1], P, [pt.z[-1] for _, pt in rows], qa),
        ("orbit_state", ("point", "state"), np.reshape([pt.z[:-2] for _, pt in rows], (len(rows), d)), "orbit state"),
        ("multiplier_real", PM, mu.real, "Floquet multiplier, real part"),
        ("multiplier_imag", PM, mu.imag, "Floquet multiplier, imaginary part"),
        ("condition_residual", P, [pt.G for _, pt in rows], g),
        ("grazing_margin", P, [pt.grazing for _, pt in rows], "grazing margin min |x_VH| - b over the cycle"),
        ("curve_kind", ("curve",), [CODES[c.kind] for c in curves], kinds.flags(kinds.CURVE_KINDS, "curve kind")),
        ("curve_period", ("curve",), np.array([c.n for c in curves], np.int16), "orbit period (mesh periods)"),
        ("curve_start", ("curve",), np.cumsum([0] + [len(c) for c in curves])[:-1], "index of the first point"),
        ("curve_length", ("curve",), [len(c) for c in curves], "number of points"),
        ("codim2_type", C2, [CODES[b.kind] for _, b in c2], kinds.flags(kinds.CODIM2, "codim-2 type")),
        ("codim2_curve", C2, np.array([k for k, _ in c2], np.int32), "index of the curve"),
        (f"codim2_{names[0]}", C2, [b.p for _, b in c2], pa),
        (f"codim2_{names[1]}", C2, [b.q for _, b in c2], qa),
        ("codim2_multiplier_real", C2M, mu2.real, "Floquet multiplier, real part"),
        ("codim2_multiplier_imag", C2M, mu2.imag, "Floquet multiplier, imaginary part"),
        ("codim2_located", C2, [int(b.located) for _, b in c2], flags(("bracketed", "located"), "located")),
    ]
    data = variables(spec)
    ends = {f"curve_{k}_end": ", ".join(f"{s}={v}" for s, v in c.end_status.items()) for k, c in enumerate(curves)}
    return xr.Dataset(data, attrs={**ends, "curve_parameters": f"{names[0]} {names[1]}"})


def boundary_dataset(bd: Any, check: Any = None) -> xr.Dataset:
    """The curves file of :class:`~geardyn.runs.continuation.curve_maps.Boundaries` ``bd``: the curves
    (:func:`curve_dataset`) with the kind ``back_grazing``, ``bounds_stable`` per point, the seeds (``curve_<k>_seed``),
    the map's records and their fates (``record_*``), the seconds per stage (``time_<stage>_s``) and, given a
    :class:`~geardyn.runs.continuation.curve_check.PixelCheck`, its samples (``check_*``, ``pixel_check_*``)."""
    names, rec, R = bd.region.names, bd.records, ("record",)
    ds = curve_dataset(bd.curves, names)
    bounds = [bounds_stable(c.kind, pt.multipliers, pt.crit) for c in bd.curves for pt in c.points]
    stable = flags(("interior", "boundary"), "the curve bounds a stable orbit here (the other multipliers inside)")
    fates = [RECORD_FATES.index(r[4]) for r in rec]
    spec = [
        (
            "curve_kind",
            ("curve",),
            [CODES[bd.file_kind(k)] for k in range(len(bd.curves))],
            kinds.flags(FILE_KINDS, "curve kind"),
        ),
        ("bounds_stable", ("point",), bounds, stable),
        ("record_kind", R, [CODES[r[0]] for r in rec], kinds.flags(FILE_KINDS, "kind of the map's record")),
        (
            "record_period",
            R,
            np.array([r[1] for r in rec], np.int16),
            "period of the orbit before the record (0: not periodic)",
        ),
        *[
            (f"record_{nm}", R, np.array([r[2 + k] for r in rec], float), {**ds[nm].attrs})
            for k, nm in enumerate(names)
        ],
        ("record_fate", R, fates, flags(RECORD_FATES, "fate of the map's record as a seed")),
    ]
    ds.update(variables(spec))
    ds.attrs.update({f"curve_{k}_seed": o for k, o in enumerate(bd.origin)})
    ds.attrs.update({f"records_{f}": int(sum(r[4] == f for r in rec)) for f in RECORD_FATES})
    ds.attrs.update({f"time_{k}_s": round(v, 3) for k, v in bd.timing.items()})
    ds.attrs["unseeded_events"] = (
        "; ".join(
            f"{kind} P{n} at ({x:.6g}, {y:.6g}){'' if located else ' (bracketed)'}"
            for kind, n, x, y, located in bd.unseeded
        )
        or "none"
    )
    ds.attrs["lines"] = "; ".join(str(line) for line in bd.lines)
    ds.attrs["box"] = ", ".join(f"{v:g}" for v in bd.region.box)
    ds.attrs["fixed_overrides"] = point.label(bd.region.fixed)
    if check is not None:
        ds.update(check.variables(names, FILE_KINDS))
        ds.attrs.update(check.attrs())
    return ds
