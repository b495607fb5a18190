"""The outputs of continuation: the branches of a sweep and the curves of a plane as CF datasets (netCDF,
each built from rows of the package's one CF-variable table, :class:`geardyn.io.Var`), the table of bifurcation
points (CSV), and the branches read back from a dataset."""

from __future__ import annotations

import csv
from collections.abc import Iterable, Mapping, Sequence
from io import StringIO

import numpy as np
import xarray as xr
from numpy.typing import DTypeLike

from geardyn import io, libm
from geardyn.io import Var
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.runs.continuation.branch import Branch
from geardyn.runs.continuation.curves import Curve
from geardyn.runs.continuation.family import Family
from geardyn.runs.cube import STATES
from geardyn.solve import bifurcations as kinds
from geardyn.solve.bifurcations import CODES

_D = len(STATES)
#: Kinds of the curves file: the library's four and the grazing of the back flank (onset of back-side contact).
FILE_KINDS = (*kinds.CURVE_KINDS, "back_grazing")
#: Fates of a map record as a seed of curves (``record_fate``).
RECORD_FATES = ("on_curve", "started_curve", "not_reproduced", "period_out_of_range")


def index(names: Sequence[str]) -> dict[str, int]:
    """The flags 0, 1, ... meaning ``names`` (of a :class:`geardyn.io.Var`)."""
    return {name: k for k, name in enumerate(names)}


def quantity(name: str) -> tuple[str, str]:
    """(units, long name) of a parameter of a plane or a sweep."""
    return point.CONTROLS.get(name, (point.units_of(name, "1"), name))


def table(rows: Sequence[tuple[Var, Json]]) -> dict[str, Json]:
    """The variables of (row, values) pairs as xarray takes them."""
    return io.variables([v for v, _ in rows], [x for _, x in rows])


def _joined(parts: list[np.ndarray], dtype: DTypeLike, shape: tuple[int, ...] = (0,)) -> np.ndarray:
    """The branches' arrays one after the other (empty of ``shape`` without branches)."""
    return np.concatenate([np.asarray(v, dtype) for v in parts]) if parts else np.zeros(shape, dtype)


def _point_vars(branches: Sequence[tuple[int, Branch]], families: Mapping[int, Family], par: str, nmax: int) -> list:
    """The per-point rows (dimension ``point``, all branches one after the other)."""
    cyc = np.full((sum(len(b) for _, b in branches), nmax), np.nan)
    k = 0
    for c, b in branches:
        for i in range(len(b)):
            cyc[k + i, : b.n] = families[c].cycle(float(b.p[i]), b.states[i], b.n)[:, 1]
        k += len(b)

    def cat(attr: str, dtype: DTypeLike = float, shape: tuple[int, ...] = (0,)) -> np.ndarray:
        return _joined([getattr(b, attr) for _, b in branches], dtype, shape)

    def each(values: Iterable[int]) -> np.ndarray:
        """One value per branch, repeated on its points."""
        return _joined([np.full(len(b), v) for v, (_, b) in zip(values, branches, strict=True)], int)

    mu = cat("multipliers", complex, (0, _D))
    radius = np.max(libm.cabs(mu), axis=1)  # (rows,), also for no rows
    P, PM, i32, i16 = "point", ("point", "multiplier"), np.int32, np.int16
    state, case = "orbit state at mesh phase 0 (x / b_c, dx/dtau / b_c)", "index of the sweep case (fixed overrides)"
    return [
        (Var("branch", P, "1", "index of the continued branch", dtype=i32), each(range(len(branches)))),
        (Var("case_index", P, "1", case, dtype=i32), each(c for c, _ in branches)),
        (Var("orbit_period", P, "1", "period of the orbit in mesh periods", dtype=i16), each(b.n for _, b in branches)),
        (Var("parameter", P, *quantity(par)), cat("p")),
        (Var("orbit_state", (P, "state"), "1", state), cat("states", float, (0, _D))),
        (Var("multiplier_real", PM, "1", "Floquet multiplier, real part"), mu.real),
        (Var("multiplier_imag", PM, "1", "Floquet multiplier, imaginary part"), mu.imag),
        (Var("spectral_radius", P, "1", "largest Floquet multiplier modulus (< 1: stable)"), radius),
        (Var("stable", P, None, "orbit asymptotically stable", index(("unstable", "stable"))), radius < 1.0),
        (Var("arclength", P, "1", "arclength along the branch in scaled variables"), cat("arclength")),
        (Var("grazing_margin", P, "1", "min over the cycle of |X_VH| / b_c - b (< 0: contact lost)"), cat("grazing")),
        (Var("cycle_x_vh", (P, "cycle"), "1", "X_VH / b_c at the phase-0 points of the cycle"), cyc),
    ]


