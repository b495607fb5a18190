"""The solver core: one event-located RK4 loop with an optional variational part.

============  ==========================================================================================
base          the contract: :class:`System` protocol, the coefficient layout, settings, results
_model        the accelerations, their linearisation, the RK4 step of orbit and tangent (private, inlined)
_kernel       the compiled loop (private)
_batch        the same loop over many points, 8 lanes in lockstep (private)
_period       rule 3 of the classifier and the early stop of the transient (private)
run           :func:`simulate` (orbit, dense output, tangent vector or monodromy), :func:`simulate_batch`,
              step tables
reference     DOP853 with switching events (independent check)
floquet       which multipliers are complex, the bifurcation an orbit meets
precision     the measured Poincare error of the integrator per step count (:data:`POINCARE_ERROR`)
============  ==========================================================================================

The contract (:mod:`~geardyn.solve.base`) is imported with the package; :func:`simulate` and its companions
are loaded on first use (PEP 562), so a job that only reads results does not import numba and the
compiled loops (about 0.45 s of each such job's start-up).
"""

from geardyn._lazy import lazy_attributes
from geardyn.solve.base import LAYOUT, SimulationResult, SimulationSettings, System
from geardyn.solve.precision import POINCARE_ERROR

#: the names loaded from :mod:`geardyn.solve.run` on first use
_RUN = (
    "EarlyStop LaneTables full_batch lane_tables simulate simulate_batch step_tables strict_period strict_periods "
    "warm_up"
).split()
__getattr__ = lazy_attributes(__name__, dict.fromkeys(_RUN, "run"))

__all__ = [
    "LAYOUT",
    "POINCARE_ERROR",
    "EarlyStop",
    "LaneTables",
    "SimulationResult",
    "SimulationSettings",
    "System",
    "full_batch",
    "lane_tables",
    "simulate",
    "simulate_batch",
    "step_tables",
    "strict_period",
    "strict_periods",
    "warm_up",
]
