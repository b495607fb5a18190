"""Ishikawa tooth compliance (rectangle to the base circle + trapezoid to the tip: bending, shear, root rotation;
Hertzian approach) and the static TE of the p-d pair with load sharing (paper 2 Eq. 9; docs/paper2.md Sec. 3).
SI units; ``u`` in m along the path of contact from its start, ``s = u / p_b`` in base pitches."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypedDict, Unpack

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geardyn import libm
from geardyn.gears.geometry import involute as inv
from geardyn.gears.stiffness import flexibility_q, pitch_point_stiffness

from .design import PlusDesign


@dataclass(frozen=True)
class ToothGeom:
    """One spur gear: teeth, module (m), pressure angle (rad), ha*, c*, profile shift x (-)."""

    z: int
    module: float
    alpha: float
    ha: float = 1.0
    c: float = 0.25
    x: float = 0.0

    @property
    def r(self) -> float:
        return self.module * self.z / 2

    @property
    def rb(self) -> float:
        return self.r * np.cos(self.alpha)

    @property
    def ra(self) -> float:
        return self.r + (self.ha + self.x) * self.module

    @property
    def rf(self) -> float:
        return self.r - (self.ha + self.c - self.x) * self.module


def half_tooth_angle(g: ToothGeom, radius: ArrayLike) -> NDArray:
    """Half angular tooth thickness (rad) at ``radius`` >= r_b: pi/(2z) + 2x tan(a)/z + inv a - inv a_r."""
    a_r = libm.arccos(np.clip(g.rb / np.asarray(radius, dtype=float), -1.0, 1.0))
    return np.pi / (2 * g.z) + 2 * g.x * libm.tan(g.alpha) / g.z + inv(g.alpha) - inv(a_r)


@dataclass(frozen=True)
class SpurPair:
    """External spur pair at the standard centre distance (x1 = x2 = 0 in paper 2)."""

    driver: ToothGeom
    driven: ToothGeom

    @property
    def centre_distance(self) -> float:
        return self.driver.r + self.driven.r

    @property
    def working_alpha(self) -> float:
        return float(libm.arccos((self.driver.rb + self.driven.rb) / self.centre_distance))

    @property
    def base_pitch(self) -> float:
        return float(np.pi * self.driver.module * np.cos(self.driver.alpha))

    @property
    def path_length(self) -> float:
        """Length of the path of contact g_a (m)."""
        g1, g2 = self.driver, self.driven
        return float(
            np.sqrt(g1.ra**2 - g1.rb**2)
            + np.sqrt(g2.ra**2 - g2.rb**2)
            - self.centre_distance * np.sin(self.working_alpha)
        )

    @property
    def contact_ratio(self) -> float:
        return self.path_length / self.base_pitch

    def roll_distances(self, u: ArrayLike) -> tuple[NDArray, NDArray]:
        """Distances (m) of the contact point from the tangent points T1, T2 on the base circles."""
        u = np.asarray(u, dtype=float)
        a_sin = self.centre_distance * np.sin(self.working_alpha)
        rho1_start = a_sin - np.sqrt(self.driven.ra**2 - self.driven.rb**2)
        rho1 = rho1_start + u
        return rho1, a_sin - rho1


def spur_pair(design: PlusDesign) -> SpurPair:
    """The p-d pair of paper 2 (z = 19 and 20, m = 4 mm, 25 deg, ha* = 1, c* = 0.25, x = 0)."""
    gp, gd = (
        ToothGeom(g.teeth, design.module, design.pressure_angle, design.addendum, design.clearance)
        for g in (design.planet_p, design.planet_d)
    )
    return SpurPair(gp, gd) if design.te.driver == "planet_p" else SpurPair(gd, gp)


@dataclass(frozen=True)
class Material:
    """Young's modulus E (Pa), Poisson's ratio, face width b (m), shear factor kappa (-)."""

    E: float
    nu: float
    b: float
    kappa: float = 1.0


def material(design: PlusDesign) -> Material:
    return Material(design.youngs_modulus, design.poisson, design.facewidth, design.te.shear_coefficient)


def tooth_compliance(g: ToothGeom, rho: ArrayLike, mat: Material) -> dict[str, NDArray]:
    """Ishikawa compliance (m/N) of one tooth loaded at roll distance ``rho`` (m) from its base tangent point: the
    parts ``bending``, ``shear``, ``root`` (rotation of the foundation) and their ``total``."""
    rho = np.asarray(rho, dtype=float)
    rx = np.sqrt(g.rb**2 + rho**2)
    psi_x = half_tooth_angle(g, rx)
    alpha_x = libm.arctan(rho / g.rb)
    gamma = alpha_x - psi_x  # load angle against the normal to the tooth centre line
    # load-line / centre-line intersection, measured from the root circle along the centre line
    hx = rx * np.cos(psi_x) - rx * np.sin(psi_x) * libm.tan(gamma) - g.rf
    psi_b, psi_a = half_tooth_angle(g, g.rb), half_tooth_angle(g, g.ra)
    sf = 2 * g.rb * np.sin(psi_b)  # rectangle width
    sa = 2 * g.ra * np.sin(psi_a)  # tip thickness
    hr = g.rb * np.cos(psi_b) - g.rf  # rectangle height
    ha = g.ra * np.cos(psi_a) - g.rf
    hi = hr + (ha - hr) * sf / (sf - sa)  # apex of the trapezoid
    E, b, nu = mat.E, mat.b, mat.nu
    c2 = np.cos(gamma) ** 2
    H = hi - hr
    in_trap = hx > hr
    # rectangle part (integral of (hx - y)^2 over [0, min(hx, hr)])
    top = np.minimum(hx, hr)
    rect = 12.0 / (E * b * sf**3) * (hx**2 * top - hx * top**2 + top**3 / 3)
    t = np.where(in_trap, (hi - hx) / H, 1.0)
    trap = np.where(in_trap, 6.0 * H**3 / (E * b * sf**3) * (t * (4 - t) - 2 * libm.log(t) - 3), 0.0)
    bending = c2 * (rect + trap)
    shear = mat.kappa * 2 * (1 + nu) * c2 / (E * b * sf) * (top + np.where(in_trap, H * libm.log(1 / t), 0.0))
    root = 24.0 * hx**2 * c2 / (np.pi * E * b * sf**2)
    return {"bending": bending, "shear": shear, "root": root, "total": bending + shear + root, "hx": hx, "gamma": gamma}


def pair_compliance(pair: SpurPair, u: ArrayLike, mat: Material) -> NDArray:
    """Compliance (m/N) of one tooth pair in contact at ``u`` (m along the path of contact): both teeth and
    Ishikawa's Hertzian approach 4 (1 - nu^2) / (pi E b)."""
    rho1, rho2 = pair.roll_distances(u)
    hertz = 4 * (1 - mat.nu**2) / (np.pi * mat.E * mat.b)
    return tooth_compliance(pair.driver, rho1, mat)["total"] + tooth_compliance(pair.driven, rho2, mat)["total"] + hertz