def _bifurcation_vars(branches: Sequence[tuple[int, Branch]], par: str) -> list:
    """The per-bifurcation rows (dimension ``bifurcation``)."""
    bifs = [(j, bf) for j, (_, b) in enumerate(branches) for bf in b.bifurcations]
    B, BM, at = "bifurcation", ("bifurcation", "multiplier"), "at the bifurcation point"
    mu = np.array([bf.multipliers for _, bf in bifs]).reshape(len(bifs), _D)
    crit = np.array([bf.critical for _, bf in bifs], complex)
    units, long_name = quantity(par)
    located = "point refined on the branch (else interpolated between two points)"
    rot = "arg(mu) / (2 pi) of the Neimark-Sacker pair (NaN otherwise)"
    kind = kinds.flags(kinds.BRANCH_KINDS)
    return [
        (Var("bifurcation_branch", B, "1", "branch of the bifurcation point", dtype=np.int32), [j for j, _ in bifs]),
        (Var("bifurcation_type", B, None, "type of the bifurcation point", kind), [CODES[bf.kind] for _, bf in bifs]),
        (Var("bifurcation_parameter", B, units, f"{long_name} {at}"), np.array([bf.p for _, bf in bifs])),
        (Var("bifurcation_x_vh", B, "1", f"X_VH / b_c of the orbit {at} (phase 0)"), [bf.state[1] for _, bf in bifs]),
        (Var("critical_multiplier_real", B, "1", "crossing multiplier, real part (NaN for grazing)"), crit.real),
        (Var("critical_multiplier_imag", B, "1", "crossing multiplier, imaginary part"), crit.imag),
        (Var("rotation_number", B, "1", rot), np.array([bf.rotation_number for _, bf in bifs])),
        (Var("located", B, None, located, index(("bracketed", "located"))), [bf.located for _, bf in bifs]),
        (Var("bifurcation_multiplier_real", BM, "1", f"Floquet multipliers {at}, real part"), mu.real),
        (Var("bifurcation_multiplier_imag", BM, "1", f"Floquet multipliers {at}, imaginary part"), mu.imag),
    ]


def branch_dataset(
    branches: Sequence[tuple[int, Branch]], families: Mapping[int, Family], parameter: str, case_labels: Sequence[str]
) -> xr.Dataset:
    """All branches of a sweep as one CF dataset (points of all branches along ``point``)."""
    nmax = max([b.n for _, b in branches], default=1)
    coords = [
        (Var("state", "state", None, "state component"), list(STATES)),
        (Var("multiplier", "multiplier", "1", "multiplier index (by decreasing modulus)", dtype=np.int32), range(_D)),
        (Var("cycle", "cycle", "1", "index of the phase-0 point in the cycle", dtype=np.int32), range(nmax)),
        (Var("case", "case", None, "case (fixed overrides)"), list(case_labels)),
    ]
    data = table(_point_vars(branches, families, parameter, nmax) + _bifurcation_vars(branches, parameter))
    ends = {
        f"branch_{j}_ends": f"down={b.end_status.get('down')} up={b.end_status.get('up')}"
        for j, (_, b) in enumerate(branches)
    }
    return xr.Dataset(data, coords=table(coords), attrs={"control_parameter": parameter, **ends})


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
) -> list[dict[str, Json]]:
    """One row per bifurcation point; ``paper_transitions``: the paper's transition values along the
    same parameter (only for a design that names its paper), nearest one and the difference."""
    rows: list[dict[str, Json]] = []
    for j, (c, b) in enumerate(branches):
        for bf in b.bifurcations:
            near, diff = "", ""
            if paper_transitions:
                t = min(paper_transitions, key=lambda v: abs(v - bf.p))
                near, diff = f"{t:g}", f"{bf.p - t:+.4f}"
            crit, rot, finite = bf.critical, bf.rotation_number, np.isfinite(bf.critical.real)
            values = [case_labels[c], j, b.n, bf.kind, parameter, f"{bf.p:.7f}"]
            values += [f"{crit.real:+.6f}{crit.imag:+.6f}j" if finite else "", f"{abs(crit):.6f}" if finite else ""]
            values += ["" if not np.isfinite(rot) else f"{rot:.5f}", int(bf.located)]
            values += [" ".join(f"{m.real:+.4f}{m.imag:+.4f}j" for m in bf.multipliers), near, diff]
            rows.append(dict(zip(TABLE_COLUMNS, values, strict=True)))
    rows.sort(key=lambda r: (r["case"], float(r["value"])))
    return rows


