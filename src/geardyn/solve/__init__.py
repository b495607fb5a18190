"""The solver core: one event-located RK4 loop with an optional variational part (modules: ``docs/numerics.md``).

The contract (:mod:`~geardyn.solve.base`) is imported with the package; :func:`simulate` and its companions
are loaded on first use (PEP 562), so a job that only reads results does not import numba."""

from geardyn._lazy import lazy_attributes
from geardyn.solve.base import (
    LAYOUT,
    EarlyStop,
    Lane,
    Monodromy,
    SimulationResult,
    SimulationSettings,
    Sums,
    System,
    Tangent,
)
from geardyn.solve.precision import POINCARE_ERROR

#: the names loaded from :mod:`geardyn.solve.run` on first use
_RUN = (
    "LaneTables full_batch lane_tables simulate simulate_batch step_tables strict_period strict_periods warm_up"
).split()
__getattr__ = lazy_attributes(__name__, dict.fromkeys(_RUN, "run"))

__all__ = [
    "LAYOUT",
    "EarlyStop",
    "POINCARE_ERROR",
    "Lane",
    "Monodromy",
    "SimulationResult",
    "SimulationSettings",
    "Sums",
    "System",
    "Tangent",
    *_RUN,
]
