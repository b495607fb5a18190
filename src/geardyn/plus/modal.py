"""Lumped-parameter modal model of the plus planetary set (paper 2, Eqs. 1-8, Table 1) on eleven coordinates
(:data:`COORDS`: rotations in rad, planets relative to the carrier; sun translation in m), its energies derived
geometrically (mesh springs along their lines of action), which fixes Eq. (6): docs/paper2.md Sec. 1."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from geardyn import libm

from .design import PlusDesign

_PLANETS = tuple(f"theta_{g}{j}" for g in "pd" for j in (1, 2, 3))
COORDS: tuple[str, ...] = ("theta_s", "theta_r", "theta_c", *_PLANETS, "x_s", "y_s")
#: Working conditions of the paper (Sec. 2.1): the static member's rotation is removed.
CONDITIONS: dict[str, str] = {"I": "theta_c", "II": "theta_r", "III": "theta_s", "free": ""}
Condition = Literal["I", "II", "III", "free"]

MESH_TYPES = ("sp", "pd", "dr")
MESH_LABELS = {"sp": "sun-planet p", "pd": "planet p-planet d", "dr": "planet d-ring", "bearing": "sun bearing"}
#: Components of Table 4 grouped for the kinetic-energy bars.
COMPONENT_GROUPS = ("revolution", "planet_p", "planet_d", "sun", "ring", "carrier")


def _rot(v: NDArray, angle: float) -> NDArray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _unit(name: str, n: int = len(COORDS)) -> NDArray:
    e = np.zeros(n)
    e[COORDS.index(name)] = 1.0
    return e


@dataclass(frozen=True)
class Geometry:
    """Centres (m) of the planets in the carrier frame at q = 0, and the centre distances (m)."""

    p_centres: NDArray
    d_centres: NDArray
    a_sp: float
    a_pd: float
    a_dr: float
    beta: float  # angle between p_j and d_j seen from the sun centre (rad)


def geometry(design: PlusDesign) -> Geometry:
    """Standard centre distances a = m (z1 +/- z2)/2 and the triangle sun-p-d that places d_j."""
    m = design.module
    zs, zp, zd, zr = design.sun.teeth, design.planet_p.teeth, design.planet_d.teeth, design.ring.teeth
    a_sp, a_pd, a_dr = m * (zs + zp) / 2, m * (zp + zd) / 2, m * (zr - zd) / 2
    cos_beta = (a_sp**2 + a_dr**2 - a_pd**2) / (2 * a_sp * a_dr)
    if not -1.0 < cos_beta < 1.0:
        raise ValueError(
            f"planets p (a={a_sp * 1e3:.1f} mm) and d (a={a_dr * 1e3:.1f} mm) cannot mesh: a_pd={a_pd * 1e3:.1f} mm"
        )
    beta = design.outer_planet_side * float(libm.arccos(cos_beta))
    psi = np.asarray(design.planet_angles)
    p_c = a_sp * np.column_stack([np.cos(psi), np.sin(psi)])
    d_c = a_dr * np.column_stack([np.cos(psi + beta), np.sin(psi + beta)])
    return Geometry(p_c, d_c, a_sp, a_pd, a_dr, beta)


@dataclass(frozen=True)
class _Gear:
    centre: NDArray  # (2,)
    base_radius: float
    rotation: NDArray  # (n,) absolute rotation map
    translation: NDArray  # (2, n) centre translation map

    def point_map(self, p: NDArray) -> NDArray:
        """(2, n) map q -> displacement of the material point at p (small rotations)."""
        r = p - self.centre
        return self.translation + np.outer([-r[1], r[0]], self.rotation)


def _line_of_action(g1: _Gear, g2: _Gear, internal: bool, drive: int) -> tuple[NDArray, NDArray]:
    """Unit normal ``n`` of the loaded flank (the contact force on gear 1 along +n when it turns in the sense
    ``drive``, +1 ccw) and a point on the line of action {p : m.p = const}: m.e = -cos a_w external, +cos a_w
    internal, e the unit vector from c1 to c2."""
    e = g2.centre - g1.centre
    a = float(math.hypot(*e))
    e = e / a
    if internal:
        m = _rot(e, -drive * libm.arccos((g2.base_radius - g1.base_radius) / a))
    else:
        m = _rot(e, np.pi - drive * libm.arccos((g1.base_radius + g2.base_radius) / a))
    n = _rot(m, np.pi / 2)
    point = g1.centre - g1.base_radius * m  # tangent point on gear 1's base circle
    return n, point


@dataclass(frozen=True)
class Element:
    """A spring-damper: mesh ``kind`` in {'sp','pd','dr','bearing'} of planet ``j``, along ``v`` (m or m/rad)."""

    name: str
    kind: str
    j: int
    k: float
    c: float
    v: NDArray
    n: NDArray  # line-of-action direction in the carrier frame (for plots)


def elements(design: PlusDesign) -> list[Element]:
    """The 3N meshes and two bearing springs with their displacement vectors ``v`` (delta = v . q)."""
    if design.n_planets != 3:
        raise ValueError("the coordinate set is written for three planet pairs (paper 2)")
    geo = geometry(design)
    n = len(COORDS)
    e_s, e_r, e_c = _unit("theta_s"), _unit("theta_r"), _unit("theta_c")
    ex, ey = _unit("x_s"), _unit("y_s")
    zero_t = np.zeros((2, n))
    sun = _Gear(np.zeros(2), design.sun.base_radius, e_s, np.vstack([ex, ey]))
    ring = _Gear(np.zeros(2), design.ring.base_radius, e_r, zero_t)
    ks, cs = design.stiffness, design.damping
    out: list[Element] = []
    # kinematic senses with the carrier fixed and the sun turning ccw: p cw, d ccw (plus set)
    for j in range(3):
        e_p, e_d = _unit(f"theta_p{j + 1}"), _unit(f"theta_d{j + 1}")
        pc, dc = geo.p_centres[j], geo.d_centres[j]
        planet_p = _Gear(pc, design.planet_p.base_radius, e_c + e_p, np.outer([-pc[1], pc[0]], e_c))
        planet_d = _Gear(dc, design.planet_d.base_radius, e_c + e_d, np.outer([-dc[1], dc[0]], e_c))
        for kind, g1, g2, internal, drive, k, c in (
            ("sp", sun, planet_p, False, +1, ks.sun_planet, cs.sun_planet),
            ("pd", planet_p, planet_d, False, -1, ks.planet_planet, cs.planet_planet),
            ("dr", planet_d, ring, True, +1, ks.planet_ring, cs.planet_ring),
        ):
            nvec, point = _line_of_action(g1, g2, internal, drive)
            v = nvec @ (g1.point_map(point) - g2.point_map(point))
            v[np.abs(v) < 1e-15] = 0.0
            out.append(Element(f"{kind}{j + 1}", kind, j, k, c, v, nvec))
    xy = [COORDS.index("x_s"), COORDS.index("y_s")]
    for el in out:  # printed variants (for the documentation of the fixes)
        if el.kind == "sp" and not design.planet_angles_in_sun_terms:
            el.v[xy] = out[0].v[xy]
        if el.kind == "pd" and not design.plus_set_sign:
            el.v[COORDS.index(f"theta_d{el.j + 1}")] *= -1.0
    out.append(Element("bearing_x", "bearing", -1, ks.sun_bearing, cs.sun_bearing, ex, np.array([1.0, 0.0])))
    out.append(Element("bearing_y", "bearing", -1, ks.sun_bearing, cs.sun_bearing, ey, np.array([0.0, 1.0])))
    return out


def mass_components(design: PlusDesign) -> dict[str, NDArray]:
    """Kinetic-energy matrices of the Table 4 components (Eq. 2; M = their sum): ``revolution{j}`` (planet centres
    moving with the carrier), ``p{j}``, ``d{j}`` (rotation th_c + th_pj, Eqs. 3-4), ``sun``, ``ring``, ``carrier``."""
    geo = geometry(design)
    e_s, e_r, e_c = _unit("theta_s"), _unit("theta_r"), _unit("theta_c")
    ex, ey = _unit("x_s"), _unit("y_s")
    rev = design.planet_p.mass * geo.a_sp**2 + design.planet_d.mass * geo.a_dr**2
    comps = {f"revolution{j}": rev * np.outer(e_c, e_c) for j in (1, 2, 3)}
    for g, planet in (("p", design.planet_p), ("d", design.planet_d)):
        for j in (1, 2, 3):
            w = e_c + _unit(f"theta_{g}{j}")
            comps[f"{g}{j}"] = planet.inertia * np.outer(w, w)
    comps["sun"] = design.sun.inertia * np.outer(e_s, e_s) + design.sun.mass * (np.outer(ex, ex) + np.outer(ey, ey))
    comps["ring"] = design.ring.inertia * np.outer(e_r, e_r)
    comps["carrier"] = design.carrier.inertia * np.outer(e_c, e_c)
    return comps


@dataclass(frozen=True)
class Matrices:
    """M (kg, kg m^2), K (N/m, N m/rad, N/rad), C (same with s) over ``coords``."""

    coords: tuple[str, ...]
    M: NDArray
    K: NDArray
    C: NDArray


def matrices(design: PlusDesign, condition: Condition = "free") -> Matrices:
    """Assemble M, K, C (Eq. 8) and remove the static member's rotation for conditions I-III."""
    if condition not in CONDITIONS:
        raise ValueError(f"unknown working condition {condition!r}; allowed: {sorted(CONDITIONS)}")
    keep = np.array([i for i, c in enumerate(COORDS) if c != CONDITIONS[condition]])
    els = elements(design)
    K, C = sum(el.k * np.outer(el.v, el.v) for el in els), sum(el.c * np.outer(el.v, el.v) for el in els)
    M = sum(mass_components(design).values())
    ix = np.ix_(keep, keep)
    return Matrices(tuple(COORDS[i] for i in keep), M[ix], K[ix], C[ix])  # type: ignore[index]  # sums of arrays


