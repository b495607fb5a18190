"""The measured precision of the solver: the Poincare error of the event RK4 integrator per step count.

A fact about the integrator (the work-precision study, ``python -m benchmarks.bench``; docs/model.md
Sec. 6), read by the validator to fill a classifier's ``error_floor`` that a run does not set.
"""

from __future__ import annotations

import math

#: Measured Poincare error of the event RK4 integrator (units of b_c) per steps_per_period: the
#: work-precision study (``python -m benchmarks.bench``; docs/model.md Sec. 6). A classifier's
#: ``error_floor`` that a run does not set is taken from here at the run's steps per period,
#: interpolated log-log between the entries; step counts outside the table need an explicit one.
POINCARE_ERROR: dict[int, float] = {32: 4.1e-3, 64: 3.0e-4, 128: 1.9e-5, 256: 1.2e-6, 512: 7.5e-8, 1024: 4.7e-9}


def measured_poincare_error(steps: int) -> float | None:
    """The measured Poincare error at ``steps`` steps per period (:data:`POINCARE_ERROR`): the table's
    value at an entry, log-log interpolation between entries, ``None`` outside the table."""
    if steps in POINCARE_ERROR:
        return POINCARE_ERROR[steps]
    known = sorted(POINCARE_ERROR)
    if not known[0] < steps < known[-1]:
        return None
    hi = next(k for k in known if k > steps)
    lo = known[known.index(hi) - 1]
    t = (math.log(steps) - math.log(lo)) / (math.log(hi) - math.log(lo))
    return math.exp((1 - t) * math.log(POINCARE_ERROR[lo]) + t * math.log(POINCARE_ERROR[hi]))