def single_pair_stiffness_pitch(pair: SpurPair, mat: Material) -> float:
    """Single-pair stiffness at the pitch point (N/m): the analogue of ISO's c' times b."""
    pitch = float(pair.driver.rb * libm.tan(pair.working_alpha) - pair.roll_distances(0.0)[0])  # u of the pitch point
    return float(1.0 / pair_compliance(pair, pitch, mat))


def iso_single_stiffness(pair: SpurPair, facewidth_mm: float) -> dict[str, float]:
    """ISO 6336-1 method B single stiffness c' b (N/m) of the pair: with the fixed 0.8 of paper 1
    (``k_iso_0.8``) and with the basic-rack factor C_B of a non-20 deg rack (``k_iso_CB``; docs/paper2.md Sec. 3)."""

    q = float(flexibility_q(pair.driver.z, pair.driven.z, pair.driver.x, pair.driven.x, internal=False))
    k08 = float(pitch_point_stiffness(q, facewidth_mm))
    hfp = pair.driver.ha + pair.driver.c
    cb = (1 + 0.5 * (1.2 - hfp)) * (1 - 0.02 * (20.0 - np.degrees(pair.driver.alpha)))
    return {"q_mm_um_per_N": q, "C_B": float(cb), "k_iso_0.8": k08, "k_iso_CB": k08 / 0.8 * (0.8 * cb)}


# --- Static transmission error with load sharing (Eq. 9) ---


def relief_profile(
    u: ArrayLike, path_length: float, amount: float, length: float, shape: str, apply_to: str = "both"
) -> NDArray:
    """Tip relief (m removed along the line of action) at ``u`` (m): ``C (1 - d/L)`` (linear) or its square
    (parabolic) for d < L from the start (driven tip) and/or the end (driver tip) of the path of contact."""
    u = np.asarray(u, dtype=float)
    if amount <= 0 or length <= 1e-12:  # below 1 pm a relief has no extent (and d/L would overflow)
        return np.zeros_like(u)
    power = {"linear": 1, "parabolic": 2}[shape]

    def ramp(d: NDArray) -> NDArray:
        return np.where(d < length, amount * np.clip(1 - d / length, 0, 1) ** power, 0.0)

    out = np.zeros_like(u)
    if apply_to in ("both", "driven"):
        out = out + ramp(u)
    if apply_to in ("both", "driver"):
        out = out + ramp(path_length - u)
    return out


@dataclass(frozen=True)
class TEResult:
    """Static TE (Eq. 9, TE = E - delta) over mesh periods ``s`` (base pitches); ``approach``: the driven
    gear's rigid-body approach (= -te up to the constant Ef1 + Ef2).  Lengths in m, forces in N."""

    s: NDArray
    te: NDArray
    approach: NDArray
    loads: NDArray  # (n_pairs, n_s) load per pair slot
    u: NDArray  # (n_pairs, n_s) position of each slot on the path of contact (NaN if out of mesh)
    stiffness: NDArray  # quasi-static mesh stiffness dW/dx (N/m) at each s

    @property
    def ptp(self) -> float:
        return float(np.ptp(self.te))