@dataclass(frozen=True)
class Modes:
    """Modal solution of one working condition: ``omega2`` (rad^2/s^2) and ``shapes`` (M-normalised columns over
    ``coords``) ascending, the first ``n_rigid`` rigid; ``damped_hz`` and ``zeta`` from the state-space eigenvalues."""

    condition: str
    coords: tuple[str, ...]
    omega2: NDArray
    shapes: NDArray
    n_rigid: int
    damped_hz: NDArray
    zeta: NDArray

    @property
    def freq_hz(self) -> NDArray:
        return np.sqrt(np.clip(self.omega2, 0.0, None)) / (2 * np.pi)

    @property
    def full_shapes(self) -> NDArray:
        """The modes on all 11 coordinates (0 on the fixed one), one column per mode."""
        out = np.zeros((len(COORDS), self.shapes.shape[1]))
        out[[COORDS.index(c) for c in self.coords]] = self.shapes
        return out


def _canonical_pairs(omega2: NDArray, shapes: NDArray, coords: tuple[str, ...], rtol: float) -> NDArray:
    """Rotate each degenerate pair so that its first member has y_s = 0 (deterministic shapes)."""
    shapes = shapes.copy()
    iy = coords.index("y_s") if "y_s" in coords else None
    i, n = 0, len(omega2)
    while i < n - 1:
        if omega2[i] > 0 and abs(omega2[i + 1] - omega2[i]) <= rtol * abs(omega2[i]):
            a, b = shapes[:, i].copy(), shapes[:, i + 1].copy()
            if iy is not None and np.hypot(a[iy], b[iy]) > 0:
                # first = cos*a + sin*b has y = 0 when tan(ang) = -a_y / b_y
                ang = libm.arctan2(-a[iy], b[iy])
                u, w = np.cos(ang) * a + np.sin(ang) * b, -np.sin(ang) * a + np.cos(ang) * b
                shapes[:, i], shapes[:, i + 1] = u, w
            i += 2
        else:
            i += 1
    for k in range(n):  # sign: largest |entry| positive
        col = shapes[:, k]
        if col[np.argmax(np.abs(col))] < 0:
            shapes[:, k] = -col
    return shapes


