"""Stage 1 of the labeller: the previous point's period-n orbit continued to this point (secant
prediction, chord iteration, Newton shooting, one monodromy run; ``docs/classify.md``)."""

from __future__ import annotations

import numpy as np

from geardyn.label._stages import Point, decide, grouped, periodic_verdicts, shoot, shoot_batch, tables_of
from geardyn.label.policy import Policy
from geardyn.solve.base import ShootingSettings
from geardyn.solve.floquet import bifurcation_type
from geardyn.solve.shooting import ChordShot, ShootingResult, chord_shooting_batch

#: Certifying a converged state is one monodromy run: Newton shooting with no iteration.
CERTIFY_ITERATIONS = 0

# ------------------------------------------------------------------------------------------------
# stage 1: follow the previous point's orbit
# ------------------------------------------------------------------------------------------------


def _predict(p: Point) -> np.ndarray:
    """The start of the follow iteration: the previous orbit point, extrapolated along the line (secant
    through the two previous orbits of the same period; the points of a line are equally spaced)."""
    a, b = p.prev, p.prev2
    if b is not None and b.periodic and b.period == a.period and b.stage in ("follow", "period_test", "shooting"):
        return 2.0 * a.final_state - b.final_state
    return a.final_state


def _chord(points: list[Point], x0s: list[np.ndarray], n: int, policy: Policy) -> list[ShootingResult]:
    """Chord iteration x <- x - (M_prev - I)^-1 (phi(x) - x) on the n-period map, with the monodromy
    M_prev of each point's previous orbit: plain runs (no variational part), all points together; it stops
    where the residual does not fall by ``policy.chord.fall`` at an iteration (then full Newton takes
    over)."""
    shots = [
        ChordShot(p.system, x, np.linalg.inv(p.prev.monodromy - np.eye(6))) for p, x in zip(points, x0s, strict=True)
    ]
    shooting = ShootingSettings(tol=policy.newton.tol, max_iter=policy.chord.max_iter - 1, max_growth=policy.chord.fall)
    return chord_shooting_batch(shots, n, policy.integration, shooting, tables_of(points))


def _certify_states(points: list[Point], xs: list[np.ndarray], n: int, policy: Policy) -> list[ShootingResult]:
    """One monodromy run of n periods at each converged state: residual and multipliers (Newton shooting
    with no iteration, within ``policy.chord.tol_factor`` times its tolerance)."""
    shooting = ShootingSettings(tol=policy.chord.tol_factor * policy.newton.tol, max_iter=CERTIFY_ITERATIONS)
    return shoot_batch(points, xs, n, policy, shooting)


def follow(points: list[Point], policy: Policy) -> list[Point]:
    """The previous point's period-n orbit continued to this point: a chord iteration from the secant
    prediction with the previous orbit's monodromy (full Newton shooting where it does not converge), then
    one monodromy run for the multipliers.  Returns the undecided points."""
    todo = [p for p in points if p.prev is not None and p.prev.periodic]
    rest = [p for p in points if not (p.prev is not None and p.prev.periodic)]
    if not todo:
        return rest

    def orbits(n: int, ks: list[int]) -> list[ShootingResult]:
        """The orbits of the points ``ks``, all of period n: the chord iteration, else Newton shooting."""
        x0 = {k: _predict(todo[k]) for k in ks}
        chord = [k for k in ks if todo[k].prev.monodromy is not None]
        got = dict(zip(chord, _chord([todo[k] for k in chord], [x0[k] for k in chord], n, policy), strict=True))
        done = [k for k in chord if got[k] is not None and got[k].converged]
        certified = _certify_states([todo[k] for k in done], [got[k].state for k in done], n, policy)
        found = {k: r for k, r in zip(done, certified, strict=True) if r.converged}
        newton = [k for k in ks if k not in found]
        shot = shoot([todo[k] for k in newton], [x0[k] for k in newton], [n] * len(newton), policy)
        found.update(zip(newton, shot, strict=True))
        return [found[k] for k in ks]

    shots = grouped([p.prev.period for p in todo], orbits)
    for p, s in zip(todo, shots, strict=True):
        if not s.converged:
            p.bifurcation = "orbit_lost"
            p.notes.append(f"the period-{s.n} orbit of the previous point is lost ({s.status})")
        elif s.spectral_radius >= 1.0 - policy.stability_margin:  # not certified stable: it is losing stability
            p.bifurcation, p.lost = bifurcation_type(s.multipliers), s
            p.notes.append(
                f"the followed period-{s.n} orbit is not stable here (|mu|max = {s.spectral_radius:.5f}, "
                f"{p.bifurcation.replace('_', '-')})"
            )
    return rest + decide(todo, periodic_verdicts(todo, shots, policy, "follow", "followed from the previous point"))
