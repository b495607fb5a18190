"""Invariant circles of a map by Newton's method on a Fourier parametrisation, with their normal stability.

A quasi-periodic motion of the T-periodic system is an invariant circle of its stroboscopic map P on which
P acts as a rotation: there is a parametrisation K of the circle and a rotation number rho with

    P(K(theta)) = K(theta + rho)            for every theta in [0, 1)                        (1)

K is stored by its values U_j = K(theta_j) at M equispaced nodes theta_j = j / M (M odd) and read between
them by trigonometric interpolation (modes |k| <= (M - 1) / 2).  Collocating (1) at the nodes gives 6M
equations; with rho and a phase condition (K may be shifted along itself) there are 6M + 1 unknowns::

    F_j(U, rho) = P(U_j) - (S_rho U)_j = 0,        sum_j <K0'(theta_j), U_j - U0_j> = 0

where S_rho is the interpolated shift by rho.  Newton's matrix is block-diagonal DP(U_j) minus S_rho x I
with the column -K'(theta_j + rho) for rho (Castellà & Jorba, "On the vertical families of two-dimensional
tori near the triangular points of the bicircular problem", Celest. Mech. Dyn. Astr. 76 (2000) 35).
Each iteration needs P and its Jacobian at the M nodes: M one-period runs with the monodromy.

Solving at the nodes alone does not make (1) hold between them: :class:`Circle` reports the invariance
error at the M midpoints theta_j + 1 / (2M), which measures the truncation of the Fourier series.

**Normal stability.**  The linearisation of P about the circle is the cocycle v(theta) -> DP(K(theta))
v(theta) over the rotation; its spectrum is a union of circles |lambda| = r (Jorba, "Numerical computation of
the normal behaviour of invariant curves of n-dimensional maps", Nonlinearity 14 (2001) 943).  The tangent
direction K' is carried onto itself with r = 1; the circle attracts when every normal radius is below 1.
Projecting out the tangent (Q(theta) = I - t t^T, t = K'/|K'|) leaves the normal cocycle, whose discretised
eigenvalues are those of S_-rho x I  blockdiag(Q(theta_j + rho) DP_j Q(theta_j)): M zeros (the tangent) and
the normal spectrum.  Eigenvalues whose eigenvector the M nodes do not resolve (more than
:data:`UNRESOLVED` of its energy in the upper half of the modes) are truncation artefacts and are left out;
the largest modulus of the rest is the normal radius.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from geardyn import libm
from geardyn.parallel import threaded_map
from geardyn.solve.base import Lane, Monodromy, SimulationSettings, System
from geardyn.solve.run import simulate_batch
from geardyn.solve.shooting import period_settings

#: P(X) -> (P(X), DP(X)) for nodes X (M, d): images (M, d) and Jacobians (M, d, d); None where diverged.
CircleMap = Callable[[np.ndarray, bool], tuple[np.ndarray, np.ndarray | None] | None]

#: energy share of an eigenvector in the upper half of the modes above which its eigenvalue is not resolved
UNRESOLVED = 0.1


@dataclass(frozen=True)
class Circle:
    """An invariant circle found (or not) by :func:`newton_circles`.

    nodes: (M, d) values of K at theta_j = j / M.  rho: rotation number (turns per mesh period, in [0, 1)).
    converged: Newton's step fell below the tolerance.  status: ``converged``, ``max_iterations``,
    ``diverged`` (a node's run diverged) or ``singular``.
    residual: max |F| at the nodes.  invariance: max |P(K) - K(. + rho)| at the midpoints, relative to
    max(1, |K|).  normal_radius: the largest modulus of the resolved normal spectrum (nan when not computed).
    """

    nodes: np.ndarray
    rho: float
    converged: bool
    status: str
    iterations: int
    residual: float
    invariance: float = math.nan
    normal_radius: float = math.nan

    @property
    def m(self) -> int:
        return int(self.nodes.shape[0])

    @property
    def rotation(self) -> float:
        """The rotation number free of the parametrisation's orientation (reversing K turns rho into 1 - rho),
        in [0, 1/2]: the angle / 2 pi of the complex pair of a Neimark-Sacker point the circle is born at."""
        return min(self.rho, 1.0 - self.rho)


# ------------------------------------------------------------------------------------------------
# trigonometric interpolation on M odd nodes
# ------------------------------------------------------------------------------------------------


def _modes(m: int) -> np.ndarray:
    if m % 2 == 0 or m < 3:
        raise ValueError(f"an invariant circle needs an odd number of nodes >= 3, got {m}")
    return np.arange(-(m // 2), m // 2 + 1)


def interpolation_matrix(m: int, theta: np.ndarray, derivative: bool = False) -> np.ndarray:
    """E (len(theta), m): E @ U is the trigonometric interpolant of the nodal values U (theta_j = j / m) at
    ``theta`` (turns), or its derivative d/dtheta with ``derivative=True``."""
    x = np.asarray(theta, float)[:, None] - (np.arange(m) / m)[None, :]
    # the Dirichlet kernel sum_k exp(2 pi i k x) / m = sin(m pi x) / (m sin(pi x)) and its derivative, with
    # the sum itself where sin(pi x) is small (sin and cos are the C library's on every CPU)
    s, c = np.sin(np.pi * x), np.cos(np.pi * x)
    sm, cm = np.sin(m * np.pi * x), np.cos(m * np.pi * x)
    near = np.abs(s) < 1e-2
    safe = np.where(near, 1.0, s)
    if derivative:
        out = np.pi * (m * cm * safe - sm * c) / (m * safe**2)
    else:
        out = sm / (m * safe)
    if np.any(near):
        k = _modes(m)
        arg = 2.0 * np.pi * np.outer(x[near], k)
        out[near] = (-(2.0 * np.pi * k * np.sin(arg)).sum(axis=1) if derivative else np.cos(arg).sum(axis=1)) / m
    return out


def shift_matrix(m: int, rho: float, derivative: bool = False) -> np.ndarray:
    """S_rho (m, m): (S_rho U)_j = K(theta_j + rho), K the interpolant of U; d S_rho / d rho with
    ``derivative=True``."""
    return interpolation_matrix(m, np.arange(m) / m + rho, derivative)


def tail_share(values: np.ndarray) -> np.ndarray:
    """The share of the energy of each column of nodal values (m, ...) in the modes |k| > m / 4."""
    m = values.shape[0]
    c = np.fft.fft(values, axis=0)
    k = np.abs(np.fft.fftfreq(m, 1.0 / m))
    e = np.abs(c) ** 2
    total = e.sum(axis=0)
    return np.where(total > 0, e[k > m / 4].sum(axis=0) / np.where(total > 0, total, 1.0), 0.0)


# ------------------------------------------------------------------------------------------------
# a first guess from a record of the orbit
# ------------------------------------------------------------------------------------------------


def circle_from_points(points: np.ndarray, m: int) -> tuple[np.ndarray, float] | None:
    """Nodal values (m, d) and rotation number of a circle fitted to an orbit on (or near) it.

    The points are projected on their two leading principal directions; where the projection winds once
    about its centre, the conjugating angle of a point is the share of the orbit at smaller projected angle
    (the invariant measure of a rotation is uniform in that angle), and rho is the median step of that angle.
    K is then the least-squares trigonometric fit of the points against their angles.  None when there are
    fewer than 2m points, a point is not finite, or the projection does not wind one way (more than 5 % of
    the angle steps go against the others)."""
    x = np.asarray(points, float)
    n = x.shape[0]
    if n < 2 * m or not np.all(np.isfinite(x)):
        return None
    c = x.mean(axis=0)
    _, _, vt = np.linalg.svd(x - c, full_matrices=False)
    z = (x - c) @ vt[:2].T
    alpha = libm.arctan2(z[:, 1], z[:, 0])
    phi = np.empty(n)
    phi[np.argsort(alpha, kind="stable")] = (np.arange(n) + 0.5) / n
    step = np.mod(np.diff(phi) + 0.5, 1.0) - 0.5
    if min(np.mean(step > 0), np.mean(step < 0)) > 0.05:
        return None
    u, *_ = np.linalg.lstsq(interpolation_matrix(m, phi), x, rcond=None)
    return u, float(np.mod(np.median(step), 1.0))


# ------------------------------------------------------------------------------------------------
# Newton
# ------------------------------------------------------------------------------------------------


@dataclass
class _NewtonState:
    """One circle's Newton iteration in progress (see :func:`_newton_step`)."""

    u: np.ndarray
    rho: float
    u0: np.ndarray
    du0: np.ndarray
    iterations: int = 0
    residual: float = math.inf
    last_dp: np.ndarray | None = None


def _start(u: np.ndarray, rho: float) -> _NewtonState:
    """A Newton iteration from nodal values u (m, d) and rotation number rho; the phase condition holds the
    shift along the circle to that of u."""
    u = np.asarray(u, float).copy()
    du0 = interpolation_matrix(u.shape[0], np.arange(u.shape[0]) / u.shape[0], derivative=True) @ u
    return _NewtonState(u, float(rho) % 1.0, u.copy(), du0)


def _newton_step(state: _NewtonState, pu: np.ndarray, dp: np.ndarray, tol: float) -> bool | str:
    """One Newton step from the images pu (m, d) and Jacobians dp (m, d, d) at the nodes ``state.u``.
    Returns True when converged (the step was below ``tol * max(1, |u|)``; the step is still applied),
    False to go on, or ``"singular"``."""
    m, d = state.u.shape
    s = shift_matrix(m, state.rho)
    f = pu - s @ state.u
    state.residual = float(np.max(np.abs(f)))
    state.last_dp = dp
    jac = np.zeros((m * d + 1, m * d + 1))
    for j in range(m):
        jac[j * d : (j + 1) * d, j * d : (j + 1) * d] = dp[j]
    jac[: m * d, : m * d] -= np.kron(s, np.eye(d))
    jac[: m * d, -1] = -(shift_matrix(m, state.rho, derivative=True) @ state.u).ravel()
    jac[-1, : m * d] = state.du0.ravel()
    rhs = np.concatenate([-f.ravel(), [-float(np.sum(state.du0 * (state.u - state.u0)))]])
    try:
        delta = np.linalg.solve(jac, rhs)
    except np.linalg.LinAlgError:
        return "singular"
    if not np.all(np.isfinite(delta)):
        return "singular"
    state.u = state.u + delta[:-1].reshape(m, d)
    state.rho = (state.rho + float(delta[-1])) % 1.0
    state.iterations += 1
    scale = max(1.0, float(np.max(np.abs(state.u))))
    return bool(np.max(np.abs(delta)) <= tol * scale)


def normal_radius(u: np.ndarray, rho: float, dp: np.ndarray) -> float:
    """The largest modulus of the resolved normal spectrum of the circle (nodes u, rotation rho, Jacobians dp
    at the nodes): see the module's docstring."""
    m, d = u.shape
    theta = np.arange(m) / m
    t_here = interpolation_matrix(m, theta, derivative=True) @ u
    t_there = interpolation_matrix(m, theta + rho, derivative=True) @ u
    t_here /= np.linalg.norm(t_here, axis=1, keepdims=True)
    t_there /= np.linalg.norm(t_there, axis=1, keepdims=True)
    eye = np.eye(d)
    blocks = np.zeros((m * d, m * d))
    for j in range(m):
        q0 = eye - np.outer(t_here[j], t_here[j])
        q1 = eye - np.outer(t_there[j], t_there[j])
        blocks[j * d : (j + 1) * d, j * d : (j + 1) * d] = q1 @ dp[j] @ q0
    op = np.kron(shift_matrix(m, -rho), eye) @ blocks
    lam, vec = np.linalg.eig(op)
    share = tail_share(vec.reshape(m, d, -1)).max(axis=0) if m >= 5 else np.zeros(lam.size)
    keep = share <= UNRESOLVED
    return float(np.max(libm.cabs(lam[keep]))) if np.any(keep) else math.nan


def _midpoints(m: int) -> np.ndarray:
    return interpolation_matrix(m, (np.arange(m) + 0.5) / m)


def distance_to_circle(u: np.ndarray, points: np.ndarray, refine: int = 3) -> np.ndarray:
    """The distance of each point (n, d) from the circle of nodal values u (m, d): the nearest of 16 m samples
    of the circle, refined by ``refine`` Newton steps on the angle."""
    m = u.shape[0]
    k = _modes(m)
    c = np.fft.fftshift(np.fft.fft(u, axis=0), axes=0) / m  # coefficients of modes k (ascending)
    a, b = c.real, c.imag
    dense = interpolation_matrix(m, np.arange(16 * m) / (16 * m)) @ u
    x = np.asarray(points, float)
    theta = np.argmin(((x[:, None, :] - dense[None]) ** 2).sum(axis=2), axis=1) / (16 * m)

    def curve(th: np.ndarray, order: int) -> np.ndarray:  # d^order K / d theta^order at th
        w = 2.0 * np.pi * k
        phase = np.outer(th, w) + order * np.pi / 2  # each derivative turns the phase by a quarter
        return (np.cos(phase) * w**order) @ a - (np.sin(phase) * w**order) @ b

    for _ in range(refine):
        g0, g1, g2 = curve(theta, 0) - x, curve(theta, 1), curve(theta, 2)
        num = np.sum(g1 * g0, axis=1)
        den = np.sum(g1 * g1, axis=1) + np.sum(g2 * g0, axis=1)
        theta = theta - np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    return np.linalg.norm(curve(theta, 0) - x, axis=1)


#: pmap(which, node sets, jacobian): for each set of nodes (m, d) of the circles ``which`` (indices of the
#: guesses), its images and Jacobians, or None where diverged.
CircleMaps = Callable[[list[int], list[np.ndarray], bool], list[tuple[np.ndarray, np.ndarray | None] | None]]


def newton_circles(
    pmap: CircleMaps,
    guesses: list[tuple[np.ndarray, float]],
    tol: float = 1e-10,
    max_iter: int = 12,
    stability: bool = True,
) -> list[Circle]:
    """Newton's method for (1) from each guess (nodal values (m, d), rotation number), every iteration
    evaluating the map at the nodes of all unfinished circles together (``pmap``); then the invariance
    error at the midpoints and (with ``stability``) the normal radius.  Each circle's iterates are those it
    gets alone.  Never raises on failure: each :class:`Circle` says what happened."""
    states = [_start(u, rho) for u, rho in guesses]
    out: list[Circle | None] = [None] * len(states)
    todo = list(range(len(states)))
    for _ in range(max_iter + 1):
        if not todo:
            break
        got = pmap(todo, [states[i].u for i in todo], True)
        left = []
        for i, g in zip(todo, got, strict=True):
            s = states[i]
            if g is None:
                out[i] = Circle(s.u, s.rho, False, "diverged", s.iterations, math.inf)
                continue
            done = _newton_step(s, g[0], g[1], tol)
            if done == "singular":
                out[i] = Circle(s.u, s.rho, False, "singular", s.iterations, s.residual)
            elif done:
                out[i] = Circle(s.u, s.rho, True, "converged", s.iterations, s.residual)
            else:
                left.append(i)
        todo = left
    for i in todo:
        s = states[i]
        out[i] = Circle(s.u, s.rho, False, "max_iterations", s.iterations, s.residual)
    done_ = [i for i, c in enumerate(out) if c is not None and c.converged]
    if not done_:
        return out  # type: ignore[return-value]
    mids = [_midpoints(states[i].u.shape[0]) @ states[i].u for i in done_]
    images = pmap(done_, mids, False)
    radii = threaded_map(
        lambda i: normal_radius(states[i].u, states[i].rho, states[i].last_dp) if stability else math.nan, done_
    )
    for i, g, radius in zip(done_, images, radii, strict=True):
        s = states[i]
        if g is None:
            out[i] = Circle(s.u, s.rho, False, "diverged", s.iterations, s.residual)
            continue
        m = s.u.shape[0]
        target = interpolation_matrix(m, (np.arange(m) + 0.5) / m + s.rho) @ s.u
        inv = float(np.max(np.abs(g[0] - target))) / max(1.0, float(np.max(np.abs(s.u))))
        out[i] = Circle(s.u, s.rho, True, "converged", s.iterations, s.residual, inv, radius)
    return out  # type: ignore[return-value]


def newton_circle(
    pmap: CircleMap, u: np.ndarray, rho: float, tol: float = 1e-10, max_iter: int = 12, stability: bool = True
) -> Circle:
    """:func:`newton_circles` for one circle of a map ``pmap(X, jacobian) -> (P(X), DP(X))`` (None when
    diverged)."""
    return newton_circles(lambda _, xs, jac: [pmap(xs[0], jac)], [(u, rho)], tol, max_iter, stability)[0]


def khv_maps(systems: list[System], settings: SimulationSettings) -> CircleMaps:
    """The one-period stroboscopic maps of KHV systems (:class:`~geardyn.solve.base.System`) with their
    Jacobians, for :func:`newton_circles` (``which`` indexes ``systems``): the nodes of every circle still
    iterating in one batch run (:func:`geardyn.solve.run.simulate_batch`, event-located RK4 with the
    variational equations, as Newton shooting)."""
    s1 = period_settings(settings, 1)

    def pmap(which: list[int], sets: list[np.ndarray], jacobian: bool):
        var = Monodromy(1) if jacobian else None
        lanes = [Lane(systems[i], y, variational=var) for i, x in zip(which, sets, strict=True) for y in x]
        runs = simulate_batch(lanes, s1)
        out, k = [], 0
        for x in sets:
            part, k = runs[k : k + x.shape[0]], k + x.shape[0]
            if any(r.diverged for r in part):
                out.append(None)
                continue
            jac = np.array([r.monodromy for r in part]) if jacobian else None
            out.append((np.array([r.final_state for r in part]), jac))
        return out

    return pmap


def find_circles(
    systems: list[System],
    records: list[np.ndarray],
    settings: SimulationSettings,
    m: int = 41,
    tol: float = 1e-10,
    max_iter: int = 8,
) -> list[Circle | None]:
    """The invariant circle of each KHV system near its record of Poincare points (n, 6): fitted
    (:func:`circle_from_points`), then Newton (:func:`newton_circles`, all systems together) with the
    invariance error and the normal radius.  None where the record gives no fit."""
    fits = [circle_from_points(r, m) for r in records]
    idx = [i for i, f in enumerate(fits) if f is not None]
    found = newton_circles(khv_maps([systems[i] for i in idx], settings), [fits[i] for i in idx], tol, max_iter)
    out: list[Circle | None] = [None] * len(systems)
    for i, c in zip(idx, found, strict=True):
        out[i] = c
    return out