def modes(design: PlusDesign, condition: Condition, *, rigid_tol: float = 1e-8, degenerate_rtol: float = 1e-7) -> Modes:
    """Undamped (generalised symmetric eigenproblem K phi = w^2 M phi) and damped natural frequencies."""
    import scipy.linalg  # noqa: PLC0415 - the captions and figures read MESH_TYPES without scipy (0.1 s per job)

    mat = matrices(design, condition)
    omega2, shapes = scipy.linalg.eigh(mat.K, mat.M)
    scale = max(float(np.max(np.abs(omega2))), 1.0)
    rigid = np.abs(omega2) < rigid_tol * scale
    omega2 = np.where(rigid, 0.0, omega2)
    n_rigid = int(rigid.sum())
    shapes = _canonical_pairs(omega2, shapes, mat.coords, degenerate_rtol)
    damped, zeta = damped_frequencies(mat, n_rigid, float(np.sqrt(omega2[n_rigid])) if n_rigid < len(omega2) else 1.0)
    return Modes(condition, mat.coords, omega2, shapes, n_rigid, damped, zeta)


def damped_frequencies(mat: Matrices, n_rigid: int, omega_min: float) -> tuple[NDArray, NDArray]:
    """Damped natural frequencies (Hz) and damping ratios (NaN for rigid modes) from the first-order form of
    Eq. (8); the oscillatory eigenvalues, sorted by |lambda|, are matched to the undamped modes in order (light
    damping).  ``omega_min`` (rad/s): the lowest undamped elastic circular frequency."""
    n = mat.M.shape[0]
    Minv = np.linalg.inv(mat.M)
    lam = np.linalg.eigvals(np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ mat.K, -Minv @ mat.C]]))
    # rigid-body modes give a (numerically split) double eigenvalue at 0: drop |lambda| << omega_min
    osc = lam[(lam.imag > 0) & (libm.cabs(lam) > 1e-3 * omega_min)]
    osc = osc[np.argsort(libm.cabs(osc))]
    n_el = n - n_rigid
    damped, zeta = np.full(n, np.nan), np.full(n, np.nan)
    if len(osc) > n_el:
        raise RuntimeError(f"{len(osc)} oscillatory eigenvalues for {n_el} elastic modes")
    # overdamped modes (none for Table 1) have no damped frequency: they keep NaN at the top of the list
    m = len(osc)
    damped[n_rigid : n_rigid + m] = osc.imag / (2 * np.pi)
    zeta[n_rigid : n_rigid + m] = -osc.real / libm.cabs(osc)
    return damped, zeta


