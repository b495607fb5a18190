"""Linear forced response of the plus set against input speed: the modal model with modal damping, excited by
the static TE of the p-d meshes as a displacement in the mesh spring, by modal superposition per harmonic
(docs/paper2.md Sec. 5).  SI units (m, N, rad/s); speeds in rpm of the sun (the input member)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from geardyn import io, libm
from geardyn.io import Var

from . import modal
from .design import PlusDesign
from .ishikawa import pd_mesh_load

#: Samples per mesh period used to find the largest force of a periodic response.
PHASE_SAMPLES = 128


def modal_frf(omega2: ArrayLike, shapes: ArrayLike, zeta: float, force: ArrayLike, omega: ArrayLike) -> NDArray:
    """Complex response X (..., n) of a modally damped system to the harmonic ``force`` (..., n): ``omega2``
    (m,) squared elastic circular frequencies, ``shapes`` (n, m) M-normalised, ``omega`` (rad/s) broadcast
    against ``force[..., 0]``."""
    omega2, shapes = np.asarray(omega2, dtype=float), np.asarray(shapes, dtype=float)
    f, w = np.asarray(force), np.asarray(omega, dtype=float)[..., None]
    wr = np.sqrt(omega2)
    modal_force = f @ shapes  # (..., m)
    q = modal_force / (omega2 - w**2 + 2j * zeta * wr * w)
    return q @ shapes.T


def te_harmonics(te: ArrayLike, n: int) -> NDArray:
    """Complex Fourier coefficients c_1..c_n (units of ``te``) of a periodic signal sampled uniformly over
    one period along its last axis: te(s) = mean + sum_h Re(c_h exp(2 pi i h s)), s in mesh periods."""
    x = np.asarray(te, dtype=float)
    npts = x.shape[-1]
    if n > npts // 2 - 1:
        raise ValueError(f"{n} harmonics need more than {2 * n + 1} samples per period, got {npts}")
    return 2.0 * np.fft.rfft(x, axis=-1)[..., 1 : n + 1] / npts


def mesh_phases(design: PlusDesign) -> NDArray:
    """Mesh phase g_j (mesh periods, in [0, 1)) of the p-d mesh of each planet (``forced.phasing``)."""
    psi = np.asarray(design.planet_angles)
    if design.forced.phasing == "in_phase":
        return np.zeros_like(psi)
    return np.mod(design.sun.teeth * psi / (2 * np.pi), 1.0)


def mesh_frequency_per_rpm(design: PlusDesign, condition: str) -> float:
    """Mesh frequency (Hz) per rpm of the sun: z_s |1 - theta_c/theta_s| / 60 (the carrier ratio of the
    condition's rigid-body motion)."""
    md = modal.modes(design, condition)  # type: ignore[arg-type]
    if md.n_rigid != 1:
        raise ValueError(f"condition {condition} has {md.n_rigid} rigid-body modes; the forced response needs one")
    rigid = md.full_shapes[:, 0]
    ts, tc = rigid[modal.COORDS.index("theta_s")], rigid[modal.COORDS.index("theta_c")]
    if ts == 0:
        raise ValueError(f"the sun does not turn in the rigid-body motion of condition {condition}")
    return design.sun.teeth * abs(1.0 - tc / ts) / 60.0


@dataclass(frozen=True)
class ForcedResponse:
    """Mesh forces of the forced response (N; speeds in rpm, frequencies in Hz): complex ``amplitude`` (case,
    speed, harmonic, mesh); ``rms``, ``dynamic_factor`` and ``min_factor`` (largest and smallest total force /
    static force; below 0 contact is lost) per (case, speed, mesh); the condition's elastic ``natural_hz``."""

    condition: str
    zeta: float
    cases: tuple[str, ...]
    meshes: tuple[str, ...]
    harmonics: NDArray
    speed_rpm: NDArray
    mesh_hz_per_rpm: float
    static_force: float
    te_ptp: NDArray
    amplitude: NDArray
    rms: NDArray
    dynamic_factor: NDArray
    min_factor: NDArray
    natural_hz: NDArray


def speed_grid(design: PlusDesign, natural_hz: NDArray, mesh_hz_per_rpm: float) -> NDArray:
    """``speed_points`` speeds (rpm) from top/points to top = factor x the speed where h = 1 meets the highest mode."""
    top = design.forced.speed_max_factor * float(np.max(natural_hz)) / mesh_hz_per_rpm
    n = design.forced.speed_points
    return np.linspace(top / n, top, n)


def forced_response(
    design: PlusDesign,
    te: ArrayLike,
    cases: tuple[str, ...] = ("unmodified",),
    *,
    speeds: ArrayLike | None = None,
    zeta: float | None = None,
) -> ForcedResponse:
    """Mesh forces against sun speed for each TE case: ``te`` (case, phase), the static TE (m) of the p-d pair
    sampled uniformly over one mesh period, shifted by each planet's mesh phase (:func:`mesh_phases`);
    ``speeds`` (rpm) default to :func:`speed_grid`, ``zeta`` to ``design.forced.damping_ratio``."""
    spec = design.forced
    zeta = spec.damping_ratio if zeta is None else float(zeta)
    te = np.atleast_2d(np.asarray(te, dtype=float))
    if te.shape[0] != len(cases):
        raise ValueError(f"{te.shape[0]} TE curves for {len(cases)} cases")
    cond = spec.condition
    md = modal.modes(design, cond)  # type: ignore[arg-type]
    keep = [modal.COORDS.index(c) for c in md.coords]
    omega2, shapes = md.omega2[md.n_rigid :], md.shapes[:, md.n_rigid :]
    natural_hz = np.sqrt(omega2) / (2 * np.pi)
    per_rpm = mesh_frequency_per_rpm(design, cond)
    speed = speed_grid(design, natural_hz, per_rpm) if speeds is None else np.asarray(speeds, dtype=float)
    meshes = [el for el in modal.elements(design) if el.kind in modal.MESH_TYPES]
    V = np.array([el.v[keep] for el in meshes])  # (9, n)
    k, pd = np.array([el.k for el in meshes]), np.array([el.kind == "pd" for el in meshes])
    phase = np.zeros(len(meshes))
    phase[pd] = mesh_phases(design)[[el.j for el in meshes if el.kind == "pd"]]
    h = np.arange(1, spec.harmonics + 1)
    c = te_harmonics(te, spec.harmonics)  # (case, H)
    # TE amplitude of every mesh element and harmonic: (case, H, 9); zero on s-p and d-r meshes
    e = libm.cmul(c[:, :, None], np.exp(2j * np.pi * h[None, :, None] * phase[None, None, :])) * pd[None, None, :]
    force = -np.einsum("chm,m,mn->chn", e, k, V)  # (case, H, n)
    omega = 2 * np.pi * per_rpm * speed[:, None] * h[None, :]  # (speed, H)
    X = modal_frf(omega2, shapes, zeta, force[:, None, :, :], omega[None, :, :])  # (case, speed, H, n)
    amp = k * (X @ V.T + e[:, None, :, :])  # (case, speed, H, 9)
    rms = np.sqrt(0.5 * np.sum(libm.cabs(amp) ** 2, axis=2))
    theta = 2 * np.pi * np.arange(PHASE_SAMPLES) / PHASE_SAMPLES
    basis = np.exp(1j * h[:, None] * theta[None, :])  # (H, T)
    static = pd_mesh_load(design)
    # largest and smallest force over a mesh period, one case at a time (keeps the (speed, mesh, phase) block small)
    fluct = [np.einsum("shm,ht->smt", a, basis).real for a in amp]
    factor = np.stack([(static + f.max(axis=-1)) / static for f in fluct])
    min_factor = np.stack([(static + f.min(axis=-1)) / static for f in fluct])
    return ForcedResponse(
        condition=cond,
        zeta=zeta,
        cases=tuple(cases),
        meshes=tuple(el.name for el in meshes),
        harmonics=h,
        speed_rpm=speed,
        mesh_hz_per_rpm=per_rpm,
        static_force=static,
        te_ptp=np.ptp(te, axis=-1),
        amplitude=amp,
        rms=rms,
        dynamic_factor=factor,
        min_factor=min_factor,
        natural_hz=natural_hz,
    )


#: The CF variables of forced_response.nc (:func:`geardyn.io.dataset`; ``{condition}``: the modal condition's).
_FORCES = ("case", "speed", "mesh")
VARIABLES = (
    Var("rms_force", _FORCES, "N", "RMS of the fluctuating mesh force"),
    Var("dynamic_factor", _FORCES, "1", "largest mesh force over a mesh period / static mesh force"),
    Var(
        "min_force_factor",
        _FORCES,
        "1",
        "smallest mesh force over a mesh period / static mesh force (< 0: contact lost)",
    ),
    Var(
        "force_amplitude",
        ("case", "speed", "harmonic", "mesh"),
        "N",
        "amplitude of the mesh force at each harmonic of the mesh frequency",
    ),
    Var("mesh_frequency", "speed", "Hz", "mesh frequency at the input (sun) speed"),
    Var("te_ptp", "case", "um", "peak-to-peak static TE of the p-d pair (excitation)"),
    Var("natural_frequency", "mode", "Hz", "undamped natural frequency of elastic mode, condition {condition}"),
    Var(
        "resonance_speed",
        ("harmonic", "mode"),
        "rpm",
        "sun speed at which the harmonic of the mesh frequency meets the mode",
    ),
    Var("case", "case", "1", "tip-relief case of the p-d pair"),
    Var("speed", "speed", "rpm", "input (sun) speed"),
    Var("mesh", "mesh", "1", "mesh (s-p, p-d, d-r of planet 1-3)"),
    Var("harmonic", "harmonic", "1", "harmonic of the mesh frequency"),
    Var("mode", "mode", "1", "elastic mode"),
)


def to_dataset(res: ForcedResponse, design: PlusDesign) -> xr.Dataset:
    """CF dataset of a :class:`ForcedResponse` (forces in N, TE in um, speeds in rpm)."""
    per_rpm = res.mesh_hz_per_rpm
    values = (res.rms, res.dynamic_factor, res.min_factor, libm.cabs(res.amplitude), res.speed_rpm * per_rpm)
    resonance = res.natural_hz[None, :] / (res.harmonics[:, None] * per_rpm)  # harmonic h of the mesh meets a mode
    coords = (list(res.cases), res.speed_rpm, list(res.meshes), res.harmonics, np.arange(1, len(res.natural_hz) + 1))
    relieved = [i for i, c in enumerate(res.cases) if c != "unmodified"]  # the best: the smallest TE
    table = [replace(v, long_name=v.long_name.format(condition=res.condition)) for v in VARIABLES]
    return io.dataset(
        table,
        (*values, res.te_ptp * 1e6, res.natural_hz, resonance, *coords),
        title=f"Forced response to the static TE against speed, design {design.name}",
        condition=res.condition,
        damping_ratio=res.zeta,
        phasing=design.forced.phasing,
        static_force_N=res.static_force,
        best_relief_case=res.cases[min(relieved, key=lambda i: res.te_ptp[i])] if relieved else "",
    )
