"""The solver core: one event-located RK4 loop with an optional variational part.

============  ==========================================================================================
base          the contract: :class:`System` protocol, the coefficient layout, settings, results
_model        the accelerations, their linearisation, the RK4 step of orbit and tangent (private, inlined)
_kernel       the compiled loop (private)
_batch        the same loop over many points, 8 lanes in lockstep (private)
_period       rule 3 of the classifier and the early stop of the transient (private)
simulate      :func:`simulate` (orbit, dense output, tangent vector or monodromy), step tables
reference     DOP853 with switching events (independent check)
floquet       monodromy and multipliers of the linear (b = 0) system
============  ==========================================================================================
"""

from geardyn.solve.base import LAYOUT, SimulationResult, SimulationSettings, System
from geardyn.solve.simulate import largest_lyapunov, simulate, step_grid, step_tables, warm_up

__all__ = [
    "LAYOUT",
    "SimulationResult",
    "SimulationSettings",
    "System",
    "largest_lyapunov",
    "simulate",
    "step_grid",
    "step_tables",
    "warm_up",
]