def energy_shares(design: PlusDesign, md: Modes) -> tuple[dict[str, NDArray], dict[str, NDArray]]:
    """Shares of each spring in the modal strain energy (rigid modes: NaN) and of each Table 4 component in the modal
    kinetic energy, per name, shape (n_modes,); U_e = k_e (v_e . phi)^2 / 2 sums to w^2 / 2 for an M-normalised phi."""
    phis = md.full_shapes
    strain = {el.name: 0.5 * el.k * (el.v @ phis) ** 2 for el in elements(design)}
    kinetic = {k: np.einsum("im,ij,jm->m", phis, Mc, phis) for k, Mc in mass_components(design).items()}
    out = []
    for energy, valid in ((strain, md.omega2 > 0), (kinetic, True)):
        total = sum(energy.values())
        with np.errstate(invalid="ignore", divide="ignore"):
            shares = {k: np.where(valid, v / total, np.nan) for k, v in energy.items()}
        out.append({k: np.where(np.abs(v) < 1e-12, 0.0, v) for k, v in shares.items()})  # round-off of exact zeros
    return out[0], out[1]


def group_strain(fr: dict[str, NDArray]) -> dict[str, NDArray]:
    """Strain-energy shares summed per mesh type (Table 3 groups 1-3, 4-6, 7-9) and the bearing."""
    out = {t: sum(v for k, v in fr.items() if k.startswith(t) and k[len(t) :].isdigit()) for t in MESH_TYPES}
    out["bearing"] = fr["bearing_x"] + fr["bearing_y"]
    return out  # type: ignore[return-value]  # sums of arrays


def group_kinetic(fr: dict[str, NDArray]) -> dict[str, NDArray]:
    """Kinetic-energy shares per component group (Table 4 grouped)."""
    planets = {"revolution": "revolution", "planet_p": "p", "planet_d": "d"}
    out = {group: sum(fr[f"{key}{j}"] for j in (1, 2, 3)) for group, key in planets.items()}
    return out | {c: fr[c] for c in ("sun", "ring", "carrier")}  # type: ignore[return-value]  # sums of arrays


def classify(md: Modes, *, rtol: float = 1e-6, atol: float = 1e-9) -> list[str]:
    """'rigid', 'planet' (doubled frequency, central members still), 'overall' (axisymmetric) or 'mixed'
    (none for the symmetric set) for each mode (docs/paper2.md, "Mode classes")."""
    out: list[str] = []
    f, phis = md.omega2, md.full_shapes
    central, xy, p, d = (
        [COORDS.index(c) for c in names] for names in (COORDS[:3], COORDS[-2:], _PLANETS[:3], _PLANETS[3:])
    )
    for i in range(len(f)):
        phi = phis[:, i]
        scale = np.max(np.abs(phi))
        degenerate = any(0 <= k < len(f) and abs(f[k] - f[i]) <= rtol * f[i] for k in (i - 1, i + 1))
        planet = degenerate and np.abs(phi[central]).max() / scale < 1e-6
        axisym = max(np.ptp(phi[p]), np.ptp(phi[d]), np.abs(phi[xy]).max()) / scale < 1e-6
        out.append("rigid" if f[i] == 0 else "planet" if planet else "overall" if axisym else "mixed")
    return out


def distinct_groups(freq: NDArray, rtol: float = 1e-6) -> list[list[int]]:
    """Indices of the elastic (positive) frequencies grouped by equal value (within ``rtol``), ascending; on
    ``Modes.omega2`` (rigid modes exactly 0) or on the natural frequencies of modal.nc."""
    groups: list[list[int]] = []
    for i, f in enumerate(freq):
        if not f > 0:
            continue
        if groups and abs(f - freq[groups[-1][0]]) <= rtol * f:
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups
