"""Hypothesis profiles. The default ``ci`` profile is derandomised: every run draws the same examples,
so a result of ``.ci/run`` does not depend on luck. ``HYPOTHESIS_PROFILE=explore`` draws fresh
random examples, ten times as many, to hunt for new failures; add what it finds as ``@example``.

geardyn is imported before anything else, so that its OpenBLAS setting (``geardyn.BLAS_CORETYPE``) holds
in the test process as in the pipeline's jobs."""

import os

from hypothesis import settings

import geardyn  # noqa: F401 - first: pins OpenBLAS's kernels before any test module loads numpy

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", derandomize=False, deadline=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
