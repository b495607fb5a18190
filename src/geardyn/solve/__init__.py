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
precision     the measured Poincare error of the integrator per step count (:data:`POINCARE_ERROR`)
============  ==========================================================================================

The contract (:mod:`~geardyn.solve.base`) is imported with the package; :func:`simulate` and its companions
are loaded on first use (PEP 562), so a job that only reads results does not import numba and the
compiled loops (about 0.45 s of each such job's start-up).
"""

import importlib
import sys
import types
from typing import TYPE_CHECKING, Any

from geardyn._lazy import lazy_attributes
from geardyn.solve.base import LAYOUT, SimulationResult, SimulationSettings, System
from geardyn.solve.precision import POINCARE_ERROR

if TYPE_CHECKING:
    from geardyn.solve.simulate import largest_lyapunov, simulate, step_grid, step_tables, warm_up

__getattr__ = lazy_attributes(
    __name__, dict.fromkeys(("largest_lyapunov", "step_grid", "step_tables", "warm_up"), "simulate")
)


class _Package(types.ModuleType):
    """``geardyn.solve.simulate`` names both a module and the function it defines; the package's attribute is
    the function, as with an eager ``from .simulate import simulate``, whichever is imported first (the
    import system's record of the submodule goes to ``sys.modules`` only)."""

    @property
    def simulate(self) -> Any:
        return importlib.import_module("geardyn.solve.simulate").simulate

    @simulate.setter
    def simulate(self, module: types.ModuleType) -> None:
        pass


sys.modules[__name__].__class__ = _Package

__all__ = [
    "LAYOUT",
    "POINCARE_ERROR",
    "SimulationResult",
    "SimulationSettings",
    "System",
    "largest_lyapunov",
    "simulate",
    "step_grid",
    "step_tables",
    "warm_up",
]
