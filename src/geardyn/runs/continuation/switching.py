"""Branch switching: the period-2n branch born at a located period-doubling point of a period-n
branch."""

from __future__ import annotations

import math

import numpy as np

from geardyn import libm
from geardyn.runs.continuation.branch import Bifurcation, Branch, ContinuationSettings
from geardyn.runs.continuation.family import Family
from geardyn.runs.continuation.stepping import continue_branch
from geardyn.solve.shooting import newton_shooting


def switch_at_period_doubling(
    family: Family, bf: Bifurcation, lo: float, hi: float, cs: ContinuationSettings = ContinuationSettings()
) -> Branch | None:
    """The period-2n branch born at a period-doubling point of a period-n branch.

    Shooting for period 2n from the bifurcating orbit moved along the eigenvector of the multiplier
    -1, a little past the point on either side (1e-3 and 1e-2 of the range; amplitudes 1e-2 to 1 of
    max(1, max|x|) times the square root of the parameter offset, the scaling of a
    period-doubling normal form); the first orbit that is genuinely of period 2n (not the period-n
    orbit) is continued away from the bifurcation point only: towards it, the period-2n branch
    ends in the bifurcating orbit and turns back as the same orbit shifted by n periods.  None when
    none is found.
    """
    n = bf.n
    flow = family.flow(bf.p, n)
    phi, M = flow(bf.state, True)
    if phi is None:
        return None
    mu, vecs = np.linalg.eig(M)
    k = int(np.argmin(libm.cabs(mu + 1.0)))
    v = np.real(vecs[:, k])
    v /= float(np.max(np.abs(v)))
    scale = max(1.0, float(np.max(np.abs(bf.state))))
    span = hi - lo
    for frac in (1e-3, 1e-2):
        for side in (1.0, -1.0):
            p = bf.p + side * frac * span
            if not lo <= p <= hi:
                continue
            for amp in (1e-2, 1e-1, 1.0):
                x0 = bf.state + amp * scale * math.sqrt(frac) * v
                r = newton_shooting(family.flow(p, 2 * n), x0, 2 * n, cs.tol)
                if not r.converged:
                    continue
                back, _ = family.flow(p, n)(r.state, False)
                if back is None or float(np.max(np.abs(back - r.state))) < 1e-6 * scale:
                    continue  # the period-n orbit itself
                return continue_branch(family, p, r.state, 2 * n, lo, hi, cs, ("up",) if side > 0 else ("down",))
    return None
