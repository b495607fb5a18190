"""Hypothesis profiles. The default ``ci`` profile is derandomised: every run draws the same examples,
so a result of ``.ci/run`` does not depend on luck. ``HYPOTHESIS_PROFILE=explore`` draws fresh
random examples, ten times as many, to hunt for new failures; add what it finds as ``@example``.

pytest restarts itself once (before any test or worker starts) when it runs the C library's math
functions built with fused multiply-adds: the tests then compute the bits that the pipeline's jobs
compute on every x86-64 CPU (``geardyn.libm``).

geardyn is imported before anything else, so that its OpenBLAS setting (``geardyn.BLAS_CORETYPE``) holds
in the test process as in the pipeline's jobs."""

import os

from hypothesis import settings

import geardyn  # first: pins OpenBLAS's kernels before any test module loads numpy

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", derandomize=False, deadline=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def pytest_configure(config):
    """The restart (:func:`geardyn.libm.restart_canonical`) with pytest's own output capture stopped, so
    that the new process writes to the terminal."""
    if geardyn.libm.needs_restart() and not os.environ.get("PYTEST_XDIST_WORKER"):
        capman = config.pluginmanager.getplugin("capturemanager")
        if capman is not None:
            capman.stop_global_capturing()
        geardyn.libm.restart_canonical()