@dataclass(frozen=True)
class MeshGrid:
    """Pair slots over one mesh period: positions ``u`` (m), in-mesh mask and compliances (m/N); built once,
    reused by the optimiser (the relief and the deviations only change the separations)."""

    pair: SpurPair
    s: NDArray
    u: NDArray
    inside: NDArray
    lam: NDArray

    @classmethod
    def build(cls, pair: SpurPair, mat: Material, points: int) -> MeshGrid:
        pb, ga = pair.base_pitch, pair.path_length
        n_slots = int(np.ceil(ga / pb)) + 1
        s = np.arange(points) / points
        u = (s[None, :] + np.arange(n_slots)[:, None]) * pb
        inside = u <= ga + 1e-15
        u = np.where(inside, u, 0.0)
        return cls(pair, s, u, inside, np.where(inside, pair_compliance(pair, u, mat), np.inf))

    def separation(
        self,
        *,
        es: float = 0.0,
        pitch_error_sign: int = 1,
        relief_amount: float = 0.0,
        relief_length: float = 0.0,
        relief_shape: str = "linear",
        relief_apply_to: str = "both",
    ) -> NDArray:
        """Separation e_k (m, material missing) of each slot; +inf out of mesh."""
        e = pitch_error_sign * es * self.u / self.pair.base_pitch + relief_profile(
            self.u, self.pair.path_length, relief_amount, relief_length, relief_shape, relief_apply_to
        )
        return np.where(self.inside, e, np.inf)

    def solve(self, load: float, e: NDArray, ef: float = 0.0) -> TEResult:
        """Loaded static TE (Eq. 9) with the separations ``e`` under ``load`` (N), ``ef`` = Ef1 + Ef2 (load
        sharing and the pitch-step model: docs/paper2.md, "Load sharing and deviations")."""
        x = _solve_approach(e, self.lam, load)
        loads = np.where(self.inside, np.clip(x[None, :] - np.where(self.inside, e, 0.0), 0.0, None) / self.lam, 0.0)
        stiff = np.sum(np.where(loads > 0, 1.0 / self.lam, 0.0), axis=0)
        return TEResult(self.s, ef - x, x, loads, np.where(self.inside, self.u, np.nan), stiff)


def _solve_approach(e: NDArray, lam: NDArray, load: float) -> NDArray:
    """Solve sum_k max(0, x - e_k)/lam_k = W for each column (piecewise linear, increasing in x)."""
    order = np.argsort(e, axis=0, kind="stable")  # ties in one order on every CPU (numpy dispatches its sorts)
    es, ks = np.take_along_axis(e, order, axis=0), np.take_along_axis(1.0 / lam, order, axis=0)
    n = e.shape[0]
    x, done = np.full(e.shape[1], np.nan), np.zeros(e.shape[1], dtype=bool)
    ksum, kesum = np.zeros(e.shape[1]), np.zeros(e.shape[1])
    for i in range(n):
        ok = np.isfinite(es[i])
        ksum = ksum + np.where(ok, ks[i], 0.0)
        kesum = kesum + ks[i] * np.where(ok, es[i], 0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            cand = (load + kesum) / ksum
        nxt = es[i + 1] if i + 1 < n else np.full(e.shape[1], np.inf)
        good = ~done & ok & (cand <= nxt)
        x = np.where(good, cand, x)
        done |= good
    if not done.all():
        raise RuntimeError("no tooth pair in contact at some mesh positions")
    return x


def pd_mesh_load(design: PlusDesign) -> float:
    """Normal load (N) on one p-d mesh: T / (N r_bs) for a sun torque shared by N planets (planet p's moment
    balance gives F_pd = F_sp), T / r_b,driver for a torque on the p-d pair's driver (``torque_member``)."""
    if design.torque_member == "sun":
        return design.torque / (design.n_planets * design.sun.base_radius)
    return design.torque / spur_pair(design).driver.rb


def design_grid(design: PlusDesign, points: int | None = None) -> MeshGrid:
    """:class:`MeshGrid` of the design's p-d pair."""
    return MeshGrid.build(spur_pair(design), material(design), points or design.te.points_per_period)


class Relief(TypedDict, total=False):
    """A tip relief of :meth:`MeshGrid.separation` (none by default)."""

    relief_amount: float
    relief_length: float
    relief_shape: str


def design_te(
    design: PlusDesign, *, points: int | None = None, grid: MeshGrid | None = None, **relief: Unpack[Relief]
) -> TEResult:
    """Static TE of the design's pair on its grid, with its load, deviations and relief placement;
    ``relief``: relief_amount, relief_length, relief_shape (none by default)."""
    t = design.te
    grid = grid or design_grid(design, points)
    e = grid.separation(es=t.es, pitch_error_sign=t.pitch_error_sign, relief_apply_to=design.relief.apply_to, **relief)
    return grid.solve(pd_mesh_load(design), e, t.ef1 + t.ef2)