def rows_to_csv(rows: Sequence[Mapping[str, Json]]) -> str:
    """The table as CSV text (columns :data:`TABLE_COLUMNS`, a header line, ``\\n`` line ends)."""

    buf = StringIO()
    w = csv.DictWriter(buf, fieldnames=list(TABLE_COLUMNS), lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow(r)
    return buf.getvalue()


def branches_from_dataset(ds: xr.Dataset) -> list[tuple[int, Branch]]:
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


def curve_dataset(curves: Sequence[Curve], names: tuple[str, str]) -> xr.Dataset:
    """The curves as one CF dataset: dimension ``point`` (every curve's points in order, ``curve_index``
    the curve's), ``curve`` (kind, period, first point, length; end statuses as attributes
    ``curve_<k>_end``) and ``codim2`` (type, curve, (p, q), multipliers, located)."""
    d = curves[0].points[0].z.size - 2 if curves and curves[0].points else 0
    rows = [(k, pt) for k, c in enumerate(curves) for pt in c.points]
    c2 = [(k, b) for k, c in enumerate(curves) for b in c.codim2]
    mu = np.array([pt.multipliers for _, pt in rows]).reshape(len(rows), d)
    mu2 = np.array([b.multipliers for _, b in c2]).reshape(len(c2), d)
    (p, q), P, PM, C2, C2M = names, "point", ("point", "multiplier"), "codim2", ("codim2", "multiplier")
    g = "defining condition G (fold: mu - 1, period doubling: mu + 1, Neimark-Sacker: |mu|^2 - 1, grazing: g)"
    i32, states = np.int32, np.reshape([pt.z[:-2] for _, pt in rows], (len(rows), d))
    starts, codim2 = np.cumsum([0] + [len(c) for c in curves])[:-1], kinds.flags(kinds.CODIM2)
    data = [
        (Var("curve_index", P, "1", "index of the curve", dtype=i32), [k for k, _ in rows]),
        (Var(p, P, *quantity(p)), [pt.z[-2] for _, pt in rows]),
        (Var(q, P, *quantity(q)), [pt.z[-1] for _, pt in rows]),
        (Var("orbit_state", (P, "state"), "1", "orbit state"), states),
        (Var("multiplier_real", PM, "1", "Floquet multiplier, real part"), mu.real),
        (Var("multiplier_imag", PM, "1", "Floquet multiplier, imaginary part"), mu.imag),
        (Var("condition_residual", P, "1", g), [pt.G for _, pt in rows]),
        (Var("grazing_margin", P, "1", "grazing margin min |x_VH| - b over the cycle"), [pt.grazing for _, pt in rows]),
        (
            Var("curve_kind", "curve", None, "curve kind", kinds.flags(kinds.CURVE_KINDS)),
            [CODES[c.kind] for c in curves],
        ),
        (Var("curve_period", "curve", "1", "orbit period (mesh periods)", dtype=np.int16), [c.n for c in curves]),
        (Var("curve_start", "curve", "1", "index of the first point", dtype=i32), starts),
        (Var("curve_length", "curve", "1", "number of points", dtype=i32), [len(c) for c in curves]),
        (Var("codim2_type", C2, None, "codim-2 type", codim2), [CODES[b.kind] for _, b in c2]),
        (Var("codim2_curve", C2, "1", "index of the curve", dtype=i32), [k for k, _ in c2]),
        (Var(f"codim2_{p}", C2, *quantity(p)), [b.p for _, b in c2]),
        (Var(f"codim2_{q}", C2, *quantity(q)), [b.q for _, b in c2]),
        (Var("codim2_multiplier_real", C2M, "1", "Floquet multiplier, real part"), mu2.real),
        (Var("codim2_multiplier_imag", C2M, "1", "Floquet multiplier, imaginary part"), mu2.imag),
        (Var("codim2_located", C2, None, "located", index(("bracketed", "located"))), [b.located for _, b in c2]),
    ]
    ends = {f"curve_{k}_end": ", ".join(f"{s}={v}" for s, v in c.end_status.items()) for k, c in enumerate(curves)}
    return xr.Dataset(table(data), attrs={**ends, "curve_parameters": f"{p} {q}"})
